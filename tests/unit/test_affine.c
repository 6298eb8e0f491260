/* An affine displacement u = A X + b (with the microrotation theta = the field's rotation for
 * micropolar models) produces zero internal force K u on every particle whose horizon (and its
 * neighbours' horizons, on which npmb's c_ij and the surface factors depend) lies inside the body.
 * Also the per-particle fields of src/system/stress.c: the least-squares strain is sym(A) at every
 * particle, corners included (1e-10 relative); with model.calibration: lattice, whose energy is
 * exact for every homogeneous strain, the bond-force stress of every interior particle is the
 * elastic C : sym(A) (1e-10 relative, in-plane components).
 * Run with a scene and -model_type. */
#include "testing.h"
#include <slepcsys.h>

/* the strain at every particle and, where the energy is exact, the stress in the interior */
static PetscErrorCode CheckFields(PeriProblem p, Vec u, const PetscReal A[3][3], PetscReal reach)
{
  const PeriParticles *pt     = &p->sys->disc.particles;
  const PetscInt       dim    = pt->dim;
  PetscReal            err[3] = {0, 0, 0}, anorm = 0; /* strain error, stress error, stress norm */
  PetscInt             have;

  PetscFunctionBeginUser;
  if (!p->sys->fields.u) PetscCall(VecDuplicate(u, &p->sys->fields.u));
  PetscCall(VecCopy(u, p->sys->fields.u));
  PetscCall(PeriSystemEvaluateEnergy(p->sys));
  have = p->sys->fields.strain ? 1 : 0;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &have, 1, MPIU_INT, MPI_MAX, p->comm));
  if (!have) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt a = 0; a < dim; a++)
    for (PetscInt b = 0; b < dim; b++) anorm = PetscMax(anorm, PetscAbsReal(A[a][b]));
  for (PetscInt i = 0; i < p->sys->disc.nowned; i++) {
    PetscBool inner = PETSC_TRUE;
    for (PetscInt d = 0; d < dim; d++) inner = (PetscBool)(inner && (pt->periodic[d] || (pt->x[3 * i + d] - pt->lower[d] >= reach && pt->upper[d] - pt->x[3 * i + d] >= reach)));
    for (PetscInt a = 0; a < dim; a++)
      for (PetscInt b = 0; b < dim; b++) {
        err[0] = PetscMax(err[0], PetscAbsReal(p->sys->fields.strain[9 * i + 3 * a + b] - 0.5 * (A[a][b] + A[b][a])));
        if (!inner) continue;
        err[1] = PetscMax(err[1], PetscAbsReal(p->sys->fields.stress[9 * i + 3 * a + b] - p->sys->fields.elastic_stress[9 * i + 3 * a + b]));
        err[2] = PetscMax(err[2], PetscAbsReal(p->sys->fields.elastic_stress[9 * i + 3 * a + b]));
      }
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, err, 3, MPIU_REAL, MPI_MAX, p->comm));
  PeriTestClose("least-squares strain of an affine field, every particle (relative to |A|)", err[0] / anorm, 0.0, 1e-10);
  if (p->sys->model->calibration == PERI_CALIBRATION_LATTICE) PeriTestClose("bond-force stress against C : eps, interior (lattice calibration, relative)", err[1] / err[2], 0.0, 1e-10);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CheckAffine(const char file[])
{
  PeriProblem        p;
  Vec                u, f;
  PetscScalar       *a;
  const PetscScalar *fa;
  PetscReal          A[3][3] = {{1e-3, 4e-4, -2e-4}, {-3e-4, 2e-3, 5e-4}, {1e-4, -6e-4, -1e-3}}, b[3] = {0.1, -0.2, 0.3};
  PetscReal          fmax = 0, scale = 0, reach;
  PetscInt           checked = 0, total;

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-output_stress", "true"));
  PetscCall(PeriProblemCreate(PETSC_COMM_WORLD, &p));
  PetscCall(PeriProblemLoad(p, file));
  PetscCall(PeriProblemSetUp(p));
  p->sys->stiffness.needs.matrix_free = PETSC_FALSE; /* the test reads K's entries: assembled */
  PetscCall(PeriSystemAssemble(p->sys));
  PetscCall(MatCreateVecs(p->sys->stiffness.K, &u, &f));
  PetscCall(VecGetArray(u, &a));
  for (PetscInt i = p->sys->disc.bonds.rstart; i < p->sys->disc.bonds.rend; i++)
    for (PetscInt c = 0; c < p->sys->disc.particles.dim; c++) {
      PetscReal v = b[c];
      for (PetscInt d = 0; d < p->sys->disc.particles.dim; d++) v += A[c][d] * p->sys->disc.particles.x[3 * i + d];
      a[(i - p->sys->disc.bonds.rstart) * p->sys->model->dofs + c] = v;
      /* micropolar models: the particles turn with the field's rotation */
      if (p->sys->model->dofs == 3 && p->sys->disc.particles.dim == 2) a[(i - p->sys->disc.bonds.rstart) * 3 + 2] = 0.5 * (A[1][0] - A[0][1]);
    }
  PetscCall(VecRestoreArray(u, &a));
  PetscCall(MatMult(p->sys->stiffness.K, u, f));
  /* the scale of the force from the strain alone: the diagonal block times the strain times dx */
  {
    Vec dg;
    PetscCall(MatCreateVecs(p->sys->stiffness.K, &dg, NULL));
    PetscCall(MatGetDiagonal(p->sys->stiffness.K, dg));
    PetscCall(VecNorm(dg, NORM_INFINITY, &scale));
    PetscCall(VecDestroy(&dg));
    scale *= 2e-3 * p->sys->disc.particles.mean_spacing;
  }
  reach = 2 * PeriSearchRadius(p->sys->disc.partial_volume, p->sys->disc.delta, p->sys->disc.particles.mean_spacing);
  PetscCall(VecGetArrayRead(f, &fa));
  for (PetscInt i = p->sys->disc.bonds.rstart; i < p->sys->disc.bonds.rend; i++) {
    PetscBool inner = PETSC_TRUE;
    for (PetscInt d = 0; d < p->sys->disc.particles.dim; d++) {
      PetscReal x = p->sys->disc.particles.x[3 * i + d];
      if (!p->sys->disc.particles.periodic[d] && (x - p->sys->disc.particles.lower[d] < reach || p->sys->disc.particles.upper[d] - x < reach)) inner = PETSC_FALSE;
    }
    if (!inner) continue;
    checked++;
    for (PetscInt c = 0; c < p->sys->model->dofs; c++) fmax = PetscMax(fmax, PetscAbsReal(PetscRealPart(fa[(i - p->sys->disc.bonds.rstart) * p->sys->model->dofs + c])));
  }
  PetscCall(VecRestoreArrayRead(f, &fa));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &fmax, 1, MPIU_REAL, MPI_MAX, p->comm));
  PetscCallMPI(MPI_Allreduce(&checked, &total, 1, MPIU_INT, MPI_SUM, p->comm));
  PetscCheck(total > 0, p->comm, PETSC_ERR_PLIB, "no particle with a full horizon: enlarge the scene");
  PetscCall(PetscPrintf(p->comm, "%s, model %s: %" PetscInt_FMT " interior particles, max |K u| / force scale = %g\n", file, p->sys->model->type, total, (double)(fmax / scale)));
  PeriTestClose("interior residual force of an affine field (relative)", fmax / scale, 0.0, 1e-11);
  PetscCall(CheckFields(p, u, A, reach));
  PetscCall(VecDestroy(&u));
  PetscCall(VecDestroy(&f));
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_affine SCENE.yaml [options]");
  PetscCall(CheckAffine(argv[1]));
  PetscCall(PeriFinalize());
  return 0;
}
