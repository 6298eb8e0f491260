/* Writers (src/output/): streaming JSON, files written under a temporary name then committed,
 * the output set. They know nothing of perilin's physics. */
#pragma once

#include <perilin/types.h>

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
/* Per-particle fields for a .vtu file: referenced arrays, named, written by PeriWriteVTU. */
typedef struct _p_PeriFieldList *PeriFieldList;
PETSC_EXTERN PetscErrorCode      PeriFieldListCreate(PetscInt, const PetscReal[], PeriFieldList *);
PETSC_EXTERN PetscErrorCode      PeriFieldListAddReal(PeriFieldList, const char[], PetscInt, const PetscReal *, PetscInt, const PetscInt[]);
PETSC_EXTERN PetscErrorCode      PeriFieldListAddInt(PeriFieldList, const char[], const PetscInt *);
PETSC_EXTERN PetscErrorCode      PeriFieldListAddFlags(PeriFieldList, const char[], PetscInt, const unsigned char *, const char *const[]);
PETSC_EXTERN PetscErrorCode      PeriFieldListAddIntConstant(PeriFieldList, const char[], PetscInt);
PETSC_EXTERN PetscErrorCode      PeriFieldListAddSolution(PeriFieldList, const char[], PetscInt, const char *const[], const PetscInt[], const PetscReal *);
PETSC_EXTERN PetscErrorCode      PeriFieldListDestroy(PeriFieldList *);
PETSC_EXTERN PetscErrorCode      PeriWriteVTU(PeriFieldList, const char[]);
PETSC_EXTERN PetscErrorCode      PeriWriteParticles(MPI_Comm, PeriFieldList, const char[], const char[]);
PETSC_EXTERN PetscErrorCode      PeriParticlesFileName(MPI_Comm, const char[], char[], size_t);
PETSC_EXTERN PetscErrorCode      PeriWritePVD(const char[], PetscInt, const PetscReal[], const char *const[]);
/* What PeriReadParticles reads back from a .vtu or .pvtu perilin wrote: the points and the
   Float64 point arrays (src/output/vturead.c). */
#define PERI_VTU_MAX_ARRAYS 32
typedef struct {
  PetscInt   n;      /* points */
  PetscReal *points; /* n x 3 */
  PetscInt   narrays;
  char       names[PERI_VTU_MAX_ARRAYS][PERI_NAME_LEN];
  PetscInt   ncomp[PERI_VTU_MAX_ARRAYS];
  PetscReal *data[PERI_VTU_MAX_ARRAYS]; /* n x ncomp */
} PeriVTUData;
PETSC_EXTERN PetscErrorCode PeriReadParticles(const char[], PeriVTUData *);
PETSC_EXTERN PetscInt       PeriVTUDataFind(const PeriVTUData *, const char[]);
PETSC_EXTERN PetscErrorCode PeriVTUDataDestroy(PeriVTUData *);
PETSC_EXTERN PetscErrorCode PeriOutputDirCreate(const char[]);
PETSC_EXTERN PetscErrorCode PeriFileCommit(const char[], const char[]);
PETSC_EXTERN PetscBool      PeriFileSystemFull(const char[]);
PETSC_EXTERN PetscErrorCode PeriFileOpenTemporary(const char[], char[], size_t, FILE **);
PETSC_EXTERN PetscErrorCode PeriFileCloseCommit(FILE *, const char[], const char[], int);
PETSC_EXTERN PetscErrorCode PeriOutputSetOpen(MPI_Comm, char[], size_t, char[], size_t);
PETSC_EXTERN PetscErrorCode PeriOutputSetCommit(MPI_Comm, const char[], const char[]);
PETSC_EXTERN void           PeriOutputSetDiscard(void);
PETSC_EXTERN void           PeriOutputSetKeep(void);
PETSC_EXTERN PetscBool      PeriOutputSetKeepCheckpoint(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriOutputSetAddNames(const char *const[]);
PETSC_EXTERN PetscErrorCode PeriOutputSetAdopt(MPI_Comm, const char[], const char[], const char[], PetscBool *);
PETSC_EXTERN int            PeriOutputRemoveTree(const char[]);
/* The pictures of one run (src/output/plots.c): asked for (output.plots), drawn, or why not. */
typedef struct {
  PetscBool enabled;
  char      kind[32];   /* set when the analysis draws pictures: summary.json then has "plots" */
  char      files[256]; /* the PNG files written, separated by spaces */
  char      error[512]; /* why none was written */
} PeriPlots;
PETSC_EXTERN PetscErrorCode PeriPlotsDraw(MPI_Comm, const char[], const char[], const char *const[], PeriPlots *);
PETSC_EXTERN PetscErrorCode PeriPlotsSummary(const PeriPlots *, PeriJSON);
