/* Patch tests on irregular clouds (docs/mesh.md, "Patch tests"):
 *   test_patch SCENE DEPTH TOL [options]: SCENE prescribes one affine field u = A X + b (its first
 *   bc's affine) on every particle within DEPTH of the body's box faces and leaves the others free.
 *   The solution must equal A X + b at every free particle within TOL of max |A X| over them; when A
 *   is a dilation s I, each free particle's strain energy density must also equal the continuum's
 *   (PeriModelIsotropicEnergy s^2) within TOL. The solve runs to a relative residual of 1e-13, so
 *   what remains is the discretization's. Any number of ranks. */
#include "testing.h"

/* A and b of the scene's first boundary condition. */
static PetscErrorCode SceneAffine(PeriProblem p, PetscReal A[3][3], PetscReal b[3])
{
  PeriNode list, aff;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(p->scene->root, "bc", &list));
  PetscCheck(list && list->n > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "the scene has no bc");
  PetscCall(PeriSceneGetNode(list->child[0], "affine", &aff));
  PetscCheck(aff, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "the scene's first bc is not affine");
  PetscCall(PeriBoundaryParseAffine(p->sys, aff, "bc.<k>.affine", A, b));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscBool Free(const PeriParticles *pt, PetscInt i, PetscReal depth)
{
  for (PetscInt d = 0; d < pt->dim; d++)
    if (pt->x[3 * i + d] - pt->lower[d] < depth || pt->upper[d] - pt->x[3 * i + d] < depth) return PETSC_FALSE;
  return PETSC_TRUE;
}

/* Is A s I? */
static PetscBool Dilation(PetscInt dim, const PetscReal A[3][3], PetscReal *s)
{
  *s = A[0][0];
  for (PetscInt a = 0; a < dim; a++)
    for (PetscInt c = 0; c < dim; c++)
      if (A[a][c] != (a == c ? *s : 0)) return PETSC_FALSE;
  return PETSC_TRUE;
}

int main(int argc, char **argv)
{
  PeriProblem        p;
  const PetscScalar *u;
  PetscReal          A[3][3] = {{0}}, b[3] = {0}, err[3] = {0, 0, 0}, s, depth, tol; /* displacement error, its scale, energy error */
  PetscInt           nfree = 0, dim;
  PetscBool          dilation;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 4, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_patch SCENE DEPTH TOL [options]");
  depth = atof(argv[2]);
  tol   = atof(argv[3]);
  PetscCall(PeriTestSetOption("-ksp_rtol", "1e-13"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
  PetscCall(SceneAffine(p, A, b));
  dim      = p->sys->disc.particles.dim;
  dilation = Dilation(dim, A, &s);
  PetscCall(VecGetArrayRead(p->sys->fields.u, &u));
  for (PetscInt i = 0; i < p->sys->disc.nowned; i++) {
    const PeriParticles *pt = &p->sys->disc.particles;
    if (!Free(pt, i, depth)) continue;
    nfree++;
    for (PetscInt c = 0; c < dim; c++) {
      PetscReal ax = 0;
      for (PetscInt d = 0; d < dim; d++) ax += A[c][d] * pt->x[3 * i + d];
      err[0] = PetscMax(err[0], PetscAbsReal(u[i * p->sys->model->dofs + c] - ax - b[c]));
      err[1] = PetscMax(err[1], PetscAbsReal(ax));
    }
    if (dilation) err[2] = PetscMax(err[2], PetscAbsReal(p->sys->fields.W[i] / (PeriModelIsotropicEnergy(p->sys->model) * s * s) - 1));
  }
  PetscCall(VecRestoreArrayRead(p->sys->fields.u, &u));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, err, 3, MPIU_REAL, MPI_MAX, PETSC_COMM_WORLD));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &nfree, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD));
  PetscCheck(nfree > 0, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "no particle lies %g inside the box", (double)depth);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%" PetscInt_FMT " free particles of %" PetscInt_FMT "\n", nfree, p->sys->disc.N));
  PeriTestClose("max |u - (A X + b)| / max |A X| at the free particles", err[0] / err[1], 0.0, tol);
  if (dilation) PeriTestClose("max |W / W_continuum - 1| at the free particles (a dilation)", err[2], 0.0, tol);
  PetscCall(PeriProblemDestroy(&p));
  PetscCall(PeriFinalize());
  return 0;
}
