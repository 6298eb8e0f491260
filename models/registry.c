/* The one place models are listed. */
#include "perilin.h"

PetscErrorCode PeriModelRegisterAll(void)
{
  static PetscBool done = PETSC_FALSE;

  PetscFunctionBeginUser;
  if (done) PetscFunctionReturn(PETSC_SUCCESS);
  done = PETSC_TRUE;
  PetscCall(PeriModelRegister("pmb", PeriModelCreate_PMB));
  PetscCall(PeriModelRegister("npmb", PeriModelCreate_NPMB));
  PetscFunctionReturn(PETSC_SUCCESS);
}
