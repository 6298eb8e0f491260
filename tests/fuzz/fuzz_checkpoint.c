/* libFuzzer harness of the checkpoint reader (-restart DIR: src/analysis/checkpoint.c, the
 * quasi-static loop's state in src/analysis/quasistatic.c, PeriCheckpointLoad in
 * src/system/bondstate.c): an input is DIR/checkpoint/state.bin, and each input runs the scene
 * tests/fuzz/checkpoint.yaml with -restart DIR, as `perilin checkpoint.yaml -restart DIR` would:
 * set-up, the header's checks, the loop's state, the bonds and u, then the rest of the loop from
 * there. The seed is the checkpoint of that scene run to its end
 * (tests/fuzz/fuzz_stage.sh); its header matches, so that mutations reach what follows it. A refused
 * checkpoint is a normal outcome; a crash, a sanitizer report or a hang is a finding. */
#include "fuzz.h"

#include <perilin.h>
#include <sys/stat.h>

#ifndef PERI_FUZZ_SCENE
#  error "PERI_FUZZ_SCENE: the path of tests/fuzz/checkpoint.yaml (tests/fuzz/CMakeLists.txt)"
#endif

/* -restart DIR/restart, no checkpoint written, the outputs (never committed) in DIR/out. */
static PetscErrorCode SetOptions(void)
{
  char dir[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(dir, sizeof(dir), "%s/restart", FuzzDir()));
  PetscCheck(!mkdir(dir, 0700), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot create %s", dir);
  PetscCall(PetscOptionsSetValue(NULL, "-restart", dir));
  PetscCall(PetscSNPrintf(dir, sizeof(dir), "%s/restart/checkpoint", FuzzDir()));
  PetscCheck(!mkdir(dir, 0700), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot create %s", dir);
  PetscCall(PetscSNPrintf(dir, sizeof(dir), "%s/out", FuzzDir()));
  PetscCall(PetscOptionsSetValue(NULL, "-output_dir", dir));
  PetscCall(PetscOptionsSetValue(NULL, "-peri_checkpoint_every", "0"));
  PetscCall(PetscOptionsSetValue(NULL, "-quiet", NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
  (void)argc;
  (void)argv;
  return FuzzInitialize() || SetOptions();
}

static PetscErrorCode Restart(PeriProblem *p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriProblemCreate(PETSC_COMM_SELF, p));
  PetscCall(PeriProblemLoad(*p, PERI_FUZZ_SCENE));
  PetscCall(PeriProblemSetUp(*p));
  PetscCall(PeriProblemRun(*p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char        path[PETSC_MAX_PATH_LEN];
  PeriProblem p = NULL;

  if (FuzzWriteFile("restart/checkpoint/state.bin", data, size, path, sizeof(path))) return 0;
  FuzzOutcome(Restart(&p));
  (void)PeriProblemDestroy(&p);
  return 0;
}
