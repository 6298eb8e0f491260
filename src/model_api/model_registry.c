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

/*@C
  PeriModelAnyComponent - whether name is a component of some built-in model in 2D or 3D (bc's
  optional: true skips the components of other models, never a misspelt one). A model that refuses
  a dimension (pds in 3D) is passed over silently. Not collective.
@*/
PetscErrorCode PeriModelAnyComponent(const char name[], PetscBool *found)
{
  PetscInt                    n;
  const PeriModelType *const *types;

  PetscFunctionBeginUser;
  *found = PETSC_FALSE;
  PetscCall(PeriModelGetTypes(&n, &types));
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  for (PetscInt k = 0; k < n && !*found; k++)
    for (PetscInt dim = 2; dim <= 3 && !*found; dim++) {
      PeriModel m = NULL;
      PetscInt  c = -1;
      if (PeriModelCreate(types[k]->name, dim, PETSC_FALSE, &m)) continue;
      if (!PeriModelComponentIndex(m, name, &c) && c >= 0) *found = PETSC_TRUE;
      if (PeriModelDestroy(&m)) break;
    }
  PetscCall(PetscPopErrorHandler());
  PetscFunctionReturn(PETSC_SUCCESS);
}
