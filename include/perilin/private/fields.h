/* The fields of the system's present state (src/system/fields.c, stress.c): the displacements and
 * loads, what is derived from them after a solve (energy density, stress, strain, shear stresses,
 * probes), and how the last linear solve reached them. */
#pragma once

#include <petscvec.h>
#include "perilin/private/disc.h"
#include "perilin/private/output.h"

typedef struct _p_PeriSystem *PeriSystem;

typedef struct {
  char        name[PERI_NAME_LEN];
  PetscReal   x[3];
  PetscMPIInt rank;          /* the rank owning the nearest particle */
  PetscInt    particle;      /* its local index on that rank (-1 on the others) */
  PetscReal   particle_x[3]; /* its position */
  PetscBool   snapped;       /* x lies outside that particle's cell, within its horizon */
  PetscReal   distance;      /* |x - particle_x| */
  /* after a solve, on every rank: */
  PetscReal u[PERI_MAX_DOF];
  PetscReal W;
  PetscReal sigma[9], epsilon[9], sigma_elastic[9]; /* output.stress */
} PeriProbe;

/* The last linear solve: what solved it, how well, and the rigid motions it left free. */
typedef struct {
  char      ksp_type[64], pc_type[64], converged_reason[64]; /* "" until a solve ran */
  PetscInt  iterations;
  PetscReal setup_s, ksp_solve_s; /* of the last PeriStaticSolve: the KSP's (and PC's) set-up, then KSPSolve */
  PetscReal residual_norm;        /* true relative residual of the last solve */
  PetscReal residual_tol;         /* the largest accepted (solver.residual_tol or its default) */
  PetscBool symmetric;            /* the operator solved was symmetric */
  PetscInt  free_modes;           /* rigid motions left free with balanced loads: solved orthogonal to them */
  PetscReal load_imbalance;       /* share of the load along those motions, removed */
  PetscReal rhs_norm;             /* ||b|| of the last solve in the scene's units (the residual's scale) */
  PetscReal load_factor;          /* the load factor it was solved at */
  char      checked[48];          /* what the status line reports instead of residual_norm when the run solved no static system (modal: the worst mode residual; dynamic: the energy drift), "" otherwise */
  PetscReal checked_value;
} PeriSolveInfo;

/* The present state and what is derived from it. */
typedef struct {
  Vec           u, f;                    /* the displacements (every DOF, global layout) and the reference loads */
  PetscReal    *u_owned;                 /* the same state's DOFs of the owned particles: this rank's piece of the output */
  PetscReal    *v_owned;                 /* their velocities (transient analyses: PeriSystemKeepVelocity), else NULL */
  PetscBool     has_solution;            /* the fields below describe a solution */
  PetscReal    *W;                       /* strain energy density per owned particle, after the solve */
  PetscReal    *tau;                     /* antiplane models, per owned particle: tau_xz, tau_yz, |tau| after the solve */
  PetscReal    *stress;                  /* vector models, per owned particle: the bond-force stress, 3 x 3 row-major (stress.c) */
  PetscReal    *strain;                  /* vector models, per owned particle: the least-squares strain, 3 x 3 row-major */
  PetscReal    *elastic_stress;          /* vector models, per owned particle: C : strain of the target elasticity */
  PetscBool     stress_output;           /* output.stress: evaluate the three above after each solve */
  PetscReal     strain_energy;           /* after the last solve */
  PetscReal     max_abs_u[PERI_MAX_DOF]; /* per component, after the last solve */
  PetscInt      nprobes;
  PeriProbe    *probes;
  PeriSolveInfo solve; /* the solve that reached the state */
} PeriFields;

PETSC_EXTERN PetscErrorCode PeriSystemEvaluateEnergy(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemKeepVelocity(PeriSystem, Vec);
PETSC_EXTERN PetscErrorCode PeriSystemLocalDOFs(PeriSystem, Vec, PetscScalar **);
PETSC_EXTERN PetscErrorCode PeriSystemFindProbe(PeriSystem, const char[], PeriProbe **);
PETSC_EXTERN PetscErrorCode PeriReadProbes(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemEvaluateStress(PeriSystem, const PetscScalar[]);
PETSC_EXTERN PetscErrorCode PeriSystemAddFields(PeriSystem, PeriFieldList);
PETSC_EXTERN PetscErrorCode PeriSystemFieldListCreate(PeriSystem, PeriFieldList *);
PETSC_EXTERN PetscErrorCode PeriSystemWriteParticles(PeriSystem, const PetscReal *, const char[], const char[]);
PETSC_EXTERN PetscErrorCode PeriSystemReadDOFs(PeriSystem, const char[], const char[], PetscReal, Vec);
PETSC_EXTERN PetscErrorCode PeriProbesSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriSystemSummaryFields(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode PeriFieldsDestroy(PeriFields *);
