/* The model registry and life cycle (src/model_api/): create a model by name, list the types. */
#pragma once

#include <perilin/model.h>
#include "perilin/private/sys.h"

PETSC_EXTERN PetscErrorCode PeriModelRegister(const char[], PetscErrorCode (*)(PeriModel));
PETSC_EXTERN PetscErrorCode PeriModelRegisterAll(void);
PETSC_EXTERN PetscErrorCode PeriModelGetTypes(PetscInt *, const PeriModelType *const **);
PETSC_EXTERN PetscErrorCode PeriModelCreate(const char[], PetscInt, PetscBool, PeriModel *);
PETSC_EXTERN PetscErrorCode PeriModelSetFromScene(PeriModel, PeriScene, PetscReal);
PETSC_EXTERN PetscErrorCode PeriModelListTypes(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriModelTypeRegistered(const char[], PetscBool *);
PETSC_EXTERN PetscErrorCode PeriModelDestroy(PeriModel *);
PETSC_EXTERN PetscErrorCode PeriModelTypeGet(const char[], const PeriModelType **);
PETSC_EXTERN PetscErrorCode PeriModelAnyComponent(const char[], PetscBool *);

/* material.*, declared next to PeriModelSetFromScene (src/package.c hands it to the scene layer). */
PETSC_EXTERN const PeriSchema PeriMaterialSchema[];
