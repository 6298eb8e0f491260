/* The declared scene keys (PeriSchema) as the scene layer uses them: the keys allowed in a section,
 * perilin -help, and the key tables of docs/scene.md. The schemas come from the core modules and
 * the plug-ins through scene->owners (or the owners passed in): this layer never asks for them. */
#include "perilin/private/scene_file.h"
#include <stdarg.h>
#include <ctype.h>
#include <errno.h>

/*@C
  PeriSceneSectionKeys - the names of the keys declared in section, NULL-ended, in the order of
  the declarations: the core's, then with plugins the plug-ins' (a shared section such as output,
  where quasistatic declares every). A section no core module declares is a bug. Not collective.
@*/
PetscErrorCode PeriSceneSectionKeys(PeriScene scene, const char section[], PetscBool plugins, const char *names[PERI_SECTION_MAX_KEYS])
{
  PetscInt  n    = 0;
  PetscBool core = PETSC_FALSE;

  PetscFunctionBeginUser;
  for (PetscInt pass = 0; pass < (plugins ? 2 : 1); pass++)
    for (PetscInt o = 0; o < scene->nowners; o++) {
      if ((pass == 0) != !strcmp(scene->owners[o].kind, "core")) continue;
      for (const PeriSchema *sec = scene->owners[o].schema; sec && sec->section; sec++) {
        if (strcmp(sec->section, section)) continue;
        core = (PetscBool)(core || pass == 0);
        for (const PeriKey *key = sec->keys; key->name; key++) {
          PetscCheck(n + 1 < PERI_SECTION_MAX_KEYS, PETSC_COMM_SELF, PETSC_ERR_PLIB, "section '%s' declares more than %d keys", section, PERI_SECTION_MAX_KEYS - 1);
          names[n++] = key->name;
        }
      }
    }
  PetscCheck(core, PETSC_COMM_SELF, PETSC_ERR_PLIB, "no core schema declares the scene section '%s'", section);
  names[n] = NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneCheckSection - checks that map (NULL: absent) has only the keys declared in section
  ("horizon", "bc.<k>"), by the core or, in a shared section, by any plug-in. Not collective.
@*/
PetscErrorCode PeriSceneCheckSection(PeriScene scene, PeriNode map, const char section[])
{
  const char *names[PERI_SECTION_MAX_KEYS];

  PetscFunctionBeginUser;
  PetscCall(PeriSceneSectionKeys(scene, section, PETSC_TRUE, names));
  PetscCall(PeriSceneCheckKeys(scene, map, names));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether section belongs under the root key top: "bc" holds "bc.<k>" and "bc.<k>.affine". */
static PetscBool SectionUnder(const char section[], const char top[])
{
  size_t len = strlen(top);
  return (PetscBool)(!strncmp(section, top, len) && (section[len] == 0 || section[len] == '.'));
}

typedef PetscErrorCode (*RowFn)(const PeriSchemaOwner *, const PeriSchema *, const PeriKey *, void *);

/* Calls fn for every key declared under the root key top, the core's first, then the plug-ins' in
 * registration order; for top itself when nothing is declared under it ("dim"). */
static PetscErrorCode ForEachRow(PetscInt nowners, const PeriSchemaOwner owners[], const PeriSchema *root, const PeriKey *top, RowFn fn, void *ctx)
{
  PetscBool any = PETSC_FALSE;

  PetscFunctionBeginUser;
  for (PetscInt pass = 0; pass < 2; pass++)
    for (PetscInt o = 0; o < nowners; o++) {
      if ((pass == 0) != !strcmp(owners[o].kind, "core")) continue;
      for (const PeriSchema *sec = owners[o].schema; sec && sec->section; sec++)
        for (const PeriKey *key = sec->keys; SectionUnder(sec->section, top->name) && key->name; key++) {
          PetscCall(fn(&owners[o], sec, key, ctx));
          any = PETSC_TRUE;
        }
    }
  if (!any) PetscCall(fn(NULL, root, top, ctx));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The core's root section: its keys order -help and the tables. */
static const PeriSchema *RootSchema(PetscInt nowners, const PeriSchemaOwner owners[])
{
  for (PetscInt o = 0; o < nowners; o++)
    for (const PeriSchema *sec = owners[o].schema; sec && sec->section && !strcmp(owners[o].kind, "core"); sec++)
      if (!sec->section[0]) return sec;
  return NULL;
}

typedef struct {
  MPI_Comm               comm;
  PetscInt               nowners;
  const PeriSchemaOwner *owners;
  char                  *buf; /* the tables: the text being built */
  size_t                 len, cap;
} RowCtx;

/* The types registered for the selector key "<kind>.type" ("" for any other key). */
static void SelectorTypes(const RowCtx *c, const PeriSchema *sec, const PeriKey *key, const char *sep, const char *quote, char types[], size_t len)
{
  types[0] = 0;
  if (strcmp(key->name, "type")) return;
  for (PetscInt o = 0; o < c->nowners; o++)
    if (!strcmp(c->owners[o].kind, sec->section)) {
      size_t used = strlen(types);
      snprintf(types + used, len - used, "%s%s%s%s", used ? sep : "", quote, c->owners[o].name, quote);
    }
}

/* The choices of key joined by sep, each in quote. */
static void Choices(const PeriKey *key, const char *sep, const char *quote, char list[], size_t len)
{
  list[0] = 0;
  for (const char *const *c = key->choices; c && *c; c++) {
    size_t used = strlen(list);
    snprintf(list + used, len - used, "%s%s%s%s", used ? sep : "", quote, *c, quote);
  }
}

/* One -help row: "path  (model mppd) help [units]; one of a | b; in range; default d". */
static PetscErrorCode HelpRow(const PeriSchemaOwner *owner, const PeriSchema *sec, const PeriKey *key, void *ctx)
{
  RowCtx *c = (RowCtx *)ctx;
  char    path[256], text[1024] = "", list[512];

  PetscFunctionBeginUser;
  PeriSchemaPath(sec, key, path, sizeof(path));
  if (owner && strcmp(owner->kind, "core")) PetscCall(PetscSNPrintf(text, sizeof(text), "(%s %s) ", owner->kind, owner->name));
  PetscCall(PetscSNPrintf(text + strlen(text), sizeof(text) - strlen(text), "%s", key->help));
  SelectorTypes(c, sec, key, ", ", "", list, sizeof(list));
  if (list[0]) PetscCall(PetscSNPrintf(text + strlen(text), sizeof(text) - strlen(text), ": %s", list));
  if (key->units) PetscCall(PetscSNPrintf(text + strlen(text), sizeof(text) - strlen(text), " %s", key->units));
  Choices(key, " | ", "", list, sizeof(list));
  if (list[0]) PetscCall(PetscSNPrintf(text + strlen(text), sizeof(text) - strlen(text), "; one of %s", list));
  if (key->range) PetscCall(PetscSNPrintf(text + strlen(text), sizeof(text) - strlen(text), "; in %s", key->range));
  if (key->deflt) PetscCall(PetscSNPrintf(text + strlen(text), sizeof(text) - strlen(text), strcmp(key->deflt, "required") ? "; default %s" : "; %s", key->deflt));
  PetscCall(PetscPrintf(c->comm, "  %-30s %s\n", path, text));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneHelp - prints every declared scene key, section by section in the order of the root
  keys: the core's, then the plug-ins' tagged with their owner ("(model mppd)"); a selector
  ("model.type") lists the registered types. Collective.
@*/
PetscErrorCode PeriSceneHelp(MPI_Comm comm, PetscInt nowners, const PeriSchemaOwner owners[])
{
  const PeriSchema *root = RootSchema(nowners, owners);
  RowCtx            c    = {comm, nowners, owners, NULL, 0, 0};

  PetscFunctionBeginUser;
  PetscCheck(root, PETSC_COMM_SELF, PETSC_ERR_PLIB, "no core schema declares the root keys");
  PetscCall(PeriSchemaCheck(nowners, owners));
  PetscCall(PetscPrintf(comm, "Scene keys (YAML; every scalar key is also an option: its path joined with '_', e.g. -material_nu 0.1):\n"));
  for (const PeriKey *top = root->keys; top->name; top++) PetscCall(ForEachRow(nowners, owners, root, top, HelpRow, &c));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Appends the n characters of text to the tables being built, with '|' escaped in table cells. */
static PetscErrorCode PutN(RowCtx *c, PetscBool cell, const char text[], size_t n)
{
  PetscFunctionBeginUser;
  for (size_t k = 0; k < n; k++) {
    if (c->len + 3 > c->cap) {
      c->cap = 2 * c->cap + 4096;
      PetscCall(PetscRealloc(c->cap, &c->buf));
    }
    if (cell && text[k] == '|') c->buf[c->len++] = '\\';
    c->buf[c->len++] = text[k];
  }
  if (c->buf) c->buf[c->len] = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Put(RowCtx *c, PetscBool cell, const char text[])
{
  PetscFunctionBeginUser;
  PetscCall(PutN(c, cell, text, strlen(text)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* "| cell " for each cell, then "|\n". */
static PetscErrorCode PutRow(RowCtx *c, PetscInt n, ...)
{
  va_list ap;

  PetscFunctionBeginUser;
  va_start(ap, n);
  for (PetscInt k = 0; k < n; k++) {
    const char *cell = va_arg(ap, const char *);
    PetscCall(Put(c, PETSC_FALSE, "| "));
    PetscCall(Put(c, PETSC_TRUE, cell[0] ? cell : "—"));
    PetscCall(Put(c, PETSC_FALSE, " "));
  }
  va_end(ap);
  PetscCall(Put(c, PETSC_FALSE, "|\n"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static const char *TypeName(PeriKeyType t)
{
  static const char *const names[] = {"number", "whole number", "boolean", "string", "string", "list of numbers", "list of booleans", "mapping", "list"};
  return names[t];
}

/* The option of path: "-regions_NAME_side" for a pattern "regions.<name>.side"; a mapping's
 * options name its entries ("-material_rho_by_region_KEY"). */
static void DocOption(const PeriKey *key, const char path[], char opt[], size_t len)
{
  size_t    k      = 0;
  PetscBool inside = PETSC_FALSE;

  opt[k++] = '`';
  opt[k++] = '-';
  for (const char *p = path; *p && k + 8 < len; p++) {
    if (*p == '<' || *p == '>')
      inside = (PetscBool)(*p == '<');
    else
      opt[k++] = *p == '.' ? '_' : inside ? (char)toupper((unsigned char)*p)
                                          : *p;
  }
  snprintf(opt + k, len - k, "%s`", key->type == PERI_KEY_MAP ? "_KEY" : "");
}

/* One table row: key, type, units, default, allowed, meaning, option. */
static PetscErrorCode DocRow(const PeriSchemaOwner *owner, const PeriSchema *sec, const PeriKey *key, void *ctx)
{
  RowCtx *c = (RowCtx *)ctx;
  char    path[256], name[260], deflt[256] = "", allowed[600], meaning[1024] = "", opt[300];

  PetscFunctionBeginUser;
  PeriSchemaPath(sec, key, path, sizeof(path));
  PetscCall(PetscSNPrintf(name, sizeof(name), "`%s`", path));
  if (key->deflt) PetscCall(PetscSNPrintf(deflt, sizeof(deflt), "%s", key->deflt));
  SelectorTypes(c, sec, key, ", ", "`", allowed, sizeof(allowed));
  if (!allowed[0]) Choices(key, ", ", "`", allowed, sizeof(allowed));
  if (!allowed[0] && key->range) PetscCall(PetscSNPrintf(allowed, sizeof(allowed), "%s", key->range));
  if (owner && strcmp(owner->kind, "core")) PetscCall(PetscSNPrintf(meaning, sizeof(meaning), "%s `%s` only: ", owner->kind, owner->name));
  PetscCall(PetscSNPrintf(meaning + strlen(meaning), sizeof(meaning) - strlen(meaning), "%s", key->help));
  DocOption(key, path, opt, sizeof(opt));
  PetscCall(PutRow(c, 7, name, TypeName(key->type), key->units ? key->units : "", deflt, allowed, meaning, opt));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The table of the root key top, into c->buf (emptied first). */
static PetscErrorCode DocTable(RowCtx *c, const PeriSchema *root, const PeriKey *top)
{
  PetscFunctionBeginUser;
  c->len = 0;
  PetscCall(Put(c, PETSC_FALSE, "| key | type | units | default | allowed | meaning | option |\n|---|---|---|---|---|---|---|\n"));
  PetscCall(ForEachRow(c->nowners, c->owners, root, top, DocRow, c));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ReadWhole(const char file[], char **text)
{
  FILE *fp = fopen(file, "rb");
  long  n;

  PetscFunctionBeginUser;
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot open %s: %s", file, strerror(errno));
  fseek(fp, 0, SEEK_END);
  n = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  PetscCall(PetscMalloc1(n + 1, text));
  (*text)[fread(*text, 1, (size_t)n, fp)] = 0;
  fclose(fp);
  PetscFunctionReturn(PETSC_SUCCESS);
}

#define DOC_OPEN  "<!-- keys "
#define DOC_CLOSE "<!-- /keys -->"

/* The root key a table marker names ("<!-- keys material -->"), or a PETSC_ERR_USER_INPUT. */
static PetscErrorCode MarkerKey(const char file[], const char *mark, const PeriSchema *root, const PeriKey **top, const char **body)
{
  const char *name = mark + strlen(DOC_OPEN), *end = strstr(name, " -->");
  const char *close = strstr(name, DOC_CLOSE);

  PetscFunctionBeginUser;
  *top = NULL;
  PetscCheck(end && close && end < close, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: a '%s' marker without ' -->' or without '%s' after it", file, DOC_OPEN, DOC_CLOSE);
  for (const PeriKey *k = root->keys; k->name; k++)
    if (strlen(k->name) == (size_t)(end - name) && !strncmp(k->name, name, (size_t)(end - name))) *top = k;
  PetscCheck(*top, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: the marker '%.*s' names no root key of the scene", file, (int)(end - mark + 4), mark);
  *body = strchr(end, '\n') ? strchr(end, '\n') + 1 : end + 4;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A root key without a table in the file: each must have one, so that none goes undocumented. */
static PetscErrorCode CheckEveryTable(const char file[], const PeriSchema *root, const PetscBool seen[])
{
  PetscFunctionBeginUser;
  for (const PeriKey *k = root->keys; k->name; k++) PetscCheck(seen[k - root->keys], PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: no key table for '%s': add the lines '%s%s -->' and '%s' where it belongs", file, k->name, DOC_OPEN, k->name, DOC_CLOSE);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneDocUpdate - regenerates the key tables of file (docs/scene.md) from the schemas: each
  table lies between "<!-- keys ROOTKEY -->" and "<!-- /keys -->" and lists the keys declared
  under that root key; the prose around them is left as it is. With check the file is not
  written: a table that differs is an error naming its section (the scene_doc test). Rank 0 of
  comm writes. Collective.
@*/
PetscErrorCode PeriSceneDocUpdate(MPI_Comm comm, const char file[], PetscBool check, PetscInt nowners, const PeriSchemaOwner owners[])
{
  const PeriSchema *root  = RootSchema(nowners, owners);
  RowCtx            table = {comm, nowners, owners, NULL, 0, 0}, out = table;
  PetscBool         seen[PERI_SECTION_MAX_KEYS] = {PETSC_FALSE};
  char             *text;
  const char       *p, *mark;
  PetscMPIInt       rank;

  PetscFunctionBeginUser;
  PetscCheck(root, PETSC_COMM_SELF, PETSC_ERR_PLIB, "no core schema declares the root keys");
  PetscCall(PeriSchemaCheck(nowners, owners));
  PetscCall(ReadWhole(file, &text));
  for (p = text; (mark = strstr(p, DOC_OPEN)); p = strstr(p, DOC_CLOSE)) {
    const PeriKey *top;
    const char    *body;
    size_t         n;
    PetscCall(MarkerKey(file, mark, root, &top, &body));
    n = (size_t)(strstr(body, DOC_CLOSE) - body);
    PetscCall(DocTable(&table, root, top));
    PetscCheck(!check || (table.len == n && !strncmp(table.buf, body, n)), PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: the key table of '%s' is out of date (the tables come from the keys declared in the code): run perilin -scene_doc_update %s", file, top->name, file);
    seen[top - root->keys] = PETSC_TRUE;
    PetscCall(PutN(&out, PETSC_FALSE, p, (size_t)(body - p)));
    PetscCall(Put(&out, PETSC_FALSE, table.buf));
    p = body;
  }
  PetscCall(Put(&out, PETSC_FALSE, p));
  PetscCall(PetscFree(text));
  PetscCall(PetscFree(table.buf));
  PetscCall(CheckEveryTable(file, root, seen));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (!check && !rank) {
    FILE *fp = fopen(file, "wb");
    PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot write %s: %s", file, strerror(errno));
    fputs(out.buf, fp);
    PetscCheck(!fclose(fp), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write %s: %s", file, strerror(errno));
  }
  PetscCall(PetscFree(out.buf));
  PetscFunctionReturn(PETSC_SUCCESS);
}
