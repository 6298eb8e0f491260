/* Modal analysis against published and independently computed values.
 *  - examples/lamina/modal.yaml (Diana & Casolo sec. 3.1, Tables 4-6): mppd's first three modes
 *    (flexural, axial, flexural) within 3 % of the FEM column for every nu; gerstle within 3 % where
 *    its lattice homogenizes to the elastic constants (nu >= 0.25; below, docs/models/mppd.md);
 *    pds reproduces the paper's failure: its first flexural frequency is > 50 % too high for
 *    nu != 1/3 and within 3 % of the paper's PDS column; at nu = 1/3 the three models coincide
 *    (all with the papers' calibration: model.calibration continuum, surface correction volume).
 *    With perilin's default lattice calibration, mppd and gerstle: the three modes within 1.5 % of
 *    the converged plane-stress FEM (docs/tools/lamina_fem.py, docs/modal.md) for nu < 1/3; at
 *    nu = 1/3 f_I is 1.65 % low at dx = 10 mm (the 1.5 % missed, docs/models/lattice.md),
 *    so there the error is asserted to shrink at dx = 5 mm (measured 1.06 %). nu = 0.3333333333
 *    gives gerstle the modes of 1/3 (1e-6), not spurious rotational ones of a few Hz.
 *  - examples/pmb/bar_modes.yaml (Ganzenmueller sec. 3.1.2): the longitudinal speed of a free bar
 *    equals sqrt(C11/rho) of the cubic lattice, C11 from the lattice sums computed here (npmb:
 *    9K sum e_x^4 / N; pmb: 9K sum |xi| e_x^4 / (pi delta^4)), within 0.2 %, and the theory
 *    sqrt((K + 4G/3)/rho) within the lattice's own anisotropy.
 *  - analysis.target_hz: the modes nearest the target in frequency, nearest first, against the
 *    lowest modes of a run without target (within 1e-8), also where omega^2 would pick another.
 *  - refusals: a preconditioner alone as the inner solve of shift-and-invert fails on the inner
 *    residual, CG to 1e-3 on the modes' residuals; CG to 1e-12 agrees with Cholesky (1e-8). */
#include "testing.h"
#include <slepcsys.h>

static const PetscReal fem[5][3] = {
    {1195.0, 2400.2, 3245.3},
    {1047.2, 2320.0, 2771.2},
    {1027.9, 2322.6, 2712.0},
    {1002.5, 2330.4, 2635.9},
    {989.89, 2336.3, 2590.0}};
/* converged plane-stress FEM (docs/modal.md, "Against the converged FEM") */
static const PetscReal fem_converged[5][3] = {
    {1194.53, 2399.91, 3244.57},
    {1047.11, 2320.83, 2771.45},
    {1027.78, 2322.61, 2712.31},
    {1002.28, 2330.32, 2636.22},
    {989.61, 2336.15, 2599.35}};
static const PetscReal paper_pds_fI[4] = {3661.5, 2294.9, 2025.5, 1565.9};

static PetscErrorCode RunModal(const char file[], const char model[], const char nu[], PeriProblem *p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-model_type", model));
  PetscCall(PeriTestSetOption("-material_nu", nu));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, file, p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Lamina(const char file[])
{
  const char *const nus[] = {"-0.5", "0", "0.1", "0.25", "1/3"}, *const kinds[] = {"flexural", "axial", "flexural"};
  const char *const models[] = {"mppd", "gerstle", "pds"};
  PetscReal         f13[3][3];
  char              what[160];

  PetscFunctionBeginUser;
  for (int k = 0; k < 5; k++)
    for (int mo = 0; mo < 3; mo++) {
      PeriProblem p;
      PeriModal  *md;
      PetscCall(RunModal(file, models[mo], nus[k], &p));
      md = PeriTestModal(p);
      for (int m = 0; m < 3; m++) PetscCheck(md->modes[m].residual < 1e-8, PETSC_COMM_SELF, PETSC_ERR_PLIB, "mode %d residual %g", m, (double)md->modes[m].residual);
      if (mo == 0 || (mo == 1 && k >= 3)) {
        for (int m = 0; m < 3; m++) {
          PetscCall(PetscSNPrintf(what, sizeof(what), "%s nu=%s mode %d (%s) f / f_FEM", models[mo], nus[k], m + 1, md->modes[m].kind));
          PeriTestClose(what, md->modes[m].f_hz / fem[k][m], 1.0, 0.03);
          PetscCheck(!strcmp(md->modes[m].kind, kinds[m]), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: kind %s, expected %s", what, md->modes[m].kind, kinds[m]);
        }
      } else if (mo == 2 && k < 4) {
        PetscReal fI = md->modes[0].f_hz;
        /* the first flexural mode; at nu = 0 it is degenerate with the axial one (c = g) */
        for (PetscInt m = 0; m < md->nmodes; m++)
          if (!strcmp(md->modes[m].kind, "flexural")) {
            fI = k == 1 ? md->modes[0].f_hz : md->modes[m].f_hz;
            break;
          }
        PetscCall(PetscSNPrintf(what, sizeof(what), "pds nu=%s first flexural f / f_FEM - 1 > 0.5 (paper PDS %+.0f %%)", nus[k], (double)(100 * (paper_pds_fI[k] / fem[k][0] - 1))));
        PetscCheck(fI / fem[k][0] - 1 > 0.5, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: got %g", what, (double)(fI / fem[k][0] - 1));
        PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s: %+.1f %%\n", what, (double)(100 * (fI / fem[k][0] - 1))));
        PetscCall(PetscSNPrintf(what, sizeof(what), "pds nu=%s first flexural f / paper's PDS f_I", nus[k]));
        PeriTestClose(what, fI / paper_pds_fI[k], 1.0, 0.03);
      }
      if (k == 4)
        for (int m = 0; m < 3; m++) f13[mo][m] = md->modes[m].f_hz;
      PetscCall(PeriProblemDestroy(&p));
    }
  for (int mo = 1; mo < 3; mo++)
    for (int m = 0; m < 3; m++) {
      PetscCall(PetscSNPrintf(what, sizeof(what), "nu=1/3: %s mode %d / mppd", models[mo], m + 1));
      PeriTestClose(what, f13[mo][m] / f13[0][m], 1.0, 1e-6);
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* f_I, f_II, f_III: the first flexural, the first axial, the second flexural mode */
static void ThreeModes(const PeriModal *md, PetscReal f[3])
{
  PetscInt nf = 0, na = 0;
  f[0] = f[1] = f[2] = 0;
  for (PetscInt m = 0; m < md->nmodes; m++) {
    if (!strcmp(md->modes[m].kind, "flexural") && nf < 2) f[nf++ ? 2 : 0] = md->modes[m].f_hz;
    if (!strcmp(md->modes[m].kind, "axial") && !na++) f[1] = md->modes[m].f_hz;
  }
}

static PetscErrorCode LaminaLattice(const char file[])
{
  const char *const nus[] = {"-0.5", "0", "0.1", "0.25", "1/3"}, *const models[] = {"mppd", "gerstle"};
  char what[160];

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-model_calibration", NULL));
  PetscCall(PeriTestSetOption("-corrections_surface", NULL));
  for (int k = 0; k < 5; k++)
    for (int mo = 0; mo < 2; mo++) {
      PeriProblem p;
      PetscReal   f[3];
      PetscCall(RunModal(file, models[mo], nus[k], &p));
      ThreeModes(PeriTestModal(p), f);
      PetscCall(PeriProblemDestroy(&p));
      for (int m = 0; m < 3 && k < 4; m++) {
        PetscCall(PetscSNPrintf(what, sizeof(what), "lattice %s nu=%s f_%s / converged FEM", models[mo], nus[k], m == 0 ? "I" : m == 1 ? "II"
                                                                                                                                       : "III"));
        PeriTestClose(what, f[m] / fem_converged[k][m], 1.0, 0.015);
      }
      if (k == 4 && mo == 1) { /* nu typed as 0.3333333333: the same model as 1/3, no spurious theta modes */
        PetscReal g[3];
        PetscCall(RunModal(file, models[mo], "0.3333333333", &p));
        ThreeModes(PeriTestModal(p), g);
        PetscCall(PeriProblemDestroy(&p));
        for (int m = 0; m < 3; m++) PeriTestClose("gerstle nu=0.3333333333 modes / nu=1/3 modes", g[m] / f[m], 1.0, 1e-6);
      }
      if (k == 4 && mo == 0) { /* nu = 1/3: the error shrinks with dx at fixed m */
        PetscReal g[3];
        PetscCall(PeriTestSetOption("-grid_spacing", "0.005"));
        PetscCall(RunModal(file, models[mo], nus[k], &p));
        PetscCall(PeriTestSetOption("-grid_spacing", NULL));
        ThreeModes(PeriTestModal(p), g);
        PetscCall(PeriProblemDestroy(&p));
        for (int m = 0; m < 3; m++) {
          PetscReal e1 = PetscAbsReal(f[m] / fem_converged[k][m] - 1), e2 = PetscAbsReal(g[m] / fem_converged[k][m] - 1);
          PetscCheck(e2 < 0.8 * e1 && e2 < 0.015, PETSC_COMM_SELF, PETSC_ERR_PLIB, "lattice mppd nu=1/3 mode %d: error %g at dx 10 mm, %g at 5 mm: should shrink below 1.5 %%", m + 1, (double)e1, (double)e2);
          PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: lattice mppd nu=1/3 mode %d: |error| vs converged FEM %.4f at dx 10 mm -> %.4f at 5 mm\n", m + 1, (double)e1, (double)e2));
        }
      }
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* C11 / (K + 4G/3) of the cubic lattice (unit spacing, no partial volumes) for delta */
static PetscReal LatticeC11Ratio(PetscBool normalized, PetscReal delta)
{
  PetscReal s4 = 0, n = 0;
  PetscInt  R = (PetscInt)delta + 1;
  for (PetscInt i = -R; i <= R; i++)
    for (PetscInt j = -R; j <= R; j++)
      for (PetscInt k = -R; k <= R; k++) {
        PetscReal L = PetscSqrtReal((PetscReal)(i * i + j * j + k * k)), ex;
        if (L == 0 || L > delta * (1 + 1e-12)) continue;
        ex = i / L;
        s4 += (normalized ? 1 : L) * ex * ex * ex * ex;
        n += 1;
      }
  /* K + 4G/3 = 9K/5 at nu = 1/4 */
  return normalized ? 9 * s4 / n / 1.8 : 9 * s4 / (PETSC_PI * PetscPowReal(delta, 4)) / 1.8;
}

static PetscErrorCode Bar(const char file[])
{
  const char *const models[] = {"npmb", "pmb"};
  char              what[160];

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-material_nu", NULL));
  for (int mo = 0; mo < 2; mo++) {
    PeriProblem p;
    PetscReal   lat = PetscSqrtReal(LatticeC11Ratio(mo == 0 ? PETSC_TRUE : PETSC_FALSE, 2.5)), ratio;
    PetscCall(PeriTestSetOption("-model_type", models[mo]));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, file, &p));
    PetscCheck(PeriTestModal(p)->longitudinal_speed > 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "no longitudinal mode among the %" PetscInt_FMT " computed", PeriTestModal(p)->nmodes);
    PetscCheck(PeriTestModal(p)->nrigid == 3, PETSC_COMM_SELF, PETSC_ERR_PLIB, "expected the 3 translations as rigid modes, got %" PetscInt_FMT, PeriTestModal(p)->nrigid);
    ratio = PeriTestModal(p)->longitudinal_speed / PeriTestModal(p)->theory_speed;
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s bar: c / c_lattice (c / theory = %.4f, paper: %s)", models[mo], (double)ratio, mo ? "+13 %" : "< 1 %"));
    PeriTestClose(what, ratio / lat, 1.0, 2e-3);
    PetscCall(PeriProblemDestroy(&p));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Stability at the extremes: a lamina held by a single particle row, nu -> -1, more modes asked
 * than there are free DOFs. */
static PetscErrorCode Extremes(const char lamina[], const char tiny[])
{
  PeriProblem p, q;
  char        what[160];

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-model_type", "mppd"));
  PetscCall(PeriTestSetOption("-material_nu", "0"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, lamina, &q));
  PetscCall(PeriTestSetOption("-regions_base_depth", "0.01"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, lamina, &p));
  PetscCall(PeriTestSetOption("-regions_base_depth", NULL));
  for (int m = 0; m < 3; m++) PetscCheck(PeriTestModal(p)->modes[m].residual < 1e-8, PETSC_COMM_SELF, PETSC_ERR_PLIB, "single-row clamp: mode %d residual %g", m, (double)PeriTestModal(p)->modes[m].residual);
  PetscCheck(PeriTestModal(p)->modes[0].f_hz < PeriTestModal(q)->modes[0].f_hz && !strcmp(PeriTestModal(p)->modes[0].kind, "flexural"), PETSC_COMM_SELF, PETSC_ERR_PLIB, "a one-row clamp must be softer than a three-row one");
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: one-row clamp: f1 = %.1f Hz < %.1f Hz (three rows), residuals < 1e-8\n", (double)PeriTestModal(p)->modes[0].f_hz, (double)PeriTestModal(q)->modes[0].f_hz));
  PetscCall(PeriProblemDestroy(&p));

  PetscCall(PeriProblemDestroy(&q));

  /* at nu = -0.99 auto's LOBPCG stalls (387 to > 2,500 iterations, machine-dependent) and gives way
     to shift-and-invert; 150 iterations reach that fallback in 3 s rather than 35 */
  PetscCall(PeriTestSetOption("-material_nu", "-0.99"));
  PetscCall(PeriTestSetOption("-eps_max_it", "150"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, lamina, &p));
  PetscCall(PeriTestSetOption("-eps_max_it", NULL));
  for (int m = 0; m < 3; m++) PetscCheck(PeriTestModal(p)->modes[m].residual < 1e-8 && PeriTestModal(p)->modes[m].f_hz > 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "nu = -0.99: mode %d residual %g", m, (double)PeriTestModal(p)->modes[m].residual);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: nu = -0.99: modes at %.1f, %.1f, %.1f Hz with residuals < 1e-8\n", (double)PeriTestModal(p)->modes[0].f_hz, (double)PeriTestModal(p)->modes[1].f_hz, (double)PeriTestModal(p)->modes[2].f_hz));
  PetscCall(PeriProblemDestroy(&p));

  PetscCall(PeriTestSetOption("-model_type", NULL));
  PetscCall(PeriTestSetOption("-material_nu", NULL));
  {
    /* a 1e6 mass ratio: one mode is the tip mass M bouncing on the lamina's axial spring
     * k = F^2/(2 U), U the strain energy under a tip force F spread like the mass; the tip row is not
     * rigid and the lamina's own mass (6e-5 of M) moves too, hence 1 % */
    char        file[PETSC_MAX_PATH_LEN], *slash;
    PeriProblem s;
    PetscReal   M = 0, k, f;
    PetscCall(PetscStrncpy(file, tiny, sizeof(file)));
    slash = strrchr(file, '/');
    PetscCall(PetscStrncpy(slash + 1, "heavy_tip_static.yaml", sizeof(file) - (size_t)(slash + 1 - file)));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, file, &s));
    k = 1000.0 * 1000.0 / (2 * s->sys->fields.strain_energy);
    for (PetscInt r = 0; r < s->sys->disc.nregions; r++)
      if (!strcmp(s->sys->disc.regions[r].name, "tip")) M = 2.5e9 * s->sys->disc.regions[r].volume;
    f = PetscSqrtReal(k / M) / (2 * PETSC_PI);
    PetscCall(PetscStrncpy(slash + 1, "heavy_tip_modal.yaml", sizeof(file) - (size_t)(slash + 1 - file)));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, file, &p));
    {
      /* the bouncing tip carries the mass along the axis: the largest axial effective mass */
      PetscInt best = 0;
      for (PetscInt m = 0; m < PeriTestModal(p)->nmodes; m++)
        if (PeriTestModal(p)->modes[m].effective_mass[1] > PeriTestModal(p)->modes[best].effective_mass[1]) best = m;
      PetscCheck(PeriTestModal(p)->modes[best].residual < 1e-8, PETSC_COMM_SELF, PETSC_ERR_PLIB, "mass ratio 1e6: residual %g", (double)PeriTestModal(p)->modes[best].residual);
      PeriTestClose("mass ratio 1e6: bouncing mode f / (sqrt(k/M) / 2 pi)", PeriTestModal(p)->modes[best].f_hz / f, 1.0, 1e-2);
    }
    PetscCall(PeriProblemDestroy(&s));
    PetscCall(PeriProblemDestroy(&p));
  }
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, tiny, &p));
  PetscCall(PetscSNPrintf(what, sizeof(what), "nev 50 on %" PetscInt_FMT " free DOFs: modes returned", PeriTestModal(p)->nfree_dofs));
  PeriTestClose(what, (PetscReal)PeriTestModal(p)->nmodes, (PetscReal)PeriTestModal(p)->nfree_dofs, 0);
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The nev modes of the run without target (f, ascending) nearest t in frequency, nearest first
 * (ties: the lower): what a run with target t must return, when no mode above f[n-1] can be
 * nearer than the last of them. */
static PetscErrorCode ExpectedNearest(PetscInt n, const PetscReal f[], PetscReal t, PetscInt nev, PetscReal expected[])
{
  PetscBool taken[PERI_MAX_MODES] = {PETSC_FALSE};

  PetscFunctionBeginUser;
  for (PetscInt m = 0; m < nev; m++) {
    PetscInt best = -1;
    for (PetscInt i = 0; i < n; i++)
      if (!taken[i] && (best < 0 || PetscAbsReal(f[i] - t) < PetscAbsReal(f[best] - t))) best = i;
    taken[best] = PETSC_TRUE;
    expected[m] = f[best];
  }
  PetscCheck(PetscAbsReal(expected[nev - 1] - t) < f[n - 1] - t, PETSC_COMM_SELF, PETSC_ERR_PLIB, "target %g: a mode above %g Hz could be nearer than %g Hz: choose another target", (double)t, (double)f[n - 1], (double)expected[nev - 1]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode RunTarget(const char lamina[], PetscReal t, PetscInt nev, PeriProblem *p)
{
  char v[64];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(v, sizeof(v), "%.17g", (double)t));
  PetscCall(PeriTestSetOption("-analysis_target_hz", v));
  PetscCall(PetscSNPrintf(v, sizeof(v), "%" PetscInt_FMT, nev));
  PetscCall(PeriTestSetOption("-analysis_nev", v));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, lamina, p));
  PetscCall(PeriTestSetOption("-analysis_target_hz", NULL));
  PetscCall(PeriTestSetOption("-analysis_nev", NULL));
  PetscCheck(PeriTestModal(*p)->nmodes == nev, PETSC_COMM_SELF, PETSC_ERR_PLIB, "target %g Hz: %" PetscInt_FMT " modes, asked for %" PetscInt_FMT, (double)t, PeriTestModal(*p)->nmodes, nev);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.target_hz returns the modes nearest the target in frequency, nearest first. The
 * reference: the lowest six modes of the same lamina computed without a target. Frequencies of
 * the same pencil from two shifts agree to the eigensolver's tolerance (1e-10): 1e-8. */
static PetscErrorCode Target(const char lamina[])
{
  PeriProblem q, p;
  PetscReal   f[PERI_MAX_MODES], expected[3], t;
  PetscInt    n;
  char        what[160];

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-model_type", "mppd"));
  PetscCall(PeriTestSetOption("-material_nu", "0"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, lamina, &q));
  n = PetscMin(PeriTestModal(q)->nmodes, PERI_MAX_MODES);
  PetscCheck(n == 6, PETSC_COMM_SELF, PETSC_ERR_PLIB, "expected the 6 lowest modes, got %" PetscInt_FMT, n);
  for (PetscInt i = 0; i < n; i++) f[i] = PeriTestModal(q)->modes[i].f_hz;

  /* strictly between modes 2 and 3, nearer 3: mode 3, then mode 2, then the nearer of 1 and 4 */
  t = f[1] + 0.7 * (f[2] - f[1]);
  PetscCall(ExpectedNearest(n, f, t, 3, expected));
  PetscCheck(expected[0] == f[2] && expected[1] == f[1], PETSC_COMM_SELF, PETSC_ERR_PLIB, "target %g: mode 3, then 2, expected nearest", (double)t);
  PetscCall(RunTarget(lamina, t, 3, &p));
  for (PetscInt m = 0; m < 3; m++) {
    PetscCall(PetscSNPrintf(what, sizeof(what), "target %.1f Hz: mode %" PetscInt_FMT " (%s) / the run without target's %.1f Hz", (double)t, m + 1, PeriTestModal(p)->modes[m].kind, (double)expected[m]));
    PeriTestClose(what, PeriTestModal(p)->modes[m].f_hz / expected[m], 1.0, 1e-8);
  }
  PetscCall(PeriProblemDestroy(&p));

  /* nearer mode 2 in frequency but nearer mode 1 in omega^2, the measure SLEPc's target uses:
   * the run must return mode 2 */
  t = 0.5 * (0.5 * (f[0] + f[1]) + PetscSqrtReal(0.5 * (f[0] * f[0] + f[1] * f[1])));
  PetscCheck(f[1] - t < t - f[0] && f[1] * f[1] - t * t > t * t - f[0] * f[0], PETSC_COMM_SELF, PETSC_ERR_PLIB, "target %g: not nearer mode 2 in f and mode 1 in omega^2", (double)t);
  PetscCall(RunTarget(lamina, t, 1, &p));
  PetscCall(PetscSNPrintf(what, sizeof(what), "target %.1f Hz (nearer %.1f Hz in f, %.1f Hz in omega^2): mode / %.1f Hz", (double)t, (double)f[1], (double)f[0], (double)f[1]));
  PeriTestClose(what, PeriTestModal(p)->modes[0].f_hz / f[1], 1.0, 1e-8);
  PetscCall(PeriProblemDestroy(&p));
  /* the same with a Krylov subspace of 3: too few pairs converge to be sure of the nearest, and
   * the run must ask SLEPc for more (-info shows it) */
  PetscCall(PeriTestSetOption("-eps_ncv", "3"));
  PetscCall(RunTarget(lamina, t, 1, &p));
  PetscCall(PeriTestSetOption("-eps_ncv", NULL));
  PetscCall(PetscSNPrintf(what, sizeof(what), "target %.1f Hz, -eps_ncv 3: mode / %.1f Hz", (double)t, (double)f[1]));
  PeriTestClose(what, PeriTestModal(p)->modes[0].f_hz / f[1], 1.0, 1e-8);
  PetscCall(PeriProblemDestroy(&p));
  PetscCall(PeriProblemDestroy(&q));
  PetscCall(PeriTestSetOption("-model_type", NULL));
  PetscCall(PeriTestSetOption("-material_nu", NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The first error's message, caught instead of aborting. */
static char caught[4096];

static PetscErrorCode Catch(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *ctx)
{
  (void)comm;
  (void)line;
  (void)fun;
  (void)file;
  (void)ctx;
  if (p == PETSC_ERROR_INITIAL && !caught[0]) PetscSNPrintf(caught, sizeof(caught), "%s", mess ? mess : "");
  return n;
}

/* The scene with options (pairs, NULL-terminated) must be refused with PETSC_ERR_NOT_CONVERGED
 * and a message that says 'says' and 'advice'. */
static PetscErrorCode ExpectRefused(const char file[], const char *const options[], const char says[], const char advice[])
{
  PeriProblem    p = NULL;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  for (int k = 0; options[k]; k += 2) PetscCall(PeriTestSetOption(options[k], options[k + 1]));
  caught[0] = 0;
  PetscCall(PetscPushErrorHandler(Catch, NULL));
  ierr = PeriTestRunScene(PETSC_COMM_WORLD, file, &p);
  PetscCall(PetscPopErrorHandler());
  for (int k = 0; options[k]; k += 2) PetscCall(PeriTestSetOption(options[k], NULL));
  PetscCheck(ierr == PETSC_ERR_NOT_CONVERGED, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s %s: expected the run refused with PETSC_ERR_NOT_CONVERGED, got error code %d (%s)", options[0], options[1], (int)ierr, caught);
  PetscCheck(strstr(caught, says) && strstr(caught, advice), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s %s: the message does not say \"%s\" and \"%s\": %s", options[0], options[1], says, advice, caught);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: refused as expected: %s\n", caught));
  /* the error left the eigensolver behind (not freed: the run stopped); the problem itself is freed */
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Option sets that give wrong modes are refused; an accurate iterative inner solve is accepted
 * and agrees with the direct one. On a coarse lamina (Delta x = 20 mm, 900 particles). 1e-6 is the
 * floor of PeriResidualTolerance: the smallest tolerance any rtol gives. */
static PetscErrorCode Checks(const char lamina[])
{
  static const char *const jacobi[]   = {"-st_ksp_type", "preonly", "-st_pc_type", "jacobi", NULL};
  static const char *const loose_cg[] = {"-st_ksp_type", "cg", "-st_pc_type", "jacobi", "-st_ksp_rtol", "1e-3", NULL};
  PeriProblem              a, b;
  char                     what[160];

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-model_type", "mppd"));
  PetscCall(PeriTestSetOption("-material_nu", "0"));
  PetscCall(PeriTestSetOption("-grid_spacing", "0.02"));
  /* the default (preonly + Cholesky): accepted, its inner residual recorded */
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, lamina, &a));
  PetscCheck(a->sys->fields.solve.residual_norm > 0 && a->sys->fields.solve.residual_norm <= 1e-6, PETSC_COMM_SELF, PETSC_ERR_PLIB, "direct inner solve: worst true residual %g, expected in (0, 1e-6]", (double)a->sys->fields.solve.residual_norm);
  for (PetscInt m = 0; m < PeriTestModal(a)->nmodes; m++) PetscCheck(PeriTestModal(a)->modes[m].residual <= 1e-6, PETSC_COMM_SELF, PETSC_ERR_PLIB, "mode %" PetscInt_FMT " residual %g", m + 1, (double)PeriTestModal(a)->modes[m].residual);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: direct inner solve: worst true residual %.2g <= 1e-6, the %" PetscInt_FMT " modes' residuals <= 1e-6\n", (double)a->sys->fields.solve.residual_norm, PeriTestModal(a)->nmodes));
  /* a preconditioner alone as the inner solve: refused at its first solve */
  PetscCall(ExpectRefused(lamina, jacobi, "inner solve 1 of the spectral transform", "-st_ksp_type preonly -st_pc_type cholesky"));
  /* CG to 1e-3: each inner solve within its own tolerance (100 rtol), the modes not: refused by the
   * check of the eigenpairs */
  PetscCall(ExpectRefused(lamina, loose_cg, "has the relative residual ||K x - omega^2 M x||", "-eps_tol"));
  /* CG to 1e-12: accepted, the frequencies of the direct solve */
  PetscCall(PeriTestSetOption("-st_ksp_type", "cg"));
  PetscCall(PeriTestSetOption("-st_pc_type", "jacobi"));
  PetscCall(PeriTestSetOption("-st_ksp_rtol", "1e-12"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, lamina, &b));
  PetscCall(PeriTestSetOption("-st_ksp_type", NULL));
  PetscCall(PeriTestSetOption("-st_pc_type", NULL));
  PetscCall(PeriTestSetOption("-st_ksp_rtol", NULL));
  PetscCheck(PeriTestModal(b)->nmodes == PeriTestModal(a)->nmodes, PETSC_COMM_SELF, PETSC_ERR_PLIB, "cg inner solve: %" PetscInt_FMT " modes, direct %" PetscInt_FMT, PeriTestModal(b)->nmodes, PeriTestModal(a)->nmodes);
  PetscCheck(b->sys->fields.solve.residual_norm <= 1e-6, PETSC_COMM_SELF, PETSC_ERR_PLIB, "cg inner solve: worst true residual %g", (double)b->sys->fields.solve.residual_norm);
  for (PetscInt m = 0; m < PeriTestModal(a)->nmodes; m++) {
    PetscCall(PetscSNPrintf(what, sizeof(what), "cg + jacobi to 1e-12 inner solves: mode %" PetscInt_FMT " f / f with Cholesky", m + 1));
    PeriTestClose(what, PeriTestModal(b)->modes[m].f_hz / PeriTestModal(a)->modes[m].f_hz, 1.0, 1e-8);
  }
  PetscCall(PeriProblemDestroy(&a));
  PetscCall(PeriProblemDestroy(&b));
  PetscCall(PeriTestSetOption("-model_type", NULL));
  PetscCall(PeriTestSetOption("-material_nu", NULL));
  PetscCall(PeriTestSetOption("-grid_spacing", NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  PetscBool checks_only;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 4, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_modal examples/lamina/modal.yaml examples/pmb/bar_modes.yaml tests/scenes/tiny_modal.yaml");
  /* -checks_only: the target and the refusals only (the 2-rank test) */
  PetscCall(PetscOptionsHasName(NULL, NULL, "-checks_only", &checks_only));
  if (!checks_only) {
    PetscCall(PeriTestSetOption("-model_calibration", "continuum"));
    PetscCall(PeriTestSetOption("-corrections_surface", "volume"));
    PetscCall(Lamina(argv[1]));
    PetscCall(LaminaLattice(argv[1]));
    PetscCall(Bar(argv[2]));
    PetscCall(Extremes(argv[1], argv[3]));
  }
  PetscCall(Target(argv[1]));
  PetscCall(Checks(argv[1]));
  PetscCall(PeriFinalize());
  return 0;
}
