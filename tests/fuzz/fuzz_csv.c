/* libFuzzer harness of the CSV particle reader (particles.file, src/disc/particles.c): an input is
 * the CSV file, read for a 2D and a 3D scene that name it, as the set-up reads it
 * (PeriParticlesCreateFromScene: the lines, then each particle's spacing and the body's extent).
 * A refused file is a normal outcome; a crash, a sanitizer report or a hang is a finding. */
#include "fuzz.h"

#include "perilin/private/disc.h"
#include "perilin/private/problem.h"

static PeriScene scene[2]; /* 2D, 3D */

/* A scene whose particles are the CSV file particles.csv beside it. */
static PetscErrorCode LoadScene(PetscInt dim, PeriScene *s)
{
  PeriSchemaOwner owners[PERI_MAX_SCHEMA_OWNERS];
  PetscInt        n;
  char            path[PETSC_MAX_PATH_LEN], text[64];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(text, sizeof(text), "dim: %d\nparticles: {file: particles.csv}\n", (int)dim));
  PetscCheck(!FuzzWriteFile(dim == 2 ? "scene2.yaml" : "scene3.yaml", (const uint8_t *)text, strlen(text), path, sizeof(path)), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write %s", path);
  PetscCall(PeriSchemaOwners(PERI_MAX_SCHEMA_OWNERS, owners, &n));
  PetscCall(PeriSceneCreateFromFile(path, n, owners, s));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
  (void)argc;
  (void)argv;
  if (FuzzInitialize()) return 1;
  return LoadScene(2, &scene[0]) || LoadScene(3, &scene[1]);
}

static PetscErrorCode ReadParticles(PeriScene s, PetscInt dim)
{
  PeriParticles  p;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  ierr = PeriParticlesCreateFromScene(s, dim, 0.01, &p);
  (void)PeriParticlesDestroy(&p);
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char path[PETSC_MAX_PATH_LEN];

  if (FuzzWriteFile("particles.csv", data, size, path, sizeof(path))) return 0;
  FuzzOutcome(ReadParticles(scene[0], 2));
  FuzzOutcome(ReadParticles(scene[1], 3));
  return 0;
}
