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
/* The typed getters apply the declaration of the key they read (PeriSceneFindKey finds it by the
 * section of the map, "bc.0" matching "bc.<k>"; in a section several plug-ins share, the core's,
 * else the active plug-in's, the one its kind's type key names, "model.type", else the first):
 *  - absent, the key takes its default when the default parses whole for the key's type: a
 *    number or a fraction a/b (number), a whole number, true or false, one of the choices, a
 *    single word of letters, digits and _-./ (string), a flow list "[0, 0]" (list of numbers).
 *    Any other default (NULL, "required", "required for a .geo", "material.E",
 *    "load_factor_step/64", "<scene file name ...>-out", "all false") is documentation only: the
 *    reader computes it and the getter leaves the variable alone. found still says "given";
 *  - present, a numeric value (each entry of a list) must lie in the range, whose forms are
 *    "[a, b]", "(a, b]", ... with ends numbers, fractions or inf, and "{a, b, ..}"; an end that
 *    names another key of the section, maybe scaled ("(0, load_factor_max]",
 *    "[load_factor_step/2^20, ..]"), is the reader's to check. A declared range of any other form,
 *    or an applying default outside its range, is refused at start-up (PeriSchemaCheck);
 *  - a getter of another type than the declaration's is an internal error (the string getter
 *    reads choices too).
 * A NULL map (an absent section) has no section: read such keys from the parent with a dotted key
 * ("output.dir" from the root) to get their defaults. */
typedef struct {
  const char        *name; /* "k_theta"; {NULL} ends a list */
  PeriKeyType        type;
  const char        *deflt;   /* "1", "required", or NULL: absent means not given */
  const char        *range;   /* "[0, inf)", "(0, 1]", "{2, 3}" or NULL; printed verbatim */
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
  /* What the readers resolved beyond the file, by the same paths: the declared defaults the
   * getters applied, input files made absolute (PeriSceneGetPath), the output directory. The
   * getters never read it: only the resolved scene (scene.yaml of the output set) merges it in. */
  PeriNode resolved;
  /* A multigrid level's view of the scene (src/system/multigrid.c): grid.spacing and
   * horizon.delta times 2^coarsen, the grid's cells halved (rounded up) per level about the box's
   * centre; 0 for the scene itself. */
  PetscInt coarsen;
  /* -peri_scene_sealed: set when the problem is set up; a getter called after it is an error
   * (nothing reads the scene during a run: issue 39, docs/python.md) */
  PetscBool sealed;
};

PETSC_EXTERN PetscErrorCode PeriSceneWhere(PeriScene, PeriNode, const char[], char[], size_t);
PETSC_EXTERN PetscErrorCode PeriSceneGetNode(PeriNode, const char[], PeriNode *);
PETSC_EXTERN PetscErrorCode PeriSceneGetMap(PeriScene, PeriNode, const char[], PetscBool, PeriNode *);
PETSC_EXTERN PetscErrorCode PeriSceneCheckKeys(PeriScene, PeriNode, const char *const[]);
PETSC_EXTERN PetscErrorCode PeriSceneCheckAbsent(PeriScene, PeriNode, const char[], const char[]);
PETSC_EXTERN PetscErrorCode PeriSceneCheckSection(PeriScene, PeriNode, const char[]);
PETSC_EXTERN PetscErrorCode PeriSceneCheckKeysSchema(PeriScene, PeriNode, const char[], const PeriSchemaOwner *);
PETSC_EXTERN const PeriKey *PeriSchemaFindKey(const PeriSchema *, const char[], const char[]);
PETSC_EXTERN PetscErrorCode PeriSceneFindKey(PeriScene, PeriNode, const char[], const PeriSchema **, const PeriKey **);
PETSC_EXTERN PetscErrorCode PeriSceneCheckRange(PeriScene, PeriNode, const PeriSchema *, const PeriKey *, PetscReal, const char[]);
PETSC_EXTERN PetscBool      PeriKeyDefaultReal(const PeriKey *, PetscReal *);
PETSC_EXTERN PetscBool      PeriKeyDefaultInt(const PeriKey *, PetscInt *);
PETSC_EXTERN PetscBool      PeriKeyDefaultBool(const PeriKey *, PetscBool *);
PETSC_EXTERN PetscBool      PeriKeyDefaultString(const PeriKey *, const char **);
PETSC_EXTERN PetscBool      PeriKeyDefaultReals(const PeriKey *, PetscInt, PetscReal[], PetscInt *);
PETSC_EXTERN PetscErrorCode PeriSceneGetReal(PeriScene, PeriNode, const char[], PetscBool, PetscReal *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetInt(PeriScene, PeriNode, const char[], PetscBool, PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetBool(PeriScene, PeriNode, const char[], PetscBool *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetString(PeriScene, PeriNode, const char[], PetscBool, char[], size_t, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetChoice(PeriScene, PeriNode, const char[], const char *const[], PetscInt *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneGetRealArray(PeriScene, PeriNode, const char[], PetscBool, PetscInt, PetscInt, PetscReal[], PetscInt *);
PETSC_EXTERN PetscErrorCode PeriSceneGetPath(PeriScene, PeriNode, const char[], PetscBool, char[], size_t, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneParseReal(PeriScene, PeriNode, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriSceneParseBool(PeriScene, PeriNode, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriSceneParseRealArray(PeriScene, PeriNode, PetscInt, PetscInt, PetscReal[], PetscInt *);
/* The solver types an option string of the scene names (a tune configuration), against the
 * registered lists: why not, or "" (src/scene/option_types.c). */
PETSC_EXTERN PetscErrorCode PeriOptionsCheckTypesString(const char[], char[], size_t);

/* A user-input error that names the file, the line and the key. */
#define PeriInputCheck(cond, scene, node, key, fmt, ...)                                      \
  do {                                                                                        \
    if (PetscUnlikely(!(cond))) {                                                             \
      char peri_where_[2 * PETSC_MAX_PATH_LEN];                                               \
      PetscCall(PeriSceneWhere((scene), (node), (key), peri_where_, sizeof(peri_where_)));    \
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: " fmt, peri_where_, ##__VA_ARGS__); \
    }                                                                                         \
  } while (0)
