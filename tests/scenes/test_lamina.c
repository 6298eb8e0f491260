/* Diana & Casolo sec. 3: the square lamina under traction, pure shear and pure bending with the
 * shear-bond (pds) and micropolar (mppd, gerstle) models, plane stress, nu in {-0.5, 0, 0.1, 0.25}.
 *
 * References, all computed here independently of perilin's assembly:
 *  - the homogenized stiffness of the infinite m = 3 lattice for each model (normal springs c,
 *    shear springs g or 12 d/|xi|^2 with the continuum calibration of eqs. 7, 21, 43, theta = 0 in
 *    homogeneous states): the effective nu, E (traction) and G (shear) the plate should approach;
 *  - the same for pmb at nu = 1/3 on the same plate, whose distance to its own lattice value is
 *    what a finite 61 x 61 plate measured over its 2-delta interior costs (boundary layers);
 *  - exact plane elasticity for bending (summary error.l2_rel).
 * Asserted: traction nu and E within 0.02 / 3 % of the lattice values; shear G within the pmb
 * plate's own distance to its lattice value + 2 %; bending within the 5 % of exact
 * elasticity for mppd, and for gerstle within 5 % of the elastic solution with its lattice's
 * constants (its 1/|xi|^2 shear springs homogenize to nu_eff = 0.08 at nu = 0 on this lattice,
 * docs/models/mppd.md); pds off by more than 30 % (the paper: 51-200 %). These run with the papers'
 * calibration (model.calibration: continuum, corrections.surface: volume).
 *
 * model.calibration: lattice (perilin's default for these models) against an exact isotropic
 * continuum loaded and measured exactly as these scenes (docs/tools/lamina_static_fem.py, an
 * independent Q9 FEM converged to 4-5 digits; its numbers are typed in below). The scenes' own
 * loading biases every exact material (G_eff 6 % low, nu_eff -0.4855 at -0.5: the loaded layers
 * are delta deep), so that FEM, not E, nu, G, is what an exact lattice must give. Asserted for mppd
 * and gerstle at every nu: nu_eff within 0.003 of the FEM's, E_eff and G_eff within 0.3 %, and
 * bending error.l2_rel within 0.3 percentage points of the FEM's own (all measured within half of
 * that, docs/models/lattice.md) and below the 3 %; pds (not rotation invariant: its shear
 * and bending are its own) nu_eff within 0.006.
 *
 * Stress (src/system/stress.c), on every lattice traction run: the body's integral of the
 * bond-force stress, sum_i V_i sigma_i, equals the virial of the applied forces, sigma l t (y_top -
 * y_bottom) in yy (the loaded layers' mean heights 0.595 and 0.015 m) and 0 elsewhere, for every
 * model (to 1e-6 of it: the solve's tolerance); at nu = 0 (where an exact continuum is homogeneous
 * on this scene) the centre particle's bond-force and elastic stresses are sigma within 1 %
 * (the check; measured 0.14 %) and its strain sigma / E within 1 %. */
#include "testing.h"
#include <slepcsys.h>

typedef enum {
  LATTICE_PMB,
  LATTICE_PDS_MPPD,
  LATTICE_GERSTLE
} LatticeModel;

static PetscReal Alpha(PetscReal r, PetscReal m)
{
  if (r >= m + 0.5) return 0;
  if (r <= m - 0.5) return 1;
  return m + 0.5 - r;
}

/* plane stress, unit E, t, spacing: effective nu, E, G of the lattice */
static void LatticePlane(LatticeModel model, PetscBool strain, PetscReal nu, PetscReal m, PetscReal *nu_eff, PetscReal *E_eff, PetscReal *G_eff)
{
  const PetscReal d3 = m * m * m;
  const PetscReal c  = strain ? 6 / (PETSC_PI * d3 * (1 - 2 * nu) * (1 + nu)) : 6 / (PETSC_PI * d3 * (1 - nu));
  const PetscReal g = strain ? 6 * (1 - 4 * nu) / (PETSC_PI * d3 * (1 - 2 * nu) * (1 + nu)) : 6 * (1 - 3 * nu) / (PETSC_PI * d3 * (1 - nu * nu)), d = g * m * m / 36;
  PetscReal       C[3][3] = {{0}}, det;
  PetscInt        R       = (PetscInt)m + 2;
  for (PetscInt i = -R; i <= R; i++)
    for (PetscInt j = -R; j <= R; j++) {
      PetscReal L = PetscSqrtReal((PetscReal)(i * i + j * j)), a, ex, ey, tx, ty, kt, bs[3], bg[3];
      if (!i && !j) continue;
      a = Alpha(L, m);
      if (a <= 0) continue;
      ex = i / L, ey = j / L, tx = -ey, ty = ex;
      kt    = model == LATTICE_PMB ? 0 : (model == LATTICE_GERSTLE ? 12 * d / (L * L) : g);
      bs[0] = ex * ex, bs[1] = ey * ey, bs[2] = ex * ey;
      bg[0] = tx * ex, bg[1] = ty * ey, bg[2] = 0.5 * (tx * ey + ty * ex);
      for (PetscInt p = 0; p < 3; p++)
        for (PetscInt q = 0; q < 3; q++) C[p][q] += 0.5 * a * (c * L * bs[p] * bs[q] + kt * L * bg[p] * bg[q]);
    }
  det     = C[0][0] * C[1][1] - C[0][1] * C[1][0];
  *nu_eff = C[0][1] / C[0][0];
  *E_eff  = det / C[0][0]; /* 1 / e_yy for unit sigma_yy */
  *G_eff  = C[2][2];
}

static void Lattice(LatticeModel model, PetscReal nu, PetscReal m, PetscReal *nu_eff, PetscReal *E_eff, PetscReal *G_eff)
{
  LatticePlane(model, PETSC_FALSE, nu, m, nu_eff, E_eff, G_eff);
}

static PetscErrorCode Run(const char[], const char[], const char[], const char[], PeriProblem *);

/* Runs a scene that may legitimately fail to converge: returns the PETSc error code. */
static PetscErrorCode TryRun(const char file[], PeriProblem *p, PetscErrorCode *ierr)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  *ierr = PeriTestRunScene(PETSC_COMM_WORLD, file, p);
  PetscCall(PetscPopErrorHandler());
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Stability at the extremes (issue 3): nu -> -1, nu above the bond-based value (negative shear
 * springs), plane strain nu -> 1/2, and m from 1.5 to 6. Each gives the lattice's answer, or, for CG
 * on an indefinite operator, the not-converged error that names the reason. */
static PetscErrorCode Extremes(const char dir[])
{
  const char *const models[] = {"pds", "mppd", "gerstle"};
  char              file[PETSC_MAX_PATH_LEN], what[200];
  PetscReal         lnu, lE, lG;
  PeriProblem       p = NULL;
  PetscMPIInt       rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCall(PetscSNPrintf(file, sizeof(file), "%s/traction.yaml", dir));
  for (int mo = 0; mo < 3; mo++) {
    LatticeModel lm = mo == 2 ? LATTICE_GERSTLE : LATTICE_PDS_MPPD;
    /* nu -> -1: the auxetic limit; CG still converges, more slowly */
    Lattice(lm, -0.99, 3, &lnu, &lE, &lG);
    PetscCall(Run(dir, "traction", models[mo], "-0.99", &p));
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s nu=-0.99 traction: nu_eff vs lattice", models[mo]));
    if (!rank) PeriTestClose(what, p->sys->reference.effective_nu, lnu, 0.03);
    PetscCall(PeriProblemDestroy(&p));
    /* nu = 0.34 > 1/3: negative shear springs. The direct solver always answers; CG either converges
     * or stops with a reason */
    Lattice(lm, 0.34, 3, &lnu, &lE, &lG);
    for (int direct = 0; direct < 2; direct++) {
      PetscErrorCode ierr;
      PetscCall(PeriTestSetOption("-ksp_type", direct ? "preonly" : NULL));
      PetscCall(PeriTestSetOption("-pc_type", direct ? "lu" : NULL));
      PetscCall(PeriTestSetOption("-model_type", models[mo]));
      PetscCall(PeriTestSetOption("-material_nu", "0.34"));
      PetscCall(TryRun(file, &p, &ierr));
      if (ierr) {
        PetscCheck(!direct && ierr == PETSC_ERR_NOT_CONVERGED, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s nu=0.34 (%s): unexpected error %d", models[mo], direct ? "lu" : "cg", (int)ierr);
        PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s nu=0.34 with CG: stops with 'did not converge' (indefinite), as documented\n", models[mo]));
      } else {
        PetscCall(PetscSNPrintf(what, sizeof(what), "%s nu=0.34 (%s) traction: nu_eff vs lattice", models[mo], direct ? "lu" : "cg"));
        if (!rank) PeriTestClose(what, p->sys->reference.effective_nu, lnu, 0.02);
      }
      PetscCall(PeriProblemDestroy(&p));
      PetscCall(PeriTestSetOption("-ksp_type", NULL));
      PetscCall(PeriTestSetOption("-pc_type", NULL));
    }
  }
  /* plane strain towards incompressibility, direct solver: the in-plane Poisson ratio nu/(1-nu) of
   * the lattice; at 0.499 the lattice locks (its nu' is 0.93 where elasticity has 0.996; the plate gives 0.89) */
  {
    const char *const nus[] = {"0.3", "0.45", "0.499"};
    PetscCall(PeriTestSetOption("-model_plane", "strain"));
    PetscCall(PeriTestSetOption("-ksp_type", "preonly"));
    PetscCall(PeriTestSetOption("-pc_type", "lu"));
    for (int k = 0; k < 3; k++) {
      LatticePlane(LATTICE_PDS_MPPD, PETSC_TRUE, (PetscReal)atof(nus[k]), 3, &lnu, &lE, &lG);
      PetscCall(Run(dir, "traction", "mppd", nus[k], &p));
      PetscCall(PetscSNPrintf(what, sizeof(what), "mppd plane strain nu=%s (lu): in-plane nu_eff vs lattice", nus[k]));
      if (!rank) PeriTestClose(what, p->sys->reference.effective_nu, lnu, 0.035);
      PetscCall(PeriProblemDestroy(&p));
    }
    PetscCall(PeriTestSetOption("-model_plane", NULL));
    PetscCall(PeriTestSetOption("-ksp_type", NULL));
    PetscCall(PeriTestSetOption("-pc_type", NULL));
  }
  /* the horizon from 1.5 to 6 spacings */
  {
    const char *const ms[] = {"1.5", "2", "3", "4", "6"};
    for (int k = 0; k < 5; k++) {
      Lattice(LATTICE_PDS_MPPD, 0.25, (PetscReal)atof(ms[k]), &lnu, &lE, &lG);
      PetscCall(PeriTestSetOption("-horizon_m", ms[k]));
      PetscCall(Run(dir, "traction", "mppd", "0.25", &p));
      PetscCall(PetscSNPrintf(what, sizeof(what), "mppd nu=0.25 m=%s traction: nu_eff vs lattice", ms[k]));
      if (!rank) PeriTestClose(what, p->sys->reference.effective_nu, lnu, 0.02);
      PetscCall(PeriProblemDestroy(&p));
    }
    PetscCall(PeriTestSetOption("-horizon_m", NULL));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* the exact continuum on the scenes at dx = 0.01 (docs/tools/lamina_static_fem.py): per nu
 * -0.5, 0, 0.1, 0.25, 1/3: E_eff / E - 1, nu_eff, G_eff / G - 1, bending l2_rel */
static const PetscReal fem_scene[5][4] = {
    {0.011187, -0.48546, -0.06947, 0.0143},
    {0.0, 0.0, -0.06172, 0.0},
    {-0.001611, 0.09732, -0.06101, 0.00252},
    {-0.003645, 0.24370, -0.06016, 0.00612},
    {-0.004579, 0.32530, -0.05977, 0.00804}};

/* the stress checks of the header, on rank 0 */
static PetscErrorCode StressChecks(PeriProblem p, const char model[], const char nu[])
{
  const PeriParticles *pt    = &p->sys->disc.particles;
  const PetscReal      sigma = 1e7, virial_yy = sigma * 0.61 * 0.001 * (0.595 - 0.015);
  PetscReal            V[9] = {0}, best = PETSC_MAX_REAL;
  PetscInt             c = 0;
  char                 what[160];

  PetscFunctionBeginUser;
  if (p->rank) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt i = 0; i < pt->n; i++) {
    PetscReal d2 = PetscSqr(pt->x[3 * i] - 0.305) + PetscSqr(pt->x[3 * i + 1] - 0.305);
    for (PetscInt k = 0; k < 9; k++) V[k] += pt->volume[i] * p->sys->fields.stress[9 * i + k];
    if (d2 < best) best = d2, c = i;
  }
  PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=%s traction: sum V sigma_yy / virial of the loads", model, nu));
  PeriTestClose(what, V[4] / virial_yy, 1.0, 1e-6);
  PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=%s traction: |sum V sigma_xx|, |sum V sigma_xy| / virial", model, nu));
  PeriTestClose(what, PetscMax(PetscAbsReal(V[0]), PetscAbsReal(V[1])) / virial_yy, 0.0, 1e-6);
  if (strcmp(nu, "0")) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=0 traction: centre sigma_yy (bond forces) / sigma", model));
  PeriTestClose(what, p->sys->fields.stress[9 * c + 4] / sigma, 1.0, 0.01);
  PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=0 traction: centre sigma_yy (C : eps) / sigma", model));
  PeriTestClose(what, p->sys->fields.elastic_stress[9 * c + 4] / sigma, 1.0, 0.01);
  PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=0 traction: centre eps_yy E / sigma", model));
  PeriTestClose(what, p->sys->fields.strain[9 * c + 4] * 7e10 / sigma, 1.0, 0.01);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode LatticeTargets(const char dir[])
{
  const char *const nus[] = {"-0.5", "0", "0.1", "0.25", "1/3"}, *const models[] = {"pds", "mppd", "gerstle"};
  const PetscReal E = 7e10;
  PeriProblem     p;
  PetscMPIInt     rank;
  char            what[160];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCall(PeriTestSetOption("-model_calibration", NULL));
  PetscCall(PeriTestSetOption("-corrections_surface", NULL));
  PetscCall(PeriTestSetOption("-output_stress", "true"));
  for (int k = 0; k < 5; k++) {
    PetscReal nu = k == 4 ? 1.0 / 3 : (PetscReal)atof(nus[k]), G = E / (2 * (1 + nu));
    for (int mo = 0; mo < 3; mo++) {
      PetscCall(Run(dir, "traction", models[mo], nus[k], &p));
      if (!rank) {
        PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=%s traction: nu_eff vs the scene's exact continuum", models[mo], nus[k]));
        PeriTestClose(what, p->sys->reference.effective_nu, fem_scene[k][1], mo ? 0.003 : 0.006);
        PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=%s traction: E_eff / E - 1 vs the scene's exact continuum", models[mo], nus[k]));
        if (mo) PeriTestClose(what, p->sys->reference.effective_E / E - 1, fem_scene[k][0], 0.003);
      }
      PetscCall(StressChecks(p, models[mo], nus[k]));
      PetscCall(PeriProblemDestroy(&p));
      if (!mo) continue;
      PetscCall(Run(dir, "shear", models[mo], nus[k], &p));
      PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=%s shear: G_eff / G - 1 vs the scene's exact continuum", models[mo], nus[k]));
      if (!rank) PeriTestClose(what, p->sys->reference.effective_G / G - 1, fem_scene[k][2], 0.003);
      PetscCall(PeriProblemDestroy(&p));
      PetscCall(Run(dir, "bending", models[mo], nus[k], &p));
      PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=%s bending: l2_rel vs the scene's exact continuum's", models[mo], nus[k]));
      if (!rank) {
        PeriTestClose(what, p->sys->reference.error_l2_rel, fem_scene[k][3], 0.003);
        PetscCheck(p->sys->reference.error_l2_rel <= 0.03, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: above 3 %%", what);
      }
      PetscCall(PeriProblemDestroy(&p));
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Run(const char dir[], const char scene[], const char model[], const char nu[], PeriProblem *p)
{
  char file[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-reference_E", NULL));
  PetscCall(PeriTestSetOption("-reference_nu", NULL));
  PetscCall(PetscSNPrintf(file, sizeof(file), "%s/%s.yaml", dir, scene));
  PetscCall(PeriTestSetOption("-model_type", model));
  PetscCall(PeriTestSetOption("-material_nu", nu));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, file, p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const char *const nus[]    = {"-0.5", "0", "0.1", "0.25"};
  const char *const models[] = {"pds", "mppd", "gerstle"};
  const PetscReal   E = 7e10, sigma = 1e7;
  PetscReal         lnu, lE, lG, shear_allow;
  PeriProblem       p;
  PetscMPIInt       rank;
  char              what[160];

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_lamina examples/lamina");
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCall(PeriTestSetOption("-model_calibration", "continuum"));
  PetscCall(PeriTestSetOption("-corrections_surface", "volume"));

  /* what the finite plate costs: pmb (= pds at nu = 1/3) against its own lattice */
  Lattice(LATTICE_PMB, 1.0 / 3, 3, &lnu, &lE, &lG);
  PetscCall(Run(argv[1], "shear", "pds", "1/3", &p));
  shear_allow = PetscAbsReal(p->sys->reference.effective_G / (E * lG) - 1) + 0.02;
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "pmb plate: G_eff / G_lattice - 1 = %+.4f: shear tolerance %.4f\n", (double)(p->sys->reference.effective_G / (E * lG) - 1), (double)shear_allow));
  PetscCall(PeriProblemDestroy(&p));

  for (int k = 0; k < 4; k++) {
    PetscReal nu = (PetscReal)atof(nus[k]), G = E / (2 * (1 + nu));
    for (int mo = 0; mo < 3; mo++) {
      LatticeModel lm = mo == 2 ? LATTICE_GERSTLE : LATTICE_PDS_MPPD;
      Lattice(lm, nu, 3, &lnu, &lE, &lG);

      PetscCall(Run(argv[1], "traction", models[mo], nus[k], &p));
      if (!rank) {
        PetscCall(PetscSNPrintf(what, sizeof(what), "%s nu=%s traction: nu_eff vs lattice", models[mo], nus[k]));
        PeriTestClose(what, p->sys->reference.effective_nu, lnu, 0.02);
        PetscCall(PetscSNPrintf(what, sizeof(what), "%s nu=%s traction: E_eff / E_lattice", models[mo], nus[k]));
        PeriTestClose(what, p->sys->reference.effective_E / (E * lE), 1.0, 0.03);
      }
      PetscCall(PeriProblemDestroy(&p));

      PetscCall(Run(argv[1], "shear", models[mo], nus[k], &p));
      if (!rank) {
        PetscCall(PetscSNPrintf(what, sizeof(what), "%s nu=%s shear: G_eff / G_lattice (exact G ratio %.4f)", models[mo], nus[k], (double)(p->sys->reference.effective_G / G)));
        PeriTestClose(what, p->sys->reference.effective_G / (E * lG), 1.0, shear_allow);
      }
      PetscCall(PeriProblemDestroy(&p));

      PetscCall(Run(argv[1], "bending", models[mo], nus[k], &p));
      if (mo == 2) {
        /* gerstle: against the elastic solution of its own lattice constants */
        char Es[64], nus_l[64];
        PetscCall(PeriProblemDestroy(&p));
        PetscCall(PetscSNPrintf(Es, sizeof(Es), "%.10g", (double)(E * lE)));
        PetscCall(PetscSNPrintf(nus_l, sizeof(nus_l), "%.10g", (double)lnu));
        PetscCall(PetscSNPrintf(what, sizeof(what), "%s/bending.yaml", argv[1]));
        PetscCall(PeriTestSetOption("-model_type", models[mo]));
        PetscCall(PeriTestSetOption("-material_nu", nus[k]));
        PetscCall(PeriTestSetOption("-reference_E", Es));
        PetscCall(PeriTestSetOption("-reference_nu", nus_l));
        PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, what, &p));
      }
      if (!rank) {
        PetscReal err = p->sys->reference.error_l2_rel;
        PetscCall(PetscSNPrintf(what, sizeof(what), "%s nu=%s bending: interior l2 error vs elasticity%s", models[mo], nus[k], mo == 2 ? " with the lattice's E, nu" : ""));
        if (mo == 0) {
          PetscCheck(err > 0.3, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: %g, but pds should miss bending by tens of percent (Table 3)", what, (double)err);
          PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s = %.4f > 0.3 (pds misses bending)\n", what, (double)err));
        } else
          PeriTestClose(what, err, 0.0, 0.05);
      }
      PetscCall(PeriProblemDestroy(&p));
    }
  }
  (void)sigma;
  PetscCall(Extremes(argv[1]));
  PetscCall(LatticeTargets(argv[1]));
  PetscCall(PeriFinalize());
  return 0;
}
