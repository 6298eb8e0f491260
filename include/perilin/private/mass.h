/* The mass of the discretized body (src/system/mass.c): densities, the lumped mass of every DOF
 * and the total mass, built on first request (a static analysis asks for none). A particle's mass
 * is rho V_i on each translation and its rotational inertia rho V_i (dx^2 + dy^2)/12 on each
 * rotation the model declares (Diana & Casolo sec. 3.1). Peridynamics has no consistent mass: the
 * particles are the quadrature points of the momentum balance, so the lumped diagonal is the mass
 * matrix itself. */
#pragma once

#include <petscmat.h>
#include "perilin/private/disc.h"

typedef struct _p_PeriSystem *PeriSystem;

typedef struct {
  PetscBool  set;   /* built (PeriMassSetUp) */
  PetscReal *rho;   /* per owned particle: material.rho, or material.rho_by_region where it applies */
  Vec        diag;  /* the lumped mass per DOF, in the layout of K */
  Mat        M;     /* the same as a diagonal matrix, built on request (PeriMassGetMatrix) */
  PetscReal  total; /* the body's mass (translations; rotations carry inertia, not mass) */
  /* settings, read at the set-up (PeriMassSetFromScene): material.rho_by_region */
  PetscInt     nby;
  PeriRegion **by_region;
  PetscReal   *by_value;
  PeriNode     where; /* the material section: locates a missing density */
} PeriMass;

PETSC_EXTERN PetscErrorCode PeriMassSetFromScene(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriMassSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriMassGetDiagonal(PeriSystem, Vec *);
PETSC_EXTERN PetscErrorCode PeriMassGetMatrix(PeriSystem, Mat *);
PETSC_EXTERN PetscErrorCode PeriMassGetTotal(PeriSystem, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriMassDestroy(PeriMass *);
