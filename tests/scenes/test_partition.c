/* Each partitioner (-peri_partition metis, ptscotch, geometric) on all ranks of the communicator:
 * every rank owns a non-empty share no larger than the partitioner promises, and the static
 * solution is the one rank's to the solver tolerance (strain energy and the largest displacement
 * of every component; both independent of the particles' order). The shares: the Hilbert curve
 * is cut into pieces of floor or ceil(N/P) particles; PT-Scotch is asked (PETSc's default) for
 * loads within 1 % of N/P and METIS (its default ufactor 30) within 3 %; one particle more is
 * allowed for the rounding of N/P. N counts the body's particles: the fictitious layer particles,
 * added after the partition, live on the rank of their mirror image. */
#include "testing.h"

static PetscErrorCode CheckShares(PeriProblem p, const char *type, PetscReal imbalance)
{
  const PeriParticles *pt = &p->sys->disc.particles;
  const PetscInt       N  = p->sys->disc.N - pt->nfictitious; /* the partition shares the body; a fictitious layer particle joins its mirror image's rank */
  PetscMPIInt          size;
  PetscInt            *count, mine = 0;
  char                 what[160];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PetscCalloc1(size, &count));
  for (PetscInt i = 0; i < p->sys->disc.nowned; i++) mine += !PeriParticleIsFictitious(pt, i);
  PetscCallMPI(MPI_Allgather(&mine, 1, MPIU_INT, count, 1, MPIU_INT, PETSC_COMM_WORLD));
  for (PetscMPIInt r = 0; r < size; r++) {
    PetscReal upper = imbalance > 0 ? (1 + imbalance) * N / size + 1 : PetscCeilReal((PetscReal)N / size);
    PetscReal lower = imbalance > 0 ? 1 : PetscFloorReal((PetscReal)N / size);
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s: rank %d owns %" PetscInt_FMT " of %" PetscInt_FMT " particles on %d ranks, between %g and %.1f", type, r, count[r], N, size, (double)lower, (double)upper));
    PetscCheck(count[r] >= lower && count[r] <= upper, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: out of bounds", what);
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s\n", what));
  }
  PetscCall(PetscFree(count));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Compare(PeriProblem p, PeriProblem q, const char *type)
{
  char what[160];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(what, sizeof(what), "%s: strain energy on %" PetscInt_FMT " ranks vs 1", type, (PetscInt)p->sys->size));
  PeriTestClose(what, p->sys->fields.strain_energy, q->sys->fields.strain_energy, 1e-8 * q->sys->fields.strain_energy);
  for (PetscInt c = 0; c < p->sys->model->dofs; c++) {
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s: max |%s| on %" PetscInt_FMT " ranks vs 1", type, p->sys->model->components[c], (PetscInt)p->sys->size));
    PeriTestClose(what, p->sys->fields.max_abs_u[c], q->sys->fields.max_abs_u[c], 1e-7 * q->sys->fields.max_abs_u[c] + 1e-300);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const char *const types[]     = {"metis", "ptscotch", "geometric"};
  const PetscReal   imbalance[] = {0.03, 0.01, 0};
  PeriProblem       p, q;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_partition SCENE.yaml [options]");
  PetscCall(PeriTestRunScene(PETSC_COMM_SELF, argv[1], &q));
  for (int t = 0; t < 3; t++) {
    PetscCall(PeriTestSetOption("-peri_partition", types[t]));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
    PetscCall(CheckShares(p, types[t], imbalance[t]));
    PetscCall(Compare(p, q, types[t]));
    PetscCall(PeriProblemDestroy(&p));
  }
  PetscCall(PeriProblemDestroy(&q));
  PetscCall(PeriFinalize());
  return 0;
}
