/* Scene files and option overrides (src/scene/): creation, -help, checks of the options. */
#pragma once

#include <perilin/scene.h>
#include "perilin/private/sys.h"

PETSC_EXTERN PetscErrorCode PeriSceneCreateFromFile(const char[], PetscInt, const PeriSchemaOwner[], PeriScene *);
PETSC_EXTERN PetscErrorCode PeriSceneDestroy(PeriScene *);
PETSC_EXTERN PetscErrorCode PeriSceneHelp(MPI_Comm, PetscInt, const PeriSchemaOwner[]);
PETSC_EXTERN PetscErrorCode PeriSceneDocUpdate(MPI_Comm, const char[], PetscBool, PetscInt, const PeriSchemaOwner[]);

/* The schemas (src/scene/schema.c): the keys declared in a section, the core's (and with plugins
 * the plug-ins' too) in declaration order, NULL-ended; a schema key's dotted path. */
#define PERI_SECTION_MAX_KEYS 64
#define PERI_OPTION_LEN       256 /* the longest option name compared for suggestions */
PETSC_EXTERN PetscErrorCode PeriSceneSectionKeys(PeriScene, const char[], PetscBool, const char *[PERI_SECTION_MAX_KEYS]);
PETSC_EXTERN void           PeriSchemaPath(const PeriSchema *, const PeriKey *, char[], size_t);
PETSC_EXTERN PetscErrorCode PeriSchemaCheck(PetscInt, const PeriSchemaOwner[]);

/* Options that name nothing (src/scene/options.c; docs/scene.md): an option naming no scene key is an
 * error before any computation, and an option nothing read is one after the analysis, both with a
 * "did you mean"; -options_unused_ok makes them warnings. */
PETSC_EXTERN PetscErrorCode PeriSceneOptionIsScene(PeriScene, const char[], PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneOptionNames(PeriScene, char ***);
PETSC_EXTERN PetscErrorCode PeriSceneOptionExplain(PeriScene, const char[], char[], size_t, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriOptionsCheckScene(MPI_Comm, PeriScene);
/* Solver types named by the options, against the registered lists (src/scene/option_types.c). */
PETSC_EXTERN PetscErrorCode PeriOptionsCheckTypes(MPI_Comm);
PETSC_EXTERN PetscErrorCode PeriOptionsCheckOwnBools(MPI_Comm);
PETSC_EXTERN PetscErrorCode PeriOptionsEachValue(const char[], PetscErrorCode (*)(const char[], const char[], void *, char[], size_t), void *, char[], size_t);
/* What the run's solvers were, so that an unread option can be explained against them. */
typedef struct {
  MPI_Comm    comm;
  PeriScene   scene;
  const char *mat_type, *ksp_type, *pc_type;                                    /* "" when the run had none */
  const char *prefix;                                                           /* the options prefix of its linear solves ("st_": an eigensolver's), or NULL */
  PetscErrorCode (*solvers_from_options)(MPI_Comm, const char[], const char[]); /* the analysis' solvers of these types, fresh and set from the options; NULL: a KSP */
} PeriRunSolvers;
PETSC_EXTERN PetscErrorCode PeriOptionsCheckUnused(const PeriRunSolvers *);
PETSC_EXTERN void           PeriSceneSuggest(const char[], const char *const[], char[], size_t);
PETSC_EXTERN void           PeriSuggest(const char[], char *const[], char[], size_t, PetscBool *);
PETSC_EXTERN void           PeriSceneOptionName(const char[], char[], size_t);

/* The tree's nodes (src/scene/tree.c), for the reader and the resolved scene. */
PETSC_EXTERN PetscErrorCode PeriNodeCreate(PeriNodeKind, const char[], const char[], int, PeriNode *);
PETSC_EXTERN PetscErrorCode PeriNodeAppend(PeriNode, PeriNode);
PETSC_EXTERN PetscErrorCode PeriNodeSetItems(PeriNode, const char[], const char[]);
PETSC_EXTERN PetscErrorCode PeriNodeDestroy(PeriNode *);
PETSC_EXTERN PetscErrorCode PeriNodeDuplicate(PeriNode, PeriNode *);
PETSC_EXTERN PetscErrorCode PeriNodeRemovePath(PeriNode, const char[]);

/* The resolved scene (docs/summary.md): the value the run used for map.key (a dotted key; list: a
 * flow list "[0, 0]" of numbers), a path made absolute (src/scene/tree.c), and the scene written
 * back as YAML, the file's tree after the overrides with these merged in, after the comment lines
 * of header (src/scene/resolved.c). */
PETSC_EXTERN PetscErrorCode PeriSceneResolve(PeriScene, PeriNode, const char[], PetscBool, const char[]);
PETSC_EXTERN PetscErrorCode PeriSceneResolvePath(PeriScene, PeriNode, const char[], const char[]);
PETSC_EXTERN PetscErrorCode PeriSceneWriteResolved(PeriScene, const char[], FILE *);
PETSC_EXTERN PetscErrorCode PeriSceneFingerprint(PeriScene, PetscInt64 *);
