/* PeriSystem (src/system/): the discretized physics of one scene, with no analysis-specific member,
 * composed of owned parts (the struct below names each and its header). Analyses drive it through
 * the parts' functions. */
#pragma once

#include <petscksp.h>
#include "perilin/private/disc.h"
#include "perilin/private/model_registry.h"
#include "perilin/private/output.h"
#include "perilin/private/sys.h"
#include "perilin/private/mass.h"
#include "perilin/private/fields.h"
#include "perilin/private/conditions.h"
#include "perilin/private/stiffness.h"
#include "perilin/private/bondstate.h"
#include "perilin/private/contact.h"

typedef struct _p_PeriSystem *PeriSystem;

/* What the run cost and how large it was. */
typedef struct {
  PetscReal neighbors_s, assembly_s, solve_s, total_s;
  PetscReal memory_mb, memory_mb_max_rank;
  PetscInt  nbonds_total;
  PetscInt  edge_cut;           /* bonds between particles of different ranks */
  PetscBool free_modes_noted;   /* the note on free motions is printed once per run */
  PetscReal memory_phase_mb[3]; /* the largest rank's peak memory at the end of set-up, first assembly, run */
  PetscBool pc_matrix_counted;  /* matrix_mb includes the first preconditioning matrix of a matrix-free K */
  PetscReal matrix_mb;          /* the bytes of K (all ranks) at the first assembly: PETSc's, or the matrix-free operator's and its preconditioning matrix's */
} PeriRunLog;

typedef enum {
  PERI_REFERENCE_NONE,
  PERI_REFERENCE_UNIAXIAL,
  PERI_REFERENCE_SHEAR,
  PERI_REFERENCE_BENDING
} PeriReferenceType;
PETSC_EXTERN const char *const PeriReferenceTypes[];

typedef struct {
  PeriReferenceType type;
  PetscReal         stress; /* sigma (uniaxial), tau (shear), the extreme fibre stress (bending) */
  PetscInt          axis;   /* uniaxial: the loaded axis */
  PetscReal         center[3];
  PetscReal         E, nu; /* elastic constants of the reference; default the material's */
  /* the comparison (PeriReferenceEvaluate) */
  PetscBool evaluated;
  PetscInt  interior_particles;
  PetscReal interior_strain[3];                     /* e_xx, e_yy, gamma_xy */
  PetscReal effective_E, effective_nu, effective_G; /* 0 where the stress state does not define it */
  PetscReal error_l2_rel, error_max_rel;
} PeriReference;

/* The run's bookkeeping: cost, progress line, interruption. */
typedef struct {
  PeriRunLog   log;
  PeriProgress progress;    /* the status line on a terminal (src/sys/progress.c) */
  int          interrupted; /* the signal (SIGINT, SIGTERM) that stopped the analysis early, or 0 */
} PeriRun;

/* Material data that varies over the body (material.thickness, material.mu_by_region). */
typedef struct {
  PetscReal  thickness; /* material.thickness (2D) */
  PetscReal *mu;        /* shear modulus per particle when material.mu_by_region is given, else NULL */
  PetscReal *bond_mu;   /* per local bond: the shear modulus across materials (eq. 60), or NULL */
} PeriMaterials;

/* The system is composed of owned parts, each with its header, set-up and destroy: */
struct _p_PeriSystem {
  MPI_Comm       comm;
  PetscMPIInt    rank, size;
  PeriScene      scene;      /* borrowed from the problem: for reading sections and locating errors */
  PeriScene      scene_view; /* a multigrid level's own view of the problem's scene (coarsen set), freed with the level */
  PeriDisc       disc;       /* the particles, regions, bonds and volumes (disc.h) */
  PeriModel      model;      /* the bond model and its calibration (model.h) */
  PeriMaterials  materials;  /* material data per particle and bond */
  PeriConditions conditions; /* bc, loads, layers, torsion, reactions (conditions.h) */
  PeriStiffness  stiffness;  /* K, matrix-free K, preconditioning matrix, solves (stiffness.h) */
  PeriMass       mass;       /* densities and lumped mass, on request (mass.h) */
  PeriBondState  bond_state; /* failure criteria, damage, breaking, checkpoints (bondstate.h) */
  PeriContact    contact;    /* contact between particles and rigid impactors (contact.h) */
  PeriFields     fields;     /* the present state and what is derived from it (fields.h) */
  PeriReference  reference;  /* an exact field to compare with */
  PeriRun        run;        /* cost, progress, interruption */
};

PETSC_EXTERN PetscErrorCode PeriSystemCreate(MPI_Comm, PeriScene, PeriSystem *);
PETSC_EXTERN PetscErrorCode PeriSystemSetFromScene(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemSetNeeds(PeriSystem, const PeriSystemNeeds *);
PETSC_EXTERN PetscErrorCode PeriSystemSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemCanReuse(PeriSystem, PetscBool *, const char **);
PETSC_EXTERN PetscErrorCode PeriSystemSetUpFrom(PeriSystem, PeriSystem, PetscBool);
PETSC_EXTERN PetscErrorCode PeriSystemGiveBackDisc(PeriSystem, PeriSystem);
PETSC_EXTERN PetscErrorCode PeriMultigridSetUp(PeriSystem, KSP, Mat);
PETSC_EXTERN PetscBool      PeriMultigridApplies(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriMultigridSetUpFree(PeriSystem, IS, PC);
PETSC_EXTERN const char    *PeriMultigridWhyNotBody(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemDestroy(PeriSystem *);
PETSC_EXTERN PetscErrorCode PeriSystemCreateVec(PeriSystem, Vec *);
PETSC_EXTERN PetscErrorCode PeriSystemBondGeometry(PeriSystem, PetscInt, PetscInt, PeriBondGeometry *);
PETSC_EXTERN PetscBool      PeriSystemBondVectorsFromCoordinates(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemFamilyGeometry(PeriSystem, PetscInt, PetscInt *, PeriBondGeometry[]);
PETSC_EXTERN PetscInt       PeriSystemMaxFamily(PeriSystem);

/* particles their bonds cannot hold, refused before a solve (src/system/holding.c) */
PETSC_EXTERN PetscErrorCode PeriCheckBonded(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriCheckHeld(PeriSystem);
PETSC_EXTERN PetscBool      PeriBlockHolds(PetscInt, const PetscReal[], const PetscBool[]);
PETSC_EXTERN const char    *PeriRegionOf(PeriSystem, PetscInt);
PETSC_EXTERN PetscBool      PeriPointBefore(const PetscReal[], const PetscReal[]);
/* pieces their bonds join to the rest too weakly to hold, refused before a solve (src/system/mechanism.c) */
PETSC_EXTERN PetscErrorCode PeriCheckMechanisms(PeriSystem);

/* assembly (src/system/assembly.c) */
/* One element of the energy, as PeriElementsForEach visits it: a live bond of a bond-based model,
 * or the family of an owned particle of a state-based model. */
typedef struct {
  PetscInt                n;      /* particles: 2 for a bond, the family's size + 1 */
  const PetscInt         *idx;    /* their local indices (the local view), the bond's or family's particle i first */
  const PetscInt         *gidx;   /* their global indices (matrix and vector rows) */
  PetscInt                nshare; /* idx[0..nshare-1] share its energy equally: a bond's 2 ends, a family's i */
  const PetscReal        *K;      /* the ((n dofs)^2) stiffness block, row-major, DOFs in the order of idx; NULL for a rank-one block: */
  const PetscReal        *G;      /* K = A G G^T (a state's gradient over the family: ops.bond_state), else NULL */
  PetscReal               A;
  const PeriBondGeometry *g;    /* the bond's geometry, or the family's n - 1 bonds */
  PetscReal              *work; /* scratch of 2 n dofs reals for the callback */
} PeriElement;
typedef PetscErrorCode (*PeriElementFn)(PeriSystem, const PeriElement *, void *);
PETSC_EXTERN PetscErrorCode PeriElementsForEach(PeriSystem, PeriElementFn, void *);
PETSC_EXTERN void           PeriElementForces(PeriSystem, const PeriElement *, const PetscScalar[]);
PETSC_EXTERN PetscReal      PeriElementEnergy(const PeriElement *, PetscInt, const PetscReal[]);

/* the matrix-free operator (src/system/operator.c) */

/* boundary conditions and loads (src/system/boundary.c) */

/* reactions and global equilibrium (src/system/reactions.c) */

/* reference solutions (src/system/reference.c) */
PETSC_EXTERN PetscErrorCode PeriReferenceSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriReferenceEvaluate(PeriSystem);
PETSC_EXTERN void           PeriReferenceDisplacement(PeriSystem, const PetscReal[], PetscReal[]);
/* failure, cracks, damage, pieces (src/system/failure.c) */
/* fictitious boundary layers and torsion (src/system/layers.c) */
PETSC_EXTERN PetscErrorCode    PeriParticlesCheckMemory(MPI_Comm, PeriScene, PeriModel, const PeriSystemNeeds *);
PETSC_EXTERN PetscErrorCode    PeriSystemBondsLean(PeriScene, PeriModel, PetscBool, PetscBool, PetscBool, PetscBool *);
PETSC_EXTERN const char *const PeriHorizonSpacings[];
PETSC_EXTERN PetscErrorCode    PeriParticlesCheckMemoryRead(MPI_Comm, PeriScene, PeriModel, const PeriSystemNeeds *, PetscInt, PetscReal);
PETSC_EXTERN PetscErrorCode    PeriSystemReleaseBondGeometry(PeriSystem, PetscBool *);
PETSC_EXTERN PetscErrorCode    PeriSystemRestoreBondGeometry(PeriSystem, PetscBool);

/* summary.json sections (src/system/system_summary.c) */
PETSC_EXTERN PetscErrorCode PeriSystemSummaryModel(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriSystemSummaryDiscretization(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriSystemSummaryCost(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriSystemSummarySolver(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriReferenceSummary(PeriSystem, PeriJSON);

/* The scene keys each system module declares, next to the code that reads them (src/package.c
 * hands them to the scene layer). */
PETSC_EXTERN const PeriSchema PeriSystemSchema[], PeriBoundarySchema[], PeriReferenceSchema[], PeriLayersSchema[], PeriFailureSchema[], PeriProbesSchema[];
