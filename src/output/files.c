/* File-system helpers shared by the output writers.
 *
 * Convention: every writer writes "<final>.tmp" and PeriFileCommit()s it only when everything
 * succeeded, removing the tmp on failure, so a crashed or failed run never leaves a half-written
 * file under the final name (rename() replaces the target atomically on POSIX). */
#include "perilin.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

/* Make sure one path (a prefix of the requested directory) is a directory, creating it if missing. */
static PetscErrorCode OutputDirEnsure(const char path[], const char full[])
{
  struct stat st;

  PetscFunctionBeginUser;
  if (stat(path, &st) == 0) {
    PetscCheck(S_ISDIR(st.st_mode), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Cannot create output directory %s: %s exists and is not a directory", full, path);
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  if (mkdir(path, 0755) != 0) {
    int err = errno;

    /* Another rank or process may have created it between stat() and mkdir(). */
    if (err == EEXIST && stat(path, &st) == 0) {
      PetscCheck(S_ISDIR(st.st_mode), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Cannot create output directory %s: %s exists and is not a directory", full, path);
      PetscFunctionReturn(PETSC_SUCCESS);
    }
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Cannot create output directory %s: mkdir %s failed: %s", full, path, strerror(err));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Like "mkdir -p dir" with mode 0755. Not collective: call it on the rank that writes. */
PetscErrorCode PeriOutputDirCreate(const char dir[])
{
  char   path[PETSC_MAX_PATH_LEN];
  size_t len, k;

  PetscFunctionBeginUser;
  PetscCheck(dir && dir[0], PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "Empty output directory name");
  len = strlen(dir);
  PetscCheck(len < sizeof(path), PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Output directory name is too long (%zu characters, at most %zu): %s", len, sizeof(path) - 1, dir);
  PetscCall(PetscStrncpy(path, dir, sizeof(path)));
  /* Trailing slashes would make the last component empty; keep a lone "/". */
  while (len > 1 && path[len - 1] == '/') path[--len] = '\0';
  /* Walk the prefixes ending just before each separator; k starts at 1 so that "/" itself is never
     truncated to "", and repeated separators ("a//b") are skipped. */
  for (k = 1; k < len; k++) {
    if (path[k] != '/' || path[k - 1] == '/') continue;
    path[k] = '\0';
    PetscCall(OutputDirEnsure(path, dir));
    path[k] = '/';
  }
  PetscCall(OutputDirEnsure(path, dir));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Atomically move a completed tmp file to its final name. On failure the tmp file is removed too,
   so that callers' error paths never leave it behind. */
PetscErrorCode PeriFileCommit(const char tmp[], const char final[])
{
  PetscFunctionBeginUser;
  if (rename(tmp, final) != 0) {
    int err = errno;

    (void)remove(tmp);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Cannot rename %s to %s: %s", tmp, final, strerror(err));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A writer's temporary file "<path>.tmp", opened for writing. Not collective. */
PetscErrorCode PeriFileOpenTemporary(const char path[], char tmp[], size_t len, FILE **fp)
{
  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(tmp, len, "%s.tmp", path));
  *fp = fopen(tmp, "w");
  PetscCheck(*fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot write %s", tmp);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Closes fp and commits tmp to path, or removes tmp when a write failed (bad). Not collective. */
PetscErrorCode PeriFileCloseCommit(FILE *fp, const char tmp[], const char path[], int bad)
{
  PetscFunctionBeginUser;
  bad |= fclose(fp) != 0;
  if (bad) remove(tmp);
  PetscCheck(!bad, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "writing %s failed", tmp);
  PetscCall(PeriFileCommit(tmp, path));
  PetscFunctionReturn(PETSC_SUCCESS);
}
