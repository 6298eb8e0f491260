/* perilin SCENE.yaml [PETSc options]: run a scene, write summary.json and particles.vtu. */
#include "perilin.h"

static const char help[] = "perilin: implicit static and modal peridynamics.\n"
                           "Usage: perilin SCENE.yaml [-material_nu 0.25 -model_type npmb ... PETSc options]\n";

/* The first error's message, printed once by main instead of PETSc's traceback. */
static char first_error[4096];

static PetscErrorCode CaptureError(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *ctx)
{
  (void)comm;
  (void)ctx;
  if (p == PETSC_ERROR_INITIAL && !first_error[0]) {
    if (n == PETSC_ERR_USER_INPUT)
      PetscSNPrintf(first_error, sizeof(first_error), "%s", mess ? mess : "invalid input");
    else
      PetscSNPrintf(first_error, sizeof(first_error), "%s (PETSc error %d in %s() at %s:%d)", mess ? mess : "error", (int)n, fun, file, line);
  }
  return n;
}

static PetscErrorCode Run(int argc, char **argv, PetscBool *incomplete)
{
  PeriProblem p;
  PetscBool   help_asked;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsHasHelp(NULL, &help_asked));
  if (help_asked) {
    PetscCall(PeriSceneHelp(PETSC_COMM_WORLD));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCheck(argc >= 2 && argv[1][0] != '-', PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "usage: perilin SCENE.yaml [options]; perilin -help lists the scene keys");
  PetscCall(PeriProblemCreate(PETSC_COMM_WORLD, &p));
  PetscCall(PeriProblemLoad(p, argv[1]));
  PetscCall(PeriProblemSetUp(p));
  PetscCall(PeriProblemRun(p));
  PetscCall(PeriProblemWriteOutput(p));
  PetscCall(PetscPrintf(p->comm, "perilin: %s, model %s, %" PetscInt_FMT " particles, %" PetscInt_FMT " bonds, %" PetscInt_FMT " dofs on %d rank(s)\n", p->analysis, p->model->type, p->particles.n, p->results.nbonds_total, p->particles.n * p->model->dofs, p->size));
  PetscCall(PetscPrintf(p->comm, "perilin: neighbours %.3f s, assembly %.3f s, solve %.3f s (%s/%s, %" PetscInt_FMT " iterations, %s), peak memory %.1f MB\n", p->results.neighbors_s, p->results.assembly_s, p->results.solve_s, p->results.ksp_type, p->results.pc_type, p->results.iterations, p->results.converged_reason, p->results.memory_mb));
  if (p->modal) {
    PetscCall(PetscPrintf(p->comm, "perilin: %" PetscInt_FMT " modes (Hz):", p->modal->nmodes));
    for (PetscInt k = 0; k < p->modal->nmodes; k++) PetscCall(PetscPrintf(p->comm, " %.6g (%s)", (double)p->modal->modes[k].f_hz, p->modal->modes[k].kind));
    PetscCall(PetscPrintf(p->comm, "; results in %s/\n", p->output_dir));
  } else {
    if (p->torsion.active) PetscCall(PetscPrintf(p->comm, "perilin: torsion: torque %g per unit length, J = %g (solid rectangle exact %g, %+.2f %%), max shear stress %g at (%g, %g)\n", (double)p->torsion.torque, (double)p->torsion.J, (double)p->torsion.J_rectangle, 100 * (double)(p->torsion.J / p->torsion.J_rectangle - 1), (double)p->torsion.max_stress, (double)p->torsion.max_at[0], (double)p->torsion.max_at[1]));
    PetscCall(PetscPrintf(p->comm, "perilin: strain energy %g; results in %s/\n", p->results.strain_energy, p->output_dir));
  }
  /* an interrupted quasi-static run wrote what it had: say so in the exit status too */
  *incomplete = (PetscBool)(p->quasistatic && !p->quasistatic->complete);
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  PetscErrorCode ierr;
  PetscMPIInt    size, rank;
  PetscBool      incomplete = PETSC_FALSE;

  PetscCall(PetscInitialize(&argc, &argv, NULL, help));
  PetscCall(PetscPushErrorHandler(CaptureError, NULL));
  ierr = Run(argc, argv, &incomplete);
  PetscCall(PetscPopErrorHandler());
  if (ierr) {
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
    if (rank == 0 || size > 1) fprintf(stderr, "perilin: error: %s\n", first_error[0] ? first_error : "unknown error");
    /* another rank may still wait in a collective call: only an abort ends them all */
    if (size > 1) MPI_Abort(PETSC_COMM_WORLD, 1);
    PetscCall(PetscFinalize());
    return 1;
  }
  PetscCall(PetscFinalize());
  return incomplete ? 130 : 0;
}
