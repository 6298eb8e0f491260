/* The one place models are listed. */
#include "perilin.h"

/* Global, not static: the registry's finalizer (src/model.c) resets it, so that a second
 * PetscInitialize in one process registers the models again. */
PetscBool PeriModelRegisterAllCalled = PETSC_FALSE;

PetscErrorCode PeriModelRegisterAll(void)
{
  PetscFunctionBeginUser;
  if (PeriModelRegisterAllCalled) PetscFunctionReturn(PETSC_SUCCESS);
  PeriModelRegisterAllCalled = PETSC_TRUE;
  PetscCall(PeriModelRegister("pmb", PeriModelCreate_PMB));
  PetscCall(PeriModelRegister("npmb", PeriModelCreate_NPMB));
  PetscCall(PeriModelRegister("pds", PeriModelCreate_PDS));
  PetscCall(PeriModelRegister("mppd", PeriModelCreate_MPPD));
  PetscCall(PeriModelRegister("gerstle", PeriModelCreate_Gerstle));
  PetscCall(PeriModelRegister("antiplane", PeriModelCreate_Antiplane));
  PetscCall(PeriModelRegister("antiplane_os", PeriModelCreate_AntiplaneOS));
  PetscFunctionReturn(PETSC_SUCCESS);
}
