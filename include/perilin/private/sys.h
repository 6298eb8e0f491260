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

/* BLAS threads (src/sys/threads.c): one outside factorizations, the library's own around them. */
PETSC_EXTERN PetscErrorCode PeriBLASThreadsInitialize(void);
PETSC_EXTERN PetscErrorCode PeriBLASThreads(PetscBool);
