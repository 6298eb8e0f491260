/* Analyses (src/analysis/): the registry and the analyses' results. */
#pragma once

#include "perilin/private/system.h"

typedef struct _p_PeriAnalysis *PeriAnalysis;
/* Writes the system's present state as NAME (a .vtu) into the output set: installed by the
 * problem, which owns the set, so that an analysis can write a series while it runs. */
typedef PetscErrorCode (*PeriSnapshotFn)(void *ctx, const char base[]); /* base.vtu, or base.pvtu on several ranks */

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

/* One load step of the quasi-static analysis. */
typedef struct {
  PetscReal lambda, control_u, seconds;
  PetscInt  broken, broken_total, iterations, ksp_iterations;
  PetscReal reaction, imbalance; /* the reaction region's force along the control component; the relative imbalance */
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
  char       stepping[16];                       /* increments | events */
  PetscInt   control_component, reaction_region; /* the model's component; index of disc.regions, or -1 */
  PetscReal *reactions;                          /* per step, every region's reaction: nregions x PERI_MAX_DOF */
} PeriQuasistatic;

/* An analysis type (src/analysis/<name>.c): what it does with the system, and what it adds to
 * the output. Each analysis file ends with its descriptor PeriAnalysis_<Id>; src/analysis/list.h
 * names them (one line each) and src/analysis/registry.c registers them. The output code calls
 * the ops and has no branch per analysis. Until the analyses take a PeriSystem only (docs/design.md,
 * "What is left"), the ops receive the problem; their results live in the problem's `modal` or
 * `quasistatic` member, freed by ops.destroy. */
typedef struct {
  PetscErrorCode (*run)(PeriAnalysis);
  PetscErrorCode (*fields)(PeriAnalysis, PeriFieldList); /* its arrays in particles.vtu, or NULL */
  PetscErrorCode (*files)(PeriAnalysis, const char[]);   /* its files in the output set (the directory), or NULL */
  PetscErrorCode (*summary)(PeriAnalysis, PeriJSON);     /* its object in summary.json, or NULL */
  PetscErrorCode (*report)(PeriAnalysis);                /* its result line on stdout, or NULL: the strain energy */
  PetscErrorCode (*destroy)(PeriAnalysis);               /* frees what data points to (data itself is freed after), or NULL */
} PeriAnalysisOps;

typedef struct {
  const char       *name;        /* analysis.type */
  const char       *help;        /* one line, for -help and the "unknown analysis" message */
  const PeriSchema *schema;      /* its analysis.* keys besides type, ended by {NULL}; NULL: none */
  PetscBool         eigensolver; /* its linear solves are an eigensolver's (options -st_ksp_type ...) */
  PeriAnalysisOps   ops;
} PeriAnalysisType;
/* One analysis of one problem: its type, the system it works on (borrowed), what the output
 * asks of it, and its own data (PeriModal, PeriQuasistatic, ...), private to its file and its
 * tests. */
struct _p_PeriAnalysis {
  const PeriAnalysisType *type;
  MPI_Comm                comm;
  PetscMPIInt             rank;
  PeriSystem              sys;
  PetscBool               vtk;        /* output.vtk: fields are written */
  PetscInt                every;      /* output.every: snapshots every k steps (0: none) */
  const char             *output_dir; /* for messages only */
  PeriSnapshotFn          snapshot;   /* writes the present state into the output set */
  void                   *snapshotctx;
  void                   *data;
};
PETSC_EXTERN PetscErrorCode PeriAnalysisCreate(const PeriAnalysisType *, PeriSystem, PeriAnalysis *);
PETSC_EXTERN PetscErrorCode PeriAnalysisDestroy(PeriAnalysis *);
PETSC_EXTERN PetscErrorCode PeriAnalysisRegisterAll(void);
PETSC_EXTERN PetscErrorCode PeriAnalysisFind(const char[], const PeriAnalysisType **);
PETSC_EXTERN PetscErrorCode PeriAnalysisListTypes(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriAnalysisGetTypes(PetscInt *, const PeriAnalysisType *const **);
