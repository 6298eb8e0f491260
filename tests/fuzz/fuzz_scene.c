/* libFuzzer harness of the scene reader: an input is a scene file, read as perilin reads one
 * (libyaml into the scene tree, option overrides) and checked as far as the keys go before any
 * particle exists (the root, output, analysis and model keys against their schemas,
 * PeriProblemSetFromScene). A refused scene is a normal outcome; a crash, a sanitizer report or a
 * hang is a finding (tests/fuzz/fuzz_stage.sh, docs/reliability.md "Fuzzing"). */
#include "fuzz.h"

#include "perilin/private/problem.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
  (void)argc;
  (void)argv;
  return FuzzInitialize();
}

static PetscErrorCode ReadScene(const char path[], PeriProblem *p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriProblemCreate(PETSC_COMM_SELF, p));
  PetscCall(PeriProblemLoad(*p, path));
  PetscCall(PeriProblemSetFromScene(*p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char        path[PETSC_MAX_PATH_LEN];
  PeriProblem p = NULL;

  if (FuzzWriteFile("scene.yaml", data, size, path, sizeof(path))) return 0;
  FuzzOutcome(ReadScene(path, &p));
  /* as the executable does after an error: what the run held is freed (a leak is a finding) */
  (void)PeriProblemDestroy(&p);
  return 0;
}
