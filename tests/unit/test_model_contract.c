/* The model contract: every registered model type (PeriModelListTypes; no names here), in every
 * dimension and plane kind its create function accepts (it refuses the others with an input
 * error), with the Poisson ratio in the middle of its ops.nu_range and every corrections.surface
 * it takes, on the patches tests/scenes/contract_2d.yaml and contract_3d.yaml, K assembled by the
 * library (PeriSystemAssemble):
 *   1. K is symmetric:                ||K - K^T||_F <= TOL ||K||_F;
 *   2. rigid modes are null vectors:  ||K r|| <= TOL ||K||_2 ||r|| for the modes of ops.rigid_modes
 *      that do not vary with position (translations), and for those that do (rotations) when the
 *      type's descriptor says rotation_invariant;
 *   3. K is positive semi-definite:   lambda_min(K) >= -TOL ||K||_2 (all eigenvalues of the dense K);
 *   4. the strain energy E the library evaluates (PeriSystemEvaluateEnergy, from the model's
 *      blocks) of u = H X below is the assembled one: |E - u^T K u / 2| <= TOL ||K||_2 ||u||^2 / 2;
 *   5. exact energy, as the descriptor's exact_energy promises (PeriExactEnergy): the energy density
 *      W_i of u = H X at every particle two search radii inside the body equals (1/2) eps:C:eps of
 *      the target elasticity within TOL_ENERGY (relative), for the isotropic expansion H = s I
 *      (EXPANSION, HOMOGENEOUS) and for a general symmetric H (HOMOGENEOUS); DOFs other than the
 *      displacements (theta) are 0. The errors of every model are printed (info:), promised or not.
 *      Every model that takes model.calibration: lattice is run once more with it (and surface none),
 *      where it promises HOMOGENEOUS; there the body's total energy of u = H X, surfaces and corners
 *      included, is printed beside the target's (it is exact where no family was too lopsided).
 *      In 2D the lattice promise is also checked at m = 2 and 4 (on a 23 x 23 patch: two search
 *      radii at m = 4 are 9 spacings), energy only.
 *
 * usage: test_model_contract tests/scenes/contract_2d.yaml tests/scenes/contract_3d.yaml
 *        [-contract_types lps -model_dilatation affine]: only the types listed, with a key of theirs
 *        [-contract_lattice false]: not the lattice calibration (a key of theirs refuses it) */
#include "testing.h"
#include <slepcds.h>

#define TOL        1e-12 /* symmetry, null space, semi-definiteness: relative to the norm of K */
#define TOL_ENERGY 1e-12 /* energy density, relative to the exact one */

/* The homogeneous strain (symmetric); in 2D the third column is unused (z = 0) and the third row is
 * the antiplane shear u_z = H_20 x + H_21 y. */
static const PetscReal H[3][3] = {
    {1e-3, 3e-4, -2e-4},
    {3e-4, -4e-4, 5e-4},
    {-2e-4, 5e-4, 7e-4}};

typedef struct {
  const char          *type;
  const PeriModelType *desc;
  PetscInt             dim;
  PetscBool            strain;
  const char          *plane; /* "stress", "strain", or NULL in 3D */
  PetscReal            nu;
  const char          *surface;
  const char          *calibration; /* "continuum" or "lattice" */
  char                 name[128];   /* for messages */
} Case;

/* Whether the model accepts dim and plane kind (its create function refuses with an input error),
 * and what it admits: the middle of its Poisson ratio range and its surface corrections. */
static PetscErrorCode Probe(Case *c, PetscBool *accepted, const char *const **surfaces, PetscBool *lattice)
{
  static const char *const defaults[] = {"none", "volume", NULL}, *const none[] = {"none", NULL};
  PeriModel      m = NULL;
  PetscErrorCode ierr;
  PetscReal      lo, hi;

  PetscFunctionBeginUser;
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = PeriModelCreate(c->type, c->dim, c->strain, &m);
  PetscCall(PetscPopErrorHandler());
  *accepted = (PetscBool)!ierr;
  if (ierr == PETSC_ERR_USER_INPUT) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(ierr);
  m->ops.nu_range(m, &lo, &hi);
  c->nu = 0.5 * (lo + hi);
  /* as the set-up decides (src/problem.c): the model's list, else none and volume; none only
     when the model corrects surfaces itself */
  *surfaces = m->surface_corrections ? m->surface_corrections : (m->allows_surface_correction ? defaults : none);
  *lattice  = m->takes_lattice;
  PetscCall(PeriModelDestroy(&m));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode SetUp(const char scene[], const Case *c, PeriProblem *p)
{
  char nu[64];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(nu, sizeof(nu), "%.17g", (double)c->nu));
  PetscCall(PeriTestSetOption("-model_type", c->type));
  PetscCall(PeriTestSetOption("-model_plane", c->plane));
  PetscCall(PeriTestSetOption("-material_nu", nu));
  PetscCall(PeriTestSetOption("-corrections_surface", c->surface));
  PetscCall(PeriTestSetOption("-model_calibration", c->calibration));
  PetscCall(PeriProblemCreate(PETSC_COMM_WORLD, p));
  PetscCall(PeriProblemLoad(*p, scene));
  PetscCall(PeriProblemSetUp(*p));
  (*p)->sys->stiffness.needs.matrix_free = PETSC_FALSE; /* the test reads K's entries: assembled */
  PetscCall(PeriSystemAssemble((*p)->sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Fails naming the case, the check, the measured value and the tolerance; else one ok: line. */
static PetscErrorCode Assert(const Case *c, const char check[], PetscReal got, PetscReal tol)
{
  PetscFunctionBeginUser;
  PetscCheck(got <= tol, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: %s = %.3g exceeds the tolerance %.3g", c->name, check, (double)got, (double)tol);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s: %s = %.3g (tolerance %.2g)\n", c->name, check, (double)got, (double)tol));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* 1 and 3: the whole K, dense on rank 0; returns ||K||_2 on every rank. */
static PetscErrorCode CheckDense(PeriProblem p, const Case *c, PetscReal *norm2)
{
  Mat       A, *sub;
  IS        is;
  PetscInt  N;
  PetscReal r[4] = {0, 0, PETSC_MAX_REAL, 0}; /* ||K - K^T||_F^2, ||K||_F^2, lambda_min, max |lambda| */
  PetscReal zero = 0;                         /* eigenvalues below 1e-10 ||K||_2 */

  PetscFunctionBeginUser;
  PetscCall(MatGetSize(p->sys->stiffness.K, &N, NULL));
  PetscCall(MatConvert(p->sys->stiffness.K, MATAIJ, MAT_INITIAL_MATRIX, &A));
  PetscCall(ISCreateStride(PETSC_COMM_SELF, p->rank ? 0 : N, 0, 1, &is));
  PetscCall(MatCreateSubMatrices(A, 1, &is, &is, MAT_INITIAL_MATRIX, &sub));
  if (p->rank == 0) {
    const PetscScalar *a;
    PetscScalar       *d, *w;
    PetscInt           ld;
    DS                 ds;

    PetscCall(MatConvert(sub[0], MATSEQDENSE, MAT_INPLACE_MATRIX, &sub[0]));
    PetscCall(MatDenseGetArrayRead(sub[0], &a));
    for (PetscInt i = 0; i < N; i++)
      for (PetscInt j = 0; j < N; j++) {
        r[0] += PetscSqr(PetscRealPart(a[i + j * N] - a[j + i * N]));
        r[1] += PetscSqr(PetscRealPart(a[i + j * N]));
      }
    /* all eigenvalues, by SLEPc's dense symmetric solver (LAPACK); divide and conquer (method 2)
       is 3x faster here than the default QR */
    PetscCall(DSCreate(PETSC_COMM_SELF, &ds));
    PetscCall(DSSetType(ds, DSHEP));
    PetscCall(DSSetMethod(ds, 2));
    PetscCall(DSAllocate(ds, N));
    PetscCall(DSSetDimensions(ds, N, 0, 0));
    PetscCall(DSGetLeadingDimension(ds, &ld));
    PetscCall(DSGetArray(ds, DS_MAT_A, &d));
    for (PetscInt j = 0; j < N; j++)
      for (PetscInt i = 0; i < N; i++) d[i + j * ld] = a[i + j * N];
    PetscCall(DSRestoreArray(ds, DS_MAT_A, &d));
    PetscCall(MatDenseRestoreArrayRead(sub[0], &a));
    PetscCall(PetscMalloc1(N, &w));
    PetscCall(DSSolve(ds, w, NULL));
    for (PetscInt k = 0; k < N; k++) {
      r[2] = PetscMin(r[2], PetscRealPart(w[k]));
      r[3] = PetscMax(r[3], PetscAbsScalar(w[k]));
    }
    for (PetscInt k = 0; k < N; k++) zero += PetscAbsScalar(w[k]) <= 1e-10 * r[3];
    PetscCall(PetscFree(w));
    PetscCall(DSDestroy(&ds));
  }
  PetscCallMPI(MPI_Bcast(r, 4, MPIU_REAL, 0, p->comm));
  PetscCallMPI(MPI_Bcast(&zero, 1, MPIU_REAL, 0, p->comm));
  *norm2 = r[3];
  PetscCall(Assert(c, "symmetry ||K - K^T||_F / ||K||_F", PetscSqrtReal(r[0] / r[1]), TOL));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "info: %s: %" PetscInt_FMT " DOFs, ||K||_2 = %.6g, %d eigenvalues below 1e-10 ||K||_2\n", c->name, N, (double)r[3], (int)zero));
  PetscCall(Assert(c, "semi-definiteness -lambda_min / ||K||_2", -r[2] / r[3], TOL));
  PetscCall(MatDestroySubMatrices(1, &sub));
  PetscCall(ISDestroy(&is));
  PetscCall(MatDestroy(&A));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* 2: the model's rigid modes (PeriRigidModes: relative to the body's centre, unit norm). A mode
 * whose values at two points differ is a rotation. */
static PetscErrorCode CheckRigid(PeriProblem p, const Case *c, PetscReal norm2)
{
  PeriModel m = p->sys->model;
  Vec       modes[PERI_MAX_MODES], Kr;
  PetscReal v0[PERI_MAX_MODES][PERI_MAX_DOF], v1[PERI_MAX_MODES][PERI_MAX_DOF];
  PetscReal X0[3] = {0, 0, 0}, X1[3] = {0.37, -0.61, 0.53};
  PetscInt  nm;

  PetscFunctionBeginUser;
  PetscCall(PeriRigidModes(p->sys, &nm, modes, NULL));
  m->ops.rigid_modes(m, X0, v0);
  m->ops.rigid_modes(m, X1, v1);
  PetscCall(MatCreateVecs(p->sys->stiffness.K, NULL, &Kr));
  for (PetscInt k = 0; k < nm; k++) {
    PetscBool rotation = PETSC_FALSE;
    PetscReal r, kr;
    char      what[128];
    for (PetscInt d = 0; d < m->dofs; d++) rotation = (PetscBool)(rotation || v0[k][d] != v1[k][d]);
    PetscCall(VecNorm(modes[k], NORM_2, &r));
    PetscCall(MatMult(p->sys->stiffness.K, modes[k], Kr));
    PetscCall(VecNorm(Kr, NORM_2, &kr));
    PetscCall(PetscSNPrintf(what, sizeof(what), "rigid mode %" PetscInt_FMT " (%s) ||K r|| / (||K||_2 ||r||)", k, rotation ? "rotation" : "translation"));
    if (!rotation || c->desc->rotation_invariant)
      PetscCall(Assert(c, what, kr / (norm2 * r), TOL));
    else
      PetscCall(PetscPrintf(PETSC_COMM_WORLD, "info: %s: %s = %.3g, not checked: the model does not promise rotation invariance\n", c->name, what, (double)(kr / (norm2 * r))));
  }
  for (PetscInt k = 0; k < nm; k++) PetscCall(VecDestroy(&modes[k]));
  PetscCall(VecDestroy(&Kr));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* (1/2) eps:C:eps of the target elasticity for the gradient G of the model's displacement
 * components: in-plane (plane stress or strain) or 3D, plus the antiplane shear in 2D. */
static PetscReal TargetEnergy(PeriModel m, const PetscReal G[3][3], const PetscInt comp[3])
{
  const PetscReal E = m->material.E, nu = m->material.nu, mu = m->material.G;
  const PetscInt  d      = m->dim;
  PetscReal       lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), W = 0, tr = 0, ee = 0;
  PetscBool       inplane = PETSC_TRUE;

  for (PetscInt a = 0; a < d; a++) inplane = (PetscBool)(inplane && comp[a] >= 0);
  if (d == 2 && !m->plane_strain) lambda = E * nu / (1 - nu * nu);
  if (inplane) {
    for (PetscInt a = 0; a < d; a++) {
      tr += G[a][a];
      for (PetscInt b = 0; b < d; b++) ee += G[a][b] * G[a][b];
    }
    W += 0.5 * lambda * tr * tr + mu * ee;
  }
  if (d == 2 && comp[2] >= 0) W += 0.5 * mu * (G[2][0] * G[2][0] + G[2][1] * G[2][1]);
  return W;
}

/* 4 and 5: the difference between the strain energy the library reports and (1/2) u^T K u, and the
 * largest relative error of W_i over the particles two search radii inside the body. */
static PetscErrorCode EnergyError(PeriProblem p, PetscReal norm2, const PetscReal G[3][3], PetscReal *err, PetscReal *mismatch, PetscInt *count, PetscReal *total)
{
  const PeriParticles *pt       = &p->sys->disc.particles;
  PeriModel            m        = p->sys->model;
  const char          *names[3] = {"ux", "uy", "uz"};
  PetscInt             comp[3];
  PetscReal            centre[3], reach, W;
  PetscScalar         *u;

  PetscFunctionBeginUser;
  for (PetscInt a = 0; a < 3; a++) {
    PetscCall(PeriModelComponentIndex(m, names[a], &comp[a]));
    centre[a] = 0.5 * (pt->lower[a] + pt->upper[a]);
  }
  if (!p->sys->fields.u) PetscCall(MatCreateVecs(p->sys->stiffness.K, &p->sys->fields.u, NULL));
  PetscCall(VecSet(p->sys->fields.u, 0));
  PetscCall(VecGetArray(p->sys->fields.u, &u));
  for (PetscInt i = p->sys->disc.bonds.rstart; i < p->sys->disc.bonds.rend; i++)
    for (PetscInt a = 0; a < 3; a++)
      if (comp[a] >= 0)
        for (PetscInt b = 0; b < pt->dim; b++) u[(i - p->sys->disc.bonds.rstart) * m->dofs + comp[a]] += G[a][b] * (pt->x[3 * i + b] - centre[b]);
  PetscCall(VecRestoreArray(p->sys->fields.u, &u));
  PetscCall(PeriSystemEvaluateEnergy(p->sys));
  /* the energy is evaluated from the model's blocks, bond by bond: it must be the assembled K's */
  {
    Vec         Ku;
    PetscScalar uKu;
    PetscReal   unorm;
    PetscCall(MatCreateVecs(p->sys->stiffness.K, NULL, &Ku));
    PetscCall(MatMult(p->sys->stiffness.K, p->sys->fields.u, Ku));
    PetscCall(VecDot(p->sys->fields.u, Ku, &uKu));
    PetscCall(VecNorm(p->sys->fields.u, NORM_2, &unorm));
    PetscCall(VecDestroy(&Ku));
    /* relative to the round-off scale ||K||_2 ||u||^2 / 2: a smooth u cancels much of K */
    *mismatch = PetscAbsReal(p->sys->fields.strain_energy - 0.5 * PetscRealPart(uKu)) / (0.5 * norm2 * unorm * unorm);
  }
  W      = TargetEnergy(m, G, comp);
  reach  = 2 * PeriSearchRadius(p->sys->disc.partial_volume, p->sys->disc.delta, pt->mean_spacing);
  *err   = 0;
  *count = 0;
  *total = 0;
  for (PetscInt i = 0; i < p->sys->disc.nowned; i++) *total += PeriParticleIsFictitious(pt, i) ? 0 : W * pt->volume[i];
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, total, 1, MPIU_REAL, MPI_SUM, p->comm));
  *total = PetscAbsReal(p->sys->fields.strain_energy - *total) / *total;
  for (PetscInt i = 0; i < p->sys->disc.nowned; i++) {
    PetscBool inner = (PetscBool)!PeriParticleIsFictitious(pt, i);
    for (PetscInt b = 0; b < pt->dim; b++) inner = (PetscBool)(inner && pt->x[3 * i + b] - pt->lower[b] >= reach && pt->upper[b] - pt->x[3 * i + b] >= reach);
    if (!inner) continue;
    *err = PetscMax(*err, PetscAbsReal(p->sys->fields.W[i] - W) / W);
    (*count)++;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, err, 1, MPIU_REAL, MPI_MAX, p->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, count, 1, MPIU_INT, MPI_SUM, p->comm));
  PetscCheck(*count > 0, p->comm, PETSC_ERR_PLIB, "no particle two search radii inside the body: enlarge the patch");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The promise holds with the energy surface correction where the model offers it, else with
 * every correction it takes (PeriExactEnergy). */
static PetscErrorCode CheckEnergy(PeriProblem p, const Case *c, PetscReal norm2, const char *const surfaces[])
{
  PetscReal       err, derr = -1, mis, dmis = 0, total, dtotal, dil[3][3] = {{1e-3, 0, 0}, {0, 1e-3, 0}, {0, 0, 1e-3}};
  PetscInt        count, comp;
  PetscBool       energy = PETSC_FALSE, promised, lattice = (PetscBool)!strcmp(c->calibration, "lattice");
  PeriExactEnergy exact         = lattice ? PERI_EXACT_HOMOGENEOUS : c->desc->exact_energy;
  char            expansion[32] = "none (no ux)";

  PetscFunctionBeginUser;
  for (PetscInt k = 0; surfaces[k]; k++) energy = (PetscBool)(energy || !strcmp(surfaces[k], "energy"));
  promised = (PetscBool)(lattice || !energy || !strcmp(c->surface, "energy"));
  PetscCall(EnergyError(p, norm2, H, &err, &mis, &count, &total));
  PetscCall(PeriModelComponentIndex(p->sys->model, "ux", &comp));
  if (comp >= 0) {
    PetscCall(EnergyError(p, norm2, dil, &derr, &dmis, &count, &dtotal));
    PetscCall(PetscSNPrintf(expansion, sizeof(expansion), "%.3g", (double)derr));
  }
  PetscCall(Assert(c, "energy evaluation |E - u^T K u / 2| / (||K||_2 ||u||^2 / 2)", PetscMax(mis, dmis), TOL));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "info: %s: relative energy density error over %" PetscInt_FMT " interior particles: homogeneous strain %.3g, isotropic expansion %s; the whole body's energy of the homogeneous strain %.3g\n", c->name, count, (double)err, expansion, (double)total));
  if (!promised || exact == PERI_EXACT_NONE) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCheck(comp >= 0 || exact == PERI_EXACT_HOMOGENEOUS, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s promises an exact isotropic expansion but has no displacement ux", c->name);
  if (comp >= 0) PetscCall(Assert(c, "energy density of an isotropic expansion |W - W_exact| / W_exact", derr, TOL_ENERGY));
  if (exact == PERI_EXACT_HOMOGENEOUS) PetscCall(Assert(c, "energy density of a homogeneous strain |W - W_exact| / W_exact", err, TOL_ENERGY));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The lattice promise at other horizons (2D): check 5 only, on a patch large enough for m = 4. */
static PetscErrorCode LatticeAtOtherM(const char scene[], Case *c, const char *const surfaces[])
{
  const char *const ms[] = {"2", "4"};

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-grid_upper", "2.3,2.3"));
  for (int k = 0; k < 2; k++) {
    PeriProblem p;
    PetscReal   norm2;
    PetscCall(PeriTestSetOption("-horizon_m", ms[k]));
    PetscCall(PetscSNPrintf(c->name, sizeof(c->name), "%s dim 2 plane %s nu %.4g calibration lattice m %s (23 x 23)", c->type, c->plane, (double)c->nu, ms[k]));
    PetscCall(SetUp(scene, c, &p));
    PetscCall(MatNorm(p->sys->stiffness.K, NORM_FROBENIUS, &norm2)); /* an upper bound of ||K||_2: scales the round-off check only */
    PetscCall(CheckEnergy(p, c, norm2, surfaces));
    PetscCall(PeriProblemDestroy(&p));
  }
  PetscCall(PeriTestSetOption("-horizon_m", NULL));
  PetscCall(PeriTestSetOption("-grid_upper", NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One case: set up, then checks 1-5. */
static PetscErrorCode RunCase(const char scene[], Case *c, const char *const surfaces[])
{
  PeriProblem p;
  PetscReal   norm2 = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(c->name, sizeof(c->name), "%s dim %" PetscInt_FMT "%s%s nu %.4g surface %s calibration %s", c->type, c->dim, c->plane ? " plane " : "", c->plane ? c->plane : "", (double)c->nu, c->surface, c->calibration));
  PetscCall(SetUp(scene, c, &p));
  PetscCall(CheckDense(p, c, &norm2));
  PetscCall(CheckRigid(p, c, norm2));
  PetscCall(CheckEnergy(p, c, norm2, surfaces));
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  char      list[4096], **types;
  int       ntypes;
  size_t    len;
  PetscBool with_lattice = PETSC_TRUE;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 3, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_model_contract contract_2d.yaml contract_3d.yaml");
  PetscCall(PeriInitializePackage());
  PetscCall(PeriModelListTypes(list, sizeof(list)));
  /* -contract_types a,b: those types only, e.g. with a model key of theirs among the options */
  PetscCall(PetscOptionsGetString(NULL, NULL, "-contract_types", list, sizeof(list), NULL));
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-contract_lattice", &with_lattice, NULL));
  PetscCall(PetscStrlen(list, &len));
  PetscCheck(len + 1 < sizeof(list), PETSC_COMM_WORLD, PETSC_ERR_PLIB, "the list of model types is too long for this test's buffer");
  for (size_t k = 0; k < len; k++)
    if (list[k] == ',') list[k] = ' ';
  PetscCall(PetscStrToArray(list, ' ', &ntypes, &types));
  PetscCheck(ntypes > 0, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "no model type is registered");
  for (int t = 0; t < ntypes; t++) {
    PetscInt ncases = 0;
    for (int s = 1; s < 3; s++) {
      PeriScene scene;
      PetscInt  dim;
      PetscCall(PeriSceneCreateFromFile(argv[s], 0, NULL, &scene));
      PetscCall(PeriSceneGetInt(scene, scene->root, "dim", PETSC_TRUE, &dim, NULL));
      PetscCall(PeriSceneDestroy(&scene));
      for (PetscInt k = 0; k < (dim == 2 ? 2 : 1); k++) {
        Case               c        = {types[t], NULL, dim, (PetscBool)(k == 1), dim == 2 ? (k ? "strain" : "stress") : NULL, 0, NULL, NULL, ""};
        const char *const *surfaces = NULL;
        PetscBool          accepted = PETSC_FALSE, lattice = PETSC_FALSE;
        PetscCall(PeriModelTypeGet(c.type, &c.desc));
        PetscCheck(c.desc, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "model type %s has no descriptor (PeriModelType) with its promises", c.type);
        PetscCall(Probe(&c, &accepted, &surfaces, &lattice));
        if (!accepted) {
          PetscCall(PetscPrintf(PETSC_COMM_WORLD, "skip: model %s refuses dim %" PetscInt_FMT "%s%s\n", c.type, dim, c.plane ? ", plane " : "", c.plane ? c.plane : ""));
          continue;
        }
        for (PetscInt sc = 0; surfaces[sc]; sc++) {
          c.surface     = surfaces[sc];
          c.calibration = "continuum";
          PetscCall(RunCase(argv[s], &c, surfaces));
          ncases++;
        }
        if (lattice && with_lattice) {
          c.surface     = "none";
          c.calibration = "lattice";
          PetscCall(RunCase(argv[s], &c, surfaces));
          if (dim == 2) PetscCall(LatticeAtOtherM(argv[s], &c, surfaces));
        }
      }
    }
    PetscCheck(ncases > 0, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "model %s accepted neither patch", types[t]);
  }
  PetscCall(PetscStrToArrayDestroy(ntypes, types));
  PetscCall(PeriTestSetOption("-model_type", NULL));
  PetscCall(PeriTestSetOption("-model_plane", NULL));
  PetscCall(PeriTestSetOption("-material_nu", NULL));
  PetscCall(PeriTestSetOption("-corrections_surface", NULL));
  PetscCall(PeriTestSetOption("-model_calibration", NULL));
  PetscCall(PeriFinalize());
  return 0;
}
