/* struct _p_PeriProblem: for src/ (problem.c, summary.c, package.c) and the white-box tests. */
#pragma once

#include "perilin.h"
#include "perilin/private/analysis.h"
#include "perilin/private/scene_file.h"
#include "perilin/private/sys.h"

struct _p_PeriProblem {
  MPI_Comm       comm;
  PetscMPIInt    rank, size;
  PeriScene      scene;
  PeriSystem     sys;                          /* the discretized physics: everything but the analysis and the output */
  char           analysis_type[PERI_NAME_LEN]; /* analysis.type */
  PeriAnalysis   analysis;                     /* created and set from the scene by PeriProblemSetUp, before the system; its results are its data */
  PetscInt       output_every;                 /* output.every (quasi-static snapshots) */
  char           output_dir[PETSC_MAX_PATH_LEN];
  char           staging_dir[PETSC_MAX_PATH_LEN]; /* where the outputs are written until the set is committed */
  PetscBool      write_output;                    /* set by the executable: check output.dir before computing */
  PetscBool      vtk;
  PetscBool      stress_output; /* output.stress */
  PetscBool      plots;         /* output.plots: the analysis draws its pictures */
  PetscLogDouble t_start;
};

/* The keys of the root, output, analysis and model read, no particle yet (PeriProblemSetUp's start). */
PETSC_EXTERN PetscErrorCode PeriProblemSetFromScene(PeriProblem);
PETSC_EXTERN PetscErrorCode PeriWriteSummary(PeriProblem, const char[]);
PETSC_EXTERN PetscErrorCode PeriWriteScene(PeriProblem, const char[]);

/* The core modules' schemas, then every built-in model's and analysis' (src/package.c), handed
 * down to the scene layer. */
#define PERI_MAX_SCHEMA_OWNERS 64
PETSC_EXTERN PetscErrorCode   PeriSchemaOwners(PetscInt, PeriSchemaOwner[], PetscInt *);
PETSC_EXTERN const PeriSchema PeriProblemSchema[];
