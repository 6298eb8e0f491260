/* Scene files: YAML -> a tree of nodes with line numbers, every scalar overridable from the
 * PETSc options database by its path joined with '_' (-material_nu 0.1). Readers validate
 * as they go and report errors as "file:line: key 'a.b' ..." (PeriInputCheck). */
#include "perilin/private/scene_file.h"
#include <yaml.h>
#include <ctype.h>
#include <errno.h>
#include <libgen.h>
#include <strings.h>

typedef struct {
  yaml_parser_t parser;
  const char   *file;
  FILE         *fp;
} Reader;

/* libyaml's input: fread, except that a signal (SIGTERM, SIGHUP, SIGINT) ends the reading. A scene
 * may come from a pipe that never ends ("perilin <(generator)"): the signal interrupts the read
 * (the handler has no SA_RESTART), and a read is not begun once it was recorded. */
static int ReadInput(void *ctx, unsigned char *buffer, size_t size, size_t *size_read)
{
  Reader *r = (Reader *)ctx;

  *size_read = 0;
  while (!PeriSignalPending()) {
    *size_read = fread(buffer, 1, size, r->fp);
    if (*size_read || !ferror(r->fp) || errno != EINTR) return !ferror(r->fp);
    clearerr(r->fp); /* another signal's handler interrupted the read: read on */
  }
  return 0;
}

/* The line of byte offset in the file: libyaml gives only the offset of an error found while it
 * decodes the input (bad UTF-8, control characters). */
static int LineAtOffset(const char file[], size_t offset)
{
  FILE *fp   = fopen(file, "rb");
  int   line = 1, c;

  if (!fp) return 0;
  for (size_t k = 0; k < offset && (c = fgetc(fp)) != EOF; k++)
    if (c == '\n') line++;
  fclose(fp);
  return line;
}

static PetscErrorCode ReaderNext(Reader *r, yaml_event_t *ev)
{
  PetscFunctionBeginUser;
  if (PetscUnlikely(!yaml_parser_parse(&r->parser, ev))) {
    int line;

    PetscCheck(!PeriSignalPending(), PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "interrupted by %s while reading the scene %s: nothing was written", PeriSignalName(PeriSignalPending()), r->file);
    line = r->parser.error == YAML_READER_ERROR ? LineAtOffset(r->file, r->parser.problem_offset) : (int)r->parser.problem_mark.line + 1;
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%d: invalid YAML: %s", r->file, line, r->parser.problem ? r->parser.problem : "syntax error");
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Deeper nesting is an error: no scene needs more than a few levels, and the reader recurses once
 * per level (a file nested thousands deep would overflow the stack). libyaml itself keeps its
 * nesting on the heap, and stopping here also stops it from reading further. */
#define PERI_SCENE_MAX_DEPTH 64

/* Builds the node for the event ev (already read) and everything below it, each node appended to
 * its parent (NULL for the root) as soon as it exists, so that the tree owns all of it whatever
 * error stops the reading. depth counts the mappings and lists enclosing ev (the root mapping is
 * at depth 1). */
static PetscErrorCode ParseNode(Reader *r, yaml_event_t *ev, const char key[], PeriNode parent, int depth, PeriNode *node)
{
  int          line = (int)ev->start_mark.line + 1;
  PeriNodeKind kind = ev->type == YAML_SEQUENCE_START_EVENT ? PERI_NODE_SEQ : ev->type == YAML_MAPPING_START_EVENT ? PERI_NODE_MAP
                                                                                                                   : PERI_NODE_SCALAR;

  PetscFunctionBeginUser;
  if (ev->type == YAML_ALIAS_EVENT || (kind == PERI_NODE_SCALAR && ev->type != YAML_SCALAR_EVENT)) {
    PetscBool alias = (PetscBool)(ev->type == YAML_ALIAS_EVENT);
    yaml_event_delete(ev);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%d: %s", r->file, line, alias ? "YAML aliases are not supported in scene files" : "unexpected YAML content");
  }
  if (kind != PERI_NODE_SCALAR && depth > PERI_SCENE_MAX_DEPTH) {
    yaml_event_delete(ev);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%d: nested more than %d levels deep", r->file, line, PERI_SCENE_MAX_DEPTH);
  }
  PetscCall(PeriNodeCreate(kind, key, parent ? parent->path : "", line, node));
  if (parent) PetscCall(PeriNodeAppend(parent, *node));
  if (kind == PERI_NODE_SCALAR) PetscCall(PetscStrallocpy((const char *)ev->data.scalar.value, &(*node)->value));
  yaml_event_delete(ev);
  if (kind == PERI_NODE_SEQ) {
    while (PETSC_TRUE) {
      yaml_event_t item;
      PeriNode     child;
      char         idx[32];
      PetscCall(ReaderNext(r, &item));
      if (item.type == YAML_SEQUENCE_END_EVENT) {
        yaml_event_delete(&item);
        break;
      }
      PetscCall(PetscSNPrintf(idx, sizeof(idx), "%" PetscInt_FMT, (*node)->n));
      PetscCall(ParseNode(r, &item, idx, *node, depth + 1, &child));
    }
  } else if (kind == PERI_NODE_MAP) {
    while (PETSC_TRUE) {
      yaml_event_t kev, vev;
      PeriNode     child, dup;
      char         k[256];
      PetscCall(ReaderNext(r, &kev));
      if (kev.type == YAML_MAPPING_END_EVENT) {
        yaml_event_delete(&kev);
        break;
      }
      line = (int)kev.start_mark.line + 1;
      if (kev.type != YAML_SCALAR_EVENT) {
        yaml_event_delete(&kev);
        SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%d: mapping keys must be plain words", r->file, line);
      }
      if (strlen((const char *)kev.data.scalar.value) >= sizeof(k)) {
        yaml_event_delete(&kev);
        SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%d: a key longer than %d characters", r->file, line, (int)sizeof(k) - 1);
      }
      PetscCall(PetscStrncpy(k, (const char *)kev.data.scalar.value, sizeof(k)));
      yaml_event_delete(&kev);
      PetscCall(PeriSceneGetNode(*node, k, &dup));
      PetscCheck(!dup, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%d: key '%s' appears twice in '%s'", r->file, line, dup->path, (*node)->path[0] ? (*node)->path : "the scene");
      PetscCall(ReaderNext(r, &vev));
      PetscCall(ParseNode(r, &vev, k, *node, depth + 1, &child));
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The names registered in a function list, comma-separated, in the order of registration (for
 * "unknown type; registered: ..." messages). */
PetscErrorCode PeriFunctionListNames(PetscFunctionList list, char buf[], size_t len)
{
  const char **names;
  int          n;

  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListGet(list, &names, &n));
  buf[0] = 0;
  for (int k = 0; k < n; k++)
    if (names[k]) PeriListAppend(buf, len, names[k]);
  PetscCall(PetscFree(names));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the option for path may be looked up. PETSc looks an option that is not set up again
 * without each of its inner numbers (-bc_0_region as -bc_region), recursively: the cost grows as
 * the factorial of the numbers, and PETSc 3.18 keeps at most 16 of them. Names with more than a few
 * numbers (lists of lists of lists, which no scene has) or too long for PETSc are not looked up. */
static PetscBool OptionQueryable(const char opt[])
{
  PetscInt numbers = 0;

  if (strlen(opt) >= 256) return PETSC_FALSE;
  for (const char *c = opt; *c; c++)
    if (c[0] == '_' && isdigit((unsigned char)c[1])) {
      const char *e = c + 1;
      while (isdigit((unsigned char)*e)) e++;
      if (*e == '_') numbers++;
      c = e - 1;
    }
  return numbers <= 4 ? PETSC_TRUE : PETSC_FALSE;
}

/* Every scalar whose option -path_joined_by_underscores is set takes the option's value; a list of
 * scalars takes a comma-separated one (-grid_upper 1,0.5). */
static PetscErrorCode ApplyOptions(PeriNode node)
{
  PetscFunctionBeginUser;
  if (node->kind == PERI_NODE_SEQ && node->n > 0 && node->child[0]->kind == PERI_NODE_SCALAR) {
    char      opt[512], val[PETSC_MAX_PATH_LEN];
    PetscBool set;
    PeriSceneOptionName(node->path, opt, sizeof(opt));
    set = PETSC_FALSE;
    if (OptionQueryable(opt)) PetscCall(PetscOptionsGetString(NULL, NULL, opt, val, sizeof(val), &set));
    if (set) {
      PetscCall(PeriNodeSetItems(node, val, ","));
      node->line = 0;
      PetscFunctionReturn(PETSC_SUCCESS);
    }
  }
  if (node->kind == PERI_NODE_SCALAR) {
    char      opt[512], val[PETSC_MAX_PATH_LEN];
    PetscBool set;
    PeriSceneOptionName(node->path, opt, sizeof(opt));
    set = PETSC_FALSE;
    if (OptionQueryable(opt)) PetscCall(PetscOptionsGetString(NULL, NULL, opt, val, sizeof(val), &set));
    if (set) {
      PetscCall(PetscFree(node->value));
      PetscCall(PetscStrallocpy(val, &node->value));
      node->line = 0;
    }
  }
  for (PetscInt k = 0; k < node->n; k++) PetscCall(ApplyOptions(node->child[k]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The key path (a documented one, "material.nu") missing from the file is added when its option
 * is given. */
static PetscErrorCode AddOptionKey(PeriNode root, const char path[])
{
  char        opt[512], val[PETSC_MAX_PATH_LEN], parent[256], leaf[128];
  const char *dot;
  PetscBool   set;
  PeriNode    map = root, child;

  PetscFunctionBeginUser;
  if (strchr(path, '<')) PetscFunctionReturn(PETSC_SUCCESS);
  PeriSceneOptionName(path, opt, sizeof(opt));
  PetscCall(PetscOptionsGetString(NULL, NULL, opt, val, sizeof(val), &set));
  if (!set) PetscFunctionReturn(PETSC_SUCCESS);
  dot = strrchr(path, '.');
  if (dot) {
    PetscCall(PetscStrncpy(parent, path, PetscMin((size_t)(dot - path + 1), sizeof(parent))));
    PetscCall(PetscStrncpy(leaf, dot + 1, sizeof(leaf)));
    PetscCall(PeriSceneGetNode(root, parent, &map));
    if (!map) {
      PetscCall(PeriNodeCreate(PERI_NODE_MAP, parent, "", 0, &map));
      PetscCall(PeriNodeAppend(root, map));
    }
    if (map->kind != PERI_NODE_MAP) PetscFunctionReturn(PETSC_SUCCESS); /* the reader reports the wrong type */
  } else
    PetscCall(PetscStrncpy(leaf, path, sizeof(leaf)));
  PetscCall(PeriSceneGetNode(map, leaf, &child));
  if (child) PetscFunctionReturn(PETSC_SUCCESS); /* ApplyOptions already set it */
  PetscCall(PeriNodeCreate(PERI_NODE_SCALAR, leaf, map->path, 0, &child));
  PetscCall(PetscStrallocpy(val, &child->value));
  PetscCall(PeriNodeAppend(map, child));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether an option may stand for the key: a value or a list of values, not a mapping or a list
 * of items, and not a pattern (regions.<name>.side: the options of the file's items exist). */
static PetscBool KeyIsOption(const PeriSchema *sec, const PeriKey *key)
{
  return (PetscBool)(key->type != PERI_KEY_MAP && key->type != PERI_KEY_LIST && !strchr(sec->section, '<') && !strchr(key->name, '<'));
}

/* Every declared key, the core's and every plug-in's, that an option adds when the file lacks it. */
static PetscErrorCode AddOptionKeys(PeriScene scene)
{
  char path[256];

  PetscFunctionBeginUser;
  for (PetscInt o = 0; o < scene->nowners; o++)
    for (const PeriSchema *sec = scene->owners[o].schema; sec && sec->section; sec++)
      for (const PeriKey *key = sec->keys; key->name; key++) {
        if (!KeyIsOption(sec, key)) continue;
        PeriSchemaPath(sec, key, path, sizeof(path));
        PetscCall(AddOptionKey(scene->root, path));
      }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Options that name the scene (src/scene/options.c checks them): a root key of the schemas, alone or
 * followed by '_'. Option names ignore case, as PETSc's do. */
PetscErrorCode PeriSceneOptionIsScene(PeriScene scene, const char opt[], PetscBool *is)
{
  const char *o = opt[0] == '-' ? opt + 1 : opt;

  PetscFunctionBeginUser;
  *is = PETSC_FALSE;
  for (PetscInt k = 0; k < scene->nowners; k++)
    for (const PeriSchema *sec = scene->owners[k].schema; sec && sec->section; sec++)
      for (const PeriKey *key = sec->keys; !sec->section[0] && key->name; key++) {
        size_t len = strlen(key->name);
        if (!strncasecmp(o, key->name, len) && (o[len] == 0 || o[len] == '_')) *is = PETSC_TRUE;
      }
  PetscFunctionReturn(PETSC_SUCCESS);
}

typedef struct {
  char   **name;
  PetscInt n, cap;
} NameList;

static PetscErrorCode NameListAdd(NameList *l, const char path[])
{
  char opt[512];

  PetscFunctionBeginUser;
  PeriSceneOptionName(path, opt, sizeof(opt));
  for (PetscInt k = 0; k < l->n; k++)
    if (!strcasecmp(l->name[k], opt)) PetscFunctionReturn(PETSC_SUCCESS);
  if (l->n + 1 >= l->cap) {
    char **more;
    l->cap = 2 * l->cap + 64;
    PetscCall(PetscCalloc1(l->cap, &more));
    for (PetscInt k = 0; k < l->n; k++) more[k] = l->name[k];
    PetscCall(PetscFree(l->name));
    l->name = more;
  }
  PetscCall(PetscStrallocpy(opt, &l->name[l->n++]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The options ApplyOptions reads below node: its scalars, and its lists of scalars as a whole. */
static PetscErrorCode NameListAddNodes(NameList *l, PeriNode node)
{
  PetscFunctionBeginUser;
  if (node->kind == PERI_NODE_SCALAR || (node->kind == PERI_NODE_SEQ && node->n > 0 && node->child[0]->kind == PERI_NODE_SCALAR)) PetscCall(NameListAdd(l, node->path));
  for (PetscInt k = 0; k < node->n; k++) PetscCall(NameListAddNodes(l, node->child[k]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneOptionNames - the options that set something in this scene ("-material_nu", ...): the
  scalars and lists of scalars of the file (after the overrides) and the documented keys. A
  NULL-terminated array; free it with PetscStrArrayDestroy(). Not collective.
@*/
PetscErrorCode PeriSceneOptionNames(PeriScene scene, char ***names)
{
  NameList l = {NULL, 0, 0};

  PetscFunctionBeginUser;
  PetscCall(NameListAddNodes(&l, scene->root));
  for (PetscInt o = 0; o < scene->nowners; o++)
    for (const PeriSchema *sec = scene->owners[o].schema; sec && sec->section; sec++)
      for (const PeriKey *key = sec->keys; key->name; key++) {
        char path[256];
        if (!KeyIsOption(sec, key)) continue;
        PeriSchemaPath(sec, key, path, sizeof(path));
        PetscCall(NameListAdd(&l, path));
      }
  if (!l.name) PetscCall(PetscCalloc1(1, &l.name));
  *names = l.name;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The child of node whose key starts rest and is followed by '_' or the end; the longest such key
 * wins (a key may contain '_' itself: boundary_layers, load_factor_max). */
static PeriNode OptionChild(PeriNode node, const char rest[])
{
  PeriNode best = NULL;

  for (PetscInt k = 0; k < node->n; k++) {
    const char *key = node->child[k]->key;
    size_t      len = strlen(key);
    if (!strncasecmp(rest, key, len) && (rest[len] == 0 || rest[len] == '_') && (!best || len > strlen(best->key))) best = node->child[k];
  }
  return best;
}

/*@C
  PeriSceneOptionExplain - why the scene option opt (which nothing read) sets nothing: the key it
  names is missing from the file, is a mapping, or is an item of a list that an option replaced.
  *exists says whether it names a node of the scene (then other names are no better). Not collective.
@*/
PetscErrorCode PeriSceneOptionExplain(PeriScene scene, const char opt[], char buf[], size_t len, PetscBool *exists)
{
  PeriNode    node = scene->root, child;
  const char *rest = opt[0] == '-' ? opt + 1 : opt;

  PetscFunctionBeginUser;
  *exists = PETSC_FALSE;
  while ((child = OptionChild(node, rest))) {
    size_t klen = strlen(child->key);
    if (rest[klen] == 0) {
      *exists = PETSC_TRUE;
      if (child->kind == PERI_NODE_MAP)
        PetscCall(PetscSNPrintf(buf, len, "'%s' is a mapping: set its keys one by one", child->path));
      else if (node->kind == PERI_NODE_SEQ && node->line == 0)
        PetscCall(PetscSNPrintf(buf, len, "the option for the whole list '%s' replaces it", node->path));
      else if (child->kind == PERI_NODE_SEQ)
        PetscCall(PetscSNPrintf(buf, len, "'%s' is %s: set its items one by one", child->path, child->n ? "a list of lists or mappings" : "an empty list"));
      else
        PetscCall(PetscSNPrintf(buf, len, "nothing reads '%s'", child->path));
      PetscFunctionReturn(PETSC_SUCCESS);
    }
    node = child;
    rest += klen + 1;
  }
  if (node->kind == PERI_NODE_SCALAR)
    PetscCall(PetscSNPrintf(buf, len, "'%s' is a single value, with no key '%s'", node->path, rest));
  else if (node->kind == PERI_NODE_SEQ && isdigit((unsigned char)rest[0]))
    PetscCall(PetscSNPrintf(buf, len, "the list '%s' has no item %ld: its items are numbered from 0 to %" PetscInt_FMT, node->path, strtol(rest, NULL, 10), node->n - 1));
  else if (node->kind == PERI_NODE_SEQ)
    PetscCall(PetscSNPrintf(buf, len, "'%s' is a list: its items are numbered from 0, and it has no '%s'", node->path, rest));
  else if (node == scene->root)
    PetscCall(PetscSNPrintf(buf, len, "the scene file has no key '%s'", rest));
  else
    PetscCall(PetscSNPrintf(buf, len, "the scene file has no key '%s' in '%s'", rest, node->path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CopyOwners(PeriScene s, PetscInt n, const PeriSchemaOwner owners[])
{
  PeriSchemaOwner *copy;

  PetscFunctionBeginUser;
  if (!n) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc1(n, &copy));
  PetscCall(PeriSchemaCheck(n, owners));
  for (PetscInt k = 0; k < n; k++) copy[k] = owners[k];
  s->owners  = copy;
  s->nowners = n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The stream start, the document start, then the root mapping and all below it. */
static PetscErrorCode ReadDocument(Reader *r, PeriScene s)
{
  yaml_event_t ev;
  int          line;

  PetscFunctionBeginUser;
  PetscCall(ReaderNext(r, &ev));
  yaml_event_delete(&ev);
  PetscCall(ReaderNext(r, &ev));
  if (ev.type == YAML_STREAM_END_EVENT) {
    yaml_event_delete(&ev);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: the scene file is empty (no YAML content, only blank lines or comments)", r->file);
  }
  yaml_event_delete(&ev);
  PetscCall(ReaderNext(r, &ev));
  line = (int)ev.start_mark.line + 1;
  if (ev.type != YAML_MAPPING_START_EVENT) {
    yaml_event_delete(&ev);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%d: a scene is a mapping of keys (dim, model, material, ...)", r->file, line);
  }
  PetscCall(ParseNode(r, &ev, "", NULL, 1, &s->root));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneCreateFromFile - reads a YAML scene file and applies option overrides. owners are the
  plug-ins' schemas (copied; the schemas themselves must outlive the scene): an option adds their
  keys as it adds the core's. Not collective: every rank reads the file.
@*/
PetscErrorCode PeriSceneCreateFromFile(const char file[], PetscInt nowners, const PeriSchemaOwner owners[], PeriScene *scene)
{
  PeriScene      s;
  FILE          *fp;
  Reader         r;
  char           tmp[PETSC_MAX_PATH_LEN];
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&s));
  PetscCall(CopyOwners(s, nowners, owners));
  PetscCall(PetscStrncpy(s->file, file, sizeof(s->file)));
  PetscCall(PetscStrncpy(tmp, file, sizeof(tmp)));
  PetscCall(PetscStrncpy(s->dir, dirname(tmp), sizeof(s->dir)));
  fp = fopen(file, "r");
  if (!fp) {
    int err = errno;
    PetscCall(PeriSceneDestroy(&s));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "cannot open scene file %s: %s", file, strerror(err));
  }
  r.file = s->file;
  r.fp   = fp;
  PetscCheck(yaml_parser_initialize(&r.parser), PETSC_COMM_SELF, PETSC_ERR_LIB, "libyaml could not initialize");
  yaml_parser_set_input(&r.parser, ReadInput, &r);
  *scene = s;
  /* the parser and the file are closed whatever the outcome; the tree read so far is the scene's */
  ierr = ReadDocument(&r, s);
  yaml_parser_delete(&r.parser);
  fclose(fp);
  PetscCall(ierr);
  PetscCall(ApplyOptions(s->root));
  PetscCall(AddOptionKeys(s));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneDestroy(PeriScene *scene)
{
  PetscFunctionBeginUser;
  if (!*scene) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriNodeDestroy(&(*scene)->root));
  PetscCall(PeriNodeDestroy(&(*scene)->resolved));
  PetscCall(PetscFree((*scene)->owners));
  PetscCall(PetscFree(*scene));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* -peri_scene_sealed: a scene read after the set-up names the key (the caller is in the
 * traceback of -peri_scene_sealed's error). */
static PetscErrorCode SealCheck(PeriScene scene, PeriNode map, const char key[])
{
  PetscFunctionBeginUser;
  PetscCheck(!scene->sealed, PETSC_COMM_SELF, PETSC_ERR_PLIB, "-peri_scene_sealed: the scene key '%s%s%s' is read after the set-up (a part reads its settings during the run)", map->path, map->path[0] ? "." : "", key);
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneGetMap(PeriScene scene, PeriNode map, const char key[], PetscBool required, PeriNode *child)
{
  PetscFunctionBeginUser;
  PetscCall(SealCheck(scene, map, key));
  PetscCall(PeriSceneGetNode(map, key, child));
  PeriInputCheck(*child || !required, scene, map, key, "is required");
  PeriInputCheck(!*child || (*child)->kind == PERI_NODE_MAP, scene, *child, NULL, "must be a mapping of keys");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The plug-in other than active that declares name in section, or NULL. */
static const PeriSchemaOwner *OtherOwner(PeriScene scene, const PeriSchemaOwner *active, const char section[], const char name[])
{
  for (PetscInt o = 0; o < scene->nowners; o++)
    if (strcmp(scene->owners[o].kind, "core") && (!active || strcmp(scene->owners[o].name, active->name)) && PeriSchemaFindKey(scene->owners[o].schema, section, name)) return &scene->owners[o];
  return NULL;
}

/* "; did you mean X?" for name among the comma-separated names of list, or "". */
static PetscErrorCode SuggestFromList(const char name[], const char list[], char buf[], size_t len)
{
  char      **names;
  int         n;
  char        hint[160];
  const char *cand[PERI_SECTION_MAX_KEYS + 1];

  PetscFunctionBeginUser;
  buf[0] = 0;
  PetscCall(PetscStrToArray(list, ',', &n, &names));
  for (int a = 0; a < n && a < PERI_SECTION_MAX_KEYS; a++) {
    cand[a] = names[a];
    while (*cand[a] == ' ') cand[a]++;
  }
  cand[PetscMin(n, PERI_SECTION_MAX_KEYS)] = NULL;
  PeriSceneSuggest(name, cand, hint, sizeof(hint));
  if (hint[0]) PetscCall(PetscSNPrintf(buf, len, "; %s", hint));
  PetscCall(PetscStrToArrayDestroy(n, names));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneCheckKeysSchema - checks the keys of map, the plug-in section named section
  ("analysis", "model"): allowed are the core's keys there (type) and the keys the active plug-in
  declares. A key another plug-in declares says which one owns it, so that a key left from another
  analysis (load_factor_max in a modal scene) is not taken for a typo; the message keeps the
  "unknown key; allowed here" start of any other unknown key. active NULL (the type is unknown,
  reported later with the list of types) allows every plug-in's keys.
@*/
PetscErrorCode PeriSceneCheckKeysSchema(PeriScene scene, PeriNode map, const char section[], const PeriSchemaOwner *active)
{
  const char *base[PERI_SECTION_MAX_KEYS];

  PetscFunctionBeginUser;
  if (!map) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneSectionKeys(scene, section, PETSC_FALSE, base));
  for (PetscInt k = 0; k < map->n; k++) {
    const char            *name      = map->child[k]->key;
    const PeriSchemaOwner *other     = OtherOwner(scene, active, section, name);
    PetscBool              ok        = PETSC_FALSE;
    char                   list[512] = "", owner[256] = "";

    for (PetscInt a = 0; base[a]; a++) ok = (PetscBool)(ok || !strcmp(name, base[a]));
    if (ok || (active ? PeriSchemaFindKey(active->schema, section, name) != NULL : other != NULL)) continue;
    for (PetscInt a = 0; base[a]; a++) PeriListAppend(list, sizeof(list), base[a]);
    for (const PeriSchema *sec = active ? active->schema : NULL; sec && sec->section; sec++)
      for (const PeriKey *key = sec->keys; !strcmp(sec->section, section) && key->name; key++) PeriListAppend(list, sizeof(list), key->name);
    if (other)
      PetscCall(PetscSNPrintf(owner, sizeof(owner), " (key '%s' belongs to %s %s, not %s)", name, other->kind, other->name, active->name));
    else
      PetscCall(SuggestFromList(name, list, owner, sizeof(owner)));
    PeriInputCheck(PETSC_FALSE, scene, map->child[k], NULL, "unknown key; allowed here: %s%s", list, owner);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A key's declaration, as the getters apply it (scene.h). */
typedef struct {
  const PeriSchema *sec;
  const PeriKey    *key;
} Decl;

/* The declaration of key in map, read by a getter of type: another type is a bug. */
static PetscErrorCode GetDecl(PeriScene scene, PeriNode map, const char key[], PeriKeyType type, Decl *d)
{
  static const char *const names[] = {"number", "whole number", "boolean", "string", "choice", "list of numbers", "list of booleans", "mapping", "list"};

  PetscFunctionBeginUser;
  PetscCall(SealCheck(scene, map, key));
  PetscCall(PeriSceneFindKey(scene, map, key, &d->sec, &d->key));
  PetscCheck(!d->key || d->key->type == type || (type == PERI_KEY_STRING && d->key->type == PERI_KEY_CHOICE), PETSC_COMM_SELF, PETSC_ERR_PLIB, "key '%s%s%s' is declared as a %s but read as a %s", map->path, map->path[0] ? "." : "", key, names[d->key->type], names[type]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A key absent from map took its declared default: the resolved scene (scene.yaml) writes it. */
static PetscErrorCode UseDefault(PeriScene scene, PeriNode map, const char key[], const Decl *d)
{
  PetscFunctionBeginUser;
  PetscCall(PeriSceneResolve(scene, map, key, d->key->type == PERI_KEY_REALS, d->key->deflt));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode GetScalar(PeriScene scene, PeriNode map, const char key[], PetscBool required, PeriKeyType type, PeriNode *node, Decl *d)
{
  PetscFunctionBeginUser;
  PetscCall(GetDecl(scene, map, key, type, d));
  PetscCall(PeriSceneGetNode(map, key, node));
  PeriInputCheck(*node || !required, scene, map, key, "is required");
  PeriInputCheck(!*node || (*node)->kind == PERI_NODE_SCALAR, scene, *node, NULL, "must be a single value, not a list or mapping");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Numbers, and simple fractions such as 1/3 (exact Poisson ratios). */
PetscErrorCode PeriSceneParseReal(PeriScene scene, PeriNode node, PetscReal *v)
{
  char  *end;
  double a, b = 1;

  PetscFunctionBeginUser;
  errno = 0;
  a     = strtod(node->value, &end);
  PeriInputCheck(end != node->value, scene, node, NULL, "expected a number, got '%s'", node->value);
  if (*end == '/') {
    const char *s = end + 1;
    b             = strtod(s, &end);
    PeriInputCheck(end != s && b != 0, scene, node, NULL, "expected a number or a fraction a/b, got '%s'", node->value);
  }
  while (isspace((unsigned char)*end)) end++;
  PeriInputCheck(!*end && errno != ERANGE, scene, node, NULL, "expected a number, got '%s'", node->value);
  *v = (PetscReal)(a / b);
  PeriInputCheck(PetscIsNormalReal(*v) || *v == 0, scene, node, NULL, "expected a finite number, got '%s'", node->value);
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneGetReal(PeriScene scene, PeriNode map, const char key[], PetscBool required, PetscReal *v, PetscBool *found)
{
  PeriNode  node;
  Decl      d;
  PetscReal x;

  PetscFunctionBeginUser;
  PetscCall(GetScalar(scene, map, key, required, PERI_KEY_REAL, &node, &d));
  if (found) *found = node ? PETSC_TRUE : PETSC_FALSE;
  if (node) {
    PetscCall(PeriSceneParseReal(scene, node, v));
    PetscCall(PeriSceneCheckRange(scene, node, d.sec, d.key, *v, node->value));
  } else if (d.key && PeriKeyDefaultReal(d.key, &x)) {
    *v = x;
    PetscCall(UseDefault(scene, map, key, &d));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneGetInt(PeriScene scene, PeriNode map, const char key[], PetscBool required, PetscInt *v, PetscBool *found)
{
  PeriNode node;
  Decl     d;
  PetscInt i;
  char    *end;
  long     l;

  PetscFunctionBeginUser;
  PetscCall(GetScalar(scene, map, key, required, PERI_KEY_INT, &node, &d));
  if (found) *found = node ? PETSC_TRUE : PETSC_FALSE;
  if (!node && d.key && PeriKeyDefaultInt(d.key, &i)) {
    *v = i;
    PetscCall(UseDefault(scene, map, key, &d));
  }
  if (!node) PetscFunctionReturn(PETSC_SUCCESS);
  errno = 0;
  l     = strtol(node->value, &end, 10);
  PeriInputCheck(end != node->value && !*end, scene, node, NULL, "expected a whole number, got '%s'", node->value);
  /* strtol saturates, and PetscInt may be 32 bits: an overflow must not become another number */
  PeriInputCheck(errno != ERANGE && l >= PETSC_MIN_INT && l <= PETSC_MAX_INT, scene, node, NULL, "the whole number %s is out of range (at most %" PetscInt_FMT ")", node->value, (PetscInt)PETSC_MAX_INT);
  PetscCall(PeriSceneCheckRange(scene, node, d.sec, d.key, (PetscReal)l, node->value));
  *v = (PetscInt)l;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneParseBool(PeriScene scene, PeriNode node, PetscBool *v)
{
  static const char *const yes[] = {"true", "yes", "on", "1"}, *const no[] = {"false", "no", "off", "0"};
  PetscBool match = PETSC_FALSE;

  PetscFunctionBeginUser;
  PeriInputCheck(node->kind == PERI_NODE_SCALAR, scene, node, NULL, "expected true or false");
  for (int k = 0; k < 4; k++) {
    PetscBool y, n;
    PetscCall(PetscStrcasecmp(node->value, yes[k], &y));
    PetscCall(PetscStrcasecmp(node->value, no[k], &n));
    if (y) *v = PETSC_TRUE;
    if (n) *v = PETSC_FALSE;
    match = (PetscBool)(match || y || n);
  }
  PeriInputCheck(match, scene, node, NULL, "expected true or false, got '%s'", node->value);
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneGetBool(PeriScene scene, PeriNode map, const char key[], PetscBool *v, PetscBool *found)
{
  PeriNode  node;
  Decl      d;
  PetscBool b;

  PetscFunctionBeginUser;
  PetscCall(GetScalar(scene, map, key, PETSC_FALSE, PERI_KEY_BOOL, &node, &d));
  if (found) *found = node ? PETSC_TRUE : PETSC_FALSE;
  if (node)
    PetscCall(PeriSceneParseBool(scene, node, v));
  else if (d.key && PeriKeyDefaultBool(d.key, &b)) {
    *v = b;
    PetscCall(UseDefault(scene, map, key, &d));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneGetString(PeriScene scene, PeriNode map, const char key[], PetscBool required, char buf[], size_t len, PetscBool *found)
{
  PeriNode    node;
  Decl        d;
  const char *s;

  PetscFunctionBeginUser;
  PetscCall(GetScalar(scene, map, key, required, PERI_KEY_STRING, &node, &d));
  if (found) *found = node ? PETSC_TRUE : PETSC_FALSE;
  if (node)
    PetscCall(PetscStrncpy(buf, node->value, len));
  else if (d.key && PeriKeyDefaultString(d.key, &s)) {
    PetscCall(PetscStrncpy(buf, s, len));
    PetscCall(UseDefault(scene, map, key, &d));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The index of the declared default of d in the reader's choices (which may differ from the
 * declared ones: a leading "none"); *idx left alone without a default. */
static PetscErrorCode ChoiceDefault(PeriScene scene, PeriNode map, const char key[], const Decl *d, const char *const choices[], PetscInt *idx)
{
  const char *s;

  PetscFunctionBeginUser;
  if (!d->key || !PeriKeyDefaultString(d->key, &s)) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; choices[k]; k++)
    if (!strcmp(choices[k], s)) {
      *idx = k;
      PetscCall(UseDefault(scene, map, key, d));
      PetscFunctionReturn(PETSC_SUCCESS);
    }
  SETERRQ(PETSC_COMM_SELF, PETSC_ERR_PLIB, "the declared default '%s' of key '%s' is not among the choices its reader knows", s, d->key->name);
}

/* choices is NULL-terminated; absent, *idx is the declared default's, or is left alone. */
PetscErrorCode PeriSceneGetChoice(PeriScene scene, PeriNode map, const char key[], const char *const choices[], PetscInt *idx, PetscBool *found)
{
  PeriNode node;
  Decl     d;
  char     list[512] = "";

  PetscFunctionBeginUser;
  PetscCall(GetScalar(scene, map, key, PETSC_FALSE, PERI_KEY_CHOICE, &node, &d));
  if (found) *found = node ? PETSC_TRUE : PETSC_FALSE;
  if (!node) PetscCall(ChoiceDefault(scene, map, key, &d, choices, idx));
  if (!node) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; choices[k]; k++) {
    if (!strcmp(node->value, choices[k])) {
      *idx = k;
      PetscFunctionReturn(PETSC_SUCCESS);
    }
    PeriListAppend(list, sizeof(list), choices[k]);
  }
  PeriInputCheck(PETSC_FALSE, scene, node, NULL, "'%s' is not allowed; choose one of: %s", node->value, list);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A list of nmin..nmax numbers. */
PetscErrorCode PeriSceneParseRealArray(PeriScene scene, PeriNode node, PetscInt nmin, PetscInt nmax, PetscReal v[], PetscInt *n)
{
  PetscFunctionBeginUser;
  PeriInputCheck(node->kind == PERI_NODE_SEQ, scene, node, NULL, "must be a list of %" PetscInt_FMT " numbers, e.g. [0, 1]", nmax);
  PeriInputCheck(node->n >= nmin && node->n <= nmax, scene, node, NULL, "must have %" PetscInt_FMT "%s entries, got %" PetscInt_FMT, nmax, nmin == nmax ? "" : " or fewer", node->n);
  for (PetscInt k = 0; k < node->n; k++) {
    PeriInputCheck(node->child[k]->kind == PERI_NODE_SCALAR, scene, node->child[k], NULL, "must be a number");
    PetscCall(PeriSceneParseReal(scene, node->child[k], &v[k]));
  }
  *n = node->n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneGetRealArray(PeriScene scene, PeriNode map, const char key[], PetscBool required, PetscInt nmin, PetscInt nmax, PetscReal v[], PetscInt *n)
{
  PeriNode  node;
  Decl      d;
  PetscReal x[64];
  PetscInt  nx;

  PetscFunctionBeginUser;
  *n = 0;
  PetscCall(GetDecl(scene, map, key, PERI_KEY_REALS, &d));
  PetscCall(PeriSceneGetNode(map, key, &node));
  PeriInputCheck(node || !required, scene, map, key, "is required");
  if (node) {
    PetscCall(PeriSceneParseRealArray(scene, node, nmin, nmax, v, n));
    for (PetscInt k = 0; k < *n; k++) PetscCall(PeriSceneCheckRange(scene, node, d.sec, d.key, v[k], node->child[k]->value));
  } else if (d.key && PeriKeyDefaultReals(d.key, 64, x, &nx)) {
    PetscCheck(nx >= nmin && nx <= nmax, PETSC_COMM_SELF, PETSC_ERR_PLIB, "the declared default %s of key '%s' does not have %" PetscInt_FMT " to %" PetscInt_FMT " entries", d.key->deflt, d.key->name, nmin, nmax);
    for (PetscInt k = 0; k < nx; k++) v[k] = x[k];
    *n = nx;
    PetscCall(UseDefault(scene, map, key, &d));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}
