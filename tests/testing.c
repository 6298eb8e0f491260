#include "testing.h"

/* Loads, sets up and runs the scene's analysis on comm; no output files. */
PetscErrorCode PeriTestRunScene(MPI_Comm comm, const char file[], PeriProblem *p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriProblemCreate(comm, p));
  PetscCall(PeriProblemLoad(*p, file));
  PetscCall(PeriProblemSetUp(*p));
  PetscCall(PeriProblemRun(*p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sets (value) or clears (NULL) an option for the next scene. */
PetscErrorCode PeriTestSetOption(const char name[], const char value[])
{
  PetscFunctionBeginUser;
  if (value)
    PetscCall(PetscOptionsSetValue(NULL, name, value));
  else
    PetscCall(PetscOptionsClearValue(NULL, name));
  PetscFunctionReturn(PETSC_SUCCESS);
}
