/* Analyses (src/analysis/): the registry and the analyses' results. */
#pragma once

#include "perilin/private/system.h"

typedef struct _p_PeriAnalysis *PeriAnalysis;
/* Writes the system's present state as NAME (a .vtu) into the output set: installed by the
 * problem, which owns the set, so that an analysis can write a series while it runs. */
typedef PetscErrorCode (*PeriSnapshotFn)(void *ctx, const char base[]); /* base.vtu, or base.pvtu on several ranks */
/* The output set's directory, opened if the run has not opened it yet (installed with the snapshot
 * callback, same ctx): where an analysis writes its checkpoints. */
typedef PetscErrorCode (*PeriOutputDirFn)(void *ctx, const char **dir);

#define PERI_MAX_VTU_MODES 12

/* One natural mode: frequency, accuracy, and what moves. */
typedef struct {
  PetscReal f_hz, omega2, residual;
  PetscReal energy_share[PERI_MAX_DOF]; /* kinetic energy share per component */
  PetscReal effective_mass[3];          /* per direction, as a fraction of the total mass */
  char      kind[32];
} PeriMode;

typedef struct {
  PetscInt   nev;     /* analysis.nev */
  PetscBool  started; /* the solve began: the outputs have a modal part */
  PetscInt   nmodes, nrigid, nfree_dofs;
  PeriMode  *modes;
  PetscReal  total_mass, target_hz;
  PetscReal  longitudinal_speed, theory_speed; /* free bars only; 0 otherwise */
  PetscInt   axis;                             /* the structure's main axis */
  PetscReal *shapes;                           /* rank 0: min(nmodes, PERI_MAX_VTU_MODES) x n x dofs, each scaled to max |u| = 1 */
  PetscInt   nshapes;
  PetscReal  factor_s, solve_s;
  PetscInt   eigensolver; /* analysis.eigensolver: as read (0 auto), then as run */
  PetscBool  free_body;   /* constraints leave rigid-body motions free: K_ff is singular */
  PetscReal  shift;       /* LOBPCG on a free body solves (K + shift M) x = (omega^2 + shift) M x (0 otherwise) */
} PeriModal;

/* One load step of the quasi-static analysis. */
typedef struct {
  PetscReal lambda, control_u, seconds;                       /* seconds: since the step before, every attempt of the step */
  PetscInt  broken, broken_total, iterations, ksp_iterations; /* broken: at this step (dead bonds), not counting softening */
  PetscInt  attempts;                                         /* the trials of the step: 1, more when a smaller increment was retried */
  PetscInt  softened;                                         /* bonds softened (alive, less than their whole stiffness) at this equilibrium */
  PetscReal reaction, imbalance;                              /* the reaction region's force along the control component; the relative imbalance */
} PeriStep;

typedef struct {
  PetscBool  started; /* the loop began: the outputs have a quasi-static part */
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
  PetscInt   checkpoints, restart_step;          /* checkpoints written; the step -restart continued from (0: none) */
  PetscReal  checkpoint_s;                       /* the time spent writing them */
  PetscReal  unfinished_s;                       /* the time after the last equilibrium: the attempts of a step that reached none */
  PetscInt   unfinished_attempts;                /* and their number (a failure's bracketing, an interrupted step) */
} PeriQuasistatic;

/* An analysis type (src/analysis/<name>.c): what it does with the system, and what it adds to
 * the output. Each analysis file ends with its descriptor PeriAnalysis_<Id>, written with
 * designated initializers (an op it does not need is left out, and a new op edits no analysis);
 * src/analysis/analysis_list.h names them (one line each) and src/analysis/analysis_registry.c registers them. The
 * problem calls the ops in PETSc's life cycle and has no branch per analysis:
 *   setfromscene  reads and checks every analysis.* key, before any particle exists (the scene and
 *                 the options only; no system yet); allocates the analysis' data
 *   setup         after the system's set-up: checks that need it (probes, regions, components)
 *   run           the analysis; its results are its data
 *   fields, files, summary, report   what the output set and stdout show of it
 *   destroy       frees what data points to (data itself is freed after)
 * Every op may be NULL. */
typedef struct {
  PetscErrorCode (*setfromscene)(PeriAnalysis, PeriScene, PeriNode); /* the analysis section, or NULL when the scene has none */
  PetscErrorCode (*setup)(PeriAnalysis);
  PetscErrorCode (*run)(PeriAnalysis);
  PetscErrorCode (*fields)(PeriAnalysis, PeriFieldList);                        /* its arrays in particles.vtu */
  PetscErrorCode (*files)(PeriAnalysis, const char[]);                          /* its files in the output set (the directory) */
  PetscErrorCode (*summary)(PeriAnalysis, PeriJSON);                            /* its object in summary.json */
  PetscErrorCode (*report)(PeriAnalysis);                                       /* its result line on stdout; NULL: the strain energy */
  PetscErrorCode (*table)(PeriAnalysis, FILE *);                                /* its rows (PeriAnalysisType.table) as CSV text, header first, on rank 0; for the embedding, which hands them to Python */
  PetscErrorCode (*solvers_from_options)(MPI_Comm, const char[], const char[]); /* fresh solvers of the kinds it used (ksp and pc types, "" for the default) set from the options, for the unused-option check; NULL: a static KSP */
  PetscErrorCode (*destroy)(PeriAnalysis);
} PeriAnalysisOps;

typedef struct {
  const char        *name;          /* analysis.type */
  const char        *help;          /* one line, for -help and the "unknown analysis" message */
  const PeriSchema  *schema;        /* its analysis.* keys besides type, ended by {NULL}; NULL: none */
  const char        *option_prefix; /* of its linear solvers' options ("st_" for an eigensolver's), NULL: none */
  const char *const *files;         /* the names of its files in the output set, NULL-terminated ('#': digits), or NULL */
  const char        *table;         /* the file of its one table of rows (steps.csv, history.csv) that ops.table writes, or NULL */
  PeriSystemNeeds    needs;         /* what it asks of the system: K's kind and memory */
  PetscBool          checkpoints;   /* it writes checkpoints at its equilibria and continues from one (-restart; src/analysis/checkpoint.c) */
  PeriAnalysisOps    ops;
} PeriAnalysisType;
/* One analysis of one problem: its type, the system it works on (borrowed, from PeriAnalysisSetUp
 * on), what the output asks of it, and its own data (PeriModal, PeriQuasistatic, ...), private to
 * its file and its tests. */
struct _p_PeriAnalysis {
  const PeriAnalysisType *type;
  PeriSystemNeeds         needs; /* its type's, refined by its scene (ops.setfromscene): what the system is set up for */
  MPI_Comm                comm;
  PetscMPIInt             rank;
  PeriSystem              sys;
  PetscBool               vtk;        /* output.vtk: fields are written */
  PetscInt                every;      /* output.every: snapshots every k steps (0: none) */
  PeriPlots               plots;      /* output.plots, and the pictures its files op drew (PeriPlotsDraw) */
  const char             *output_dir; /* for messages only */
  PeriSnapshotFn          snapshot;   /* writes the present state into the output set */
  PeriOutputDirFn         outputdir;  /* the output set's directory (ctx: snapshotctx) */
  void                   *snapshotctx;
  /* a type with checkpoints (src/analysis/checkpoint.c): -restart DIR, -peri_checkpoint_every N */
  char       restart[PETSC_MAX_PATH_LEN]; /* continue from DIR/checkpoint ("": from the start) */
  PetscInt   checkpoint_every;            /* a checkpoint every this many equilibria (0: none) */
  PetscInt64 fingerprint;                 /* of the scene as the run began (PeriSceneFingerprint) */
  void      *data;
};
/* TSALPHA2's period error on one mode (src/analysis/period_error.c) */
PETSC_EXTERN PetscReal      PeriAlpha2PeriodError(PetscReal, PetscReal);
PETSC_EXTERN PetscReal      PeriAlpha2ResolvedFrequency(PetscReal, PetscReal, PetscReal);
PETSC_EXTERN PetscErrorCode PeriAnalysisCreate(MPI_Comm, const PeriAnalysisType *, PeriAnalysis *);
PETSC_EXTERN PetscErrorCode PeriAnalysisSetFromScene(PeriAnalysis, PeriScene);
PETSC_EXTERN PetscErrorCode PeriAnalysisSetUp(PeriAnalysis, PeriSystem);
PETSC_EXTERN PetscErrorCode PeriAnalysisRun(PeriAnalysis);
PETSC_EXTERN PetscErrorCode PeriAnalysisDestroy(PeriAnalysis *);
PETSC_EXTERN PetscErrorCode PeriAnalysisWriteTable(PeriAnalysis, PetscBool, int (*)(PeriAnalysis, FILE *), const char[], FILE *);
PETSC_EXTERN PetscErrorCode PeriAnalysisCheckpointSetFromOptions(PeriAnalysis);
PETSC_EXTERN PetscErrorCode PeriAnalysisCheckpointWrite(PeriAnalysis, PetscErrorCode (*)(PeriAnalysis, PetscViewer, void *), void *);
PETSC_EXTERN PetscErrorCode PeriAnalysisRestartBegin(PeriAnalysis, PetscViewer *, char[], size_t);
PETSC_EXTERN PetscErrorCode PeriAnalysisRestartEnd(PeriAnalysis, PetscViewer *, const char[], PetscErrorCode);
PETSC_EXTERN PetscErrorCode PeriAnalysisCheckpointFits(PeriAnalysis, PetscViewer, PetscInt, size_t);
PETSC_EXTERN PetscErrorCode PeriAnalysisCheckpointFinite(PeriAnalysis, const PetscReal[], PetscInt, Vec, const char[]);
PETSC_EXTERN PetscErrorCode PeriAnalysisAdoptSnapshots(PeriAnalysis, PetscInt *, PetscInt[], PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriAnalysisRegisterAll(void);
PETSC_EXTERN PetscErrorCode PeriAnalysisGetModes(PeriAnalysis, PetscInt *, const PeriMode **, PetscInt *, const PetscReal **);
/* perilin's LOBPCG as a SLEPc eigensolver type (src/analysis/lobpcg.c) */
#define PERI_EPSLOBPCG "perilin_lobpcg"
PETSC_EXTERN PetscErrorCode PeriEPSRegisterLOBPCG(void);
PETSC_EXTERN PetscErrorCode PeriAnalysisFind(const char[], const PeriAnalysisType **);
PETSC_EXTERN PetscErrorCode PeriAnalysisListTypes(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriAnalysisGetTypes(PetscInt *, const PeriAnalysisType *const **);
