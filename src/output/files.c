/* File-system helpers shared by the output writers.
 *
 * Convention: every writer writes "<final>.tmp" and PeriFileCommit()s it only when everything
 * succeeded, removing the tmp on failure, so a crashed or failed run never leaves a half-written
 * file under the final name (rename() replaces the target atomically on POSIX). */
#define _GNU_SOURCE /* renameat2 */
#include "perilin/private/output.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <libgen.h>
#include <stdlib.h>
#include <unistd.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
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

/*@C
  PeriFileSystemFull - whether the file system holding path has no block left for this user: the
  cause of a failed write whose errno was lost (PETSc's error paths and stdio's later calls may
  reset it). Ask before the failed file's blocks are freed. Not collective.
@*/
PetscBool PeriFileSystemFull(const char path[])
{
  struct statvfs fs;
  return (PetscBool)(statvfs(path, &fs) == 0 && fs.f_bavail == 0);
}

/* A writer's temporary file "<path>.tmp", opened for writing. Not collective. */
PetscErrorCode PeriFileOpenTemporary(const char path[], char tmp[], size_t len, FILE **fp)
{
  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(tmp, len, "%s.tmp", path));
  *fp = fopen(tmp, "w");
  PetscCheck(*fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot write %s: %s", tmp, strerror(errno));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Closes fp and commits tmp to path, or removes tmp when a write failed (bad, or the flush of the
 * buffered rest, where a full disk usually shows first), naming the file and the cause: a full
 * disk at the end of a run said only "writing FILE failed" (issue 40). Not collective. */
PetscErrorCode PeriFileCloseCommit(FILE *fp, const char tmp[], const char path[], int bad)
{
  char dir[PETSC_MAX_PATH_LEN];
  int  err = bad ? errno : 0; /* the failed fprintf's, unless a later call changed it */

  PetscFunctionBeginUser;
  if (fflush(fp) != 0) bad = 1, err = errno;
  bad |= ferror(fp) != 0;
  if (fclose(fp) != 0 && !err) bad = 1, err = errno;
  if (bad) {
    PetscCall(PetscStrncpy(dir, tmp, sizeof(dir)));
    if (!err && PeriFileSystemFull(dirname(dir))) err = ENOSPC;
    (void)remove(tmp);
  }
  PetscCheck(!bad, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Error writing %s: %s%s", tmp, err ? strerror(err) : "a write failed", err == ENOSPC || err == EDQUOT ? " (the disk or the quota is full)" : "");
  PetscCall(PeriFileCommit(tmp, path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* ------------------------------------------------------------------ output sets
 * A run's outputs are one set describing one state: they are written into a staging directory
 * "<dir>.partial-XXXXXX" beside the output directory, and swapped in as a whole at the end
 * (renameat2 RENAME_EXCHANGE, then the old set is removed), so no file of an earlier run
 * survives beside a new run's, and a failed run leaves the previous set untouched. */
#define PERI_OUTPUT_MARKER ".perilin-output"

/* The staging directory of this process's open set, removed on failure (PeriOutputSetDiscard). */
static char peri_staging[PETSC_MAX_PATH_LEN];

static int RemoveEntry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
  (void)sb;
  (void)flag;
  (void)ftw;
  return remove(path);
}

/* rm -rf path (no symbolic link is followed). */
static int RemoveTree(const char path[])
{
  return nftw(path, RemoveEntry, 16, FTW_DEPTH | FTW_PHYS);
}

/* rm -rf path, for the writers' own scratch directories. Not collective. */
int PeriOutputRemoveTree(const char path[])
{
  return RemoveTree(path);
}

/* The names the analyses write into an output set, as they declare them (PeriOutputSetAddNames):
 * static strings, kept by reference. */
#define PERI_OUTPUT_MAX_NAMES 64
static const char *peri_output_names[PERI_OUTPUT_MAX_NAMES];
static PetscInt    peri_output_nnames;

/*@C
  PeriOutputSetAddNames - adds names a writer puts into output sets (NULL-terminated; '#' stands
  for one or more digits: "mode_#.vtu"), so that an output directory holding them may be replaced.
  The strings must outlive the process' runs (static). Not collective.
@*/
PetscErrorCode PeriOutputSetAddNames(const char *const names[])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; names && names[k]; k++) {
    PetscCheck(peri_output_nnames < PERI_OUTPUT_MAX_NAMES, PETSC_COMM_SELF, PETSC_ERR_PLIB, "more than %d output names", PERI_OUTPUT_MAX_NAMES);
    peri_output_names[peri_output_nnames++] = names[k];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether name matches pattern, where '#' matches one or more digits. */
static PetscBool NameMatches(const char *name, const char *pattern)
{
  for (; *pattern; pattern++) {
    if (*pattern != '#') {
      if (*name++ != *pattern) return PETSC_FALSE;
      continue;
    }
    if (*name < '0' || *name > '9') return PETSC_FALSE;
    while (*name >= '0' && *name <= '9') name++;
  }
  return (PetscBool) !*name;
}

/* Whether a file name is one perilin writes into an output directory: the set's own files
 * (summary.json, scene.yaml, particles.vtu or .pvtu and the directory of its pieces, the marker, temporary
 * files), and the names the analyses declared. */
static PetscBool IsOutputName(const char name[])
{
  static const char *const own[] = {"summary.json", "scene.yaml", "particles.vtu", "particles.pvtu", "particles", PERI_OUTPUT_MARKER, NULL};
  size_t                   n     = strlen(name);

  for (PetscInt k = 0; own[k]; k++)
    if (NameMatches(name, own[k])) return PETSC_TRUE;
  for (PetscInt k = 0; k < peri_output_nnames; k++)
    if (NameMatches(name, peri_output_names[k])) return PETSC_TRUE;
  return (PetscBool)(n > 4 && !strcmp(name + n - 4, ".tmp"));
}

/* An existing output directory may be replaced only when perilin wrote it (its marker, or only
 * names perilin writes): never a directory of the user's own files such as "." or $HOME. */
static void CheckReplaceable(const char dir[], char msg[], size_t len)
{
  DIR           *d = opendir(dir);
  struct dirent *e;

  if (!d) {
    snprintf(msg, len, "cannot read the output directory %s: %s", dir, strerror(errno));
    return;
  }
  while ((e = readdir(d))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    if (!strcmp(e->d_name, PERI_OUTPUT_MARKER)) {
      msg[0] = 0;
      break;
    }
    if (!msg[0] && !IsOutputName(e->d_name)) snprintf(msg, len, "the output directory %s holds files perilin did not write (%s): perilin replaces the whole directory with each run, so choose a new output.dir (-output_dir)", dir, e->d_name);
  }
  closedir(d);
}

/* Rank 0's part of PeriOutputSetOpen: msg[0] != 0 on failure. An output directory given as a
 * symbolic link (to scratch space, say) is replaced where it points, not the link itself. */
static void OpenStaging(char dir[], size_t dlen, char staging[], size_t len, char msg[], size_t mlen)
{
  char        copy[PETSC_MAX_PATH_LEN], *base;
  struct stat st;

  msg[0] = 0;
  if (lstat(dir, &st) == 0 && S_ISLNK(st.st_mode) && stat(dir, &st) == 0 && S_ISDIR(st.st_mode) && realpath(dir, copy) && strlen(copy) < dlen) PetscStrncpy(dir, copy, dlen);
  PetscStrncpy(copy, dir, sizeof(copy));
  base = basename(copy);
  if (!dir[0] || !strcmp(base, ".") || !strcmp(base, "..") || !strcmp(base, "/")) {
    snprintf(msg, mlen, "output.dir '%s' must name a directory of its own (not ., .. or /): perilin replaces it as a whole", dir);
    return;
  }
  if (lstat(dir, &st) == 0 && S_ISLNK(st.st_mode) && stat(dir, &st) != 0) {
    snprintf(msg, mlen, "cannot create output directory %s: it is a symbolic link to nothing", dir);
    return;
  }
  if (stat(dir, &st) == 0) {
    if (!S_ISDIR(st.st_mode)) {
      snprintf(msg, mlen, "cannot create output directory %s: a file of that name exists", dir);
      return;
    }
    CheckReplaceable(dir, msg, mlen);
    if (msg[0]) return;
  } else {
    PetscStrncpy(copy, dir, sizeof(copy));
    if (PeriOutputDirCreate(dirname(copy))) {
      snprintf(msg, mlen, "cannot create output directory %s: its parent cannot be created (%s)", dir, strerror(errno));
      return;
    }
  }
  snprintf(staging, len, "%s.partial-XXXXXX", dir);
  if (!mkdtemp(staging)) {
    snprintf(msg, mlen, "cannot create output directory %s: cannot write beside it (%s)", dir, strerror(errno));
    staging[0] = 0;
    return;
  }
  {
    /* mkdtemp makes it private (0700): give the set the permissions of any new directory */
    mode_t mask = umask(0);
    umask(mask);
    (void)chmod(staging, 0777 & ~mask);
  }
  PetscStrncpy(peri_staging, staging, sizeof(peri_staging));
}

/*@C
  PeriOutputSetOpen - checks that the output directory dir can be written (or replaced), resolves
  it when it is a symbolic link, and creates the staging directory the writers write into. Called
  before any computation, so a bad output.dir costs nothing. Collective: rank 0 works, every rank gets staging or the same error.
@*/
PetscErrorCode PeriOutputSetOpen(MPI_Comm comm, char dir[], size_t dlen, char staging[], size_t len)
{
  char        msg[2 * PETSC_MAX_PATH_LEN + 256] = "";
  PetscMPIInt rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    /* mkdir -p reports through PETSc errors: keep them quiet, msg carries the cause */
    PetscCall(PetscPushErrorHandler(PetscIgnoreErrorHandler, NULL));
    OpenStaging(dir, dlen, staging, len, msg, sizeof(msg));
    PetscCall(PetscPopErrorHandler());
  }
  PetscCallMPI(MPI_Bcast(msg, (PetscMPIInt)sizeof(msg), MPI_CHAR, 0, comm));
  PetscCheck(!msg[0], comm, PETSC_ERR_USER_INPUT, "%s", msg);
  PetscCallMPI(MPI_Bcast(staging, (PetscMPIInt)len, MPI_CHAR, 0, comm));
  PetscCallMPI(MPI_Bcast(dir, (PetscMPIInt)dlen, MPI_CHAR, 0, comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rank 0's part of PeriOutputSetCommit. */
static PetscErrorCode SwapIn(const char staging[], const char dir[])
{
  char        marker[PETSC_MAX_PATH_LEN + 32];
  FILE       *fp;
  struct stat st;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(marker, sizeof(marker), "%s/%s", staging, PERI_OUTPUT_MARKER));
  fp = fopen(marker, "w");
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write %s: %s", marker, strerror(errno));
  fprintf(fp, "perilin output set: the next run writing here replaces this directory as a whole\n");
  PetscCheck(fclose(fp) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write %s: %s", marker, strerror(errno));
  if (stat(dir, &st) != 0) {
    PetscCheck(rename(staging, dir) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot rename %s to %s: %s", staging, dir, strerror(errno));
  } else if (renameat2(AT_FDCWD, staging, AT_FDCWD, dir, RENAME_EXCHANGE) == 0) {
    /* the previous set now lies at the staging name */
    PetscCheck(RemoveTree(staging) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "the new results are in %s, but the previous ones could not be removed from %s: %s", dir, staging, strerror(errno));
  } else {
    /* a file system without RENAME_EXCHANGE: move the old set aside, then the new one in */
    char old[PETSC_MAX_PATH_LEN + 16];
    PetscCall(PetscSNPrintf(old, sizeof(old), "%s.old-XXXXXX", dir));
    PetscCheck(mkdtemp(old) && rmdir(old) == 0 && rename(dir, old) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot replace %s: %s", dir, strerror(errno));
    PetscCheck(rename(staging, dir) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot rename %s to %s (the previous results are in %s): %s", staging, dir, old, strerror(errno));
    (void)RemoveTree(old);
  }
  peri_staging[0] = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOutputSetCommit - replaces the output directory by the staging directory as one set.
  Collective; rank 0 works.
@*/
PetscErrorCode PeriOutputSetCommit(MPI_Comm comm, const char staging[], const char dir[])
{
  PetscMPIInt rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) PetscCall(SwapIn(staging, dir));
  PetscCallMPI(MPI_Barrier(comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOutputSetDiscard - removes the staging directory of a set that will not be committed (a
  failed run), leaving the previous results as they were. Not collective; safe in error paths.
@*/
void PeriOutputSetDiscard(void)
{
  if (!peri_staging[0]) return;
  (void)RemoveTree(peri_staging);
  peri_staging[0] = 0;
}

/*@C
  PeriOutputSetKeepCheckpoint - a run that failed writing its results (a full disk, a quota) after
  it wrote a checkpoint: its staging directory, which holds that whole checkpoint, is kept for
  -restart instead of discarded; its path goes to dir (len bytes). False (nothing kept) when the
  set holds no checkpoint. Not collective: rank 0's.
@*/
PetscBool PeriOutputSetKeepCheckpoint(char dir[], size_t len)
{
  char        path[PETSC_MAX_PATH_LEN + 32];
  struct stat st;

  if (!peri_staging[0]) return PETSC_FALSE;
  snprintf(path, sizeof(path), "%s/checkpoint/state.bin", peri_staging);
  if (stat(path, &st) != 0 || !S_ISREG(st.st_mode)) return PETSC_FALSE;
  snprintf(dir, len, "%s", peri_staging);
  peri_staging[0] = 0;
  return PETSC_TRUE;
}

/*@C
  PeriOutputSetKeep - a failed run's staging directory is kept by PeriOutputSetDiscard: it holds
  the last checkpoint of a run whose next one could not be written (a full disk), which -restart
  continues. Not collective: rank 0 discards.
@*/
void PeriOutputSetKeep(void)
{
  peri_staging[0] = 0;
}

/* dst as a hard link to src (the same file system: no copy), else a copy. Not collective. */
static PetscErrorCode LinkOrCopy(const char src[], const char dst[])
{
  char   buf[65536];
  size_t n;
  FILE  *in, *out;
  int    bad = 0;

  PetscFunctionBeginUser;
  if (link(src, dst) == 0) PetscFunctionReturn(PETSC_SUCCESS);
  in = fopen(src, "rb");
  PetscCheck(in, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot read %s: %s", src, strerror(errno));
  out = fopen(dst, "wb");
  if (!out) fclose(in);
  PetscCheck(out, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write %s: %s", dst, strerror(errno));
  while ((n = fread(buf, 1, sizeof(buf), in)) > 0 && !bad)
    if (fwrite(buf, 1, n, out) != n) bad = errno ? errno : EIO;
  if (ferror(in) && !bad) bad = errno ? errno : EIO;
  fclose(in);
  if (fclose(out) != 0 && !bad) bad = errno ? errno : EIO;
  if (bad) (void)remove(dst);
  PetscCheck(!bad, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "copying %s to %s failed: %s", src, dst, strerror(bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rank 0's part of PeriOutputSetAdopt: from/name, a file or a directory of files, into to/name. */
static PetscErrorCode Adopt(const char from[], const char to[], const char name[], PetscBool *found)
{
  char           src[PETSC_MAX_PATH_LEN], dst[PETSC_MAX_PATH_LEN];
  struct stat    st;
  DIR           *d;
  struct dirent *e;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(src, sizeof(src), "%s/%s", from, name));
  PetscCall(PetscSNPrintf(dst, sizeof(dst), "%s/%s", to, name));
  *found = (PetscBool)(stat(src, &st) == 0);
  if (!*found) PetscFunctionReturn(PETSC_SUCCESS);
  if (!S_ISDIR(st.st_mode)) {
    PetscCall(LinkOrCopy(src, dst));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PeriOutputDirCreate(dst));
  d = opendir(src);
  PetscCheck(d, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot read %s: %s", src, strerror(errno));
  while ((e = readdir(d))) {
    char f[PETSC_MAX_PATH_LEN], g[PETSC_MAX_PATH_LEN];
    if (e->d_name[0] == '.') continue;
    PetscCall(PetscSNPrintf(f, sizeof(f), "%s/%s", src, e->d_name));
    PetscCall(PetscSNPrintf(g, sizeof(g), "%s/%s", dst, e->d_name));
    PetscCall(LinkOrCopy(f, g));
  }
  closedir(d);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOutputSetAdopt - takes the file or directory (of files) name of an earlier output set from
  into the staging directory to, hard-linked where the file system allows, else copied: a run
  continued from another's checkpoint keeps the snapshots that run wrote. *found: whether from had
  it. Collective; rank 0 works.
@*/
PetscErrorCode PeriOutputSetAdopt(MPI_Comm comm, const char from[], const char to[], const char name[], PetscBool *found)
{
  PetscMPIInt    rank;
  PetscErrorCode ierr  = PETSC_SUCCESS;
  int            ok[2] = {0, 0};

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    ierr  = Adopt(from, to, name, found);
    ok[0] = ierr == PETSC_SUCCESS;
    ok[1] = ok[0] && *found;
  }
  PetscCallMPI(MPI_Bcast(ok, 2, MPI_INT, 0, comm));
  PetscCall(ierr);
  PetscCheck(ok[0], comm, PETSC_ERR_FILE_WRITE, "cannot take %s/%s into the output set", from, name);
  *found = (PetscBool)ok[1];
  PetscFunctionReturn(PETSC_SUCCESS);
}
