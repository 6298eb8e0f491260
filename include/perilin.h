/* perilin: implicit static and modal peridynamics on PETSc. The public API: what the executable
 * (src/main.c) and a program embedding perilin need.
 *
 * One run (see docs/design.md):
 *   PeriInitialize -> PeriProblemCreate -> PeriProblemLoad (scene file + options)
 *   -> PeriProblemSetUp (particles, bonds, model, conditions) -> PeriProblemRun (the analysis)
 *   -> PeriProblemWriteOutput -> PeriProblemReport -> PeriProblemDestroy -> PeriFinalize.
 * Model authors use include/perilin/model.h; in-tree modules and white-box tests use
 * include/perilin/private/. */
#pragma once

#include <petscmat.h>

#if PETSC_VERSION_LT(3, 19, 0)
#  define PETSC_SUCCESS 0
#endif

typedef struct _p_PeriProblem *PeriProblem;

/* SLEPc (which starts PETSc) once per process, the signal handlers and the registries. */
PETSC_EXTERN PetscErrorCode PeriInitialize(int *, char ***, const char[]);
PETSC_EXTERN PetscErrorCode PeriFinalize(void);
/* The usage, perilin's own options and every scene key with its meaning (perilin -help). */
PETSC_EXTERN PetscErrorCode PeriPrintHelp(MPI_Comm);
/* perilin's version as built, PETSc's and SLEPc's (perilin -version, summary.json's "build"). */
#define PERI_VERSION_LEN 128
PETSC_EXTERN PetscErrorCode PeriGetVersions(char[], char[], char[], size_t);
PETSC_EXTERN PetscErrorCode PeriPrintVersion(MPI_Comm);
PETSC_EXTERN PetscErrorCode PeriSceneDoc(MPI_Comm, const char[], PetscBool);

PETSC_EXTERN PetscErrorCode PeriProblemCreate(MPI_Comm, PeriProblem *);
/* Reads the scene file and applies the option overrides (-material_nu 0.3). */
PETSC_EXTERN PetscErrorCode PeriProblemLoad(PeriProblem, const char[]);
/* The executable writes an output set: its directory is checked before any computation. */
PETSC_EXTERN PetscErrorCode PeriProblemSetWriteOutput(PeriProblem, PetscBool);
/* An option that names no scene key is an error (before the set-up); so is one nothing read
 * (after the run); -options_unused_ok makes both warnings. */
PETSC_EXTERN PetscErrorCode PeriProblemCheckOptions(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemCheckUnusedOptions(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemSetUp(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemRun(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriProblemWriteOutput(PeriProblem);
/* The lines on stdout: what ran, what it cost, the main results. */
PETSC_EXTERN PetscErrorCode PeriProblemReport(PeriProblem);
/* The signal (SIGINT, SIGTERM) that stopped the run early, or 0: the result is incomplete. */
PETSC_EXTERN PetscErrorCode PeriProblemInterrupted(PeriProblem, int *);
PETSC_EXTERN PetscErrorCode PeriProblemDestroy(PeriProblem *);

/* The first error's message as perilin states it (src/package.c): PeriErrorCapture is the error
 * handler that keeps it. */
PETSC_EXTERN PetscErrorCode PeriErrorCapture(MPI_Comm, int, const char *, const char *, PetscErrorCode, PetscErrorType, const char *, void *);
PETSC_EXTERN const char    *PeriErrorFirst(void);
PETSC_EXTERN void           PeriErrorReset(void);

/* Embedding (src/embed.c): perilin in another program's PETSc session, as the Python module
 * (python/perilin_ext.c, docs/python.md) runs it. */
PETSC_EXTERN PetscErrorCode PeriInitializeEmbedded(void);
PETSC_EXTERN PetscErrorCode PeriProblemLoadOverrides(PeriProblem, const char[], PetscInt, const char *const[], const char *const[]);
PETSC_EXTERN PetscErrorCode PeriProblemSetOutputDir(PeriProblem, const char[]);
PETSC_EXTERN PetscErrorCode PeriProblemGetStiffness(PeriProblem, Mat *);
PETSC_EXTERN PetscErrorCode PeriProblemGetLoads(PeriProblem, Vec *);
PETSC_EXTERN PetscErrorCode PeriProblemGetMass(PeriProblem, Vec *);
PETSC_EXTERN PetscErrorCode PeriProblemGetSolution(PeriProblem, Vec *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriProblemGetConstraints(PeriProblem, PetscInt *, const PetscInt *[], const PetscReal *[]);
PETSC_EXTERN PetscErrorCode PeriProblemGetLayout(PeriProblem, PetscInt *, PetscInt *, const char *const **, PetscInt *, PetscInt *, PetscInt *, const PetscReal *[]);
PETSC_EXTERN PetscErrorCode PeriProblemGetSummary(PeriProblem, char **);
PETSC_EXTERN PetscErrorCode PeriProblemGetScene(PeriProblem, char **);
/* q set up on p's particles and bonds where the changed keys leave them (set() without
 * rebuilding, docs/python.md); *reused says whether it did; p is then to be destroyed. */
PETSC_EXTERN PetscErrorCode PeriProblemSetUpFrom(PeriProblem, PeriProblem, PetscInt, const char *const[], PetscBool *);
PETSC_EXTERN PetscErrorCode PeriProblemGetBonds(PeriProblem, const void **, PetscInt *);
/* The body's K as a MATSHELL applied bond by bond (the matrix-free operator, no conditions). */
PETSC_EXTERN PetscErrorCode PeriProblemGetOperator(PeriProblem, Mat *);
/* A modal run's modes: their count and the shapes kept, then mode k's frequency (Hz), relative
 * residual, kind and this rank's part of its shape (max |u| = 1). */
PETSC_EXTERN PetscErrorCode PeriProblemGetModes(PeriProblem, PetscInt *, PetscInt *);
PETSC_EXTERN PetscErrorCode PeriProblemGetMode(PeriProblem, PetscInt, PetscReal *, PetscReal *, const char **, const PetscReal **);
/* The analysis' table of rows (steps.csv, history.csv): its file name and CSV text on every rank. */
PETSC_EXTERN PetscErrorCode PeriProblemGetTable(PeriProblem, const char **, char **);
