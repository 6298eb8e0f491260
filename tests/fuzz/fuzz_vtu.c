/* libFuzzer harness of the VTU reader of analysis.initial (src/output/vturead.c): an input is a
 * .vtu file, or a .pvtu when it holds a PUnstructuredGrid (its pieces are then whatever files its
 * Source attributes name: the ones the seeds' runs left, or none). A refused file is a normal
 * outcome; a crash, a sanitizer report or a hang is a finding. */
#define _GNU_SOURCE /* memmem */
#include "fuzz.h"

#include <string.h>

#include "perilin/private/output.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
  (void)argc;
  (void)argv;
  return FuzzInitialize();
}

/* Reads every value the reader says it holds, as the dynamic analysis may (src/system/readback.c):
 * ASan reports an array shorter than its count. */
static volatile PetscReal sink;
static void               Touch(const PeriVTUData *d)
{
  PetscReal sum = 0;

  for (PetscInt i = 0; i < 3 * d->n; i++) sum += d->points[i];
  for (PetscInt k = 0; k < d->narrays; k++)
    for (PetscInt i = 0; i < d->n * d->ncomp[k]; i++) sum += d->data[k][i];
  sink = sum + PeriVTUDataFind(d, "u");
}

static PetscErrorCode ReadVTU(const char path[])
{
  PeriVTUData    d;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  ierr = PeriReadParticles(path, &d);
  if (!ierr) Touch(&d);
  (void)PeriVTUDataDestroy(&d);
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the input holds needle (memmem: the input may hold NULs). */
static int Holds(const uint8_t *data, size_t size, const char needle[])
{
  return memmem(data, size, needle, strlen(needle)) != NULL;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char path[PETSC_MAX_PATH_LEN];

  if (FuzzWriteFile(Holds(data, size, "PUnstructuredGrid") ? "particles.pvtu" : "particles.vtu", data, size, path, sizeof(path))) return 0;
  FuzzOutcome(ReadVTU(path));
  return 0;
}
