/* The particle writers, white-box (src/output/vtu.c):
 * - the .pvd equal-time rule: ParaView collapses equal times into one frame, so PeriWritePVD
 *   writes a time not above the one before as that one x (1 + 1e-12) (0 after 0: the smallest
 *   normal number); the times read back must increase strictly and equal the given ones to
 *   1e-11 relative (degenerate frequencies, equal load factors);
 * - PeriWriteParticles on any number of ranks: base.vtu (1 rank) or base.pvtu and one piece per
 *   rank; and when one rank cannot write its piece (its temporary name is taken by a directory),
 *   every rank fails and neither the index nor any piece is left under a final or temporary name.
 * usage: test_output (on 1 or more ranks) */
#include "testing.h"
#include "perilin/private/output.h"
#include <float.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

static PetscBool Exists(const char dir[], const char name[])
{
  char        path[PETSC_MAX_PATH_LEN];
  struct stat st;

  PetscSNPrintf(path, sizeof(path), "%s/%s", dir, name);
  return stat(path, &st) == 0 ? PETSC_TRUE : PETSC_FALSE;
}

/* The times of a .pvd as written (rank 0). */
static PetscErrorCode ReadTimes(const char path[], PetscInt max, double t[], PetscInt *n)
{
  FILE *fp = fopen(path, "r");
  char  line[512];

  PetscFunctionBeginUser;
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot read %s", path);
  *n = 0;
  while (fgets(line, sizeof(line), fp)) {
    const char *s = strstr(line, "timestep=\"");
    if (s && *n < max) t[(*n)++] = strtod(s + strlen("timestep=\""), NULL);
  }
  fclose(fp);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode TestPVDTimes(const char dir[])
{
  const PetscReal   times[] = {0, 0, 1, 1, 1, 2.5, 2.5, 9573.6478049594516, 9573.6478049594516};
  const char *const files[] = {"a", "b", "c", "d", "e", "f", "g", "h", "i"};
  const PetscInt    n       = (PetscInt)(sizeof(times) / sizeof(times[0]));
  char              path[PETSC_MAX_PATH_LEN];
  double            t[16];
  PetscInt          m;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/equal.pvd", dir));
  PetscCall(PeriWritePVD(path, n, times, files));
  PetscCall(ReadTimes(path, 16, t, &m));
  PetscCheck(m == n, PETSC_COMM_SELF, PETSC_ERR_PLIB, "equal.pvd: %" PetscInt_FMT " frames, expected %" PetscInt_FMT, m, n);
  for (PetscInt k = 1; k < n; k++) PetscCheck(t[k] > t[k - 1], PETSC_COMM_SELF, PETSC_ERR_PLIB, "equal.pvd: time %" PetscInt_FMT " (%.17g) is not above the one before (%.17g)", k, t[k], t[k - 1]);
  PetscCheck(t[0] == 0 && t[1] > 0 && t[1] <= 1e-300, PETSC_COMM_SELF, PETSC_ERR_PLIB, "equal.pvd: 0 after 0 became %.17g, expected the smallest normal number", t[1]);
  for (PetscInt k = 2; k < n; k++) PeriTestClose("a .pvd time against the given one, relative", t[k] / times[k], 1.0, 1e-11);
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "ok: equal.pvd: %" PetscInt_FMT " frames, strictly increasing times\n", n));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A list of rank + 2 points with one real and one integer field. */
static PetscErrorCode PieceList(PetscMPIInt rank, PetscReal x[], PetscReal v[], PetscInt id[], PeriFieldList *fl)
{
  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < rank + 2; i++) {
    x[3 * i] = rank, x[3 * i + 1] = i, x[3 * i + 2] = 0;
    v[i]  = 10 * rank + i;
    id[i] = rank;
  }
  PetscCall(PeriFieldListCreate(rank + 2, x, fl));
  PetscCall(PeriFieldListAddReal(*fl, "value", 1, v, 1, NULL));
  PetscCall(PeriFieldListAddInt(*fl, "rank", id));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode TestSet(MPI_Comm comm, const char dir[])
{
  PetscMPIInt   rank, size;
  PetscReal     x[3 * 64], v[64];
  PetscInt      id[64];
  PeriFieldList fl;
  char          sub[PETSC_MAX_PATH_LEN], name[64];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCheck(size <= 62, comm, PETSC_ERR_SUP, "at most 62 ranks");
  PetscCall(PieceList(rank, x, v, id, &fl));
  PetscCall(PeriWriteParticles(comm, fl, dir, "set"));
  PetscCall(PeriFieldListDestroy(&fl));
  PetscCall(PetscSNPrintf(sub, sizeof(sub), "%s/set", dir));
  for (PetscMPIInt r = 0; rank == 0 && r < size; r++) {
    PetscCall(PetscSNPrintf(name, sizeof(name), "piece_%04d.vtu", r));
    PetscCheck(size == 1 || Exists(sub, name), PETSC_COMM_SELF, PETSC_ERR_PLIB, "no piece %s/%s", sub, name);
    PetscCall(PetscStrlcat(name, ".tmp", sizeof(name)));
    PetscCheck(!Exists(sub, name), PETSC_COMM_SELF, PETSC_ERR_PLIB, "a temporary piece %s/%s was left", sub, name);
  }
  PetscCheck(rank || Exists(dir, size > 1 ? "set.pvtu" : "set.vtu"), PETSC_COMM_SELF, PETSC_ERR_PLIB, "no set.%s", size > 1 ? "pvtu" : "vtu");
  PetscCheck(rank || !Exists(dir, size > 1 ? "set.vtu" : "set.pvtu"), PETSC_COMM_SELF, PETSC_ERR_PLIB, "set.%s beside the set", size > 1 ? "vtu" : "pvtu");
  PetscCall(PetscPrintf(comm, "ok: %d rank(s) wrote set.%s%s\n", size, size > 1 ? "pvtu" : "vtu", size > 1 ? " and one piece per rank" : ""));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The last rank cannot open its temporary file: every rank must fail, nothing must be left. */
static PetscErrorCode TestFailure(MPI_Comm comm, const char dir[])
{
  PetscMPIInt    rank, size;
  PetscReal      x[3 * 64], v[64];
  PetscInt       id[64];
  PeriFieldList  fl;
  PetscErrorCode ierr;
  char           blocker[PETSC_MAX_PATH_LEN], sub[PETSC_MAX_PATH_LEN], name[64];
  int            failed, all;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscSNPrintf(sub, sizeof(sub), "%s/fail", dir));
  if (size > 1)
    PetscCall(PetscSNPrintf(blocker, sizeof(blocker), "%s/piece_%04d.vtu.tmp", sub, size - 1));
  else
    PetscCall(PetscSNPrintf(blocker, sizeof(blocker), "%s/fail.vtu.tmp", dir));
  if (rank == 0) PetscCall(PeriOutputDirCreate(blocker));
  PetscCallMPI(MPI_Barrier(comm));
  PetscCall(PieceList(rank, x, v, id, &fl));
  PetscCall(PetscPushErrorHandler(PetscIgnoreErrorHandler, NULL));
  ierr = PeriWriteParticles(comm, fl, dir, "fail");
  PetscCall(PetscPopErrorHandler());
  PetscCall(PeriFieldListDestroy(&fl));
  failed = ierr != PETSC_SUCCESS;
  PetscCallMPI(MPI_Allreduce(&failed, &all, 1, MPI_INT, MPI_MIN, comm));
  PetscCheck(all, PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: PeriWriteParticles succeeded although rank %d could not write", rank, size - 1);
  PetscCheck(rank || (!Exists(dir, "fail.pvtu") && !Exists(dir, "fail.vtu") && !Exists(dir, "fail.pvtu.tmp")), PETSC_COMM_SELF, PETSC_ERR_PLIB, "a failed set left its index");
  for (PetscMPIInt r = 0; rank == 0 && size > 1 && r < size; r++) {
    PetscCall(PetscSNPrintf(name, sizeof(name), "piece_%04d.vtu", r));
    PetscCheck(!Exists(sub, name), PETSC_COMM_SELF, PETSC_ERR_PLIB, "a failed set left %s/%s", sub, name);
    PetscCall(PetscStrlcat(name, ".tmp", sizeof(name)));
    PetscCheck(r == size - 1 || !Exists(sub, name), PETSC_COMM_SELF, PETSC_ERR_PLIB, "a failed set left %s/%s", sub, name);
  }
  PetscCall(PetscPrintf(comm, "ok: rank %d could not write: every rank failed, no index and no piece left\n", size - 1));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  char        dir[PETSC_MAX_PATH_LEN] = "";
  PetscMPIInt rank;

  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  if (rank == 0) {
    PetscCall(PetscStrncpy(dir, "/tmp/perilin-test-output-XXXXXX", sizeof(dir)));
    PetscCheck(mkdtemp(dir), PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot create a temporary directory");
    PetscCall(TestPVDTimes(dir));
  }
  PetscCallMPI(MPI_Bcast(dir, (PetscMPIInt)sizeof(dir), MPI_CHAR, 0, PETSC_COMM_WORLD));
  PetscCall(TestSet(PETSC_COMM_WORLD, dir));
  PetscCall(TestFailure(PETSC_COMM_WORLD, dir));
  PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
  if (rank == 0) {
    char cmd[PETSC_MAX_PATH_LEN + 16];
    PetscCall(PetscSNPrintf(cmd, sizeof(cmd), "rm -rf '%s'", dir));
    PetscCheck(system(cmd) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot remove %s", dir);
  }
  PetscCall(PetscFinalize());
  return 0;
}
