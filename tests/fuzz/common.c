/* The harnesses' shared start (fuzz.h). */
#include "fuzz.h"

#include <perilin.h>
#include <slepcsys.h>
#include <sanitizer/lsan_interface.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char fuzz_dir[PETSC_MAX_PATH_LEN];

/* The directory and what the harness left in it; the files are only ever the harness' own. */
static void RemoveDir(void)
{
  char cmd[PETSC_MAX_PATH_LEN + 16];

  if (!fuzz_dir[0]) return;
  snprintf(cmd, sizeof(cmd), "rm -rf '%s'", fuzz_dir);
  if (system(cmd)) fprintf(stderr, "fuzz: could not remove %s\n", fuzz_dir);
}

int FuzzInitialize(void)
{
  const char *tmp = getenv("TMPDIR");

  /* PETSc must leave SIGSEGV and SIGABRT to ASan and libFuzzer, which report them; and it gets no
     arguments: libFuzzer's (-max_total_time=60) are not PETSc options */
  if (setenv("PETSC_OPTIONS", "-no_signal_handler", 1)) return 1;
  /* what MPI allocates at start is MPI's, kept to the end: not a leak of an input */
  __lsan_disable();
  if (SlepcInitialize(NULL, NULL, NULL, NULL)) return 1;
  __lsan_enable();
  if (PeriInitializeEmbedded()) return 1;
  if (PetscPushErrorHandler(PeriErrorCapture, NULL)) return 1;
  snprintf(fuzz_dir, sizeof(fuzz_dir), "%s/perilin-fuzz-XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
  if (!mkdtemp(fuzz_dir)) {
    perror("fuzz: mkdtemp");
    return 1;
  }
  atexit(RemoveDir);
  return 0;
}

const char *FuzzDir(void)
{
  return fuzz_dir;
}

int FuzzWriteFile(const char name[], const uint8_t *data, size_t size, char path[], size_t len)
{
  FILE *fp;
  int   bad;

  snprintf(path, len, "%s/%s", fuzz_dir, name);
  if (!(fp = fopen(path, "wb"))) return 1;
  bad = size && fwrite(data, 1, size, fp) != size;
  return fclose(fp) || bad;
}

void FuzzOutcome(PetscErrorCode ierr)
{
  if (getenv("FUZZ_VERBOSE")) fprintf(stderr, "fuzz: %s\n", ierr ? PeriErrorFirst() : "accepted");
  PeriErrorReset();
}
