/* perilin SCENE.yaml [options]: run a scene, write its output set; perilin -help, perilin -version. */
#include "perilin.h"
#include "perilin/private/output.h" /* PeriOutputSetDiscard: the error path */
#include "perilin/private/sys.h"    /* PeriSignalPending: the exit status of a stopped read */
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* What the command line asks for, decided before PETSc starts (ParseMode). */
typedef enum {
  MODE_RUN,
  MODE_HELP,       /* -help, -h, --help: perilin's help only */
  MODE_HELP_PETSC, /* -help petsc: perilin's help, then PETSc's and SLEPc's generic list */
  MODE_VERSION     /* -version, --version */
} Mode;

static int IsArg(const char *arg, const char *a, const char *b, const char *c)
{
  return !strcmp(arg, a) || !strcmp(arg, b) || (c && !strcmp(arg, c));
}

/* Takes -help, -h, --help (with "petsc" after it) and -version, --version out of the arguments
 * PETSc sees: PETSc would print its banner and generic list at initialization, before anything of
 * perilin's. -help petsc leaves "-help" in, and main gathers what PETSc prints (GatherPetscHelp)
 * to print it after perilin's help. Runs before PETSc starts: plain C. */
static Mode ParseMode(int *argc, char **argv)
{
  Mode mode = MODE_RUN;
  int  n    = 1;

  for (int k = 1; k < *argc; k++) {
    if (IsArg(argv[k], "-help", "-h", "--help")) {
      if (k + 1 < *argc && !strcmp(argv[k + 1], "petsc")) {
        mode      = MODE_HELP_PETSC;
        argv[n++] = (char *)"-help";
        k++;
      } else if (mode != MODE_HELP_PETSC)
        mode = MODE_HELP;
      continue;
    }
    if (IsArg(argv[k], "-version", "--version", NULL)) {
      if (mode == MODE_RUN) mode = MODE_VERSION;
      continue;
    }
    argv[n++] = argv[k];
  }
  argv[n] = NULL;
  *argc   = n;
  return mode;
}

/* What PETSc prints through PetscHelpPrintf while it starts under -help petsc, held for after
 * perilin's help. Installed before PETSc starts: plain C, rank 0 of comm only, as PETSc prints. */
static char  *petsc_help;
static size_t petsc_help_len, petsc_help_cap;

static PetscErrorCode GatherPetscHelp(MPI_Comm comm, const char fmt[], ...)
{
  va_list ap;
  int     rank = 0, n;

  if (MPI_Comm_rank(comm, &rank) != MPI_SUCCESS || rank) return PETSC_SUCCESS;
  va_start(ap, fmt);
  n = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  if (n <= 0) return PETSC_SUCCESS;
  if (petsc_help_len + (size_t)n + 1 > petsc_help_cap) {
    size_t cap  = 2 * (petsc_help_len + (size_t)n + 1);
    char  *more = realloc(petsc_help, cap);
    if (!more) return PETSC_ERR_MEM;
    petsc_help     = more;
    petsc_help_cap = cap;
  }
  va_start(ap, fmt);
  vsnprintf(petsc_help + petsc_help_len, (size_t)n + 1, fmt, ap);
  va_end(ap);
  petsc_help_len += (size_t)n;
  return PETSC_SUCCESS;
}

/* perilin -help [petsc]: perilin's help, then what PETSc printed at its start. */
static PetscErrorCode PrintHelp(Mode mode)
{
  PetscFunctionBeginUser;
  PetscCall(PeriPrintHelp(PETSC_COMM_WORLD));
  if (mode == MODE_HELP_PETSC && petsc_help) {
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "----------------------------------------\nPETSc's and SLEPc's generic options:\n"));
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s", petsc_help));
  }
  free(petsc_help);
  petsc_help = NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The scene file must be the first argument. An option before it ("perilin -quiet scene.yaml")
 * gets the command line in the right order when a later argument looks like the scene. */
static PetscErrorCode CheckSceneFirst(int argc, char **argv)
{
  char order[1024] = "";
  int  scene       = 0;

  PetscFunctionBeginUser;
  PetscCheck(argc >= 2, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "usage: perilin SCENE.yaml [options]; perilin -help lists the options and the scene keys");
  if (argv[1][0] != '-') PetscFunctionReturn(PETSC_SUCCESS);
  for (int k = 2; k < argc && !scene; k++) {
    size_t len = strlen(argv[k]);
    if (argv[k][0] == '-') continue;
    if ((len > 5 && !strcmp(argv[k] + len - 5, ".yaml")) || (len > 4 && !strcmp(argv[k] + len - 4, ".yml")) || !access(argv[k], R_OK)) scene = k;
  }
  PetscCheck(scene, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "the scene file comes first: perilin SCENE.yaml [options] (the first argument is the option %s); perilin -help lists the options", argv[1]);
  PetscCall(PetscStrlcat(order, argv[scene], sizeof(order)));
  for (int k = 1; k < argc; k++) {
    if (k == scene) continue;
    PetscCall(PetscStrlcat(order, " ", sizeof(order)));
    PetscCall(PetscStrlcat(order, argv[k], sizeof(order)));
  }
  SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "the scene file comes first, then the options: perilin %s", order);
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

static PetscErrorCode Run(int argc, char **argv, Mode mode, PeriProblem *problem, int *status)
{
  PeriProblem p;
  PetscBool   help_asked;

  PetscFunctionBeginUser;
  if (mode == MODE_VERSION) {
    PetscCall(PeriPrintVersion(PETSC_COMM_WORLD));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscOptionsHasHelp(NULL, &help_asked)); /* also -help from PETSC_OPTIONS or a file */
  if (mode != MODE_RUN || help_asked) {
    PetscCall(PrintHelp(mode));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(SceneDoc(&help_asked));
  if (help_asked) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(CheckSceneFirst(argc, argv));
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
  Mode           mode   = ParseMode(&argc, argv);

  if (mode == MODE_HELP_PETSC) PetscHelpPrintf = GatherPetscHelp;
  PetscCall(PeriInitialize(&argc, &argv, NULL)); /* the usage is perilin's help, PeriPrintHelp */
  PetscHelpPrintf = PetscHelpPrintfDefault;
  PetscCall(PetscPushErrorHandler(PeriErrorCapture, NULL)); /* the first error's message, printed once below instead of PETSc's traceback */
  ierr = Run(argc, argv, mode, &p, &status);
  PetscCall(PetscPopErrorHandler());
  if (ierr) {
    PetscBool all, kept = PETSC_FALSE;
    char      staging[PETSC_MAX_PATH_LEN] = "";
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
    /* a write that failed after a checkpoint (a full disk at the end): that checkpoint stays for
       -restart; else the previous results stay as they were */
    if (rank == 0 && ierr == PETSC_ERR_FILE_WRITE) kept = PeriOutputSetKeepCheckpoint(staging, sizeof(staging));
    if (rank == 0) PeriOutputSetDiscard();
    all = size == 1 ? PETSC_TRUE : EveryRankFailed();
    /* through PETSc's printer, which first erases a status line on the terminal (src/sys/progress.c) */
    if (rank == 0 || !all) (void)PetscFPrintf(PETSC_COMM_SELF, stderr, "perilin: error: %s\n", PeriErrorFirst()[0] ? PeriErrorFirst() : "unknown error");
    if (kept) (void)PetscFPrintf(PETSC_COMM_SELF, stderr, "perilin: the run's last checkpoint is kept whole in %s: free space, then continue with -restart %s\n", staging, staging);
    if (!all) MPI_Abort(PETSC_COMM_WORLD, 1);
    /* every rank is here: free what the run held, so that -malloc_dump shows real leaks only */
    PetscCall(PetscPushErrorHandler(PetscIgnoreErrorHandler, NULL));
    (void)PeriProblemDestroy(&p);
    PetscCall(PetscPopErrorHandler());
    PetscCall(PeriFinalize());
    return PeriSignalPending() ? 128 + PeriSignalPending() : 1; /* a read the signal stopped: as a shell says it */
  }
  PetscCall(PeriFinalize());
  return status;
}
