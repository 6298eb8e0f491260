/* The declarations applied by the typed getters (include/perilin/scene.h): the declaration of a
 * key read in a section, its range parsed and enforced, its default parsed for the key's type.
 * PeriSchemaCheck refuses at start-up a range this file cannot read. */
#include "perilin/private/scene_file.h"
#include <ctype.h>
#include <errno.h>

#define RANGE_MAX_SET 16

/* A declared range: a set {a, b, ..} or an interval whose ends are numbers; an end that names
 * another key ("(0, load_factor_max]") is the reader's to check, and is open to the getter. */
typedef struct {
  PetscBool set;
  PetscInt  n;
  PetscReal v[RANGE_MAX_SET];
  PetscReal lo, hi;
  PetscBool lo_open, hi_open;
} Range;

/* The n characters at s without the spaces around them, into buf. */
static void Trim(const char s[], size_t n, char buf[], size_t len)
{
  while (n && isspace((unsigned char)s[0])) s++, n--;
  while (n && isspace((unsigned char)s[n - 1])) n--;
  snprintf(buf, len, "%.*s", (int)PetscMin(n, len - 1), s);
}

/* The n characters at s, whole, as a number: a decimal, a fraction a/b, inf or -inf. */
static PetscBool ParseNumber(const char s[], size_t n, PetscReal *x)
{
  char   buf[64], *end;
  double a, b = 1;

  Trim(s, n, buf, sizeof(buf));
  if (!strcmp(buf, "inf") || !strcmp(buf, "+inf") || !strcmp(buf, "-inf")) {
    *x = buf[0] == '-' ? PETSC_NINFINITY : PETSC_INFINITY;
    return PETSC_TRUE;
  }
  errno = 0;
  a     = strtod(buf, &end);
  if (end == buf || isalpha((unsigned char)buf[0])) return PETSC_FALSE;
  if (*end == '/') {
    const char *d = end + 1;
    b             = strtod(d, &end);
    if (end == d || b == 0) return PETSC_FALSE;
  }
  *x = (PetscReal)(a / b);
  return (PetscBool)(!*end && errno != ERANGE && !PetscIsInfOrNanReal(*x));
}

/* The n characters at s as a bound naming a key of sec's section, maybe scaled:
 * "load_factor_step/2^20". The key may be declared in any entry of the owner's schema for that
 * section (the failure criteria declare failure.* in one entry each); with schema NULL (a getter,
 * after PeriSchemaCheck verified every declaration at start-up) any key name is taken. */
static PetscBool ParseSymbol(const PeriSchema *schema, const PeriSchema *sec, const char s[], size_t n)
{
  char   buf[128];
  size_t id = 0;

  Trim(s, n, buf, sizeof(buf));
  while (isalnum((unsigned char)buf[id]) || buf[id] == '_') id++;
  if (!id || isdigit((unsigned char)buf[0])) return PETSC_FALSE;
  for (const char *c = buf + id; *c; c++)
    if (!strchr("0123456789.+-*/^ ", *c)) return PETSC_FALSE;
  if (!schema) return PETSC_TRUE;
  for (const PeriSchema *e = schema; e->section; e++) {
    if (strcmp(e->section, sec->section)) continue;
    for (const PeriKey *k = e->keys; k->name; k++)
      if (strlen(k->name) == id && !strncmp(k->name, buf, id)) return PETSC_TRUE;
  }
  return PETSC_FALSE;
}

/* One end of an interval: a number, or a key of sec (then no bound to the getter: none). */
static PetscBool ParseEnd(const PeriSchema *schema, const PeriSchema *sec, const char s[], size_t n, PetscReal none, PetscReal *x, PetscBool *open)
{
  if (ParseNumber(s, n, x)) return PETSC_TRUE;
  *x    = none;
  *open = PETSC_FALSE;
  return ParseSymbol(schema, sec, s, n);
}

/* The range of key (declared in sec); *ok false when it is not one of the forms. No range: all. */
static void ParseRange(const PeriSchema *schema, const PeriSchema *sec, const PeriKey *key, Range *r, PetscBool *ok)
{
  const char *s = key->range, *comma;
  size_t      n = s ? strlen(s) : 0;

  *r  = (Range){PETSC_FALSE, 0, {0}, PETSC_NINFINITY, PETSC_INFINITY, PETSC_FALSE, PETSC_FALSE};
  *ok = (PetscBool)!s;
  if (!s || n < 3) return;
  if (s[0] == '{' && s[n - 1] == '}') {
    const char *item = s + 1;
    r->set           = PETSC_TRUE;
    for (*ok = PETSC_TRUE; *ok && item < s + n; item = comma + 1) {
      comma = strchr(item, ',');
      if (!comma) comma = s + n - 1;
      *ok = (PetscBool)(r->n < RANGE_MAX_SET && ParseNumber(item, (size_t)(comma - item), &r->v[r->n++]));
    }
    return;
  }
  comma = strchr(s, ',');
  if (!strchr("[(", s[0]) || !strchr("])", s[n - 1]) || !comma || strchr(comma + 1, ',')) return;
  r->lo_open = (PetscBool)(s[0] == '(');
  r->hi_open = (PetscBool)(s[n - 1] == ')');
  *ok        = (PetscBool)(ParseEnd(schema, sec, s + 1, (size_t)(comma - s - 1), PETSC_NINFINITY, &r->lo, &r->lo_open) && ParseEnd(schema, sec, comma + 1, (size_t)(s + n - 2 - comma), PETSC_INFINITY, &r->hi, &r->hi_open));
}

static PetscBool RangeHolds(const Range *r, PetscReal x)
{
  if (r->set) {
    for (PetscInt k = 0; k < r->n; k++)
      if (x == r->v[k]) return PETSC_TRUE;
    return PETSC_FALSE;
  }
  return (PetscBool)((r->lo_open ? x > r->lo : x >= r->lo) && (r->hi_open ? x < r->hi : x <= r->hi));
}

/* Whether key declares a default at all: not NULL, not "required". */
static PetscBool HasDefault(const PeriKey *key)
{
  return (PetscBool)(key->deflt && strcmp(key->deflt, "required"));
}

PetscBool PeriKeyDefaultReal(const PeriKey *key, PetscReal *x)
{
  return (PetscBool)(key->type == PERI_KEY_REAL && HasDefault(key) && ParseNumber(key->deflt, strlen(key->deflt), x));
}

PetscBool PeriKeyDefaultInt(const PeriKey *key, PetscInt *v)
{
  char *end;
  long  l;

  if (key->type != PERI_KEY_INT || !HasDefault(key)) return PETSC_FALSE;
  errno = 0;
  l     = strtol(key->deflt, &end, 10);
  *v    = (PetscInt)l;
  return (PetscBool)(end != key->deflt && !*end && errno != ERANGE && l >= PETSC_MIN_INT && l <= PETSC_MAX_INT);
}

PetscBool PeriKeyDefaultBool(const PeriKey *key, PetscBool *v)
{
  if (key->type != PERI_KEY_BOOL || !HasDefault(key) || (strcmp(key->deflt, "true") && strcmp(key->deflt, "false"))) return PETSC_FALSE;
  *v = (PetscBool)!strcmp(key->deflt, "true");
  return PETSC_TRUE;
}

/* A string default is one word (letters, digits, _ - . /); a choice default one of the choices. */
PetscBool PeriKeyDefaultString(const PeriKey *key, const char **s)
{
  if (!HasDefault(key) || (key->type != PERI_KEY_STRING && key->type != PERI_KEY_CHOICE) || !key->deflt[0]) return PETSC_FALSE;
  *s = key->deflt;
  if (key->type == PERI_KEY_CHOICE) {
    for (const char *const *c = key->choices; c && *c; c++)
      if (!strcmp(*c, key->deflt)) return PETSC_TRUE;
    return PETSC_FALSE;
  }
  for (const char *c = key->deflt; *c; c++)
    if (!isalnum((unsigned char)*c) && !strchr("_-./", *c)) return PETSC_FALSE;
  return PETSC_TRUE;
}

/* A list default is a flow list of at most max numbers, "[0, 0]". */
PetscBool PeriKeyDefaultReals(const PeriKey *key, PetscInt max, PetscReal v[], PetscInt *n)
{
  const char *s = key->deflt, *item, *comma;
  size_t      len;

  *n = 0;
  if (key->type != PERI_KEY_REALS || !HasDefault(key) || (len = strlen(s)) < 2 || s[0] != '[' || s[len - 1] != ']') return PETSC_FALSE;
  for (item = s + 1; item < s + len - 1; item = comma + 1) {
    comma = strchr(item, ',');
    if (!comma) comma = s + len - 1;
    if (*n >= max || !ParseNumber(item, (size_t)(comma - item), &v[*n])) return PETSC_FALSE;
    (*n)++;
  }
  return PETSC_TRUE;
}

/*@C
  PeriSchemaCheck - refuses (PETSC_ERR_PLIB) a declaration the getters cannot apply: a range on a
  key that is not a number, a whole number or a list of numbers, a range not of the forms of
  scene.h, a default that applies but lies outside its range. Not collective.
@*/
PetscErrorCode PeriSchemaCheck(PetscInt nowners, const PeriSchemaOwner owners[])
{
  PetscFunctionBeginUser;
  for (PetscInt o = 0; o < nowners; o++)
    for (const PeriSchema *sec = owners[o].schema; sec && sec->section; sec++)
      for (const PeriKey *key = sec->keys; key->name; key++) {
        char      path[256];
        Range     r;
        PetscBool ok, has;
        PetscReal x;
        PetscInt  i;
        if (!key->range) continue;
        PeriSchemaPath(sec, key, path, sizeof(path));
        PetscCheck(key->type == PERI_KEY_REAL || key->type == PERI_KEY_INT || key->type == PERI_KEY_REALS, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s %s declares the range '%s' on key '%s', which is not numeric", owners[o].kind, owners[o].name, key->range, path);
        ParseRange(owners[o].schema, sec, key, &r, &ok);
        PetscCheck(ok, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s %s declares for key '%s' the range '%s', which the scene layer cannot read: write [a, b], (a, inf), (0, 1] or {2, 3}, an end a number, a fraction a/b, inf, or a key of the same section", owners[o].kind, owners[o].name, path, key->range);
        has = PeriKeyDefaultReal(key, &x);
        if (PeriKeyDefaultInt(key, &i)) x = (PetscReal)i, has = PETSC_TRUE;
        PetscCheck(!has || RangeHolds(&r, x), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s %s declares for key '%s' the default %s, outside its range %s", owners[o].kind, owners[o].name, path, key->deflt, key->range);
      }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the dotted path matches the section pattern component by component ("<k>": any). */
static PetscBool PathMatches(const char pattern[], const char path[])
{
  while (PETSC_TRUE) {
    size_t pl = strcspn(pattern, "."), ql = strcspn(path, ".");
    if (!pl != !ql) return PETSC_FALSE;
    if (!pl) return PETSC_TRUE;
    if (pattern[0] != '<' && (pl != ql || strncmp(pattern, path, pl))) return PETSC_FALSE;
    if (!pattern[pl] != !path[ql]) return PETSC_FALSE;
    if (!pattern[pl]) return PETSC_TRUE;
    pattern += pl + 1;
    path += ql + 1;
  }
}

/* Whether the plug-in owner is the scene's: its kind's type key ("model.type") names it, given
 * or by the core's declared default ("analysis.type": static). */
static PetscErrorCode OwnerActive(PeriScene scene, const PeriSchemaOwner *owner, PetscBool *active)
{
  char        path[128];
  PeriNode    node;
  const char *type = NULL;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s.type", owner->kind));
  PetscCall(PeriSceneGetNode(scene->root, path, &node));
  if (node && node->kind == PERI_NODE_SCALAR) type = node->value;
  for (PetscInt o = 0; !node && o < scene->nowners; o++) {
    const PeriKey *key = PeriSchemaFindKey(scene->owners[o].schema, owner->kind, "type");
    if (!strcmp(scene->owners[o].kind, "core") && key && !PeriKeyDefaultString(key, &type)) type = NULL;
  }
  *active = (PetscBool)(type && !strcmp(type, owner->name));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The key named name in the section matching section, declared by owner; NULL when none. */
static const PeriKey *OwnerKey(const PeriSchemaOwner *owner, const char section[], const char name[], const PeriSchema **sec)
{
  for (*sec = owner->schema; *sec && (*sec)->section; (*sec)++) {
    if (!PathMatches((*sec)->section, section)) continue;
    for (const PeriKey *key = (*sec)->keys; key->name; key++)
      if (!strcmp(key->name, name) || key->name[0] == '<') return key;
  }
  return NULL;
}

/*@C
  PeriSceneFindKey - the declaration of key read in map (a dotted key walks down from map): the
  core's, else the active plug-in's (scene.h), else the first plug-in's that declares it; NULL
  when none does, or map is NULL (an absent section: read it from the parent with a dotted key).
  Not collective.
@*/
PetscErrorCode PeriSceneFindKey(PeriScene scene, PeriNode map, const char key[], const PeriSchema **sec, const PeriKey **decl)
{
  char path[512], *dot;

  PetscFunctionBeginUser;
  *decl = NULL;
  *sec  = NULL;
  if (!map || !scene->nowners) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s%s%s", map->path, map->path[0] ? "." : "", key));
  dot = strrchr(path, '.');
  if (dot) *dot = 0;
  for (PetscInt pass = 0; pass < 3 && !*decl; pass++)
    for (PetscInt o = 0; o < scene->nowners && !*decl; o++) {
      PetscBool core = (PetscBool)!strcmp(scene->owners[o].kind, "core"), active = PETSC_TRUE;
      if (core != (pass == 0)) continue;
      if (pass == 1) PetscCall(OwnerActive(scene, &scene->owners[o], &active));
      if (active) *decl = OwnerKey(&scene->owners[o], dot ? path : "", dot ? dot + 1 : path, sec);
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneCheckRange - the value x of node (its text value) against the declared range of decl
  (NULL: none): "file:line: key 'a.b': must lie in (0, 1], got 2 (help)". Not collective.
@*/
PetscErrorCode PeriSceneCheckRange(PeriScene scene, PeriNode node, const PeriSchema *sec, const PeriKey *decl, PetscReal x, const char value[])
{
  Range     r;
  PetscBool ok;

  PetscFunctionBeginUser;
  if (!decl || !decl->range) PetscFunctionReturn(PETSC_SUCCESS);
  ParseRange(NULL, sec, decl, &r, &ok);
  PetscCheck(ok, PETSC_COMM_SELF, PETSC_ERR_PLIB, "key '%s' declares the range '%s', which the scene layer cannot read", node->path, decl->range);
  PeriInputCheck(RangeHolds(&r, x), scene, node, NULL, "must %s %s%s%s, got %s (%s)", r.set ? "be one of" : "lie in", decl->range, decl->units ? " " : "", decl->units ? decl->units : "", value, decl->help);
  PetscFunctionReturn(PETSC_SUCCESS);
}
