/* Checkpoints of an analysis and -restart (docs/failure.md, "Restart"). An analysis whose type
 * has checkpoints writes the state of its last equilibrium into checkpoint/state.bin of the output
 * set, a PETSc binary file (portable, written by rank 0 from every rank's part), rewritten under a
 * temporary name and renamed at each equilibrium, so that the file is always one whole state.
 * -restart DIR continues a run from DIR/checkpoint/state.bin. The file starts with a header that
 * ties it to the run that wrote it (the scene's fingerprint, the ranks, the particles, bonds and
 * DOFs); the analysis writes its own state after it, then the system's (PeriCheckpointView). */
#include "perilin/private/analysis.h"

#include <sys/stat.h>
#include <unistd.h>

#define PERI_CHECKPOINT_MAGIC   0x50455249 /* "PERI" */
#define PERI_CHECKPOINT_VERSION 3          /* 2: each step carries its attempts; 3: bond flags only with failure, dynamic runs */
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

/*@C
  PeriAnalysisCheckpointBegin - opens the temporary checkpoint file tmp in the output set and
  writes its header; the analysis then writes its state into v, and PeriAnalysisCheckpointEnd
  renames the file into place. Collective.
@*/
PetscErrorCode PeriAnalysisCheckpointBegin(PeriAnalysis an, PetscViewer *v, char tmp[], size_t len)
{
  const char *dir;
  char        sub[PETSC_MAX_PATH_LEN + 16];
  Header      h;

  PetscFunctionBeginUser;
  PetscCall(HeaderOfRun(an, &h));
  PetscCall(an->outputdir(an->snapshotctx, &dir));
  PetscCall(PetscSNPrintf(sub, sizeof(sub), "%s/checkpoint", dir));
  if (!an->rank) PetscCall(PeriOutputDirCreate(sub)); /* rank 0 alone writes the file */
  PetscCall(PetscSNPrintf(tmp, len, "%s/%s.tmp", dir, PERI_CHECKPOINT_FILE));
  PetscCall(OpenViewer(an->comm, tmp, FILE_MODE_WRITE, v));
  PetscCall(PetscViewerBinaryWrite(*v, h.n, 6, PETSC_INT));
  PetscCall(PetscViewerBinaryWrite(*v, h.analysis, sizeof(h.analysis), PETSC_CHAR));
  PetscCall(PetscViewerBinaryWrite(*v, &h.fingerprint, 1, PETSC_INT64));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisCheckpointEnd - closes v and renames tmp (…/state.bin.tmp) to state.bin. Collective.
@*/
PetscErrorCode PeriAnalysisCheckpointEnd(PeriAnalysis an, PetscViewer *v, const char tmp[])
{
  char final[PETSC_MAX_PATH_LEN + 32];

  PetscFunctionBeginUser;
  PetscCall(PetscViewerDestroy(v));
  PetscCall(PetscStrncpy(final, tmp, sizeof(final)));
  final[strlen(final) - 4] = 0; /* less ".tmp" */
  if (!an->rank) PetscCall(PeriFileCommit(tmp, final));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The header of the checkpoint open in v, checked against this run's: the same analysis, ranks,
 * particles, bonds and scene, each refused with what to do. */
static PetscErrorCode CheckHeader(PeriAnalysis an, PetscViewer v, const char file[], const Header *run)
{
  Header h;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerBinaryRead(v, h.n, 6, NULL, PETSC_INT));
  PetscCheck(h.n[0] == PERI_CHECKPOINT_MAGIC, an->comm, PETSC_ERR_USER_INPUT, "-restart: %s is no perilin checkpoint", file);
  PetscCheck(h.n[1] == PERI_CHECKPOINT_VERSION, an->comm, PETSC_ERR_USER_INPUT, "-restart: %s has format %" PetscInt_FMT ", this perilin reads %d: run the scene from the start", file, h.n[1], PERI_CHECKPOINT_VERSION);
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

/*@C
  PeriAnalysisRestartBegin - opens -restart's checkpoint (its path in file) and checks its header
  against this run: the same analysis, ranks, particles, bonds and scene, each refused with what to
  do. The analysis then reads its state from v and destroys v. Collective.
@*/
PetscErrorCode PeriAnalysisRestartBegin(PeriAnalysis an, PetscViewer *v, char file[], size_t len)
{
  Header         run;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(HeaderOfRun(an, &run));
  PetscCall(PetscSNPrintf(file, len, "%s/%s", an->restart, PERI_CHECKPOINT_FILE));
  PetscCall(OpenViewer(an->comm, file, FILE_MODE_READ, v));
  /* a refused header closes the file: the caller has no viewer to destroy (found by
     tests/fuzz/fuzz_checkpoint.c) */
  ierr = CheckHeader(an, *v, file, &run);
  if (ierr) PetscCall(PetscViewerDestroy(v));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
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
