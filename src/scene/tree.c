/* The scene's tree as the readers walk it (src/scene/): a child by its (dotted) key, where a node is
 * (file, line, key, option) for messages, the keys allowed in a mapping, and a key's declaration in
 * a schema. Below the getters (scene.c), the declarations (keys.c) and the schema tables
 * (schema.c). */
#include "perilin/private/scene_file.h"

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
