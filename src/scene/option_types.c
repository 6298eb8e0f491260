/* Solver types named by options (-ksp_type, -pc_type, -st_type, with any prefix: -st_ksp_type,
 * -mg_levels_pc_type), checked against PETSc's and SLEPc's registered lists before any solver
 * reads them. PETSc 3.18 refuses an unknown type from inside KSPSetFromOptions, PCSetFromOptions
 * or STSetFromOptions, whose error path returns before it frees a 16-byte copy of the name (a leak
 * under -malloc_dump, docs/reliability.md): refused here first, PETSc never takes that path, and
 * the message names the option, the types allowed and the closest of them. */
#include "perilin/private/scene_file.h"
#include <petscksp.h>
#include <slepcst.h>

/* The options whose value is a type, by the end of their name, the word PETSc's own refusal uses
 * ("Unable to find requested KSP type x", kept so that messages read the same) and the list. */
typedef struct {
  const char        *suffix, *kind;
  PetscFunctionList *list;
} TypeOption;

/* The registered names of list, NULL-ended (for the suggestion), in *names; free with PetscFree. */
static PetscErrorCode ListNames(PetscFunctionList list, const char ***names)
{
  const char **got = NULL;
  int          n   = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListGet(list, &got, &n));
  PetscCall(PetscMalloc1(n + 1, names));
  for (int k = 0; k < n; k++) (*names)[k] = got[k];
  (*names)[n] = NULL;
  PetscCall(PetscFree(got));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* msg (len bytes): why option name's value is no registered type of t, or "" when it is one. */
static PetscErrorCode CheckOne(const TypeOption *t, const char name[], const char value[], char msg[], size_t len)
{
  PetscErrorCode (*create)(void) = NULL;
  const char **names;
  char         hint[128];
  size_t       at;

  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListFind(*t->list, value, &create));
  if (create) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(ListNames(*t->list, &names));
  PeriSceneSuggest(value, names, hint, sizeof(hint));
  PetscCall(PetscSNPrintf(msg, len, "Unable to find requested %s type %s, given by %s (%s%sthe %s types: ", t->kind, value, name, hint, hint[0] ? "; " : "", t->kind));
  for (PetscInt k = 0; names[k]; k++) {
    PetscCall(PetscStrlen(msg, &at));
    PetscCall(PetscSNPrintf(msg + at, len - at, "%s%s", k ? ", " : "", names[k]));
  }
  PetscCall(PetscStrlcat(msg, ")", len));
  PetscCall(PetscFree(names));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether an option name (with its '-') ends with the part suffix, as a whole word. */
static PetscBool EndsWith(const char name[], const char suffix[])
{
  size_t n = strlen(name), s = strlen(suffix);
  return (PetscBool)(n > s && !strcmp(name + n - s, suffix) && (name[n - s - 1] == '-' || name[n - s - 1] == '_'));
}

/*@C
  PeriOptionsEachValue - calls check(name, value, ctx, msg, len) for every option of the option
  string opts ("-ksp_type cg -pc_type gamg", as PetscOptionsGetAll gives the database) that has a
  value, in order, until one sets msg (len bytes; "" when none does). A token starting with '-'
  is an option's name: no value this walk serves (a type, a boolean) starts with one. Not
  collective.
@*/
PetscErrorCode PeriOptionsEachValue(const char opts[], PetscErrorCode (*check)(const char[], const char[], void *, char[], size_t), void *ctx, char msg[], size_t len)
{
  char *copy, *tok, *save = NULL, *name = NULL;

  PetscFunctionBeginUser;
  msg[0] = 0;
  PetscCall(PetscStrallocpy(opts, &copy));
  for (tok = strtok_r(copy, " \t\n", &save); tok && !msg[0]; tok = strtok_r(NULL, " \t\n", &save)) {
    if (tok[0] == '-') {
      name = tok;
      continue;
    }
    if (name) PetscCall(check(name, tok, ctx, msg, len));
    name = NULL;
  }
  PetscCall(PetscFree(copy));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* PeriOptionsEachValue's check for the solver types (ctx: the TypeOption table, NULL-ended) */
static PetscErrorCode CheckTypeValue(const char name[], const char value[], void *ctx, char msg[], size_t len)
{
  PetscFunctionBeginUser;
  for (const TypeOption *t = (const TypeOption *)ctx; t->suffix && !msg[0]; t++)
    if (EndsWith(name, t->suffix)) PetscCall(CheckOne(t, name, value, msg, len));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOptionsCheckTypesString - checks the solver types an option string names ("-ksp_type cg
  -pc_type gamg", as PetscOptionsGetAll gives the database or as a tune configuration is written):
  msg (len bytes) says the first unknown one with the option, the closest names and every
  registered one; "" when all are known. Not collective.
@*/
PetscErrorCode PeriOptionsCheckTypesString(const char opts[], char msg[], size_t len)
{
  TypeOption types[] = {
      {"ksp_type", "KSP", &KSPList},
      {"pc_type", "PC", &PCList},
      {"st_type", "ST", &STList},
      {NULL, NULL, NULL},
  };

  PetscFunctionBeginUser;
  PetscCall(KSPInitializePackage()); /* the lists are filled when their package starts */
  PetscCall(PCInitializePackage());
  PetscCall(STInitializePackage());
  PetscCall(PeriOptionsEachValue(opts, CheckTypeValue, types, msg, len));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOptionsCheckTypes - refuses an option naming an unknown solver type (-ksp_type, -pc_type,
  -st_type, with any prefix) before any solver reads it, naming the option and listing the types
  allowed (PeriOptionsCheckTypesString). Marks no option as read. Collective: every rank has the
  same options, and rank 0 says the error.
@*/
PetscErrorCode PeriOptionsCheckTypes(MPI_Comm comm)
{
  char *all, msg[4096];

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetAll(NULL, &all));
  PetscCall(PeriOptionsCheckTypesString(all, msg, sizeof(msg)));
  PetscCall(PetscFree(all));
  PetscCheck(!msg[0], comm, PETSC_ERR_USER_INPUT, "%s", msg);
  PetscFunctionReturn(PETSC_SUCCESS);
}
