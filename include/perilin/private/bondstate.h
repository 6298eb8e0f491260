/* The state of the bonds (src/system/failure.c, bondstate.c): which are intact, broken or
 * softened, the criteria that break them, damage, and checkpoints of an equilibrium to return to.
 * The flags themselves live with the bonds (disc.bonds.live, intact, cause); this part owns what
 * changes them. */
#pragma once

#include <petscvec.h>
#include "perilin/private/disc.h"
#include "perilin/private/fields.h"

typedef struct _p_PeriSystem *PeriSystem;

/* Why a bond broke: a pre-existing crack, or the criterion that broke it. */
typedef enum {
  PERI_CAUSE_CRACK,
  PERI_CAUSE_TENSION,
  PERI_CAUSE_COMPRESSION,
  PERI_CAUSE_SLIDING,
  PERI_CAUSE_SHEAR_ANGLE,
  PERI_NCAUSES
} PeriFailureCause;
PETSC_EXTERN const char *const PeriFailureCauses[];

/* Bond failure criteria (failure:, src/system/failure.c); 0 = criterion not given. */
typedef struct {
  PetscBool active;
  PetscReal stretch, G, compressive, sliding, friction_angle, cohesion, shear_angle;
  PetscReal ultimate, ultimate_compressive; /* softening: the stretch where the stiffness is gone (0: brittle) */
  PetscInt  istretch, isliding, ishear;     /* the model's measures, -1 when absent */
  PetscInt  precracked_bonds;               /* bonds the scene's cracks removed */
} PeriFailure;

/* The bond state's part of the system. */
typedef struct {
  PeriFailure failure;
  PetscReal  *damage; /* scenes with failure, per owned particle: phi, then phi per PeriFailureCause */
} PeriBondState;

/* A saved state: the displacements, the bonds' flags and the solve that reached it, so that every
 * output of a set shows one state when a later step fails or a run is interrupted. */
typedef struct {
  Vec            u;
  unsigned char *live;
  PetscReal     *intact;
  PeriSolveInfo  solve;
} PeriCheckpoint;

PETSC_EXTERN PetscErrorCode PeriFailureSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriCracksApply(PeriSystem);
PETSC_EXTERN PetscReal      PeriBondFailureIndex(PeriSystem, const PeriBondGeometry *, const PetscReal[], PeriFailureCause *);
PETSC_EXTERN PetscReal      PeriBondCriticalLoad(PeriSystem, const PeriBondGeometry *, const PetscReal[], PetscInt);
PETSC_EXTERN PetscReal      PeriBondSoftening(PeriSystem, const PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriDamage(PeriSystem, PetscReal **);
PETSC_EXTERN PetscErrorCode PeriFamilySync(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriPieces(PeriSystem, PetscInt *, PetscInt **, PetscReal **, PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriFailureAddFields(PeriSystem, PeriFieldList);
PETSC_EXTERN PetscErrorCode PeriBondsBreak(PeriSystem, Vec, PetscBool, PetscReal, PetscInt *);
PETSC_EXTERN PetscErrorCode PeriCheckpointCreate(PeriSystem, PeriCheckpoint *);
PETSC_EXTERN PetscErrorCode PeriCheckpointSave(PeriSystem, PeriCheckpoint *);
PETSC_EXTERN PetscErrorCode PeriCheckpointRestore(PeriSystem, PeriCheckpoint *, PetscBool, PetscBool);
PETSC_EXTERN PetscErrorCode PeriCheckpointDestroy(PeriCheckpoint *);
PETSC_EXTERN PetscErrorCode PeriBondStateDestroy(PeriBondState *);
