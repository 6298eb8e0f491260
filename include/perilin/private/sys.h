/* Package life cycle, log events, signals and small utilities (src/sys/). */
#pragma once

#include <perilin/types.h>

PETSC_EXTERN void           PeriListAppend(char[], size_t, const char[]);
PETSC_EXTERN PetscErrorCode PeriFunctionListNames(PetscFunctionList, char[], size_t);

/* signals (src/signals.c) */
PETSC_EXTERN PetscErrorCode PeriSignalsInstall(void);
PETSC_EXTERN PetscErrorCode PeriSignalReceived(MPI_Comm, int *);
PETSC_EXTERN int            PeriSignalPending(void);

/* log events */
PETSC_EXTERN PetscLogEvent  PERI_EVENT_Neighbors, PERI_EVENT_Partition, PERI_EVENT_Assembly, PERI_EVENT_Solve, PERI_EVENT_MatMultFree;
PETSC_EXTERN PetscLogStage  PERI_STAGE_Setup, PERI_STAGE_Assembly, PERI_STAGE_Solve, PERI_STAGE_Output;
PETSC_EXTERN PetscErrorCode PeriInitializePackage(void);
PETSC_EXTERN PetscReal      PeriPeakMemoryMB(void);
PETSC_EXTERN PetscErrorCode PeriMallocInitialize(void);

/* the status line of a long run on a terminal (src/sys/progress.c): its slots, left to right */
typedef enum {
  PERI_PROGRESS_ANALYSIS, /* e.g. the quasi-static step and load factor */
  PERI_PROGRESS_PHASE,    /* setup, assembly, solve, eigensolve, output */
  PERI_PROGRESS_SOLVER,   /* KSP iteration and residual, converged eigenpairs */
  PERI_PROGRESS_SLOTS
} PeriProgressSlot;
typedef struct _p_PeriProgress *PeriProgress;
PETSC_EXTERN PetscErrorCode     PeriProgressCreate(MPI_Comm, PeriProgress *);
PETSC_EXTERN PetscErrorCode     PeriProgressUpdate(PeriProgress, PeriProgressSlot, const char[], ...);
PETSC_EXTERN PetscBool          PeriProgressActive(PeriProgress);
PETSC_EXTERN PetscErrorCode     PeriProgressDestroy(PeriProgress *);

/* BLAS threads (src/sys/threads.c): one outside factorizations, the library's own around them. */
PETSC_EXTERN PetscErrorCode PeriBLASThreadsInitialize(void);
PETSC_EXTERN PetscErrorCode PeriBLASThreads(PetscBool);
