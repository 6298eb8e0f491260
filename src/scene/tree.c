/* The scene's tree as the readers walk it (src/scene/): its nodes, a child by its (dotted) key,
 * where a node is (file, line, key, option) for messages, the keys allowed in a mapping, a key's
 * declaration in a schema, and the values the run resolved beyond the file (PeriSceneResolve, for
 * the resolved scene of resolved.c). Below the getters (scene.c), the declarations (keys.c) and
 * the schema tables (schema.c). */
#include "perilin/private/scene_file.h"
#include <errno.h>
#include <unistd.h>

PetscErrorCode PeriNodeCreate(PeriNodeKind kind, const char key[], const char parent_path[], int line, PeriNode *node)
{
  PeriNode n;
  size_t   len;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&n));
  n->kind = kind;
  n->line = line;
  PetscCall(PetscStrallocpy(key, &n->key));
  if (parent_path && parent_path[0]) {
    len = strlen(parent_path) + strlen(key) + 2;
    PetscCall(PetscMalloc1(len, &n->path));
    PetscCall(PetscSNPrintf(n->path, len, "%s.%s", parent_path, key));
  } else
    PetscCall(PetscStrallocpy(key ? key : "", &n->path));
  *node = n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriNodeAppend(PeriNode parent, PeriNode child)
{
  PeriNode *c;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(parent->n + 1, &c));
  for (PetscInt k = 0; k < parent->n; k++) c[k] = parent->child[k];
  c[parent->n] = child;
  PetscCall(PetscFree(parent->child));
  parent->child = c;
  parent->n++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriNodeDestroy(PeriNode *node)
{
  PetscFunctionBeginUser;
  if (!*node) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; k < (*node)->n; k++) PetscCall(PeriNodeDestroy(&(*node)->child[k]));
  PetscCall(PetscFree((*node)->child));
  PetscCall(PetscFree((*node)->key));
  PetscCall(PetscFree((*node)->path));
  PetscCall(PetscFree((*node)->value));
  PetscCall(PetscFree(*node));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriNodeDuplicate - a deep copy of node (NULL for NULL): a problem set up again from its scene
  with one key changed keeps the values the first set-up resolved (PeriProblemSetUpFrom). Not
  collective.
@*/
PetscErrorCode PeriNodeDuplicate(PeriNode node, PeriNode *copy)
{
  PeriNode c;

  PetscFunctionBeginUser;
  *copy = NULL;
  if (!node) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscNew(&c));
  c->kind = node->kind;
  c->line = node->line;
  PetscCall(PetscStrallocpy(node->key, &c->key));
  PetscCall(PetscStrallocpy(node->path, &c->path));
  PetscCall(PetscStrallocpy(node->value, &c->value));
  if (node->n) PetscCall(PetscCalloc1(node->n, &c->child));
  for (PetscInt k = 0; k < node->n; k++) PetscCall(PeriNodeDuplicate(node->child[k], &c->child[k]));
  c->n  = node->n;
  *copy = c;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriNodeRemovePath - removes the node at the dotted path below root (and all below it), if there
  is one: a changed key's resolved value is stale. Not collective.
@*/
PetscErrorCode PeriNodeRemovePath(PeriNode root, const char path[])
{
  char     buf[512], *tok, *next, *save;
  PeriNode node = root;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(buf, path, sizeof(buf)));
  for (tok = strtok_r(buf, ".", &save); tok && node; tok = next) {
    PetscInt k = 0;
    next       = strtok_r(NULL, ".", &save);
    while (k < node->n && strcmp(node->child[k]->key, tok)) k++;
    if (k == node->n) break;
    if (next) {
      node = node->child[k];
      continue;
    }
    PetscCall(PeriNodeDestroy(&node->child[k]));
    for (PetscInt m = k + 1; m < node->n; m++) node->child[m - 1] = node->child[m];
    node->n--;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The option that sets a key: "-material_nu" for path "material.nu". */
void PeriSceneOptionName(const char path[], char opt[], size_t len)
{
  size_t k = 0;
  opt[k++] = '-';
  for (const char *c = path; *c && k + 1 < len; c++) opt[k++] = (*c == '.') ? '_' : *c;
  opt[k] = 0;
}

/* "file:line: key 'material.nu' (option -material_nu)" for node (or its child key when given). */
PetscErrorCode PeriSceneWhere(PeriScene scene, PeriNode node, const char key[], char buf[], size_t len)
{
  char        path[512], opt[512];
  const char *p = node ? node->path : "";

  PetscFunctionBeginUser;
  if (key && key[0])
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s%s%s", p, p[0] ? "." : "", key));
  else
    PetscCall(PetscStrncpy(path, p, sizeof(path)));
  PeriSceneOptionName(path, opt, sizeof(opt));
  if (node && node->line > 0) {
    PeriNode child = NULL;
    int      line  = node->line;
    if (key && key[0]) PetscCall(PeriSceneGetNode(node, key, &child));
    if (child && child->line > 0) line = child->line;
    PetscCall(PetscSNPrintf(buf, len, "%s:%d: key '%s'", scene->file, line, path));
  } else if (node)
    PetscCall(PetscSNPrintf(buf, len, "%s: key '%s' (set by option %s)", scene->file, path, opt));
  else
    PetscCall(PetscSNPrintf(buf, len, "%s: key '%s'", scene->file, path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The child of map named key; the key may be dotted ("material.nu"). NULL when absent. */
PetscErrorCode PeriSceneGetNode(PeriNode map, const char key[], PeriNode *child)
{
  const char *dot;
  size_t      len;

  PetscFunctionBeginUser;
  *child = NULL;
  if (!map || map->kind != PERI_NODE_MAP) PetscFunctionReturn(PETSC_SUCCESS);
  dot = strchr(key, '.');
  len = dot ? (size_t)(dot - key) : strlen(key);
  for (PetscInt k = 0; k < map->n; k++) {
    if (strlen(map->child[k]->key) == len && !strncmp(map->child[k]->key, key, len)) {
      if (dot)
        PetscCall(PeriSceneGetNode(map->child[k], dot + 1, child));
      else
        *child = map->child[k];
      break;
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneCheckAbsent - a key that does not apply (why says when it does) must be absent. Readers
  read such a key only where it applies, so that its declared default, which the resolved scene
  writes, is never taken for a given key. Not collective.
@*/
PetscErrorCode PeriSceneCheckAbsent(PeriScene scene, PeriNode map, const char key[], const char why[])
{
  PeriNode node;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(map, key, &node));
  PeriInputCheck(!node, scene, map, key, "%s", why);
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSceneCheckKeys(PeriScene scene, PeriNode map, const char *const allowed[])
{
  PetscFunctionBeginUser;
  if (!map) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; k < map->n; k++) {
    PetscBool ok = PETSC_FALSE;
    for (PetscInt a = 0; allowed[a]; a++)
      if (!strcmp(map->child[k]->key, allowed[a])) ok = PETSC_TRUE;
    if (!ok) {
      char list[512] = "", hint[160];
      for (PetscInt a = 0; allowed[a]; a++) PeriListAppend(list, sizeof(list), allowed[a]);
      PeriSceneSuggest(map->child[k]->key, allowed, hint, sizeof(hint));
      PeriInputCheck(PETSC_FALSE, scene, map->child[k], NULL, "unknown key; allowed here: %s%s%s", list, hint[0] ? "; " : "", hint);
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSchemaFindKey - the key name that schema (a {NULL}-ended array, or NULL) declares in section,
  or NULL.
@*/
const PeriKey *PeriSchemaFindKey(const PeriSchema *schema, const char section[], const char name[])
{
  for (const PeriSchema *sec = schema; sec && sec->section; sec++) {
    if (strcmp(sec->section, section)) continue;
    for (const PeriKey *key = sec->keys; key->name; key++)
      if (!strcmp(key->name, name)) return key;
  }
  return NULL;
}

/*@C
  PeriSchemaPath - "section.key" of a schema key; a root key ("dim") is its name alone.
@*/
void PeriSchemaPath(const PeriSchema *sec, const PeriKey *key, char path[], size_t len)
{
  snprintf(path, len, "%s%s%s", sec->section, sec->section[0] ? "." : "", key->name);
}

/* The child of node named key (a list item's key is its index), created with kind when missing. */
static PetscErrorCode Child(PeriNode node, const char key[], PeriNodeKind kind, PeriNode *child)
{
  PetscFunctionBeginUser;
  *child = NULL;
  for (PetscInt k = 0; k < node->n && !*child; k++)
    if (!strcmp(node->child[k]->key, key)) *child = node->child[k];
  if (*child) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriNodeCreate(kind, key, node->path, 0, child));
  PetscCall(PeriNodeAppend(node, *child));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriNodeSetItems - node (a list) drops its items and takes those of text split at any of delims
  (a flow list "[0, 0]" with "[], ", an option's "0,0" with ",").
@*/
PetscErrorCode PeriNodeSetItems(PeriNode node, const char text[], const char delims[])
{
  char buf[PETSC_MAX_PATH_LEN], *tok, *save;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < node->n; k++) PetscCall(PeriNodeDestroy(&node->child[k]));
  node->n = 0;
  PetscCall(PetscStrncpy(buf, text, sizeof(buf)));
  for (tok = strtok_r(buf, delims, &save); tok; tok = strtok_r(NULL, delims, &save)) {
    PeriNode item;
    char     idx[32];
    PetscCall(PetscSNPrintf(idx, sizeof(idx), "%" PetscInt_FMT, node->n));
    PetscCall(PeriNodeCreate(PERI_NODE_SCALAR, idx, node->path, 0, &item));
    PetscCall(PetscStrallocpy(tok, &item->value));
    PetscCall(PeriNodeAppend(node, item));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneResolve - records value as the one the run used for map.key (key may be dotted: from the
  root, "output.dir"), a flow list of numbers when list: the resolved scene writes it instead of
  the file's (or where the file has none). The getters never see it. Not collective.
@*/
PetscErrorCode PeriSceneResolve(PeriScene scene, PeriNode map, const char key[], PetscBool list, const char value[])
{
  char     path[512], *tok, *next, *save;
  PeriNode node;

  PetscFunctionBeginUser;
  if (!scene->resolved) PetscCall(PeriNodeCreate(PERI_NODE_MAP, "", "", 0, &scene->resolved));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s%s%s", map ? map->path : "", map && map->path[0] ? "." : "", key));
  node = scene->resolved;
  for (tok = strtok_r(path, ".", &save); tok; tok = next) {
    next = strtok_r(NULL, ".", &save);
    PetscCall(Child(node, tok, next ? PERI_NODE_MAP : list ? PERI_NODE_SEQ
                                                           : PERI_NODE_SCALAR,
                    &node));
  }
  if (list) {
    PetscCall(PeriNodeSetItems(node, value, "[], "));
  } else {
    PetscCall(PetscFree(node->value));
    PetscCall(PetscStrallocpy(value, &node->value));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* path as an absolute path: relative paths are the working directory's. */
static PetscErrorCode Absolute(const char path[], char abs[], size_t len)
{
  char cwd[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  if (path[0] == '/') {
    PetscCall(PetscStrncpy(abs, path, len));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCheck(getcwd(cwd, sizeof(cwd)), PETSC_COMM_SELF, PETSC_ERR_SYS, "cannot get the working directory: %s", strerror(errno));
  while (path[0] == '.' && path[1] == '/') path += 2;
  PetscCall(PetscSNPrintf(abs, len, "%s/%s", cwd, path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneResolvePath - records path (relative to the working directory, or absolute) made absolute
  as the value of map.key in the resolved scene, which stays valid wherever it is read from. Not
  collective.
@*/
PetscErrorCode PeriSceneResolvePath(PeriScene scene, PeriNode map, const char key[], const char path[])
{
  char abs[2 * PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(Absolute(path, abs, sizeof(abs)));
  PetscCall(PeriSceneResolve(scene, map, key, PETSC_FALSE, abs));
  PetscFunctionReturn(PETSC_SUCCESS);
}
