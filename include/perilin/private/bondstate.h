/* The state of the bonds (src/system/failure.c, bondstate.c): which are intact, broken or
 * softened, the criteria that break them, damage, and checkpoints of an equilibrium to return to.
 * The flags themselves live with the bonds (disc.bonds.live, intact, cause); this part owns what
 * changes them. */
#pragma once

#include <petscvec.h>
#include "perilin/private/disc.h"
#include "perilin/private/fields.h"
#include "perilin/private/model_registry.h"

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

/* A failure criterion of failure: (docs/design.md, "How to add a failure criterion"): one file
 * src/system/criterion_<name>.c that defines its descriptor PeriCriterion_<Id>, and one line
 * PERI_CRITERION(<Id>) in src/system/criterion_list.h. src/system/failure.c reads the keys and
 * asks every criterion the scene switches on; a bond's failure index is the largest of theirs. */
#define PERI_CRITERION_MAX_KEYS 3
#define PERI_MAX_CRITERIA       8

typedef struct _PeriCriterionType PeriCriterionType;

/* One criterion of the scene: its type, the values of its keys and what it found in the model. */
typedef struct {
  const PeriCriterionType *type;
  PetscBool                active;                             /* the scene switches it on (its first key), or the anisotropy analysis selected it */
  PetscBool                given[PERI_CRITERION_MAX_KEYS + 1]; /* which of type->keys, then softening_keys, the scene gives */
  PetscReal                value[PERI_CRITERION_MAX_KEYS + 1]; /* their values, in that order; 0 when not given */
  PetscInt                 measure[2];                         /* the model's measures of the kinds type->measures, -1 when absent */
  PetscBool                softens;                            /* set by setfromscene: bonds past the limit keep a falling share of stiffness */
  PetscInt                 causes;                             /* set by setfromscene: the PeriFailureCauses it gives, bit (1 << cause) each */
  PetscReal               *critical;                           /* type->per_bond: each listed bond's critical value, computed on first use (-1: not yet) */
  PetscInt                 ncritical;
} PeriCriterion;

struct _PeriCriterionType {
  const char *name;     /* its name ("tension"); the anisotropy analysis selects criteria by it */
  const char *given_as; /* its entry in "give at least one criterion: ..."; NULL: its first key */
  /* its failure.* keys, numbers, ended by {NULL}; value[k] is keys[k]'s. The first switches the
     criterion on; the others refine it. Those with a range must be positive (failure.c checks). */
  PeriKey         keys[PERI_CRITERION_MAX_KEYS + 1];
  PeriKey         softening_keys[2]; /* its key of softening, listed after every criterion's keys; value[] continues with it */
  PeriMeasureKind measures[2];       /* the kinds of measure[] that failure.c looks up (nmeasures of them) */
  PetscInt        nmeasures;
  /* for a bound on one measure's magnitude, |measure[0]| <= value[0], served by the shared ops of
     src/system/criterion_magnitude.c: the cause it gives, the models that have the measure (for
     the message), the symbol of the run log */
  PeriFailureCause cause;
  const char      *holders, *symbol;
  /* its critical value differs per bond but not in time (from G by the model): failure.c keeps
     c->critical, one per bond, so that a time loop does not recompute it every step */
  PetscBool per_bond;
  struct {
    /* Checks its keys against each other and the model (c->measure[] are set): the scene's
       messages; sets c->causes and c->softens. Called when the scene gives any of its keys. */
    PetscErrorCode (*setfromscene)(PeriCriterion *c, PeriScene s, PeriNode failure, PeriModel m);
    /* The bond's failure index (it breaks at 1), 0 when the criterion does not apply; *cause its
       PeriFailureCause. meas[] are the model's measures of the bond. */
    PetscReal (*index)(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause);
    /* Where the index is s/limit for a stretch s > 0 and 0 otherwise (a bound on tension): bond
       k's limit, for the every-step check's screen (PeriBondsBreak); < 0 when unknown yet or when
       the bond is not bounded so (softening). NULL: the criterion is not of that form. */
    PetscReal (*stretch_limit)(const PeriCriterion *c, PeriModel m, PetscInt k);
    /* The share of its stiffness the bond keeps (1: untouched); NULL: brittle. */
    PetscReal (*softening)(const PeriCriterion *c, const PetscReal meas[]);
    /* Its part of the run log's "failure:" line, starting with a blank. */
    PetscErrorCode (*view)(const PeriCriterion *c, PeriModel m, MPI_Comm comm);
  } ops;
};

/* The ops of a bound on one measure's magnitude (src/system/criterion_magnitude.c). */
PETSC_EXTERN PetscErrorCode PeriCriterionMagnitudeSetFromScene(PeriCriterion *, PeriScene, PeriNode, PeriModel);
PETSC_EXTERN PetscReal      PeriCriterionMagnitudeIndex(const PeriCriterion *, PeriModel, const PeriBondGeometry *, const PetscReal[], PeriFailureCause *);
PETSC_EXTERN PetscErrorCode PeriCriterionMagnitudeView(const PeriCriterion *, PeriModel, MPI_Comm);

/* Bond failure criteria (failure:, src/system/failure.c): every registered criterion, those the
 * scene switches on active. */
typedef struct {
  PetscBool     active;    /* the scene has failure: */
  PetscBool     softening; /* a criterion softens bonds: bonds.intact is kept */
  PetscBool     screen;    /* -peri_failure_screen: PeriFailureScreens may say yes */
  PetscInt      screen_xi; /* the screen's bond vectors: -1 not yet known, 0 stored, 1 from the coordinates (every stored one equals x_j - x_i) */
  PetscInt      ncriteria;
  PeriCriterion criterion[PERI_MAX_CRITERIA]; /* in the order of src/system/criterion_list.h */
  PetscInt      precracked_bonds;             /* bonds the scene's cracks removed */
  PetscInt      ncracks;                      /* the items of cracks: */
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
PETSC_EXTERN PetscErrorCode PeriFailureCacheBonds(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriBondsCount(PeriSystem, PetscInt *, PetscInt *);
struct _PeriCrackSet; /* the cracks' geometry: perilin/private/crack_surfaces.h */
PETSC_EXTERN const PeriKey  PeriCrackKeys[], PeriCrackDiscKeys[];
PETSC_EXTERN PetscErrorCode PeriCracksApply(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriCracksRead(PeriSystem, PeriNode, struct _PeriCrackSet *);
PETSC_EXTERN PetscInt       PeriCracksCut(const PeriParticles *, PeriBonds *, const struct _PeriCrackSet *, PetscInt[]);
PETSC_EXTERN PetscReal      PeriBondFailureIndex(PeriSystem, const PeriBondGeometry *, const PetscReal[], PeriFailureCause *);
PETSC_EXTERN PetscBool      PeriFailureScreens(PeriSystem, PetscInt *, const PeriCriterion *[]);
PETSC_EXTERN PetscReal      PeriBondCriticalLoad(PeriSystem, const PeriBondGeometry *, const PetscReal[], PetscInt);
PETSC_EXTERN PetscReal      PeriBondSoftening(PeriSystem, const PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriFailureView(const PeriFailure *, PeriModel, MPI_Comm);
PETSC_EXTERN PetscErrorCode PeriFailureSelect(PeriFailure *, const char *const[], PetscBool);
PETSC_EXTERN PetscBool      PeriFailureIsActive(const PeriFailure *, const char[]);
PETSC_EXTERN PetscReal      PeriFailureValue(const PeriFailure *, const char[]);
PETSC_EXTERN PetscErrorCode PeriFailureSetValue(PeriFailure *, const char[], PetscReal);
PETSC_EXTERN PetscErrorCode PeriDamage(PeriSystem, PetscReal **);
PETSC_EXTERN PetscErrorCode PeriFamilySync(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriPieces(PeriSystem, PetscInt *, PetscInt **, PetscReal **, PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriFailureAddFields(PeriSystem, PeriFieldList);
PETSC_EXTERN PetscErrorCode PeriBondsBreak(PeriSystem, Vec, PetscBool, PetscReal, PetscInt *, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriCheckpointCreate(PeriSystem, PeriCheckpoint *);
PETSC_EXTERN PetscErrorCode PeriCheckpointSave(PeriSystem, PeriCheckpoint *);
PETSC_EXTERN PetscErrorCode PeriCheckpointRestore(PeriSystem, PeriCheckpoint *, PetscBool, PetscBool);
PETSC_EXTERN PetscErrorCode PeriCheckpointView(PeriSystem, const PeriCheckpoint *, PetscViewer);
PETSC_EXTERN PetscErrorCode PeriCheckpointLoad(PeriSystem, PeriCheckpoint *, PetscViewer, const char[]);
PETSC_EXTERN PetscErrorCode PeriCheckpointDestroy(PeriCheckpoint *);
PETSC_EXTERN PetscErrorCode PeriBondStateDestroy(PeriBondState *);
