/* perilin SCENE.yaml [PETSc options]: run a scene, write summary.json and particles.vtu. */
#include "perilin.h"
#include "perilin/private/output.h" /* PeriOutputSetDiscard: the error path */
#include <signal.h>
#include <unistd.h>

static const char help[] = "perilin: implicit static and modal peridynamics.\n"
                           "Usage: perilin SCENE.yaml [-material_nu 0.25 -model_type npmb ... PETSc options]\n";

/* The first error's message, printed once by main instead of PETSc's traceback. */
static char first_error[4096];

static PetscErrorCode CaptureError(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *ctx)
{
  (void)comm;
  (void)ctx;
  if (p == PETSC_ERROR_INITIAL && !first_error[0]) {
    if (n == PETSC_ERR_USER_INPUT || n == PETSC_ERR_NOT_CONVERGED)
      PetscSNPrintf(first_error, sizeof(first_error), "%s", mess ? mess : "invalid input");
    else
      PetscSNPrintf(first_error, sizeof(first_error), "%s (PETSc error %d in %s() at %s:%d)", mess ? mess : "error", (int)n, fun, file, line);
  }
  return n;
}

/* -scene_doc_update FILE rewrites the key tables of docs/scene.md from the declared keys;
 * -scene_doc_check FILE fails when they are out of date (the scene_doc test). *done: either ran. */
static PetscErrorCode SceneDoc(PetscBool *done)
{
  char      file[PETSC_MAX_PATH_LEN];
  PetscBool update, check;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-scene_doc_update", file, sizeof(file), &update));
  if (!update)
    PetscCall(PetscOptionsGetString(NULL, NULL, "-scene_doc_check", file, sizeof(file), &check));
  else
    check = PETSC_FALSE;
  *done = (PetscBool)(update || check);
  if (*done) PetscCall(PeriSceneDoc(PETSC_COMM_WORLD, file, check));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Run(int argc, char **argv, PeriProblem *problem, int *status)
{
  PeriProblem p;
  PetscBool   help_asked;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsHasHelp(NULL, &help_asked));
  if (help_asked) {
    PetscCall(PeriPrintHelp(PETSC_COMM_WORLD));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(SceneDoc(&help_asked));
  if (help_asked) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCheck(argc >= 2 && argv[1][0] != '-', PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "usage: perilin SCENE.yaml [options]; perilin -help lists the scene keys");
  PetscCall(PeriProblemCreate(PETSC_COMM_WORLD, problem));
  p = *problem;
  PetscCall(PeriProblemSetWriteOutput(p, PETSC_TRUE));
  PetscCall(PeriProblemLoad(p, argv[1]));
  PetscCall(PeriProblemCheckOptions(p)); /* an option naming no scene key: before any work */
  PetscCall(PeriProblemSetUp(p));
  PetscCall(PeriProblemRun(p));
  PetscCall(PeriProblemCheckUnusedOptions(p)); /* an option nothing read: before anything is written */
  PetscCall(PeriProblemWriteOutput(p));
  PetscCall(PeriProblemReport(p));
  /* a run stopped by a signal says so in its exit status too: 128 + the signal, as shells do */
  PetscCall(PeriProblemInterrupted(p, status));
  if (*status) *status += 128;
  PetscCall(PeriProblemDestroy(problem));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether every rank failed (they all reach this barrier within a few seconds): then rank 0
 * alone prints the error and all end cleanly. Otherwise some rank still waits in a collective
 * call, and only MPI_Abort ends it. */
static PetscBool EveryRankFailed(void)
{
  MPI_Request req;
  int         done = 0;
  double      t0   = MPI_Wtime();

  if (MPI_Ibarrier(PETSC_COMM_WORLD, &req) != MPI_SUCCESS) return PETSC_FALSE;
  while (!done && MPI_Wtime() - t0 < 3.0) {
    if (MPI_Test(&req, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS) return PETSC_FALSE;
    if (!done) usleep(1000);
  }
  return done ? PETSC_TRUE : PETSC_FALSE;
}

int main(int argc, char **argv)
{
  PetscErrorCode ierr;
  PetscMPIInt    size, rank;
  int            status = 0;
  PeriProblem    p      = NULL;

  PetscCall(PeriInitialize(&argc, &argv, help));
  PetscCall(PetscPushErrorHandler(CaptureError, NULL));
  ierr = Run(argc, argv, &p, &status);
  PetscCall(PetscPopErrorHandler());
  if (ierr) {
    PetscBool all;
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
    if (rank == 0) PeriOutputSetDiscard(); /* the previous results stay as they were */
    all = size == 1 ? PETSC_TRUE : EveryRankFailed();
    /* through PETSc's printer, which first erases a status line on the terminal (src/sys/progress.c) */
    if (rank == 0 || !all) (void)PetscFPrintf(PETSC_COMM_SELF, stderr, "perilin: error: %s\n", first_error[0] ? first_error : "unknown error");
    if (!all) MPI_Abort(PETSC_COMM_WORLD, 1);
    /* every rank is here: free what the run held, so that -malloc_dump shows real leaks only */
    PetscCall(PetscPushErrorHandler(PetscIgnoreErrorHandler, NULL));
    (void)PeriProblemDestroy(&p);
    PetscCall(PetscPopErrorHandler());
    PetscCall(PeriFinalize());
    return 1;
  }
  PetscCall(PeriFinalize());
  return status;
}
