/* Checkpoints of an analysis and -restart (docs/failure.md, "Restart"). An analysis whose type
 * has checkpoints writes the state of its last equilibrium into checkpoint/state.bin of the output
 * set, a PETSc binary file (portable, written by rank 0 from every rank's part), rewritten under a
 * temporary name and renamed at each equilibrium, so that the file is always one whole state.
 * -restart DIR continues a run from DIR/checkpoint/state.bin. The file starts with a header that
 * ties it to the run that wrote it (the scene's fingerprint, the ranks, the particles, bonds and
 * DOFs); the analysis writes its own state after it, then the system's (PeriCheckpointView), and
 * the file ends with a mark, so that one cut short is told from a damaged one. A write that fails
 * (a full disk) keeps the previous file and stops the run; a file refused on -restart is named,
 * with what is wrong in it (docs/reliability.md, "Faults during runs"). */
#include "perilin/private/analysis.h"

#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

#define PERI_CHECKPOINT_MAGIC   0x50455249 /* "PERI" */
#define PERI_CHECKPOINT_VERSION 4          /* 2: each step carries its attempts; 3: bond flags only with failure, dynamic runs; 4: an end mark */
#define PERI_CHECKPOINT_FILE    "checkpoint/state.bin"

/* What ties a checkpoint to a run. */
typedef struct {
  PetscInt   n[6]; /* magic, version, ranks, particles, bonds (over all ranks), DOFs per particle */
  char       analysis[32];
  PetscInt64 fingerprint;
} Header;

static PetscErrorCode HeaderOfRun(PeriAnalysis an, Header *h)
{
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(h, sizeof(*h)));
  PetscCallMPI(MPI_Comm_size(an->comm, &size));
  PetscCallMPI(MPI_Allreduce(&an->sys->disc.bonds.nbonds, &h->n[4], 1, MPIU_INT, MPI_SUM, an->comm));
  h->n[0] = PERI_CHECKPOINT_MAGIC;
  h->n[1] = PERI_CHECKPOINT_VERSION;
  h->n[2] = size;
  h->n[3] = an->sys->disc.N;
  h->n[5] = an->sys->model->dofs;
  PetscCall(PetscStrncpy(h->analysis, an->type->name, sizeof(h->analysis)));
  h->fingerprint = an->fingerprint;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode OpenViewer(MPI_Comm comm, const char path[], PetscFileMode mode, PetscViewer *v)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerCreate(comm, v));
  PetscCall(PetscViewerSetType(*v, PETSCVIEWERBINARY));
  PetscCall(PetscViewerFileSetMode(*v, mode));
  PetscCall(PetscViewerBinarySetSkipInfo(*v, PETSC_TRUE)); /* no .info file of options beside it */
  PetscCall(PetscViewerFileSetName(*v, path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisCheckpointSetFromOptions - -restart DIR and -peri_checkpoint_every N (default 1; 0
  writes none) of an analysis whose type has checkpoints (the problem refuses -restart for the
  others), before any particle exists: a DIR without a checkpoint is refused at no cost. Collective.
@*/
PetscErrorCode PeriAnalysisCheckpointSetFromOptions(PeriAnalysis an)
{
  PetscBool given, found;
  char      path[PETSC_MAX_PATH_LEN + 32];

  PetscFunctionBeginUser;
  an->checkpoint_every = 1;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-restart", an->restart, sizeof(an->restart), &given));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-peri_checkpoint_every", &an->checkpoint_every, NULL));
  PetscCheck(an->checkpoint_every >= 0, an->comm, PETSC_ERR_USER_INPUT, "-peri_checkpoint_every %" PetscInt_FMT ": give a number of equilibria or time steps >= 1, or 0 for no checkpoints", an->checkpoint_every);
  if (!given) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCheck(an->restart[0], an->comm, PETSC_ERR_USER_INPUT, "-restart needs a directory: -restart DIR, the output directory of the run to continue");
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/%s", an->restart, PERI_CHECKPOINT_FILE));
  PetscCall(PetscTestFile(path, 'r', &found));
  PetscCheck(found, an->comm, PETSC_ERR_USER_INPUT, "-restart %s: no checkpoint there (%s): give the output directory of a %s run that wrote one (an equilibrium, or a dynamic run's step, with -peri_checkpoint_every not 0); a run killed by SIGKILL left its own in %s.partial-XXXXXX", an->restart, path, an->type->name, an->restart);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The file's last bytes: a file without them was cut short (a write that did not finish, a full
 * disk, a copy that stopped), which a reader would otherwise meet as "Read past end of file". */
static const char peri_checkpoint_end[12] = "perilin end\n";

/* Rank 0's checkpoint file tmp: the header, the analysis' part (body) and the end mark. */
static PetscErrorCode WriteFile(PeriAnalysis an, const char tmp[], PetscErrorCode (*body)(PeriAnalysis, PetscViewer, void *), void *ctx, PetscViewer *v)
{
  Header h;

  PetscFunctionBeginUser;
  PetscCall(HeaderOfRun(an, &h));
  PetscCall(OpenViewer(an->comm, tmp, FILE_MODE_WRITE, v));
  PetscCall(PetscViewerBinaryWrite(*v, h.n, 6, PETSC_INT));
  PetscCall(PetscViewerBinaryWrite(*v, h.analysis, sizeof(h.analysis), PETSC_CHAR));
  PetscCall(PetscViewerBinaryWrite(*v, &h.fingerprint, 1, PETSC_INT64));
  PetscCall(body(an, *v, ctx));
  PetscCall(PetscViewerBinaryWrite(*v, peri_checkpoint_end, sizeof(peri_checkpoint_end), PETSC_CHAR));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A checkpoint that could not be written (rank 0 writes: a full disk, a quota, an I/O error): its
 * temporary file removed, the previous checkpoint and the staging directory it lies in kept for
 * -restart (a failed run's set is otherwise discarded), and the cause said. */
static PetscErrorCode WriteFailed(const char dir[], const char tmp[], int err)
{
  char      prev[PETSC_MAX_PATH_LEN + 32];
  PetscBool found;

  PetscFunctionBeginUser;
  if (!err) err = PeriFileSystemFull(dir) ? ENOSPC : 0; /* PETSc's error path may have reset errno; before the file's blocks are freed */
  (void)remove(tmp);
  PetscCall(PetscSNPrintf(prev, sizeof(prev), "%s/%s", dir, PERI_CHECKPOINT_FILE));
  PetscCall(PetscTestFile(prev, 'r', &found));
  if (found) PeriOutputSetKeep();
  SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write the checkpoint %s: %s%s: %s; free space (or give -peri_checkpoint_every 0 for no checkpoints)%s%s", tmp, err ? strerror(err) : "a write failed", err == ENOSPC || err == EDQUOT ? " (the disk or the quota is full)" : "", found ? "the previous checkpoint is kept whole" : "there was no previous checkpoint", found ? ", then continue the run with -restart " : " and run the scene again", found ? dir : "");
}

/*@C
  PeriAnalysisCheckpointWrite - checkpoint/state.bin of the output set: the header, then what
  body(an, v, ctx) writes into v (the analysis' state), then an end mark; written under a
  temporary name and renamed into place, so that the file is always one whole state. A write that
  fails keeps the previous checkpoint (and its staging directory) and stops the run, saying the
  file and the cause. Collective.
@*/
PetscErrorCode PeriAnalysisCheckpointWrite(PeriAnalysis an, PetscErrorCode (*body)(PeriAnalysis, PetscViewer, void *), void *ctx)
{
  const char    *dir;
  char           sub[PETSC_MAX_PATH_LEN + 32], tmp[PETSC_MAX_PATH_LEN + 32];
  PetscViewer    v = NULL;
  PetscErrorCode ierr, cerr;
  int            err;

  PetscFunctionBeginUser;
  PetscCall(an->outputdir(an->snapshotctx, &dir));
  PetscCall(PetscSNPrintf(sub, sizeof(sub), "%s/checkpoint", dir));
  if (!an->rank) PetscCall(PeriOutputDirCreate(sub)); /* rank 0 alone writes the file */
  PetscCall(PetscSNPrintf(tmp, sizeof(tmp), "%s/%s.tmp", dir, PERI_CHECKPOINT_FILE));
  /* PETSc's own message ("Error writing to file total size 6 err -1") names neither the file nor
     the cause: its errors are taken here and said by WriteFailed */
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  errno = 0;
  ierr  = WriteFile(an, tmp, body, ctx, &v);
  err   = errno;
  cerr  = PetscViewerDestroy(&v); /* closes the file: a last failure may show here */
  if (!ierr && cerr) ierr = cerr, err = errno;
  PetscCall(PetscPopErrorHandler());
  if (ierr) PetscCall(WriteFailed(dir, tmp, err));
  PetscCall(PetscSNPrintf(sub, sizeof(sub), "%s/%s", dir, PERI_CHECKPOINT_FILE));
  if (!an->rank) PetscCall(PeriFileCommit(tmp, sub));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The header of the checkpoint open in v, checked against this run's: the same analysis, ranks,
 * particles, bonds and scene, each refused with what to do. */
static PetscErrorCode CheckHeader(PeriAnalysis an, PetscViewer v, const char file[], const Header *run, PetscBool ends)
{
  Header h;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerBinaryRead(v, h.n, 6, NULL, PETSC_INT));
  PetscCheck(h.n[0] == PERI_CHECKPOINT_MAGIC, an->comm, PETSC_ERR_USER_INPUT, "-restart: %s is no perilin checkpoint", file);
  PetscCheck(h.n[1] == PERI_CHECKPOINT_VERSION, an->comm, PETSC_ERR_USER_INPUT, "-restart: %s has format %" PetscInt_FMT ", this perilin reads %d: run the scene from the start", file, h.n[1], PERI_CHECKPOINT_VERSION);
  PetscCheck(ends, an->comm, PETSC_ERR_USER_INPUT, "-restart: %s is cut short (truncated: it lacks the end of a whole checkpoint, as when its copy or its write stopped): restart from a whole checkpoint, or run the scene from the start", file);
  PetscCall(PetscViewerBinaryRead(v, h.analysis, sizeof(h.analysis), NULL, PETSC_CHAR));
  PetscCall(PetscViewerBinaryRead(v, &h.fingerprint, 1, NULL, PETSC_INT64));
  h.analysis[sizeof(h.analysis) - 1] = 0;
  PetscCheck(!strcmp(h.analysis, run->analysis), an->comm, PETSC_ERR_USER_INPUT, "-restart: %s is a checkpoint of a %s analysis, and this run's is %s", file, h.analysis, run->analysis);
  PetscCheck(h.n[2] == run->n[2], an->comm, PETSC_ERR_USER_INPUT, "-restart: %s was written on %" PetscInt_FMT " ranks and this run has %" PetscInt_FMT ": restart on %" PetscInt_FMT " (each rank's bonds are kept as that rank held them)", file, h.n[2], run->n[2], h.n[2]);
  PetscCheck(h.fingerprint == run->fingerprint && h.n[3] == run->n[3] && h.n[4] == run->n[4] && h.n[5] == run->n[5], an->comm, PETSC_ERR_USER_INPUT,
             "-restart: %s was written by a run of another scene (%" PetscInt_FMT " particles, %" PetscInt_FMT " bonds; this one has %" PetscInt_FMT " and %" PetscInt_FMT "%s): give the scene and scene options of the run that wrote it, or its resolved scene: perilin %s/scene.yaml -restart %s",
             file, h.n[3], h.n[4], run->n[3], run->n[4], h.n[3] == run->n[3] && h.n[4] == run->n[4] ? ", but the scenes' keys differ" : "", an->restart, an->restart);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The size of the checkpoint file and whether it ends with the end mark, as rank 0 (which reads it)
 * sees them. Collective. */
static PetscErrorCode FileEnds(PeriAnalysis an, const char file[], PetscInt64 *size, PetscBool *ends)
{
  PetscInt64 r[2] = {0, 0}; /* size, ends */

  PetscFunctionBeginUser;
  if (!an->rank) {
    FILE *fp = fopen(file, "rb");
    char  tail[sizeof(peri_checkpoint_end)];
    long  n;

    if (fp && !fseek(fp, 0, SEEK_END) && (n = ftell(fp)) >= 0) {
      r[0] = n;
      r[1] = n >= (long)sizeof(tail) && !fseek(fp, -(long)sizeof(tail), SEEK_END) && fread(tail, 1, sizeof(tail), fp) == sizeof(tail) && !memcmp(tail, peri_checkpoint_end, sizeof(tail));
    }
    if (fp) (void)fclose(fp);
  }
  PetscCallMPI(MPI_Bcast(r, 2, MPIU_INT64, 0, an->comm));
  *size = r[0];
  *ends = r[1] ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisRestartBegin - opens -restart's checkpoint (its path in file) and checks its header
  against this run: the same analysis, ranks, particles, bonds and scene, each refused with what to
  do. The analysis then reads its state from v and destroys v. Collective.
@*/
PetscErrorCode PeriAnalysisRestartBegin(PeriAnalysis an, PetscViewer *v, char file[], size_t len)
{
  Header         run;
  PetscInt64     size;
  PetscBool      ends;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(HeaderOfRun(an, &run));
  PetscCall(PetscSNPrintf(file, len, "%s/%s", an->restart, PERI_CHECKPOINT_FILE));
  PetscCall(FileEnds(an, file, &size, &ends));
  PetscCheck(size >= (PetscInt64)(6 * sizeof(PetscInt) + sizeof(run.analysis) + sizeof(PetscInt64)), an->comm, PETSC_ERR_USER_INPUT, "-restart: %s is cut short (truncated: %" PetscInt64_FMT " bytes, less than a checkpoint's header): restart from a whole checkpoint, or run the scene from the start", file, size);
  PetscCall(OpenViewer(an->comm, file, FILE_MODE_READ, v));
  /* a refused header closes the file: the caller has no viewer to destroy (found by
     tests/fuzz/fuzz_checkpoint.c) */
  ierr = CheckHeader(an, *v, file, &run, ends);
  if (ierr) PetscCall(PetscViewerDestroy(v));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisRestartEnd - closes the checkpoint v the analysis has read, its reading run under
  PetscReturnErrorHandler and ended with ierr. PETSc's own refusals of a damaged file ("Not a
  vector next in file", "Vector in file different size (7) than input vector (320)", "Read past
  end of file") name neither the file nor -restart: they are said as a damaged checkpoint. perilin's
  own refusals, and errors that are not the file's (memory), go on as they were. Collective.
@*/
PetscErrorCode PeriAnalysisRestartEnd(PeriAnalysis an, PetscViewer *v, const char file[], PetscErrorCode ierr)
{
  char     *msg = NULL, copy[1024] = "";
  PetscBool file_error;

  PetscFunctionBeginUser;
  if (ierr) {
    PetscCall(PetscErrorMessage(ierr, NULL, &msg));
    PetscCall(PetscStrncpy(copy, msg ? msg : "", sizeof(copy)));
  }
  PetscCall(PetscViewerDestroy(v));
  if (!ierr) PetscFunctionReturn(PETSC_SUCCESS);
  file_error = (PetscBool)(ierr == PETSC_ERR_FILE_READ || ierr == PETSC_ERR_FILE_UNEXPECTED || ierr == PETSC_ERR_FILE_OPEN || ierr == PETSC_ERR_ARG_SIZ || ierr == PETSC_ERR_ARG_WRONG || ierr == PETSC_ERR_ARG_OUTOFRANGE);
  PetscCheck(!file_error, an->comm, PETSC_ERR_USER_INPUT, "-restart: %s is damaged (%s): restart from an undamaged checkpoint, or run the scene from the start", file, copy);
  SETERRQ(an->comm, ierr, "%s", copy);
}

/*@C
  PeriAnalysisCheckpointFits - refuses a count read from the checkpoint open in v when n items of
  each bytes cannot be in what is left of the file (or n < 0): a damaged count would otherwise size
  an allocation. Collective.
@*/
PetscErrorCode PeriAnalysisCheckpointFits(PeriAnalysis an, PetscViewer v, PetscInt n, size_t each)
{
  int         fd;
  struct stat st;
  off_t       at;
  PetscInt    bad = n < 0;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerBinaryGetDescriptor(v, &fd));
  /* the rank that reads the file (rank 0) knows its size; the others agree with it */
  if (!bad && fd >= 0 && !fstat(fd, &st) && (at = lseek(fd, 0, SEEK_CUR)) >= 0) bad = (double)n * (double)each > (double)(st.st_size - at);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_MAX, an->comm));
  PetscCheck(!bad, an->comm, PETSC_ERR_USER_INPUT, "-restart: %s/%s is damaged: it counts %" PetscInt_FMT " items where the rest of the file holds fewer: restart from an undamaged checkpoint, or run the scene from the start", an->restart, PERI_CHECKPOINT_FILE, n);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisCheckpointFinite - refuses the n reals x (or, with x NULL, the vector u) read from the
  checkpoint when one is not finite: a NaN there would otherwise come out later as a solver's
  failure (a singular operator) or in the results. what names them. Collective.
@*/
PetscErrorCode PeriAnalysisCheckpointFinite(PeriAnalysis an, const PetscReal x[], PetscInt n, Vec u, const char what[])
{
  PetscReal norm = 0;
  PetscInt  bad  = 0;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < n && !bad; k++) bad = PetscIsInfOrNanReal(x[k]);
  if (u) PetscCall(VecNorm(u, NORM_INFINITY, &norm)); /* a NaN or inf anywhere makes it so */
  bad = bad || PetscIsInfOrNanReal(norm);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_MAX, an->comm));
  PetscCheck(!bad, an->comm, PETSC_ERR_USER_INPUT, "-restart: %s/%s is damaged: its %s are not finite (NaN or inf): restart from an undamaged checkpoint, or run the scene from the start", an->restart, PERI_CHECKPOINT_FILE, what);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisAdoptSnapshots - the snapshots of the checkpoint's run (particles_NNNN, NNNN = idx[k],
  k < *n: particles.pvd's frames so far), taken from -restart's directory into this run's output
  set; one that is gone leaves the series, and idx (and times, when given) keep the others. Collective.
@*/
PetscErrorCode PeriAnalysisAdoptSnapshots(PeriAnalysis an, PetscInt *n, PetscInt idx[], PetscReal times[])
{
  const char *dir;
  PetscInt    kept = 0;
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(an->comm, &size));
  PetscCall(an->outputdir(an->snapshotctx, &dir));
  for (PetscInt k = 0; k < *n; k++) {
    char      base[32], file[40];
    PetscBool found, pieces = PETSC_TRUE;
    PetscCall(PetscSNPrintf(base, sizeof(base), "particles_%04" PetscInt_FMT, idx[k]));
    PetscCall(PeriParticlesFileName(an->comm, base, file, sizeof(file)));
    PetscCall(PeriOutputSetAdopt(an->comm, an->restart, dir, file, &found));
    if (found && size > 1) PetscCall(PeriOutputSetAdopt(an->comm, an->restart, dir, base, &pieces)); /* base/piece_RRRR.vtu */
    if (!found || !pieces) continue;
    if (times) times[kept] = times[k];
    idx[kept++] = idx[k];
  }
  if (kept < *n) PetscCall(PetscPrintf(an->comm, "perilin: note: %" PetscInt_FMT " of the %" PetscInt_FMT " snapshots of %s are gone: particles.pvd lists the others\n", *n - kept, *n, an->restart));
  *n = kept;
  PetscFunctionReturn(PETSC_SUCCESS);
}
