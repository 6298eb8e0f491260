/* PeriSystem (src/system/): the discretized physics of one scene, with no analysis-specific member:
 * particles, bonds, model, conditions, layers, torsion, failure, the stiffness K and the fields of
 * the last solve. Analyses drive it through these functions. */
#pragma once

#include <petscksp.h>
#include "perilin/private/disc.h"
#include "perilin/private/model.h"
#include "perilin/private/output.h"
#include "perilin/private/sys.h"
#include "perilin/private/mass.h"

typedef struct {
  char        name[PERI_NAME_LEN];
  PetscReal   x[3];
  PetscMPIInt rank;          /* the rank owning the nearest particle */
  PetscInt    particle;      /* its local index on that rank (-1 on the others) */
  PetscReal   particle_x[3]; /* its position */
  /* after a solve, on every rank: */
  PetscReal u[PERI_MAX_DOF];
  PetscReal W;
  PetscReal sigma[9], epsilon[9], sigma_elastic[9]; /* output.stress */
} PeriProbe;

/* The last linear solve: what solved it, how well, and the rigid motions it left free. */
typedef struct {
  char      ksp_type[64], pc_type[64], converged_reason[64]; /* "" until a solve ran */
  PetscInt  iterations;
  PetscReal residual_norm;  /* true relative residual of the last solve */
  PetscReal residual_tol;   /* the largest accepted (solver.residual_tol or its default) */
  PetscBool symmetric;      /* the operator solved was symmetric */
  PetscInt  free_modes;     /* rigid motions left free with balanced loads: solved orthogonal to them */
  PetscReal load_imbalance; /* share of the load along those motions, removed */
  PetscReal rhs_norm;       /* ||b|| of the last solve in the scene's units (the residual's scale) */
  PetscReal load_factor;    /* the load factor it was solved at */
} PeriSolveInfo;

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

/* How K is applied (solver.operator, src/system/operator.c), and the bodies small enough for
 * CG + Jacobi on a matrix-free K (PeriSystemAssemble). */
#define PERI_JACOBI_MAX_PARTICLES 500000
#define PERI_JACOBI_MAX_SPAN      200
#define PERI_JACOBI_BUDGET        400 /* iterations, about the cost of GAMG's set-up and solve */
typedef enum {
  PERI_OPERATOR_AUTO,
  PERI_OPERATOR_ASSEMBLED,
  PERI_OPERATOR_MATRIX_FREE
} PeriOperatorKind;
PETSC_EXTERN const char *const  PeriOperatorKinds[];
typedef struct _p_PeriOperator *PeriOperator;

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

typedef struct _p_PeriSystem *PeriSystem;
struct _p_PeriSystem {
  MPI_Comm         comm;
  PetscMPIInt      rank, size;
  PeriScene        scene;     /* borrowed from the problem: for reading sections and locating errors */
  PetscReal        thickness; /* material.thickness (2D) */
  PeriDisc         disc;      /* the particles, regions, bonds and volumes: their one owner */
  PetscReal       *mu;        /* shear modulus per particle when material.mu_by_region is given, else NULL */
  PetscReal       *bond_mu;   /* per local bond: the shear modulus across materials (eq. 60), or NULL */
  PeriLayers       layers;
  PeriTorsion      torsion;
  PetscReal       *tau;            /* antiplane models, per owned particle: tau_xz, tau_yz, |tau| after the solve */
  PetscReal       *stress;         /* vector models, per owned particle: the bond-force stress, 3 x 3 row-major (stress.c) */
  PetscReal       *strain;         /* vector models, per owned particle: the least-squares strain, 3 x 3 row-major */
  PetscReal       *elastic_stress; /* vector models, per owned particle: C : strain of the target elasticity */
  PetscBool        stress_output;  /* output.stress: evaluate the three above after each solve */
  PeriFailure      failure;
  PetscReal       *damage; /* scenes with failure, per owned particle: phi, then phi per PeriFailureCause */
  PeriModel        model;
  PeriMass         mass;                    /* densities and lumped mass, on request (mass.h) */
  Mat              K;                       /* stiffness: assembled, or a MATSHELL over op */
  Mat              Kpc;                     /* with op: the assembled short-range stiffness that preconditions K */
  PeriOperator     op;                      /* solver.operator: matrix_free, else NULL */
  PeriOperatorKind operator_kind;           /* solver.operator */
  PetscReal        pc_radius;               /* solver.pc_radius */
  char             pc_default[16];          /* the static solve's PC unless -pc_type: gamg, or jacobi (matrix-free K on a small 3D body) */
  PetscBool        matrix_free_ok;          /* set by an analysis that uses K through MatMult and PeriStiffnessScaleBond only: K may be matrix-free */
  char             mat_type[PERI_NAME_LEN]; /* default type of K, before -mat_type */
  Vec              u, f;
  PetscInt         nconstrained; /* owned constrained DOFs */
  PetscInt        *constrained;  /* their global rows */
  PetscReal       *constrained_value;
  PetscInt        *constrained_region; /* the region (index of disc.regions) of the bc item that set each, or -1 */
  PeriReactions    reactions;
  PetscInt         nprobes;
  PeriProbe       *probes;
  PetscReal       *W;            /* strain energy density per owned particle, after the solve */
  PetscReal       *u_owned;      /* the same state's DOFs of the owned particles: this rank's piece of the output */
  PetscBool        has_solution; /* the fields above describe a solution */
  PeriSolveInfo    solve;
  PeriRunLog       log;
  PetscReal        strain_energy;           /* after the last solve */
  PetscReal        max_abs_u[PERI_MAX_DOF]; /* per component, after the last solve */
  PeriReference    reference;
  int              interrupted;  /* the signal (SIGINT, SIGTERM) that stopped the analysis early, or 0 */
  PetscReal        residual_tol; /* solver.residual_tol: the largest true relative residual accepted (0: the default) */
  PeriProgress     progress;     /* the status line on a terminal (src/sys/progress.c) */
};

PETSC_EXTERN PetscErrorCode PeriSystemCreate(MPI_Comm, PeriScene, PeriSystem *);
PETSC_EXTERN PetscErrorCode PeriSystemSetFromScene(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemDestroy(PeriSystem *);
PETSC_EXTERN PetscErrorCode PeriSystemAssemble(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemCreateVec(PeriSystem, Vec *);
PETSC_EXTERN PetscErrorCode PeriSystemBondGeometry(PeriSystem, PetscInt, PetscInt, PeriBondGeometry *);
PETSC_EXTERN PetscErrorCode PeriSystemFamilyGeometry(PeriSystem, PetscInt, PetscInt *, PeriBondGeometry[]);
PETSC_EXTERN PetscInt       PeriSystemMaxFamily(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemEvaluateEnergy(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemLocalDOFs(PeriSystem, Vec, PetscScalar **);
PETSC_EXTERN PetscErrorCode PeriSystemFindProbe(PeriSystem, const char[], PeriProbe **);
PETSC_EXTERN PetscReal      PeriResidualTolerance(PeriSystem, PetscReal);
PETSC_EXTERN PetscErrorCode PeriReadProbes(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemEvaluateStress(PeriSystem, const PetscScalar[]);
PETSC_EXTERN PetscErrorCode PeriSystemAddFields(PeriSystem, PeriFieldList);
PETSC_EXTERN PetscErrorCode PeriSystemFieldListCreate(PeriSystem, PeriFieldList *);
PETSC_EXTERN PetscErrorCode PeriSystemWriteParticles(PeriSystem, const PetscReal *, const char[], const char[]);

/* assembly (src/system/assembly.c) */
/* One element of the energy, as PeriElementsForEach visits it: a live bond of a bond-based model,
 * or the family of an owned particle of a state-based model. */
typedef struct {
  PetscInt                n;      /* particles: 2 for a bond, the family's size + 1 */
  const PetscInt         *idx;    /* their local indices (the local view), the bond's or family's particle i first */
  const PetscInt         *gidx;   /* their global indices (matrix and vector rows) */
  PetscInt                nshare; /* idx[0..nshare-1] share its energy equally: a bond's 2 ends, a family's i */
  const PetscReal        *K;      /* the ((n dofs)^2) stiffness block, row-major, DOFs in the order of idx */
  const PeriBondGeometry *g;      /* the bond's geometry, or the family's n - 1 bonds */
  PetscReal              *work;   /* scratch of 2 n dofs reals for the callback */
} PeriElement;
typedef PetscErrorCode (*PeriElementFn)(PeriSystem, const PeriElement *, void *);
PETSC_EXTERN PetscErrorCode PeriElementsForEach(PeriSystem, PeriElementFn, void *);
PETSC_EXTERN void           PeriElementForces(PeriSystem, const PeriElement *, const PetscScalar[]);
PETSC_EXTERN PetscErrorCode PeriAssembleStiffness(PeriSystem, Mat *);
PETSC_EXTERN PetscErrorCode PeriRigidModes(PeriSystem, PetscInt *, Vec[], PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriSetNearNullSpace(PeriSystem, Mat, IS);
PETSC_EXTERN PetscErrorCode PeriMatrixMB(Mat, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriAssembleShortRange(PeriSystem, PetscReal, PetscReal, PetscReal, Mat *);
PETSC_EXTERN PetscErrorCode PeriStiffnessScaleBond(PeriSystem, PetscInt, PetscInt, PetscReal);
PETSC_EXTERN PetscErrorCode PeriStiffnessScaled(PeriSystem);

/* the matrix-free operator (src/system/operator.c) */
PETSC_EXTERN PetscErrorCode PeriOperatorCreate(PeriSystem, PetscReal, PeriOperator *);
PETSC_EXTERN PetscErrorCode PeriOperatorPreconditioner(PeriSystem);
PETSC_EXTERN PetscBool      PeriOperatorServesPC(const char[]);
PETSC_EXTERN PetscBool      PeriOperatorPCWithoutMatrix(const char[]);
PETSC_EXTERN PetscErrorCode PeriOperatorCreateMat(PeriSystem, Mat *);
PETSC_EXTERN PetscErrorCode PeriOperatorMemoryMB(PeriSystem, PeriOperator, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriOperatorScaleBond(PeriSystem, PetscInt, PetscInt, PetscReal, const PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriOperatorScaled(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriOperatorDestroy(PeriOperator *);

/* boundary conditions and loads (src/system/boundary.c) */
PETSC_EXTERN PetscErrorCode PeriBoundarySetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriLoadsAssemble(PeriSystem, Vec);

/* reactions and global equilibrium (src/system/reactions.c) */
PETSC_EXTERN PetscErrorCode PeriReactionsSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemEvaluateReactions(PeriSystem, PetscReal);
PETSC_EXTERN PetscErrorCode PeriReactionsFindRegion(PeriSystem, const char[], PetscInt *);
PETSC_EXTERN PetscErrorCode PeriReactionsSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriReactionsDestroy(PeriReactions *);

/* reference solutions (src/system/reference.c) */
PETSC_EXTERN PetscErrorCode PeriReferenceSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriReferenceEvaluate(PeriSystem);
PETSC_EXTERN void           PeriReferenceDisplacement(PeriSystem, const PetscReal[], PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriStaticSolve(PeriSystem, KSP *, PetscReal, PetscBool, PetscInt, const PetscInt[], const PetscReal[], KSPConvergedReason *);
PETSC_EXTERN PetscErrorCode PeriStaticCheckConverged(PeriSystem, KSPConvergedReason);
PETSC_EXTERN PetscErrorCode PeriStaticConverged(PeriSystem, KSP, KSPConvergedReason, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriStaticDefaultMatType(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriRigidMotionFree(PeriSystem, PetscInt *, char[], size_t, Vec[]);
/* failure, cracks, damage, pieces (src/system/failure.c) */
PETSC_EXTERN PetscErrorCode PeriFailureSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriCracksApply(PeriSystem);
PETSC_EXTERN PetscReal      PeriBondFailureIndex(PeriSystem, const PeriBondGeometry *, const PetscReal[], PeriFailureCause *);
PETSC_EXTERN PetscReal      PeriBondCriticalLoad(PeriSystem, const PeriBondGeometry *, const PetscReal[], PetscInt);
PETSC_EXTERN PetscReal      PeriBondSoftening(PeriSystem, const PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriDamage(PeriSystem, PetscReal **);
PETSC_EXTERN PetscErrorCode PeriFamilySync(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriPieces(PeriSystem, PetscInt *, PetscInt **, PetscReal **, PetscInt *, PetscBool *);
/* fictitious boundary layers and torsion (src/system/layers.c) */
PETSC_EXTERN PetscErrorCode PeriLayersAddParticles(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriLayersSetUp(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriLayersApply(PeriSystem, PetscReal, Mat *, Vec);
PETSC_EXTERN PetscErrorCode PeriLayersComplete(PeriSystem, PetscReal, Vec);
PETSC_EXTERN PetscErrorCode PeriLayersDestroy(PeriLayers *);
PETSC_EXTERN PetscErrorCode PeriTorsionEvaluate(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriTorsionLoads(PeriSystem, Vec);
PETSC_EXTERN PetscErrorCode PeriParticlesCheckMemory(MPI_Comm, PeriScene, PeriModel);
PETSC_EXTERN PetscErrorCode PeriSystemReleaseBondGeometry(PeriSystem, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSystemRestoreBondGeometry(PeriSystem, PetscBool);

/* summary.json sections (src/system/summary.c) */
PETSC_EXTERN PetscErrorCode PeriSystemSummaryModel(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriSystemSummaryDiscretization(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriSystemSummaryCost(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriSystemSummarySolver(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriTorsionSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriLayersSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriLayersAddFields(PeriSystem, PeriFieldList);
PETSC_EXTERN PetscErrorCode PeriFailureAddFields(PeriSystem, PeriFieldList);
PETSC_EXTERN PetscErrorCode PeriSystemSummaryFields(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriReferenceSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriProbesSummary(PeriSystem, PeriJSON);

/* The scene keys each system module declares, next to the code that reads them (src/package.c
 * hands them to the scene layer). */
PETSC_EXTERN const PeriSchema PeriSystemSchema[], PeriBoundarySchema[], PeriReferenceSchema[], PeriLayersSchema[], PeriFailureSchema[], PeriProbesSchema[];
