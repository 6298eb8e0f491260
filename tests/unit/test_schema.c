/* Every declared scene key (the core's, every model's and every analysis', from PeriSchemaOwners:
 * a new plug-in is covered with no edit) is well formed: a name, a help line, names unique in
 * their section and no plug-in key shadowing a core key there; choices for a choice key; and a
 * numeric default that parses and lies in its numeric range ("[a, b]", "(a, inf)"), a choice
 * default among the choices, a boolean default true or false. Defaults in words ("required",
 * "the model's fixed value") and symbolic ranges ("(0, load_factor_max]") are left alone. */
#include "testing.h"
#include <stdlib.h>

/* x parsed whole as a number (or inf) */
static PetscBool Number(const char s[], PetscReal *x)
{
  char *end;
  while (*s == ' ') s++;
  if (!strncmp(s, "inf", 3) && (s[3] == 0 || s[3] == ' ')) {
    *x = PETSC_INFINITY;
    return PETSC_TRUE;
  }
  *x = (PetscReal)strtod(s, &end);
  while (*end == ' ') end++;
  return (PetscBool)(end != s && *end == 0);
}

/* "[a, b)" with numeric ends: the interval; otherwise PETSC_FALSE */
static PetscBool Interval(const char range[], PetscReal *lo, PetscReal *hi, PetscBool *lo_open, PetscBool *hi_open)
{
  char        a[64], b[64];
  const char *comma = range ? strchr(range, ',') : NULL;
  size_t      n     = range ? strlen(range) : 0;

  if (!comma || n < 5 || (range[0] != '[' && range[0] != '(') || (range[n - 1] != ']' && range[n - 1] != ')')) return PETSC_FALSE;
  if ((size_t)(comma - range - 1) >= sizeof(a) || n - (size_t)(comma - range) >= sizeof(b)) return PETSC_FALSE;
  snprintf(a, sizeof(a), "%.*s", (int)(comma - range - 1), range + 1);
  snprintf(b, sizeof(b), "%.*s", (int)(n - (size_t)(comma - range) - 2), comma + 1);
  *lo_open = (PetscBool)(range[0] == '(');
  *hi_open = (PetscBool)(range[n - 1] == ')');
  return (PetscBool)(Number(a, lo) && Number(b, hi));
}

static PetscErrorCode CheckDefault(const char where[], const PeriKey *k)
{
  PetscReal x, lo, hi;
  PetscBool lo_open, hi_open;

  PetscFunctionBeginUser;
  if (!k->deflt) PetscFunctionReturn(PETSC_SUCCESS);
  if ((k->type == PERI_KEY_REAL || k->type == PERI_KEY_INT) && Number(k->deflt, &x) && Interval(k->range, &lo, &hi, &lo_open, &hi_open))
    PetscCheck((lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: default %s outside its range %s", where, k->deflt, k->range);
  if (k->type == PERI_KEY_BOOL) PetscCheck(!strcmp(k->deflt, "true") || !strcmp(k->deflt, "false"), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: boolean default '%s'", where, k->deflt);
  if (k->type == PERI_KEY_CHOICE && strcmp(k->deflt, "required")) {
    PetscBool found = PETSC_FALSE;
    for (PetscInt c = 0; k->choices[c]; c++) found = (PetscBool)(found || !strcmp(k->choices[c], k->deflt));
    PetscCheck(found, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: default '%s' is not among its choices", where, k->deflt);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* the same name in section, declared by the core (when owner is a plug-in) or earlier in the same owner */
static PetscBool Shadows(const PeriSchemaOwner owners[], PetscInt n, PetscInt o, const char section[], const PeriKey *k)
{
  for (PetscInt q = 0; q < n; q++) {
    if (q != o && (strcmp(owners[q].kind, "core") || !strcmp(owners[o].kind, "core"))) continue;
    for (const PeriSchema *s = owners[q].schema; s && s->section; s++) {
      if (strcmp(s->section, section)) continue;
      for (const PeriKey *j = s->keys; j->name && j != k; j++)
        if (!strcmp(j->name, k->name) && (q != o || j < k)) return PETSC_TRUE;
    }
  }
  return PETSC_FALSE;
}

int main(int argc, char **argv)
{
  PeriSchemaOwner owners[64];
  PetscInt        n, nkeys = 0, ndefaults = 0;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCall(PeriSchemaOwners(64, owners, &n));
  for (PetscInt o = 0; o < n; o++)
    for (const PeriSchema *s = owners[o].schema; s && s->section; s++)
      for (const PeriKey *k = s->keys; k->name; k++) {
        char where[256];
        PetscCall(PetscSNPrintf(where, sizeof(where), "%s %s: key '%s%s%s'", owners[o].kind, owners[o].name, s->section, s->section[0] ? "." : "", k->name));
        PetscCheck(k->name[0] && k->help && k->help[0], PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: no help line", where);
        PetscCheck(k->type != PERI_KEY_CHOICE || (k->choices && k->choices[0]), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: a choice without choices", where);
        PetscCheck(!Shadows(owners, n, o, s->section, k), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: declared twice in its section", where);
        PetscCall(CheckDefault(where, k));
        nkeys++;
        ndefaults += k->deflt != NULL;
      }
  PetscCheck(nkeys > 50, PETSC_COMM_SELF, PETSC_ERR_PLIB, "only %" PetscInt_FMT " keys declared: a schema is missing", nkeys);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %" PetscInt_FMT " keys of %" PetscInt_FMT " owners well formed (help, unique names, %" PetscInt_FMT " defaults within their declared choices and ranges)\n", nkeys, n, ndefaults));
  PetscCall(PeriFinalize());
  return 0;
}
