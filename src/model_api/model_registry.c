/* Registers the built-in models of models/model_list.h. Only PeriInitializePackage calls this;
 * src/model_api/model.c holds the list it fills and never calls back here. */
#include "perilin/private/model_registry.h"

#define PERI_MODEL(id) extern const PeriModelType PeriModel_##id;
#include "../../models/model_list.h"
#undef PERI_MODEL

static const PeriModelType *const builtin[] = {
#define PERI_MODEL(id) &PeriModel_##id,
#include "../../models/model_list.h"
#undef PERI_MODEL
};

static PetscBool registered = PETSC_FALSE;

/* Run by PetscFinalize: a second PetscInitialize in one process registers the models again. */
static PetscErrorCode PeriModelRegisterAllFinalize(void)
{
  PetscFunctionBeginUser;
  registered = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriModelRegisterAll(void)
{
  PetscFunctionBeginUser;
  if (registered) PetscFunctionReturn(PETSC_SUCCESS);
  registered = PETSC_TRUE;
  PetscCall(PetscRegisterFinalize(PeriModelRegisterAllFinalize));
  for (size_t k = 0; k < PETSC_STATIC_ARRAY_LENGTH(builtin); k++) PetscCall(PeriModelRegister(builtin[k]->name, builtin[k]->create));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The descriptor of the built-in model type name, with its promises; NULL for a type registered
 * with PeriModelRegister alone. Not collective. */
PetscErrorCode PeriModelTypeGet(const char name[], const PeriModelType **type)
{
  PetscFunctionBeginUser;
  *type = NULL;
  for (size_t k = 0; k < PETSC_STATIC_ARRAY_LENGTH(builtin); k++)
    if (!strcmp(builtin[k]->name, name)) *type = builtin[k];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The built-in types, in the order of models/model_list.h: their schemas for validation and -help. A
 * model registered at run time (PeriModelRegister) has no descriptor here, hence no keys of its own. */
PetscErrorCode PeriModelGetTypes(PetscInt *n, const PeriModelType *const **types)
{
  PetscFunctionBeginUser;
  *n     = (PetscInt)PETSC_STATIC_ARRAY_LENGTH(builtin);
  *types = builtin;
  PetscFunctionReturn(PETSC_SUCCESS);
}
