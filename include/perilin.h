/* perilin: implicit static and modal peridynamics on PETSc.
 *
 * The flow of one run (see docs/design.md):
 *   scene (YAML + options) -> particles -> partition + neighbours (bonds) -> corrections
 *   -> model calibration -> assembly of K -> analysis -> output.
 * PeriProblem owns every stage; the executable and the tests drive it through this header. */
#pragma once

#include <petscksp.h>

#if PETSC_VERSION_LT(3, 19, 0)
#  define PETSC_SUCCESS 0
#endif

#define PERI_MAX_DOF     3
#define PERI_MAX_MODES   6
#define PERI_NAME_LEN    64
#define PERI_MAX_MEASURE 3

/* ------------------------------------------------------------------ scene (src/scene.c) */
typedef enum {
  PERI_NODE_MAP,
  PERI_NODE_SEQ,
  PERI_NODE_SCALAR
} PeriNodeKind;

typedef struct _PeriNode *PeriNode;
struct _PeriNode {
  PeriNodeKind kind;
  char        *key;   /* key in the parent mapping, or the index for sequence items */
  char        *path;  /* dotted path from the root, e.g. "material.nu", "bc.0.region" */
  char        *value; /* scalars only */
  int          line;  /* 1-based line in the scene file; 0 when set from the options database */
  PetscInt     n;
  PeriNode    *child;
};

typedef struct _p_PeriScene *PeriScene;
struct _p_PeriScene {
  char     file[PETSC_MAX_PATH_LEN];
  char     dir[PETSC_MAX_PATH_LEN]; /* directory of the scene file, for relative paths */
  PeriNode root;
};

PETSC_EXTERN PetscErrorCode PeriSceneCreateFromFile(const char[], PeriScene *);
PETSC_EXTERN PetscErrorCode PeriSceneDestroy(PeriScene *);
PETSC_EXTERN PetscErrorCode PeriSceneHelp(MPI_Comm);
PETSC_EXTERN PetscErrorCode PeriSceneWhere(PeriScene, PeriNode, const char[], char[], size_t);
PETSC_EXTERN PetscErrorCode PeriSceneGetNode(PeriNode, const char[], PeriNode *);
PETSC_EXTERN PetscErrorCode PeriSceneGetMap(PeriScene, PeriNode, const char[], PetscBool, PeriNode *);
PETSC_EXTERN PetscErrorCode PeriSceneCheckKeys(PeriScene, PeriNode, const char *const[]);
PETSC_EXTERN PetscErrorCode PeriSceneGetReal(PeriScene, PeriNode, const char[], PetscBool, PetscReal *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetInt(PeriScene, PeriNode, const char[], PetscBool, PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetBool(PeriScene, PeriNode, const char[], PetscBool *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetString(PeriScene, PeriNode, const char[], PetscBool, char[], size_t, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetChoice(PeriScene, PeriNode, const char[], const char *const[], PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetRealArray(PeriScene, PeriNode, const char[], PetscBool, PetscInt, PetscInt, PetscReal[], PetscInt *);
PETSC_EXTERN PetscErrorCode PeriSceneParseReal(PeriScene, PeriNode, PetscReal *);
PETSC_EXTERN void           PeriListAppend(char[], size_t, const char[]);
PETSC_EXTERN PetscErrorCode PeriFunctionListNames(PetscFunctionList, char[], size_t);
PETSC_EXTERN PetscErrorCode PeriSceneParseBool(PeriScene, PeriNode, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneParseRealArray(PeriScene, PeriNode, PetscInt, PetscInt, PetscReal[], PetscInt *);

/* Options that name nothing (src/options.c; docs/scene.md): an option naming no scene key is an
 * error before any computation, and an option nothing read is one after the analysis, both with a
 * "did you mean"; -options_unused_ok makes them warnings. */
PETSC_EXTERN PetscErrorCode PeriSceneOptionIsScene(const char[], PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneOptionNames(PeriScene, char ***);
PETSC_EXTERN PetscErrorCode PeriSceneOptionExplain(PeriScene, const char[], char[], size_t, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriOptionsCheckScene(MPI_Comm, PeriScene);
struct _p_PeriProblem; /* PeriProblem, below */
PETSC_EXTERN PetscErrorCode PeriOptionsCheckUnused(struct _p_PeriProblem *);

/* A user-input error that names the file, the line and the key. */
#define PeriInputCheck(cond, scene, node, key, fmt, ...)                                      \
  do {                                                                                        \
    if (PetscUnlikely(!(cond))) {                                                             \
      char peri_where_[2 * PETSC_MAX_PATH_LEN];                                               \
      PetscCall(PeriSceneWhere((scene), (node), (key), peri_where_, sizeof(peri_where_)));    \
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: " fmt, peri_where_, ##__VA_ARGS__); \
    }                                                                                         \
  } while (0)

/* ------------------------------------------------------------------ particles (src/particles.c) */
typedef struct {
  PetscInt   dim;
  PetscInt   n;           /* global number of particles; every rank holds all coordinates */
  PetscReal *x;           /* 3 per particle (z = 0 in 2D) */
  PetscReal *volume;      /* includes the thickness in 2D */
  PetscReal *spacing;     /* the particle's own grid spacing, for partial volumes */
  PetscInt  *source_line; /* line in the CSV file (0 for grid particles), for messages */
  PetscReal  thickness;   /* 2D only */
  PetscReal  lower[3], upper[3];
  PetscBool  periodic[3];
  PetscReal  mean_spacing;
  /* fictitious boundary layers (src/layers.c): NULL when the scene has none */
  PetscInt      *image;   /* -1 for a particle of the body; else the body particle it mirrors */
  unsigned char *crossed; /* faces crossed to reach the particle: bit 2 axis + (upper face) */
  PetscInt       nfictitious;
} PeriParticles;

#define PeriParticleIsFictitious(pt, k) ((pt)->image && (pt)->image[k] >= 0)

PETSC_EXTERN PetscErrorCode PeriParticlesCreateFromScene(PeriScene, PetscInt, PetscReal, PeriParticles *);
PETSC_EXTERN PetscErrorCode PeriParticlesPermute(PeriParticles *, const PetscInt[]);
PETSC_EXTERN PetscErrorCode PeriParticlesDestroy(PeriParticles *);

/* ------------------------------------------------------------------ regions (src/regions.c) */
typedef enum {
  PERI_REGION_ALL,
  PERI_REGION_BOX,
  PERI_REGION_LAYER
} PeriRegionKind;

typedef struct {
  char           name[PERI_NAME_LEN];
  PeriRegionKind kind;
  PetscReal      lower[3], upper[3]; /* the box, or the layer's slab */
  PetscInt       axis, side;         /* layers: axis 0..2, side -1 (lower face) or +1 (upper face) */
  PetscReal      depth;              /* layers */
  PetscReal      face_area;          /* layers: area of the body's face the layer lies on */
  PetscInt       count;              /* particles inside */
  PetscReal      volume;             /* their total volume */
  PeriNode       node;
} PeriRegion;

PETSC_EXTERN PetscErrorCode PeriRegionsCreateFromScene(PeriScene, const PeriParticles *, PetscReal, PetscInt *, PeriRegion **);
PETSC_EXTERN PetscErrorCode PeriRegionFind(PeriScene, PeriNode, const char[], PetscInt, PeriRegion *, PeriRegion **);
PETSC_EXTERN PetscBool      PeriRegionContains(const PeriRegion *, const PetscReal[]);

/* ------------------------------------------------------------------ bonds (src/neighbors.c, src/corrections.c) */
typedef enum {
  PERI_PARTIAL_VOLUME_NONE,
  PERI_PARTIAL_VOLUME_LINEAR,
  PERI_PARTIAL_VOLUME_LINEAR_CONTINUED
} PeriPartialVolume;
PETSC_EXTERN const char *const PeriPartialVolumes[];

typedef enum {
  PERI_SURFACE_NONE,
  PERI_SURFACE_VOLUME,
  PERI_SURFACE_ENERGY
} PeriSurfaceCorrection;
PETSC_EXTERN const char *const PeriSurfaceCorrections[];

/* Bonds are stored once per pair, in the row of the smaller global index (CSR over owned particles). */
typedef struct {
  PetscInt       rstart, rend; /* owned particles */
  PetscInt      *offset;       /* rend - rstart + 1 */
  PetscInt      *j;            /* the other particle (global index, j >= i; j == i only for periodic self-images) */
  PetscReal     *xi;           /* 3 per bond: X_j - X_i, minimum image on periodic axes */
  PetscReal     *length;
  PetscReal     *alpha;  /* partial-volume factor */
  PetscReal     *lambda; /* surface correction factor */
  unsigned char *live;   /* 1 intact, 0 broken */
  unsigned char *cause;  /* scenes with failure: why a dead bond broke (PeriFailureCause) */
  PetscReal     *intact; /* softening bonds (Diana & Casolo eqs. 45-46): the remaining share of stiffness in (0, 1]; NULL otherwise */
  PetscInt       nbonds; /* local */
} PeriBonds;

PETSC_EXTERN PetscErrorCode PeriNeighborSearch(const PeriParticles *, PetscReal, PeriPartialVolume, PetscInt, PetscInt, PetscBool, PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriBondsDestroy(PeriBonds *);
PETSC_EXTERN PetscReal      PeriPartialVolumeFactor(PeriPartialVolume, PetscReal, PetscReal, PetscReal);
PETSC_EXTERN PetscReal      PeriSearchRadius(PeriPartialVolume, PetscReal, PetscReal);
PETSC_EXTERN PetscErrorCode PeriNeighborhoodVolumes(MPI_Comm, const PeriParticles *, const PeriBonds *, PetscReal[], PetscInt[]);
PETSC_EXTERN PetscErrorCode PeriSurfaceCorrectionApply(PeriSurfaceCorrection, const PeriParticles *, PetscReal, const PetscReal[], PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriPartition(MPI_Comm, const PeriParticles *, PetscReal, PetscInt **, PetscInt **);

/* ------------------------------------------------------------------ models (src/model.c, models/) */
typedef struct {
  PetscReal E, nu, K, G; /* Young's modulus, Poisson ratio, 3D bulk and shear moduli */
  PetscReal rho;         /* density (0 when the scene gives none) */
  PetscReal thickness;   /* 2D */
} PeriMaterial;

/* One bond as the kernels see it: plain data, no PETSc objects. */
typedef struct {
  PetscInt  i, j;
  PetscReal xi[3], length;
  PetscReal Vi, Vj;
  PetscReal weight; /* alpha * lambda */
  PetscReal mu;     /* the bond's shear modulus across materials (Oterkus & Madenci eq. 60); 0: the material's */
} PeriBondGeometry;

/* What calibration may use besides the material: the discrete family volumes sum_j alpha_ij V_j. */
typedef struct {
  PetscInt              n;
  const PetscReal      *family_volume;
  const PetscReal      *mu; /* shear modulus per particle (material.mu_by_region), or NULL: uniform */
  MPI_Comm              comm;
  const PeriParticles  *particles;
  const PeriBonds      *bonds; /* this rank's bonds, for corrections computed from the family */
  PeriSurfaceCorrection surface;
} PeriCalibrationData;

typedef struct _p_PeriModel *PeriModel;
typedef struct {
  /* Reads the model's own scene keys (model.*); may be NULL. */
  PetscErrorCode (*setfromscene)(PeriModel, PeriScene, PeriNode);
  /* Admissible Poisson ratio range for this dimension / plane kind. */
  void (*nu_range)(PeriModel, PetscReal *, PetscReal *);
  PetscErrorCode (*calibrate)(PeriModel, const PeriCalibrationData *);
  /* The (2 dofs)^2 linearized stiffness block of one bond, row-major, DOFs of i then of j. */
  void (*bond_stiffness)(PeriModel, const PeriBondGeometry *, PetscReal[]);
  /* The bond's strain measures (stretch, sliding, ...) from the two particles' DOFs. */
  void (*bond_measures)(PeriModel, const PeriBondGeometry *, const PetscReal[], const PetscReal[], PetscReal[]);
  /* State-based models only (else NULL): the dense stiffness of particle i's energy, which depends
     on its whole family fam[0..n-1] (all with fam[k].i == i): ((n+1) dofs)^2, row-major, the DOFs
     of i first, then those of fam[0], fam[1], ... */
  PetscErrorCode (*family_stiffness)(PeriModel, PetscInt, const PeriBondGeometry[], PetscReal[]);
  /* The critical value of the first measure (stretch, shear angle) of this bond for the energy
     release rate G: breaking every bond across a unit crack area releases G. May be NULL. */
  PetscReal (*critical_from_G)(PeriModel, const PeriBondGeometry *, PetscReal);
  /* Values of the rigid-body (zero-energy) modes at a point, nmodes x dofs; returns nmodes. */
  PetscInt (*rigid_modes)(PeriModel, const PetscReal[], PetscReal[][PERI_MAX_DOF]);
  PetscErrorCode (*destroy)(PeriModel); /* frees what data points to; data itself is freed after; may be NULL */
} PeriModelOps;

struct _p_PeriModel {
  char               type[PERI_NAME_LEN];
  PeriModelOps       ops;
  PetscInt           dim;
  PetscBool          plane_strain;
  PetscInt           dofs;
  const char *const *components; /* dofs names, e.g. "ux", "uy" */
  PetscInt           nmeasures;
  const char *const *measure_names;
  PetscBool          allows_surface_correction;
  const char *const *surface_corrections;      /* allowed corrections.surface values; NULL: none, volume */
  PetscBool          antiplane;                /* one DOF, the out-of-plane displacement uz: stresses tau_xz, tau_yz */
  const char *const *keys;                     /* the model's own scene keys besides model.type and model.plane, or NULL */
  PetscBool          inactive[PERI_MAX_DOF];   /* components without stiffness after calibration: held at 0 */
  PetscBool          rotational[PERI_MAX_DOF]; /* rotations: their lumped mass is an inertia rho V r^2 */
  char               warning[256];             /* set by calibration; printed once by the problem */
  PeriMaterial       material;
  PetscReal          delta;
  void              *data;
};

PETSC_EXTERN PetscErrorCode PeriModelRegister(const char[], PetscErrorCode (*)(PeriModel));
PETSC_EXTERN PetscErrorCode PeriModelRegisterAll(void);
PETSC_EXTERN PetscErrorCode PeriModelCreate(const char[], PetscInt, PetscBool, PeriModel *);
PETSC_EXTERN PetscErrorCode PeriModelSetFromScene(PeriModel, PeriScene, PetscReal);
PETSC_EXTERN PetscErrorCode PeriModelListTypes(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriModelTypeRegistered(const char[], PetscBool *);
PETSC_EXTERN PetscErrorCode PeriModelDestroy(PeriModel *);
PETSC_EXTERN PetscReal      PeriModelIsotropicEnergy(PeriModel);
PETSC_EXTERN PetscReal      PeriModelHorizonMoment(PeriModel, PetscInt);
PETSC_EXTERN void           PeriCentralBondBlock(PeriModel, const PeriBondGeometry *, PetscReal, PetscReal[]);
PETSC_EXTERN void           PeriAddSpring(PetscInt, const PetscReal[], PetscReal, PetscReal[]);
PETSC_EXTERN void           PeriPlaneMicromoduli(PeriModel, PetscReal *, PetscReal *);
PETSC_EXTERN void           PeriShearBondNuRange(PeriModel, PetscReal *, PetscReal *);
PETSC_EXTERN PetscReal      PeriCriticalStretchSpring(PeriModel, PetscReal, PetscReal);
PETSC_EXTERN void           PeriBondStretch(PeriModel, const PeriBondGeometry *, const PetscReal[], const PetscReal[], PetscReal[]);
PETSC_EXTERN void           PeriBondBasedNuRange(PeriModel, PetscReal *, PetscReal *);
PETSC_EXTERN void           PeriModelSetCentralForce(PeriModel);
PETSC_EXTERN PetscInt       PeriTranslationalRigidModes(PeriModel, const PetscReal[], PetscReal[][PERI_MAX_DOF]);
PETSC_EXTERN PetscErrorCode PeriModelComponentIndex(PeriModel, const char[], PetscInt *);

PETSC_EXTERN PetscErrorCode PeriParticlesCheckMemory(MPI_Comm, PeriScene, PeriModel);

/* The scene keys a plug-in owns. Declared only: until the scene sections declare their keys, every
 * type's schema is NULL. */
typedef struct _PeriSchema PeriSchema;

/* What a model type promises about the energy of a homogeneous strain at a particle whose family
 * and its neighbours' families lie inside the body, on a uniform grid: that it equals the energy
 * density of the target elasticity (plane stress or strain as set up; antiplane models: the shear
 * modulus), for the isotropic expansion u = s X only or for every strain. The promise holds with
 * corrections.surface: energy where the model offers it (that correction calibrates the discrete
 * energy of linear fields), otherwise with every correction the model takes.
 * tests/unit/test_model_contract.c checks it. */
typedef enum {
  PERI_EXACT_NONE,
  PERI_EXACT_EXPANSION,
  PERI_EXACT_HOMOGENEOUS
} PeriExactEnergy;

/* A built-in model type. Each model file (models/) ends with its descriptor(s) PeriModel_<id>,
 * whose create function stays static; models/list.h names them and models/registry.c registers
 * them. */
typedef struct {
  const char       *name; /* model.type */
  const PeriSchema *schema;
  PetscErrorCode (*create)(PeriModel);
  /* the modes of ops.rigid_modes that vary with position (rotations) store no energy; false when
     they are listed only as AMG's near-null space */
  PetscBool       rotation_invariant;
  PeriExactEnergy exact_energy;
} PeriModelType;
PETSC_EXTERN PetscErrorCode PeriModelTypeGet(const char[], const PeriModelType **);

/* ------------------------------------------------------------------ the problem (src/problem.c) */
typedef struct {
  char      name[PERI_NAME_LEN];
  PetscReal x[3];
  PetscInt  particle; /* nearest particle (global index) */
  PetscReal u[PERI_MAX_DOF];
  PetscReal W;
} PeriProbe;

typedef struct {
  PetscReal neighbors_s, assembly_s, solve_s, total_s;
  PetscReal memory_mb, memory_mb_max_rank;
  char      ksp_type[64], pc_type[64], converged_reason[64];
  PetscInt  iterations;
  PetscReal residual_norm; /* true relative residual of the last solve */
  PetscReal residual_tol;  /* the largest accepted (solver.residual_tol or its default) */
  PetscReal strain_energy;
  PetscReal max_abs_u[PERI_MAX_DOF];
  PetscInt  nbonds_total;
  PetscBool symmetric;      /* the operator solved was symmetric */
  PetscInt  free_modes;     /* rigid motions left free with balanced loads: solved orthogonal to them */
  PetscReal load_imbalance; /* share of the load along those motions, removed */
  PetscInt  precracked_bonds;
  PetscBool free_modes_noted; /* the note on free motions is printed once per run */
  PetscInt  edge_cut;         /* bonds between particles of different ranks */
  /* against the scene's reference field (src/reference.c) */
  PetscBool has_reference;
  PetscInt  interior_particles;
  PetscReal interior_strain[3];                     /* e_xx, e_yy, gamma_xy */
  PetscReal effective_E, effective_nu, effective_G; /* 0 where the stress state does not define it */
  PetscReal error_l2_rel, error_max_rel;
} PeriResults;

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
} PeriReference;

#define PERI_MAX_VTU_MODES 12

/* One natural mode: frequency, accuracy, and what moves. */
typedef struct {
  PetscReal f_hz, omega2, residual;
  PetscReal energy_share[PERI_MAX_DOF]; /* kinetic energy share per component */
  PetscReal effective_mass[3];          /* per direction, as a fraction of the total mass */
  char      kind[32];
} PeriMode;

typedef struct {
  PetscInt   nmodes, nrigid, nfree_dofs;
  PeriMode  *modes;
  PetscReal  total_mass, target_hz;
  PetscReal  longitudinal_speed, theory_speed; /* free bars only; 0 otherwise */
  PetscInt   axis;                             /* the structure's main axis */
  PetscReal *shapes;                           /* rank 0: min(nmodes, PERI_MAX_VTU_MODES) x n x dofs, each scaled to max |u| = 1 */
  PetscInt   nshapes;
  PetscReal  factor_s, solve_s;
} PeriModal;

/* Fictitious boundary layers outside the body's faces (Oterkus & Madenci sec. 6, src/layers.c):
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

/* Bond failure criteria (failure:, src/failure.c); 0 = criterion not given. */
typedef struct {
  PetscBool active;
  PetscReal stretch, G, compressive, sliding, friction_angle, cohesion, shear_angle;
  PetscReal ultimate, ultimate_compressive; /* softening: the stretch where the stiffness is gone (0: brittle) */
  PetscInt  istretch, isliding, ishear;     /* the model's measures, -1 when absent */
} PeriFailure;

/* One load step of the quasi-static analysis. */
typedef struct {
  PetscReal lambda, control_u, seconds;
  PetscInt  broken, broken_total, iterations, ksp_iterations;
} PeriStep;

typedef struct {
  PetscInt   nsteps, cap;
  PeriStep  *steps;
  PetscReal  peak_load_factor, critical_load_factor;
  PetscInt   broken_bonds;                      /* at the last equilibrium: steps.csv's last broken_total */
  PetscInt   failure_step, failed_trial_broken; /* the step that failed, and the bonds its trial broke */
  PetscReal *trial_damage;                      /* rank 0: the damage of the failed trial (like p->damage) */
  PetscInt   fragments_held, pc_setups, solves;
  PetscBool  failed, complete;
  char       ending[160];
  char       control[PERI_NAME_LEN];
} PeriQuasistatic;

typedef struct _p_PeriProblem *PeriProblem;
struct _p_PeriProblem {
  MPI_Comm              comm;
  PetscMPIInt           rank, size;
  PeriScene             scene;
  PeriParticles         particles;
  PetscInt              nregions;
  PeriRegion           *regions;
  PetscReal             delta;
  PeriPartialVolume     partial_volume;
  PeriSurfaceCorrection surface;
  PeriBonds             bonds;
  PetscReal            *family_volume;  /* sum_j alpha_ij V_j over the family, per particle (all ranks) */
  PetscInt             *neighbor_count; /* per particle (all ranks) */
  PetscInt             *owner;          /* rank owning each particle (all ranks) */
  PetscReal            *mu;             /* shear modulus per particle when material.mu_by_region is given, else NULL */
  PetscReal            *bond_mu;        /* per local bond: the shear modulus across materials (eq. 60), or NULL */
  PeriBonds             family;         /* state-based models: every bond of each owned particle (both directions) */
  PeriLayers            layers;
  PeriTorsion           torsion;
  PetscReal            *tau; /* antiplane models, rank 0: tau_xz, tau_yz, |tau| per particle after the solve */
  PeriFailure           failure;
  PetscReal            *damage;      /* rank 0, scenes with failure: per particle phi, then phi per PeriFailureCause */
  PeriQuasistatic      *quasistatic; /* the quasi-static analysis' results */
  PetscInt              output_every;
  PeriModel             model;
  Mat                   K;                       /* stiffness */
  char                  mat_type[PERI_NAME_LEN]; /* default type of K, before -mat_type */
  Vec                   u, f;
  PetscInt              nconstrained; /* owned constrained DOFs */
  PetscInt             *constrained;  /* their global rows */
  PetscReal            *constrained_value;
  PetscInt              nprobes;
  PeriProbe            *probes;
  char                  analysis[PERI_NAME_LEN];
  char                  output_dir[PETSC_MAX_PATH_LEN];
  char                  staging_dir[PETSC_MAX_PATH_LEN]; /* where the outputs are written until the set is committed */
  PetscBool             write_output;                    /* set by the executable: check output.dir before computing */
  PetscBool             vtk;
  PetscReal            *W;     /* strain energy density per particle (rank 0, after the solve) */
  PetscReal            *u_all; /* displacements of all particles (rank 0, after the solve) */
  PeriResults           results;
  PeriReference         reference;
  PeriModal            *modal;        /* modal analysis results, when the scene asks for modes */
  int                   interrupted;  /* the signal (SIGINT, SIGTERM) that stopped the analysis early, or 0 */
  PetscReal             residual_tol; /* solver.residual_tol: the largest true relative residual accepted (0: the default) */
  PetscLogDouble        t_start;
};

PETSC_EXTERN PetscErrorCode PeriProblemCreate(MPI_Comm, PeriProblem *);
PETSC_EXTERN PetscErrorCode PeriProblemLoad(PeriProblem, const char[]);
PETSC_EXTERN PetscErrorCode PeriProblemSetUp(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemAssemble(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemRun(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemWriteOutput(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemDestroy(PeriProblem *);
PETSC_EXTERN PetscErrorCode PeriProblemCreateVec(PeriProblem, Vec *);
PETSC_EXTERN PetscErrorCode PeriProblemBondGeometry(PeriProblem, PetscInt, PetscInt, PeriBondGeometry *);
PETSC_EXTERN PetscErrorCode PeriProblemEvaluateEnergy(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemFamilyGeometry(PeriProblem, PetscInt, PetscInt *, PeriBondGeometry[]);
PETSC_EXTERN PetscInt       PeriProblemMaxFamily(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemFindProbe(PeriProblem, const char[], PeriProbe **);
PETSC_EXTERN PetscReal      PeriResidualTolerance(PeriProblem, PetscReal);

/* assembly (src/assembly.c) */
PETSC_EXTERN PetscErrorCode PeriAssembleStiffness(PeriProblem, Mat *);
PETSC_EXTERN PetscErrorCode PeriRigidModes(PeriProblem, PetscInt *, Vec[], PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriSetNearNullSpace(PeriProblem, Mat);

/* boundary conditions and loads (src/boundary.c) */
PETSC_EXTERN PetscErrorCode PeriBoundarySetUp(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriLoadsAssemble(PeriProblem, Vec);

/* reference solutions (src/reference.c) */
PETSC_EXTERN PetscErrorCode PeriReferenceSetUp(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriReferenceEvaluate(PeriProblem);
PETSC_EXTERN void           PeriReferenceDisplacement(PeriProblem, const PetscReal[], PetscReal[]);

/* analyses (src/analysis/). A built-in analysis type: each analysis file ends with its descriptor
 * PeriAnalysis_<id>, whose run function stays static; src/analysis/list.h names them and
 * src/analysis/registry.c registers them. */
typedef struct {
  const char       *name; /* analysis.type */
  const PeriSchema *schema;
  PetscErrorCode (*run)(PeriProblem);
} PeriAnalysisType;
PETSC_EXTERN PetscErrorCode PeriAnalysisRegister(const char[], PetscErrorCode (*)(PeriProblem));
PETSC_EXTERN PetscErrorCode PeriAnalysisRegisterAll(void);
PETSC_EXTERN PetscErrorCode PeriAnalysisFind(const char[], PetscErrorCode (**)(PeriProblem));
PETSC_EXTERN PetscErrorCode PeriAnalysisListTypes(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriStaticSolve(PeriProblem, KSP *, PetscReal, PetscBool, PetscInt, const PetscInt[], const PetscReal[], KSPConvergedReason *);
PETSC_EXTERN PetscErrorCode PeriStaticCheckConverged(PeriProblem, KSPConvergedReason);
PETSC_EXTERN PetscErrorCode PeriStaticConverged(PeriProblem, KSP, KSPConvergedReason, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriStaticDefaultMatType(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriAssembleMass(PeriProblem, Mat *);
PETSC_EXTERN PetscErrorCode PeriRigidMotionFree(PeriProblem, PetscInt *, char[], size_t, Vec[]);

/* failure, cracks, damage, pieces (src/failure.c) */
PETSC_EXTERN PetscErrorCode PeriFailureSetUp(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriCracksApply(PeriProblem);
PETSC_EXTERN PetscReal      PeriBondFailureIndex(PeriProblem, const PeriBondGeometry *, const PetscReal[], PeriFailureCause *);
PETSC_EXTERN PetscReal      PeriBondSoftening(PeriProblem, const PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriDamage(PeriProblem, PetscReal **);
PETSC_EXTERN PetscErrorCode PeriComponents(PeriProblem, PetscInt[]);
PETSC_EXTERN PetscErrorCode PeriFamilySync(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriPieces(PeriProblem, PetscInt *, PetscInt **, PetscReal **, PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriWriteStepsCSV(PeriProblem, const char[]);

/* fictitious boundary layers and torsion (src/layers.c) */
PETSC_EXTERN PetscErrorCode PeriLayersAddParticles(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriLayersSetUp(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriLayersApply(PeriProblem, PetscReal, Mat *, Vec);
PETSC_EXTERN PetscErrorCode PeriLayersComplete(PeriProblem, PetscReal, Vec);
PETSC_EXTERN PetscErrorCode PeriLayersDestroy(PeriLayers *);
PETSC_EXTERN PetscErrorCode PeriTorsionEvaluate(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriTorsionLoads(PeriProblem, Vec);
PETSC_EXTERN PetscErrorCode PeriWriteModesCSV(PeriProblem, const char[]);

/* output (src/output/) */
typedef struct _PeriJSON   *PeriJSON;
PETSC_EXTERN PetscErrorCode PeriJSONOpen(const char[], PeriJSON *);
PETSC_EXTERN PetscErrorCode PeriJSONClose(PeriJSON *, PetscBool);
PETSC_EXTERN PetscErrorCode PeriJSONBeginObject(PeriJSON, const char[]);
PETSC_EXTERN PetscErrorCode PeriJSONEndObject(PeriJSON);
PETSC_EXTERN PetscErrorCode PeriJSONBeginArray(PeriJSON, const char[]);
PETSC_EXTERN PetscErrorCode PeriJSONEndArray(PeriJSON);
PETSC_EXTERN PetscErrorCode PeriJSONString(PeriJSON, const char[], const char[]);
PETSC_EXTERN PetscErrorCode PeriJSONReal(PeriJSON, const char[], PetscReal);
PETSC_EXTERN PetscErrorCode PeriJSONInt(PeriJSON, const char[], PetscInt);
PETSC_EXTERN PetscErrorCode PeriJSONBool(PeriJSON, const char[], PetscBool);
PETSC_EXTERN PetscErrorCode PeriJSONRealArray(PeriJSON, const char[], PetscInt, const PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriWriteSummary(PeriProblem, const char[]);
PETSC_EXTERN PetscErrorCode PeriWriteVTU(PeriProblem, const char[]);
PETSC_EXTERN PetscErrorCode PeriWritePVD(const char[], PetscInt, const PetscReal[], const char *const[]);
PETSC_EXTERN PetscErrorCode PeriWriteModeShapes(PeriProblem, const char[]);
PETSC_EXTERN PetscErrorCode PeriWriteSnapshotsPVD(PeriProblem, const char[]);
PETSC_EXTERN PetscErrorCode PeriOutputDirCreate(const char[]);
PETSC_EXTERN PetscErrorCode PeriFileCommit(const char[], const char[]);
PETSC_EXTERN PetscErrorCode PeriFileOpenTemporary(const char[], char[], size_t, FILE **);
PETSC_EXTERN PetscErrorCode PeriFileCloseCommit(FILE *, const char[], const char[], int);
PETSC_EXTERN PetscErrorCode PeriOutputSetOpen(MPI_Comm, char[], size_t, char[], size_t);
PETSC_EXTERN PetscErrorCode PeriOutputSetCommit(MPI_Comm, const char[], const char[]);
PETSC_EXTERN void           PeriOutputSetDiscard(void);

/* signals (src/signals.c) */
PETSC_EXTERN PetscErrorCode PeriSignalsInstall(void);
PETSC_EXTERN PetscErrorCode PeriSignalReceived(MPI_Comm, int *);
PETSC_EXTERN int            PeriSignalPending(void);

/* log events */
PETSC_EXTERN PetscLogEvent  PERI_EVENT_Neighbors, PERI_EVENT_Partition, PERI_EVENT_Assembly, PERI_EVENT_Solve;
PETSC_EXTERN PetscLogStage  PERI_STAGE_Setup, PERI_STAGE_Assembly, PERI_STAGE_Solve, PERI_STAGE_Output;
PETSC_EXTERN PetscErrorCode PeriInitializePackage(void);
