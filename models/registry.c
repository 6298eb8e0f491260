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
  PetscCall(PeriModelRegister("pds", PeriModelCreate_PDS));
  PetscCall(PeriModelRegister("mppd", PeriModelCreate_MPPD));
  PetscCall(PeriModelRegister("gerstle", PeriModelCreate_Gerstle));
  PetscCall(PeriModelRegister("antiplane", PeriModelCreate_Antiplane));
  PetscCall(PeriModelRegister("antiplane_os", PeriModelCreate_AntiplaneOS));
  PetscFunctionReturn(PETSC_SUCCESS);
}
