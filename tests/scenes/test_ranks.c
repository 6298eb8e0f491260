/* A scene solved on all ranks of the communicator must give what each rank gets alone: the
 * strain energy and the largest displacement of every component (static), with output.stress the
 * body's integral and the largest magnitude of every stress and strain component (independent of
 * the particles' order, which the partition changes), or the frequencies (modal), to the solver
 * tolerance. */
#include "testing.h"
#include <slepcsys.h>

/* per component of a 3 x 3 field of the owned particles: the integral sum V f and the largest |f|
 * over the ranks */
static PetscErrorCode FieldMeasures(PeriProblem p, const PetscReal *f, PetscReal sum[9], PetscReal big[9])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 9; k++) sum[k] = big[k] = 0;
  for (PetscInt i = 0; i < p->sys->disc.nowned; i++)
    for (PetscInt k = 0; k < 9; k++) {
      sum[k] += p->sys->disc.particles.volume[i] * f[9 * i + k];
      big[k] = PetscMax(big[k], PetscAbsReal(f[9 * i + k]));
    }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, sum, 9, MPIU_REAL, MPI_SUM, p->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, big, 9, MPIU_REAL, MPI_MAX, p->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CompareFields(PeriProblem p, PeriProblem q, PetscMPIInt size)
{
  const char *const names[] = {"stress", "strain"};

  PetscFunctionBeginUser;
  if (!q->sys->fields.stress) PetscFunctionReturn(PETSC_SUCCESS); /* q: the whole body on one rank */
  for (int f = 0; f < 2; f++) {
    PetscReal sp[9], bp[9], sq[9], bq[9], scale = 0;
    char      what[128];
    PetscCall(FieldMeasures(p, f ? p->sys->fields.strain : p->sys->fields.stress, sp, bp));
    PetscCall(FieldMeasures(q, f ? q->sys->fields.strain : q->sys->fields.stress, sq, bq));
    for (PetscInt k = 0; k < 9; k++) scale = PetscMax(scale, bq[k]);
    for (PetscInt k = 0; k < 9; k++) {
      PetscCall(PetscSNPrintf(what, sizeof(what), "%s: %s component %" PetscInt_FMT ", max |.| on %d ranks vs 1", p->sys->model->type, names[f], k, size));
      PeriTestClose(what, bp[k], bq[k], 1e-7 * scale);
      PetscCall(PetscSNPrintf(what, sizeof(what), "%s: %s component %" PetscInt_FMT ", sum V . on %d ranks vs 1", p->sys->model->type, names[f], k, size));
      PeriTestClose(what, sp[k], sq[k], 1e-7 * scale * p->sys->disc.N * q->sys->disc.particles.volume[0]);
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  PeriProblem p, q;
  PetscMPIInt size;
  char        what[128];

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_ranks SCENE.yaml [options]");
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
  PetscCall(PeriTestRunScene(PETSC_COMM_SELF, argv[1], &q));
  if (PeriTestModal(p)) {
    /* modes: the frequencies, which the eigensolver converges to 1e-10 */
    for (PetscInt k = 0; k < PeriTestModal(p)->nmodes; k++) {
      PetscCall(PetscSNPrintf(what, sizeof(what), "%s: mode %" PetscInt_FMT " frequency on %d ranks vs 1", p->sys->model->type, k + 1, size));
      PeriTestClose(what, PeriTestModal(p)->modes[k].f_hz, PeriTestModal(q)->modes[k].f_hz, 1e-7 * PeriTestModal(q)->modes[k].f_hz);
    }
    PetscCall(PeriProblemDestroy(&p));
    PetscCall(PeriProblemDestroy(&q));
    PetscCall(PeriFinalize());
    return 0;
  }
  if (PeriTestQuasistatic(p)) {
    /* the same bonds break at the same loads: the bracket of the critical load is identical */
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s: last equilibrium load factor on %d ranks vs 1", p->sys->model->type, size));
    PeriTestClose(what, PeriTestQuasistatic(p)->peak_load_factor, PeriTestQuasistatic(q)->peak_load_factor, 1e-12 * PeriTestQuasistatic(q)->peak_load_factor);
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s: load steps on %d ranks vs 1", p->sys->model->type, size));
    PeriTestClose(what, (PetscReal)PeriTestQuasistatic(p)->nsteps, (PetscReal)PeriTestQuasistatic(q)->nsteps, 0);
    PetscCall(PeriProblemDestroy(&p));
    PetscCall(PeriProblemDestroy(&q));
    PetscCall(PeriFinalize());
    return 0;
  }
  PetscCall(PetscSNPrintf(what, sizeof(what), "%s: strain energy on %d ranks vs 1", p->sys->model->type, size));
  PeriTestClose(what, p->sys->fields.strain_energy, q->sys->fields.strain_energy, 1e-8 * q->sys->fields.strain_energy);
  for (PetscInt c = 0; c < p->sys->model->dofs; c++) {
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s: max |%s| on %d ranks vs 1", p->sys->model->type, p->sys->model->components[c], size));
    PeriTestClose(what, p->sys->fields.max_abs_u[c], q->sys->fields.max_abs_u[c], 1e-7 * q->sys->fields.max_abs_u[c] + 1e-300);
  }
  PetscCall(CompareFields(p, q, size));
  if (p->sys->conditions.torsion.active) {
    PetscCall(PetscSNPrintf(what, sizeof(what), "%s: torsion constant J on %d ranks vs 1", p->sys->model->type, size));
    PeriTestClose(what, p->sys->conditions.torsion.J, q->sys->conditions.torsion.J, 1e-8 * q->sys->conditions.torsion.J);
  }
  PetscCall(PeriProblemDestroy(&p));
  PetscCall(PeriProblemDestroy(&q));
  PetscCall(PeriFinalize());
  return 0;
}
