/* The conditions of the scene (src/system/boundary.c, layers.c, reactions.c): what is prescribed
 * (bc), loaded (loads, torsion) and mirrored (fictitious boundary layers), and the reactions the
 * prescribed DOFs carry. */
#pragma once

#include <petscmat.h>
#include "perilin/private/disc.h"
#include "perilin/private/output.h"

typedef struct _p_PeriSystem *PeriSystem;

/* Fictitious boundary layers outside the body's faces (Oterkus & Madenci sec. 6, src/system/layers.c):
 * each fictitious particle copies its mirror image in the body, u_f = sign u_m + offset. */
typedef enum {
  PERI_LAYER_NONE,
  PERI_LAYER_DISPLACEMENT,
  PERI_LAYER_SHEAR_STRESS,
  PERI_LAYER_FREE
} PeriLayerKind;
PETSC_EXTERN const char *const PeriLayerKinds[];

typedef struct {
  PetscInt      nfaces;
  PeriLayerKind kind[6]; /* per face 2 axis + (upper face) */
  PetscReal     value[6];
  Mat           T; /* u = T u_body + g: identity on body DOFs, the mirror relation on fictitious ones */
  Vec           g;
} PeriLayers;

/* Torsion of a bar (antiplane models): the twist psi enters the free-surface conditions. */
typedef struct {
  PetscBool active;
  PetscReal twist, center[2];
  PetscReal torque, J, J_rectangle, max_stress, max_at[2]; /* results, per unit length; kept contiguous (broadcast as 6 reals) */
} PeriTorsion;

/* Reactions of the constrained regions and the global equilibrium (src/system/reactions.c): per
 * region of the scene (index of disc.regions), the sum of K u - lambda f over the DOFs a bc item on
 * it constrains, K the unconstrained stiffness. */
typedef struct {
  PetscInt   nregions;                /* disc.nregions */
  PetscBool *holds;                   /* [nregions][PERI_MAX_DOF]: a bc item on the region constrains component c */
  PetscBool *moves;                   /* [nregions]: a nonzero value is prescribed on it */
  PetscReal *force;                   /* [nregions][PERI_MAX_DOF]: the reaction, after the last evaluation */
  PetscReal  applied[PERI_MAX_DOF];   /* lambda times the total of loads: per component */
  PetscReal  imbalance[PERI_MAX_DOF]; /* sum of the reactions + applied, translational components */
  PetscReal  relative_imbalance;      /* |imbalance| / sum over particles of |reaction| + |load| */
  PetscReal  scale;                   /* that sum: the force scale of the check */
  PetscReal  allowed;                 /* the largest relative imbalance the solve's residual tolerance explains */
  PetscReal  load_factor;             /* of the evaluated state */
  PetscBool  evaluated, checked;      /* checked: false with fictitious layers (their faces carry no reaction) */
  /* the moment balance about the body's box centre (rotation-invariant models without periodic
     axes or layers: nmoments 1 in 2D, 3 in 3D; else 0 and not checked) */
  PetscInt  nmoments;
  PetscReal moment[3];                 /* the moments of the reactions (couples included) + of the loads */
  PetscReal relative_moment_imbalance; /* |moment| / sum of |lever x force| + |couple| over reactions and loads */
  PetscReal moment_allowed;            /* the largest relative moment imbalance the solve's residual explains */
} PeriReactions;

/* The conditions as particle arrays of the output (src/system/bc_fields.c), over the owned
 * particles: kept here from one writing of the fields to the next, as the field list references
 * them. */
typedef struct {
  unsigned char *fixed;      /* [n][dofs]: 1 where a DOF is constrained */
  PetscReal     *prescribed; /* [n][dofs]: its value at load factor 1, 0 elsewhere */
  PetscReal     *force;      /* [n][dofs]: the loads at load factor 1 (sys->fields.f) */
  unsigned char *in_region;  /* [nregions][n]: 1 inside the region */
} PeriConditionFields;

/* A load's amplitude in time (src/system/amplitude.c): loads.<k>.amplitude and
   analysis.amplitude of a transient analysis. */
typedef enum {
  PERI_AMPLITUDE_STEP,
  PERI_AMPLITUDE_RAMP,
  PERI_AMPLITUDE_SINE,
  PERI_AMPLITUDE_TABLE
} PeriAmplitudeShape;
typedef struct {
  PetscInt   shape;        /* PeriAmplitudeShape */
  PetscReal  rise, period; /* ramp, sine */
  PetscInt   n;            /* table: rows of (t, a) */
  PetscReal *t, *a;
} PeriAmplitude;

/* Everything the scene prescribes or loads. */
typedef struct {
  PeriLayers          layers;
  PeriTorsion         torsion;
  PetscInt            nconstrained;         /* owned constrained DOFs */
  PetscInt           *constrained;          /* their global rows, sorted */
  PetscReal          *constrained_value;    /* their values at load factor 1 */
  PetscInt           *constrained_region;   /* the region (index of disc.regions) of the bc item that set each, or -1 */
  PetscReal          *constrained_velocity; /* bc.<k>.velocity: their velocity w (u = value + w I(t), I the integral of the item's amplitude), or NULL when none of this rank's moves */
  PetscInt           *constrained_amp;      /* with constrained_velocity: the index in bc_amp of the amplitude that moves each */
  PetscInt            nbc_amp;              /* bc items */
  PeriAmplitude      *bc_amp;               /* bc.<k>.amplitude of each bc item (a step where absent: the velocity from t = 0) */
  PetscBool           moving;               /* a bc velocity moves DOFs on some rank */
  PeriReactions       reactions;
  PeriConditionFields fields;
} PeriConditions;

PETSC_EXTERN const PeriKey  PeriAmplitudeKeys[];
PETSC_EXTERN PetscErrorCode PeriAmplitudeFromScene(PeriScene, PeriNode, PeriAmplitude *);
PETSC_EXTERN PetscReal      PeriAmplitudeValue(const PeriAmplitude *, PetscReal);
PETSC_EXTERN PetscReal      PeriAmplitudeRate(const PeriAmplitude *, PetscReal);
PETSC_EXTERN PetscReal      PeriAmplitudeIntegral(const PeriAmplitude *, PetscReal);
PETSC_EXTERN void           PeriConditionsMotion(const PeriConditions *, PetscInt, PetscReal, PetscReal *, PetscReal *, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriAmplitudeDestroy(PeriAmplitude *);

PETSC_EXTERN PetscErrorCode PeriBoundarySetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriBoundaryParseAffine(PeriSystem, PeriNode, const char[], PetscReal[3][3], PetscReal[3]);
PETSC_EXTERN PetscErrorCode PeriLoadsAssemble(PeriSystem, Vec);
PETSC_EXTERN PetscErrorCode PeriLoadAssemble(PeriSystem, PetscInt, Vec);
PETSC_EXTERN PetscErrorCode PeriReactionsSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemEvaluateReactions(PeriSystem, PetscReal);
PETSC_EXTERN PetscErrorCode PeriReactionsFindRegion(PeriSystem, const char[], PetscInt *);
PETSC_EXTERN PetscErrorCode PeriReactionsSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriReactionsDestroy(PeriReactions *);
PETSC_EXTERN PetscErrorCode PeriRigidMotionFree(PeriSystem, PetscInt *, char[], size_t, Vec[]);
PETSC_EXTERN PetscErrorCode PeriLayersAddParticles(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriLayersSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriLayersApply(PeriSystem, PetscReal, Mat *, Vec);
PETSC_EXTERN PetscErrorCode PeriLayersComplete(PeriSystem, PetscReal, Vec);
PETSC_EXTERN PetscErrorCode PeriLayersDestroy(PeriLayers *);
PETSC_EXTERN PetscErrorCode PeriTorsionEvaluate(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriTorsionLoads(PeriSystem, Vec);
PETSC_EXTERN PetscErrorCode PeriTorsionSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriLayersSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriLayersAddFields(PeriSystem, PeriFieldList);
PETSC_EXTERN PetscErrorCode PeriConditionsDestroy(PeriConditions *);
PETSC_EXTERN PetscErrorCode PeriConditionsAddFields(PeriSystem, PeriFieldList);
PETSC_EXTERN PetscErrorCode PeriConditionFieldsDestroy(PeriConditionFields *);
