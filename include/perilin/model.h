/* The model-author API: what a bond model (models/) implements and the kernel helpers it may
 * use. A model file includes this header only. */
#pragma once

#include <perilin/scene.h>

/* What calibration may use besides the material: the discrete family volumes sum_j alpha_ij V_j.
 * The arrays cover the rank's local view: particles 0..nowned-1 are its own, the rest (to n) copies
 * of other ranks' particles within a horizon of them (ghosts). */
typedef struct PeriCalibrationData_s PeriCalibrationData;
struct PeriCalibrationData_s {
  PetscInt              n, nowned, N; /* local view, owned, whole body */
  const PetscReal      *family_volume;
  const PetscReal      *mu; /* shear modulus per particle (material.mu_by_region), or NULL: uniform */
  MPI_Comm              comm;
  const PeriParticles  *particles;
  const PeriBonds      *bonds; /* this rank's bonds (rows: owned particles; j: local indices) */
  PeriSurfaceCorrection surface;
  /* Combines, with op, the values (count of type base per local particle) that the ranks holding a
     particle accumulated for it, and leaves the result on every copy: what a sum over the ends of
     this rank's bonds needs to become the particle's own. Collective. */
  PetscErrorCode (*combine)(const PeriCalibrationData *, MPI_Datatype base, PetscInt count, MPI_Op op, void *values);
  const void *ctx;
};

typedef struct _p_PeriModel *PeriModel;

/* What a bond measure is (PeriModel.measure_kinds): the failure criteria find the measures they
 * read by kind (PeriModelMeasureIndex), never by name; the names are for output. */
typedef enum {
  PERI_MEASURE_STRETCH,           /* (|xi + eta| - |xi|)/|xi|, linearized: e . (u_j - u_i)/|xi| */
  PERI_MEASURE_SLIDING,           /* the shear angle of the bond's axis, gamma (Diana & Casolo) */
  PERI_MEASURE_RELATIVE_ROTATION, /* theta_j - theta_i (micropolar models) */
  PERI_MEASURE_SHEAR_ANGLE        /* antiplane: r = (u_j - u_i)/|xi| (Oterkus & Madenci eq. 5) */
} PeriMeasureKind;

/* model.calibration: the micromoduli from the continuous horizon (the papers'), or with every
 * particle's discrete family made to reproduce the continuum's moments (models/lattice.c) */
typedef enum {
  PERI_CALIBRATION_CONTINUUM,
  PERI_CALIBRATION_LATTICE,
  PERI_CALIBRATION_PATCH /* lattice, then corrected so that affine fields are exact on any cloud (models/patch.c) */
} PeriCalibrationKind;
PETSC_EXTERN const char *const PeriCalibrationKinds[];
typedef struct _n_PeriLattice *PeriLattice;
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
  /* Family models with scalar states per particle (the LPS dilatation; models/lps.c), else NULL.
     Their energy is the pair springs of bond_stiffness plus sum_i sum_s (1/2) A_is theta_is^2,
     s < nstates, where theta_is = sum over i's live bonds of gi_s . (u_j - u_i) (each bond (i, j)
     adds gi_s to theta_is and gj_s to theta_js, both times the same u_j - u_i). bond_state writes
     the bond's gi and gj of state s (dofs each); state_modulus returns A_is of local particle i
     (it may be negative: the springs and the other states keep the whole positive). The system
     applies, assembles and breaks these terms from the two kernels (src/system/operator.c,
     assembly.c); a broken bond leaves its spring and its share of every state. */
  void (*bond_state)(PeriModel, const PeriBondGeometry *, PetscInt, PetscReal[], PetscReal[]);
  PetscReal (*state_modulus)(PeriModel, PetscInt, PetscInt);
  /* The critical value of the first measure (stretch, shear angle) of this bond for the energy
     release rate G: breaking every bond across a unit crack area releases G. May be NULL. */
  PetscReal (*critical_from_G)(PeriModel, const PeriBondGeometry *, PetscReal);
  /* Values of the rigid-body (zero-energy) modes at a point, nmodes x dofs; returns nmodes. */
  PetscInt (*rigid_modes)(PeriModel, const PetscReal[], PetscReal[][PERI_MAX_DOF]);
  PetscErrorCode (*destroy)(PeriModel); /* frees what data points to; data itself is freed after; may be NULL */
} PeriModelOps;

struct _p_PeriModel {
  char                type[PERI_NAME_LEN];
  PeriModelOps        ops;
  PetscInt            dim;
  PetscBool           plane_strain;
  PetscInt            dofs;
  const char *const  *components; /* dofs names, e.g. "ux", "uy" */
  PetscInt            nmeasures;
  const char *const  *measure_names;
  PetscBool           allows_surface_correction;
  const char *const  *surface_corrections;      /* allowed corrections.surface values; NULL: none, volume */
  PetscBool           inactive[PERI_MAX_DOF];   /* components without stiffness after calibration: held at 0 */
  PetscBool           rotational[PERI_MAX_DOF]; /* rotations: their lumped mass is an inertia rho V r^2 */
  PetscInt            axis[PERI_MAX_DOF];       /* the axis (0, 1, 2) of each translation, -1 for a rotation: the force balance, loads, reactions and outputs read these, never the names */
  PetscBool           central_force;            /* every bond block is k [e e^T, -e e^T; -e e^T, e e^T], k >= 0 (PeriModelSetCentralForce) */
  PetscBool           takes_lattice;            /* the model implements model.calibration: lattice */
  PeriCalibrationKind calibration;              /* set before calibrate */
  char                warning[256];             /* set by calibration; printed once by the problem */
  PeriMaterial        material;
  PetscReal           delta;              /* the horizon; with per-particle horizons, the largest */
  const PetscReal    *horizon;            /* horizon.spacing: own: each particle's of the local view (b->i, b->j index it); else NULL */
  PetscBool           takes_own_horizon;  /* the model calibrates per particle, so it takes per-particle horizons */
  PetscInt            nstates;            /* states per particle of ops.bond_state (set by the model, 1 or more) */
  PetscInt            states_along_bonds; /* the leading states whose weights lie along their bond (the matrix-free operator keeps 2 numbers per bond for each, 2 dofs for the others) */
  void               *data;
  /* what each of the nmeasures bond measures is, in the order of measure_names: the failure
     criteria find theirs by kind (PeriModelMeasureIndex) */
  const PeriMeasureKind *measure_kinds;
};

/* Whether the model's energy couples a particle's whole family (state-based): through a dense
   family block (family_stiffness) or a per-particle state (bond_state). Such a stiffness reaches
   two horizons. */
static inline PetscBool PeriModelHasFamilies(PeriModel m)
{
  return (PetscBool)(m->ops.family_stiffness || m->ops.bond_state);
}

PETSC_EXTERN PetscReal       PeriModelIsotropicEnergy(PeriModel);
PETSC_EXTERN PetscReal       PeriModelHorizonMoment(PeriModel, PetscInt);
PETSC_EXTERN PetscReal       PeriModelHorizonMomentAt(PeriModel, PetscInt, PetscReal);
PETSC_EXTERN PetscReal       PeriModelBondHorizon(PeriModel, const PeriBondGeometry *);
PETSC_EXTERN void            PeriCentralBondBlock(PeriModel, const PeriBondGeometry *, PetscReal, PetscReal[]);
PETSC_EXTERN void            PeriAddSpring(PetscInt, const PetscReal[], PetscReal, PetscReal[]);
PETSC_EXTERN void            PeriPlaneMicromoduli(PeriModel, PetscReal *, PetscReal *);
PETSC_EXTERN void            PeriShearBondNuRange(PeriModel, PetscReal *, PetscReal *);
PETSC_EXTERN PetscReal       PeriCriticalStretchSpring(PeriModel, const PeriBondGeometry *, PetscReal, PetscReal);
PETSC_EXTERN void            PeriBondStretch(PeriModel, const PeriBondGeometry *, const PetscReal[], const PetscReal[], PetscReal[]);
PETSC_EXTERN void            PeriBondBasedNuRange(PeriModel, PetscReal *, PetscReal *);
PETSC_EXTERN void            PeriModelSetCentralForce(PeriModel);
PETSC_EXTERN PetscInt        PeriTranslationalRigidModes(PeriModel, const PetscReal[], PetscReal[][PERI_MAX_DOF]);
PETSC_EXTERN PetscErrorCode  PeriModelComponentIndex(PeriModel, const char[], PetscInt *);
PETSC_EXTERN PetscInt        PeriModelTranslation(PeriModel, PetscInt);
PETSC_EXTERN PetscBool       PeriModelOutOfPlane(PeriModel);
PETSC_EXTERN PetscBool       PeriModelInPlane(PeriModel);
PETSC_EXTERN PetscInt        PeriModelMeasureIndex(PeriModel, PeriMeasureKind);
PETSC_EXTERN PetscErrorCode  PeriLatticeCreate(PeriModel, const PeriCalibrationData *, PetscInt, PetscReal (*)(PeriModel, PetscReal), PeriLattice *);
PETSC_EXTERN PetscReal       PeriLatticeFactor(PeriLattice, const PeriBondGeometry *);
PETSC_EXTERN void            PeriLatticeMultipliers(PeriLattice, const PeriBondGeometry *, PetscReal *, PetscReal *);
PETSC_EXTERN PetscReal       PeriProfileLength(PeriModel, PetscReal);
PETSC_EXTERN PetscReal       PeriProfileOne(PeriModel, PetscReal);
PETSC_EXTERN PetscErrorCode  PeriLatticeDestroy(PeriLattice *);
typedef struct _n_PeriPatch *PeriPatch;
PETSC_EXTERN PetscErrorCode  PeriPatchCreate(PeriModel, const PeriCalibrationData *, PetscReal (*)(PeriModel, PetscReal), const PetscReal[], PetscReal, PeriPatch *);
PETSC_EXTERN PetscReal       PeriPatchCorrection(PeriPatch, const PeriBondGeometry *);
PETSC_EXTERN PetscErrorCode  PeriPatchDestroy(PeriPatch *);

/* A built-in model type. Each model file (models/) ends with its descriptor(s) PeriModel_<id>,
 * whose create function stays static; models/model_list.h names them and src/model_api/model_registry.c registers
 * them. */
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

typedef struct {
  const char       *name;   /* model.type */
  const PeriSchema *schema; /* its model.* keys besides type and plane, ended by {NULL}; NULL: none */
  PetscErrorCode (*create)(PeriModel);
  /* the modes of ops.rigid_modes that vary with position (rotations) store no energy; false when
     they are listed only as AMG's near-null space */
  PetscBool       rotation_invariant;
  PeriExactEnergy exact_energy;
} PeriModelType;
