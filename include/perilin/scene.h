/* Reading a scene section: the YAML tree with line numbers, typed getters that check and locate
 * errors (file, line, key). For in-tree modules and model authors (a model reads model.*). */
#pragma once

#include <perilin/types.h>

typedef enum {
  PERI_NODE_MAP,
  PERI_NODE_SEQ,
  PERI_NODE_SCALAR
} PeriNodeKind;

typedef struct _PeriNode *PeriNode;
struct _PeriNode {
  PeriNodeKind kind;
  char        *key;   /* key in the parent mapping, or the index for sequence items */
  char        *path;  /* dotted path from the root, e.g. "material.nu", "bc.0.region" */
  char        *value; /* scalars only */
  int          line;  /* 1-based line in the scene file; 0 when set from the options database */
  PetscInt     n;
  PeriNode    *child;
};

/* A scene key, declared once next to the code that reads it: validation, -help, the key tables of
 * docs/scene.md and the options that add a missing key all come from the declaration. */
typedef enum {
  PERI_KEY_REAL,
  PERI_KEY_INT,
  PERI_KEY_BOOL,
  PERI_KEY_STRING,
  PERI_KEY_CHOICE,
  PERI_KEY_REALS,
  PERI_KEY_BOOLS,
  PERI_KEY_MAP,
  PERI_KEY_LIST
} PeriKeyType;
typedef struct {
  const char        *name; /* "k_theta"; {NULL} ends a list */
  PeriKeyType        type;
  const char        *deflt;   /* "1", "required", or NULL: absent means not given */
  const char        *range;   /* "[0, inf)", "(0, 1]" or NULL; printed verbatim */
  const char        *units;   /* "[stress]" or NULL */
  const char *const *choices; /* PERI_KEY_CHOICE: NULL-terminated; else NULL */
  const char        *help;    /* one line */
} PeriKey;
/* The keys one owner declares in one section: "model", "bc.<k>" (each item of the list bc),
 * "regions.<name>" (each entry of the mapping regions), "" for the root keys. A schema is an array
 * of these ended by {NULL}, so that an owner may declare keys in several sections. */
typedef struct _PeriSchema {
  const char    *section;
  const PeriKey *keys;
} PeriSchema;
/* An owner of keys and its schema, as the core hands them to the scene layer: kind "core" (name
 * its module, "system"), "model" or "analysis" (name its type, "mppd"); schema NULL when it
 * declares no key. */
typedef struct {
  const char       *kind, *name;
  const PeriSchema *schema;
} PeriSchemaOwner;

typedef struct _p_PeriScene *PeriScene;
struct _p_PeriScene {
  char                   file[PETSC_MAX_PATH_LEN];
  char                   dir[PETSC_MAX_PATH_LEN]; /* directory of the scene file, for relative paths */
  PeriNode               root;
  PetscInt               nowners;
  const PeriSchemaOwner *owners; /* the core's schemas, then every plug-in's */
};

PETSC_EXTERN PetscErrorCode PeriSceneWhere(PeriScene, PeriNode, const char[], char[], size_t);
PETSC_EXTERN PetscErrorCode PeriSceneGetNode(PeriNode, const char[], PeriNode *);
PETSC_EXTERN PetscErrorCode PeriSceneGetMap(PeriScene, PeriNode, const char[], PetscBool, PeriNode *);
PETSC_EXTERN PetscErrorCode PeriSceneCheckKeys(PeriScene, PeriNode, const char *const[]);
PETSC_EXTERN PetscErrorCode PeriSceneCheckSection(PeriScene, PeriNode, const char[]);
PETSC_EXTERN PetscErrorCode PeriSceneCheckKeysSchema(PeriScene, PeriNode, const char[], const PeriSchemaOwner *);
PETSC_EXTERN const PeriKey *PeriSchemaFindKey(const PeriSchema *, const char[], const char[]);
PETSC_EXTERN PetscErrorCode PeriSceneGetReal(PeriScene, PeriNode, const char[], PetscBool, PetscReal *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetInt(PeriScene, PeriNode, const char[], PetscBool, PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetBool(PeriScene, PeriNode, const char[], PetscBool *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetString(PeriScene, PeriNode, const char[], PetscBool, char[], size_t, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetChoice(PeriScene, PeriNode, const char[], const char *const[], PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetRealArray(PeriScene, PeriNode, const char[], PetscBool, PetscInt, PetscInt, PetscReal[], PetscInt *);
PETSC_EXTERN PetscErrorCode PeriSceneParseReal(PeriScene, PeriNode, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriSceneParseBool(PeriScene, PeriNode, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneParseRealArray(PeriScene, PeriNode, PetscInt, PetscInt, PetscReal[], PetscInt *);

/* A user-input error that names the file, the line and the key. */
#define PeriInputCheck(cond, scene, node, key, fmt, ...)                                      \
  do {                                                                                        \
    if (PetscUnlikely(!(cond))) {                                                             \
      char peri_where_[2 * PETSC_MAX_PATH_LEN];                                               \
      PetscCall(PeriSceneWhere((scene), (node), (key), peri_where_, sizeof(peri_where_)));    \
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: " fmt, peri_where_, ##__VA_ARGS__); \
    }                                                                                         \
  } while (0)
