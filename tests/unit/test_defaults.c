/* The getters apply the declarations (include/perilin/scene.h): for every key of every schema of
 * every owner (PeriSchemaOwners: a new plug-in is covered with no edit), read from an empty
 * section of a scene (with the plug-in active: model.type: mppd), the getter of its type returns
 * the declared default parsed here on its own (a number or a fraction, a whole number, true or
 * false, a choice, one word), or leaves the variable alone, and says "not given" either way; and
 * a value just outside each numeric declared range ("[1, inf)": 0; "(0, 1]": 0; "{2, 3}": 4) is
 * refused as a user-input error. */
#include "testing.h"
#include <stdlib.h>
#include <unistd.h>

#define SENTINEL 12345.25

/* s parsed whole as a number, a fraction a/b, or +-inf */
static PetscBool Number(const char s[], size_t n, PetscReal *x)
{
  char   buf[64], *end, *b = buf;
  double a, d = 1;

  snprintf(buf, sizeof(buf), "%.*s", (int)PetscMin(n, sizeof(buf) - 1), s);
  while (*b == ' ') b++;
  for (char *e = b + strlen(b); e > b && e[-1] == ' '; e--) e[-1] = 0;
  if (!strcmp(b, "inf") || !strcmp(b, "-inf")) {
    *x = b[0] == '-' ? PETSC_NINFINITY : PETSC_INFINITY;
    return PETSC_TRUE;
  }
  a = strtod(b, &end);
  if (end == b || ((*b < '0' || *b > '9') && *b != '-' && *b != '.')) return PETSC_FALSE;
  if (*end == '/') d = strtod(end + 1, &end);
  *x = (PetscReal)(a / d);
  return (PetscBool)(!*end && d != 0);
}

/* A value just outside the numeric part of range, as text; PETSC_FALSE when it has none. */
static PetscBool Outside(const PeriKey *k, char out[], size_t len)
{
  const char *r = k->range, *comma = r ? strchr(r, ',') : NULL;
  size_t      n = r ? strlen(r) : 0;
  PetscReal   lo, hi, x;

  if (!r) return PETSC_FALSE;
  if (r[0] == '{') {
    PetscReal top = PETSC_NINFINITY;
    for (const char *item = r + 1; item < r + n; item = comma + 1) {
      if (!(comma = strchr(item, ','))) comma = r + n - 1;
      if (Number(item, (size_t)(comma - item), &x)) top = PetscMax(top, x);
    }
    snprintf(out, len, "%g", (double)(top + 1));
    return PETSC_TRUE;
  }
  if (Number(r + 1, (size_t)(comma - r - 1), &lo) && lo > PETSC_NINFINITY)
    x = r[0] == '(' ? lo : lo - 1;
  else if (Number(comma + 1, (size_t)(r + n - 2 - comma), &hi) && hi < PETSC_INFINITY)
    x = r[n - 1] == ')' ? hi : hi + 1;
  else
    return PETSC_FALSE;
  snprintf(out, len, k->type == PERI_KEY_REALS ? "[%g]" : "%g", (double)x);
  return PETSC_TRUE;
}

/* The YAML of the mapping at depth i of the section's components comps[0..n): leaf in the section. */
static void Mapping(char *const comps[], int n, int i, const char leaf[], char out[], size_t len)
{
  char val[1024], m[1000];

  if (i == n) {
    snprintf(out, len, "{%s}", leaf);
    return;
  }
  if (i + 1 < n && comps[i + 1][0] == '<') {
    Mapping(comps, n, i + 2, leaf, m, sizeof(m));
    snprintf(val, sizeof(val), !strcmp(comps[i + 1], "<k>") ? "[%s]" : "{x: %s}", m);
  } else
    Mapping(comps, n, i + 1, leaf, val, sizeof(val));
  snprintf(out, len, "{%s: %.900s}", comps[i], val);
}

/* A scene file holding the section of owner, the plug-in active, with key: value (value NULL: the
 * section empty); *map its section's node. */
static PetscErrorCode SceneWith(const PeriSchemaOwner *o, const char section[], const char key[], const char value[], const char file[], PeriScene *scene, PeriNode *map)
{
  PeriSchemaOwner owners[PERI_MAX_SCHEMA_OWNERS];
  PetscInt        nowners;
  char            leaf[512] = "", text[2048], sec[256], *comps[16];
  int             n         = 0;
  PetscBool       plugin    = (PetscBool)strcmp(o->kind, "core");
  FILE           *fp;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(sec, section, sizeof(sec)));
  for (char *c = strtok(sec, "."); c && n < 16; c = strtok(NULL, ".")) comps[n++] = c;
  if (plugin && n == 1 && !strcmp(comps[0], o->kind)) snprintf(leaf, sizeof(leaf), "type: %s%s", o->name, value ? ", " : "");
  if (value) snprintf(leaf + strlen(leaf), sizeof(leaf) - strlen(leaf), "%s: %s", key, value);
  Mapping(comps, n, 0, leaf, text, sizeof(text));
  if (plugin && n > 1 && !strcmp(comps[0], o->kind)) {
    /* a sub-section of the plug-in's own section (analysis.pulse): the type goes beside it */
    char        more[2100];
    const char *inner = strchr(text + 1, '{');
    snprintf(more, sizeof(more), "%.*s{type: %s, %s", (int)(inner - text), text, o->name, inner + 1);
    PetscCall(PetscStrncpy(text, more, sizeof(text)));
  } else if (plugin && (n != 1 || strcmp(comps[0], o->kind))) {
    char   more[2100];
    size_t inner = strlen(text) - 2; /* text without its braces */
    snprintf(more, sizeof(more), "{%s: {type: %s}%s%.*s}", o->kind, o->name, inner ? ", " : "", (int)inner, text + 1);
    PetscCall(PetscStrncpy(text, more, sizeof(text)));
  }
  PetscCheck((fp = fopen(file, "w")), PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot write %s", file);
  fprintf(fp, "%s\n", text);
  fclose(fp);
  PetscCall(PeriSchemaOwners(PERI_MAX_SCHEMA_OWNERS, owners, &nowners));
  PetscCall(PeriSceneCreateFromFile(file, nowners, owners, scene));
  *map = (*scene)->root;
  for (int i = 0; i < n && *map; i++) {
    if (comps[i][0] == '<')
      *map = (*map)->n ? (*map)->child[0] : NULL;
    else
      PetscCall(PeriSceneGetNode(*map, comps[i], map));
  }
  PetscCheck(*map && (*map)->kind == PERI_NODE_MAP, PETSC_COMM_SELF, PETSC_ERR_PLIB, "no section %s in the scene %s", section, text);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The key read from an empty section: the declared default, or the variable left alone. */
static PetscErrorCode CheckDefault(PeriScene s, PeriNode map, const PeriKey *k, const char name[], const char where[], PetscInt *napplied)
{
  PetscBool   found = PETSC_TRUE, given = (PetscBool)(k->deflt && strcmp(k->deflt, "required")), b = (PetscBool)7;
  PetscReal   x = SENTINEL, want = SENTINEL, v[16];
  PetscInt    i = -7, nv = -1, want_i = -7;
  char        str[256] = "sentinel";
  const char *want_s   = "sentinel";

  PetscFunctionBeginUser;
  switch (k->type) {
  case PERI_KEY_REAL:
    PetscCall(PeriSceneGetReal(s, map, name, PETSC_FALSE, &x, &found));
    if (given && !Number(k->deflt, strlen(k->deflt), &want)) want = SENTINEL; /* a default in words documents the reader's rule */
    PetscCheck(x == want, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: read %g from an empty section, the declared default is '%s'", where, (double)x, k->deflt ? k->deflt : "none");
    *napplied += x != SENTINEL;
    break;
  case PERI_KEY_INT:
    PetscCall(PeriSceneGetInt(s, map, name, PETSC_FALSE, &i, &found));
    if (given && Number(k->deflt, strlen(k->deflt), &want) && want == (PetscInt)want) want_i = (PetscInt)want;
    PetscCheck(i == want_i, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: read %" PetscInt_FMT " from an empty section, the declared default is '%s'", where, i, k->deflt ? k->deflt : "none");
    *napplied += i != -7;
    break;
  case PERI_KEY_BOOL:
    PetscCall(PeriSceneGetBool(s, map, name, &b, &found));
    PetscCheck((int)b == (given && !strcmp(k->deflt, "true") ? 1 : given && !strcmp(k->deflt, "false") ? 0
                                                                                                       : 7),
               PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: read %d from an empty section, the declared default is '%s'", where, (int)b, k->deflt ? k->deflt : "none");
    *napplied += (int)b != 7;
    break;
  case PERI_KEY_STRING:
  case PERI_KEY_CHOICE:
    if (given && !strpbrk(k->deflt, " <>()")) want_s = k->deflt;
    if (k->type == PERI_KEY_STRING)
      PetscCall(PeriSceneGetString(s, map, name, PETSC_FALSE, str, sizeof(str), &found));
    else {
      PetscCall(PeriSceneGetChoice(s, map, name, k->choices, &i, &found));
      for (PetscInt c = 0; given && k->choices[c]; c++)
        if (!strcmp(k->choices[c], k->deflt)) want_i = c;
      PetscCheck(i == want_i, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: read choice %" PetscInt_FMT " from an empty section, the declared default is '%s'", where, i, k->deflt ? k->deflt : "none");
      if (i >= 0) PetscCall(PetscStrncpy(str, k->choices[i], sizeof(str)));
    }
    PetscCheck(!strcmp(str, want_s), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: read '%s' from an empty section, the declared default is '%s'", where, str, k->deflt ? k->deflt : "none");
    *napplied += strcmp(str, "sentinel") != 0;
    break;
  case PERI_KEY_REALS:
    PetscCall(PeriSceneGetRealArray(s, map, name, PETSC_FALSE, 0, 16, v, &nv));
    found = (PetscBool)(nv > 0);
    PetscCheck(nv == 0 || (given && k->deflt[0] == '['), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: read %" PetscInt_FMT " numbers from an empty section, the declared default is '%s'", where, nv, k->deflt ? k->deflt : "none");
    *napplied += nv > 0;
    break;
  default:
    break;
  }
  PetscCheck(!found || k->type == PERI_KEY_REALS, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: an absent key reported as given", where);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The key set to a value outside its range: a user-input error from the getter. */
static PetscErrorCode CheckRefused(PeriScene s, PeriNode map, const PeriKey *k, const char name[], const char where[], const char value[])
{
  PetscErrorCode ierr = PETSC_SUCCESS;
  PetscReal      x, v[16];
  PetscInt       i, n;

  PetscFunctionBeginUser;
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  if (k->type == PERI_KEY_REAL) ierr = PeriSceneGetReal(s, map, name, PETSC_FALSE, &x, NULL);
  if (k->type == PERI_KEY_INT) ierr = PeriSceneGetInt(s, map, name, PETSC_FALSE, &i, NULL);
  if (k->type == PERI_KEY_REALS) ierr = PeriSceneGetRealArray(s, map, name, PETSC_FALSE, 0, 16, v, &n);
  PetscCall(PetscPopErrorHandler());
  PetscCheck(ierr == PETSC_ERR_USER_INPUT, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: the value %s outside the range %s was not refused (error %d)", where, value, k->range, (int)ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  PeriSchemaOwner owners[PERI_MAX_SCHEMA_OWNERS];
  PetscInt        n, nkeys = 0, napplied = 0, nrefused = 0;
  char            file[PETSC_MAX_PATH_LEN];
  const char     *tmp = getenv("TMPDIR");

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCall(PetscSNPrintf(file, sizeof(file), "%s/perilin_defaults_%d.yaml", tmp && tmp[0] ? tmp : "/tmp", (int)getpid()));
  PetscCall(PeriSchemaOwners(PERI_MAX_SCHEMA_OWNERS, owners, &n));
  for (PetscInt o = 0; o < n; o++)
    for (const PeriSchema *sec = owners[o].schema; sec && sec->section; sec++)
      for (const PeriKey *k = sec->keys; k->name; k++) {
        const char *name = k->name[0] == '<' ? "p" : k->name;
        char        where[512], value[64];
        PeriScene   scene;
        PeriNode    map;
        if (k->type == PERI_KEY_MAP || k->type == PERI_KEY_LIST || k->type == PERI_KEY_BOOLS) continue;
        PetscCall(PetscSNPrintf(where, sizeof(where), "%s %s: key '%s%s%s'", owners[o].kind, owners[o].name, sec->section, sec->section[0] ? "." : "", k->name));
        PetscCall(SceneWith(&owners[o], sec->section, name, NULL, file, &scene, &map));
        PetscCall(CheckDefault(scene, map, k, name, where, &napplied));
        PetscCall(PeriSceneDestroy(&scene));
        nkeys++;
        if (!Outside(k, value, sizeof(value))) continue;
        PetscCall(SceneWith(&owners[o], sec->section, name, value, file, &scene, &map));
        PetscCall(CheckRefused(scene, map, k, name, where, value));
        PetscCall(PeriSceneDestroy(&scene));
        nrefused++;
      }
  remove(file);
  PetscCheck(napplied > 10 && nrefused > 10, PETSC_COMM_SELF, PETSC_ERR_PLIB, "too few defaults (%" PetscInt_FMT ") or ranges (%" PetscInt_FMT ") checked", napplied, nrefused);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %" PetscInt_FMT " keys read from empty sections, %" PetscInt_FMT " declared defaults applied, %" PetscInt_FMT " out-of-range values refused\n", nkeys, napplied, nrefused));
  PetscCall(PeriFinalize());
  return 0;
}
