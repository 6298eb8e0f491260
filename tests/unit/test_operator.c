/* The matrix-free operator (solver.operator: matrix_free, src/system/operator.c) against the
 * assembled K of the same scene, for every registered model type the operator applies to
 * (PeriOperatorWhyNotModel: central springs, 2D shear and micropolar bonds; no names here), on
 * the scenes given (2D and 3D; the shear and micropolar types at nu = 0.2, where their shear
 * springs act):
 *   1. A x = K x for a random x:                    ||A x - K x|| <= TOL ||K x||;
 *   2. the diagonals agree:                         ||diag A - diag K|| <= TOL ||diag K||;
 *   3. after MatScale and MatZeroRowsColumns with a prescribed x, both on each: the adjusted
 *      right-hand sides and the products agree to TOL;
 *   4. the preconditioning matrix P (the short-range stiffness), central springs: rigid
 *      translations are null vectors, ||P t|| <= TOL ||P||_1 ||t||, and the energy of a uniform
 *      expansion u = X is K's, |u^T P u - u^T K u| <= TOL u^T K u (the scaling promises it);
 *      shear and micropolar bonds: P's diagonal is K's (their scaling promises that instead);
 *   5. the static solve of each scene (its own model) gives the same strain energy and largest
 *      displacements with either operator, to the solver tolerance (1e-8 relative);
 *   6. on the slender beam (third scene) the default CG + Jacobi of a small 3D body hands over to
 *      GAMG after PERI_JACOBI_BUDGET iterations, and the answer is still the assembled K's (5);
 *   7. the same for a periodic body narrower than the horizon (fourth scene): bonds to several
 *      images of a particle and to its own;
 *   8. 5 for the micropolar cantilever (fifth scene, gerstle): Jacobi at 30 spacings, the multigrid
 *      at 50 (clamped) and 100; and for the mppd lamina held by two pins at 61 spacings (sixth
 *      scene, examples/lamina/bending.yaml): Jacobi.
 * usage: test_operator operator_2d.yaml operator_3d.yaml operator_beam_3d.yaml operator_periodic_2d.yaml operator_micropolar_2d.yaml
 *   examples/lamina/bending.yaml [-operator_types lps -model_dilatation affine -operator_solve_pc PC]
 *   (those types only, checks 1-4 and 5 on the first two scenes) */
#include "testing.h"

#define TOL 1e-12

static PetscErrorCode Assert(const char name[], const char check[], PetscReal got, PetscReal tol)
{
  PetscFunctionBeginUser;
  PetscCheck(got <= tol, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "%s: %s = %.3g exceeds the tolerance %.3g", name, check, (double)got, (double)tol);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s: %s = %.3g (tolerance %.2g)\n", name, check, (double)got, (double)tol));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* ||A x - K x|| / ||K x|| */
static PetscErrorCode ProductError(Mat A, Mat K, Vec x, PetscReal *err)
{
  Vec       y, z;
  PetscReal n;

  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(K, &y, &z));
  PetscCall(MatMult(K, x, y));
  PetscCall(MatMult(A, x, z));
  PetscCall(VecNorm(y, NORM_2, &n));
  PetscCall(VecAXPY(z, -1, y));
  PetscCall(VecNorm(z, NORM_2, err));
  *err /= n;
  PetscCall(VecDestroy(&y));
  PetscCall(VecDestroy(&z));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode DiagonalError(Mat A, Mat K, PetscReal *err)
{
  Vec       d, e;
  PetscReal n;

  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(K, &d, &e));
  PetscCall(MatGetDiagonal(K, d));
  PetscCall(MatGetDiagonal(A, e));
  PetscCall(VecNorm(d, NORM_2, &n));
  PetscCall(VecAXPY(e, -1, d));
  PetscCall(VecNorm(e, NORM_2, err));
  *err /= n;
  PetscCall(VecDestroy(&d));
  PetscCall(VecDestroy(&e));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* 3: the same scaling and elimination on both, with every 5th owned DOF held at a random value. */
static PetscErrorCode CheckElimination(const char name[], Mat A, Mat K, Vec x)
{
  PetscInt  rstart, rend, n = 0, *rows;
  Vec       u, b, c;
  PetscReal nb, err;

  PetscFunctionBeginUser;
  PetscCall(MatGetOwnershipRange(K, &rstart, &rend));
  PetscCall(PetscMalloc1(rend - rstart, &rows));
  for (PetscInt r = rstart; r < rend; r += 5) rows[n++] = r;
  PetscCall(VecDuplicate(x, &u));
  PetscCall(VecDuplicate(x, &b));
  PetscCall(VecSetRandom(u, NULL));
  PetscCall(VecSetRandom(b, NULL));
  PetscCall(VecDuplicate(b, &c));
  PetscCall(VecCopy(b, c));
  PetscCall(MatScale(K, 0.37));
  PetscCall(MatScale(A, 0.37));
  PetscCall(MatZeroRowsColumns(K, n, rows, 2.5, u, b));
  PetscCall(MatZeroRowsColumns(A, n, rows, 2.5, u, c));
  PetscCall(VecNorm(b, NORM_2, &nb));
  PetscCall(VecAXPY(c, -1, b));
  PetscCall(VecNorm(c, NORM_2, &err));
  PetscCall(Assert(name, "held rows: ||b_A - b_K|| / ||b_K||", err / nb, TOL));
  PetscCall(ProductError(A, K, x, &err));
  PetscCall(Assert(name, "held rows: ||A x - K x|| / ||K x||", err, TOL));
  PetscCall(DiagonalError(A, K, &err));
  PetscCall(Assert(name, "held rows: ||diag A - diag K|| / ||diag K||", err, TOL));
  PetscCall(PetscFree(rows));
  PetscCall(VecDestroy(&u));
  PetscCall(VecDestroy(&b));
  PetscCall(VecDestroy(&c));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* u^T M u for u = X (the uniform expansion), and ||M t|| / (||M||_1 ||t||) over the translations. */
static PetscErrorCode ExpansionAndTranslations(PeriSystem sys, Mat M, PetscReal *energy, PetscReal *trans)
{
  const PetscInt bs = sys->model->dofs, rstart = sys->disc.bonds.rstart;
  Vec            u, t, y;
  PetscScalar   *a, *ta;
  PetscReal      norm1;

  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(M, &u, &y));
  PetscCall(VecDuplicate(u, &t));
  PetscCall(MatNorm(M, NORM_1, &norm1));
  PetscCall(VecGetArray(u, &a));
  for (PetscInt i = rstart; i < sys->disc.bonds.rend; i++)
    for (PetscInt d = 0; d < bs; d++) a[(i - rstart) * bs + d] = sys->disc.particles.x[3 * i + d];
  PetscCall(VecRestoreArray(u, &a));
  PetscCall(MatMult(M, u, y));
  PetscCall(VecDot(u, y, energy));
  *trans = 0;
  for (PetscInt c = 0; c < bs; c++) {
    PetscReal r, n;
    PetscCall(VecGetArray(t, &ta));
    for (PetscInt k = 0; k < (sys->disc.bonds.rend - rstart) * bs; k++) ta[k] = k % bs == c;
    PetscCall(VecRestoreArray(t, &ta));
    PetscCall(MatMult(M, t, y));
    PetscCall(VecNorm(y, NORM_2, &r));
    PetscCall(VecNorm(t, NORM_2, &n));
    *trans = PetscMax(*trans, r / (norm1 * n));
  }
  PetscCall(VecDestroy(&u));
  PetscCall(VecDestroy(&t));
  PetscCall(VecDestroy(&y));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CheckPreconditioner(const char name[], PeriSystem sys, Mat K)
{
  PetscReal eK, eP, tP, tK, err;

  PetscFunctionBeginUser;
  if (!sys->model->central_force) {
    PetscCall(DiagonalError(sys->stiffness.Kpc, K, &err));
    PetscCall(Assert(name, "P: ||diag P - diag K|| / ||diag K||", err, TOL));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(ExpansionAndTranslations(sys, K, &eK, &tK));
  PetscCall(ExpansionAndTranslations(sys, sys->stiffness.Kpc, &eP, &tP));
  PetscCall(Assert(name, "P: ||P t|| / (||P||_1 ||t||) over translations", tP, TOL));
  PetscCall(Assert(name, "P: |X^T P X - X^T K X| / X^T K X", PetscAbsReal(eP - eK) / eK, 1e-10));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One model on one scene: K assembled, then the matrix-free pair (A, P), compared. */
static PetscErrorCode CheckCase(const char scene[], const char type[], const char surface[], const char nu[])
{
  PeriProblem p;
  Mat         K;
  Vec         x;
  PetscReal   err;
  char        name[256];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(name, sizeof(name), "%s on %s (surface %s)", type, scene, surface));
  PetscCall(PeriTestSetOption("-model_type", type));
  PetscCall(PeriTestSetOption("-corrections_surface", surface));
  PetscCall(PeriTestSetOption("-material_nu", nu));
  PetscCall(PeriProblemCreate(PETSC_COMM_WORLD, &p));
  PetscCall(PeriProblemLoad(p, scene));
  PetscCall(PeriProblemSetUp(p));
  p->sys->stiffness.needs.matrix_free = PETSC_FALSE; /* the reference: K assembled */
  PetscCall(PeriSystemAssemble(p->sys));
  K                                   = p->sys->stiffness.K;
  p->sys->stiffness.K                 = NULL;
  p->sys->stiffness.needs.matrix_free = PETSC_TRUE;
  p->sys->stiffness.operator_kind     = PERI_OPERATOR_MATRIX_FREE;
  PetscCall(PeriSystemAssemble(p->sys));
  PetscCall(PeriOperatorPreconditioner(p->sys));
  PetscCheck(p->sys->stiffness.op && p->sys->stiffness.Kpc, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "%s: solver.operator matrix_free gave no matrix-free operator", name);
  PetscCall(MatCreateVecs(K, &x, NULL));
  PetscCall(VecSetRandom(x, NULL));
  PetscCall(ProductError(p->sys->stiffness.K, K, x, &err));
  PetscCall(Assert(name, "||A x - K x|| / ||K x||", err, TOL));
  PetscCall(DiagonalError(p->sys->stiffness.K, K, &err));
  PetscCall(Assert(name, "||diag A - diag K|| / ||diag K||", err, TOL));
  PetscCall(CheckPreconditioner(name, p->sys, K));
  PetscCall(CheckElimination(name, p->sys->stiffness.K, K, x));
  PetscCall(VecDestroy(&x));
  PetscCall(MatDestroy(&K));
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the type accepts dim (plane stress in 2D) with bonds the operator applies (*applies),
 * whether they are shear or micropolar ones, and its surface correction for the test (volume
 * where it takes one and has no lattice calibration). */
static PetscErrorCode Probe(const char type[], PetscInt dim, PetscBool *applies, PetscBool *shear, const char **surface, const char **nu)
{
  PeriModel      m = NULL;
  PetscErrorCode ierr;
  PetscReal      lo, hi;
  PetscBool      volume = PETSC_TRUE;

  PetscFunctionBeginUser;
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = PeriModelCreate(type, dim, PETSC_FALSE, &m);
  PetscCall(PetscPopErrorHandler());
  *applies = PETSC_FALSE;
  if (ierr == PETSC_ERR_USER_INPUT) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(ierr);
  *applies = (PetscBool)!PeriOperatorWhyNotModel(m);
  *shear   = (PetscBool)!m->central_force;
  /* the lattice calibration (a default) corrects surfaces itself */
  if (m->surface_corrections) {
    volume = PETSC_FALSE;
    for (PetscInt k = 0; m->surface_corrections[k]; k++) volume = (PetscBool)(volume || !strcmp(m->surface_corrections[k], "volume"));
  }
  *surface = volume && m->allows_surface_correction && m->calibration != PERI_CALIBRATION_LATTICE ? "volume" : "none";
  /* a model with a range of Poisson ratios gets 0.2, where shear springs act and LPS's state
     modulus A = K - 5G/3 is negative (3D) */
  m->ops.nu_range(m, &lo, &hi);
  *nu = lo < hi ? "0.2" : NULL;
  PetscCall(PeriModelDestroy(&m));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* 5: the whole static run with either operator. */
static PetscErrorCode CheckSolve(const char scene[], const char pc_after[])
{
  PeriProblem p, q;
  char        what[256];

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-solver_operator", "assembled"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, scene, &p));
  PetscCall(PeriTestSetOption("-solver_operator", "matrix_free"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, scene, &q));
  PetscCall(PeriTestSetOption("-solver_operator", NULL));
  PetscCheck(q->sys->stiffness.op, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "%s: the static run did not use the matrix-free operator", scene);
  PetscCheck(!pc_after[0] || !strcmp(q->sys->fields.solve.pc_type, pc_after), PETSC_COMM_WORLD, PETSC_ERR_PLIB, "%s: the matrix-free solve ended with PC %s, expected %s", scene, q->sys->fields.solve.pc_type, pc_after);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s: the matrix-free solve ended with PC %s\n", scene, q->sys->fields.solve.pc_type));
  PetscCall(PetscSNPrintf(what, sizeof(what), "%s: strain energy, matrix_free vs assembled", scene));
  PeriTestClose(what, q->sys->fields.strain_energy, p->sys->fields.strain_energy, 1e-8 * p->sys->fields.strain_energy);
  for (PetscInt c = 0; c < p->sys->model->dofs; c++) {
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s: max |%s|, matrix_free vs assembled", scene, p->sys->model->components[c]));
    PeriTestClose(what, q->sys->fields.max_abs_u[c], p->sys->fields.max_abs_u[c], 1e-7 * p->sys->fields.max_abs_u[c]);
  }
  PetscCall(PeriProblemDestroy(&p));
  PetscCall(PeriProblemDestroy(&q));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  char      list[1024], **types, solve_pc[16] = "";
  int       ntypes;
  PetscInt  ncases = 0, nshear = 0;
  PetscBool only;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 7, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_operator operator_2d.yaml operator_3d.yaml operator_beam_3d.yaml operator_periodic_2d.yaml operator_micropolar_2d.yaml lamina/bending.yaml");
  PetscCall(PeriInitializePackage());
  PetscCall(PeriModelListTypes(list, sizeof(list)));
  /* -operator_types a,b: those types only (with a model key of theirs among the options), and the
     static solve of the first two scenes with the last of them (ending with -operator_solve_pc if given) */
  PetscCall(PetscOptionsGetString(NULL, NULL, "-operator_types", list, sizeof(list), &only));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-operator_solve_pc", solve_pc, sizeof(solve_pc), NULL));
  for (size_t k = 0; list[k]; k++)
    if (list[k] == ',') list[k] = ' ';
  PetscCall(PetscStrToArray(list, ' ', &ntypes, &types));
  for (int s = 1; s < 3; s++)
    for (int t = 0; t < ntypes; t++) {
      PeriScene   scene;
      PetscInt    dim;
      PetscBool   applies = PETSC_FALSE, shear = PETSC_FALSE;
      const char *surface = NULL, *nu = NULL;
      PetscCall(PeriSceneCreateFromFile(argv[s], 0, NULL, &scene));
      PetscCall(PeriSceneGetInt(scene, scene->root, "dim", PETSC_TRUE, &dim, NULL));
      PetscCall(PeriSceneDestroy(&scene));
      PetscCall(Probe(types[t], dim, &applies, &shear, &surface, &nu));
      if (!applies) continue;
      PetscCall(CheckCase(argv[s], types[t], surface, nu));
      ncases++;
      nshear += shear;
    }
  if (only) {
    PetscCall(CheckSolve(argv[1], solve_pc));
    PetscCall(CheckSolve(argv[2], solve_pc));
    PetscCheck(ncases >= 1, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "-operator_types: no case ran");
    PetscCall(PetscStrToArrayDestroy(ntypes, types));
    PetscCall(PeriFinalize());
    return 0;
  }
  /* the scenes' own models and corrections from here on */
  PetscCall(PeriTestSetOption("-model_type", NULL));
  PetscCall(PeriTestSetOption("-corrections_surface", NULL));
  PetscCall(PeriTestSetOption("-material_nu", NULL));
  PetscCall(CheckSolve(argv[1], PCGAMG));   /* 2D, 10 cells across: too few to coarsen, GAMG */
  PetscCall(CheckSolve(argv[2], PCJACOBI)); /* a small 3D body: Jacobi */
  PetscCall(CheckSolve(argv[3], PCGAMG));   /* slender: Jacobi, then GAMG */
  PetscCall(CheckSolve(argv[4], PCGAMG));   /* periodic */
  PetscCall(CheckSolve(argv[5], PCJACOBI)); /* a small 2D micropolar body (30 spacings): Jacobi */
  PetscCall(PeriTestSetOption("-grid_spacing", "0.012"));
  PetscCall(CheckSolve(argv[5], PCMG)); /* the same at 50 spacings, clamped: the multigrid from 48 on */
  PetscCall(PeriTestSetOption("-grid_spacing", "0.006"));
  PetscCall(CheckSolve(argv[5], PCMG)); /* the same at 100 spacings: the multigrid */
  PetscCall(PeriTestSetOption("-grid_spacing", NULL));
  PetscCall(CheckSolve(argv[6], PCJACOBI)); /* the mppd lamina at 61 spacings held by two pins: Jacobi up to 64 */
  PetscCheck(ncases >= 7 && nshear >= 3, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "only %" PetscInt_FMT " cases ran (%" PetscInt_FMT " shear or micropolar): expected the central-force models (pmb, npmb, cpmb) in 2D and 3D and pds, mppd and gerstle in 2D", ncases, nshear);
  PetscCall(PetscStrToArrayDestroy(ntypes, types));
  PetscCall(PeriFinalize());
  return 0;
}
