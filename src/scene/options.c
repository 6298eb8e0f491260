/* Options that name nothing. PETSc ignores an option nobody reads, so a misspelt -ksp_rtoll or
 * -material_nuu would silently run another computation than the one asked for. Two checks make
 * such options errors, each with a "did you mean":
 *   PeriOptionsCheckScene, right after the scene is read: options that name the scene (-material_...)
 *     must name one of its keys; their set is known then, so the error costs nothing;
 *   PeriOptionsCheckUnused, after the analysis and before any output: every other option that no
 *     rank read (PETSc's options-left machinery), which only the run itself can tell.
 * -options_unused_ok makes both warnings, for options meant for other tools (docs/scene.md). */
#include "perilin/private/scene_file.h"
#include <petscksp.h>
#include "perilin/private/sys.h"
#include <ctype.h>
#include <stdarg.h>
#include <strings.h>

/* Options that are still unread when the late check runs although they do what they say. Measured
 * with PETSc 3.18 on the static, modal and quasi-static examples (docs/scene.md says why each is
 * here); every other global option (-log_view, -malloc_dump, -info, ...) is read by
 * PetscInitialize. Names without the '-', compared ignoring case. */
static const char *const read_later[] = {
    "options_left",          /* PetscFinalize: lists the unused options */
    "options_view",          /* PetscFinalize: prints the database */
    "malloc_view_threshold", /* PetscFinalize, with -malloc_view */
    "get_total_flops",       /* PetscFinalize */
    "nox",                   /* PetscFinalize (X windows off) */
    "quiet",                 /* perilin: the status line and the quasi-static step log read it */
    NULL,
};

/* Common options that no object prints under -help (global ones, solver packages set up only at
 * factorization): candidates for "did you mean" only. */
static const char *const more_names[] = {"-help", "-version", "-info", "-log_view", "-log_trace", "-log_all", "-malloc_debug", "-malloc_dump", "-malloc_view", "-malloc_test", "-memory_view", "-options_left", "-options_file", "-options_view", "-objects_dump", "-on_error_abort", "-on_error_attach_debugger", "-start_in_debugger", "-fp_trap", "-quiet", "-progress", "-restart", "-options_unused_ok", "-scene_doc_update", "-scene_doc_check", "-mat_mumps_icntl_4", "-mat_mumps_icntl_7", "-mat_mumps_icntl_14", "-mat_mumps_icntl_24", "-mat_mumps_cntl_1", "-mat_mumps_cntl_3", NULL};

typedef struct {
  char   **name;
  PetscInt n, cap;
} Names;

static PetscErrorCode NamesAdd(Names *l, const char name[])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < l->n; k++)
    if (!strcasecmp(l->name[k], name)) PetscFunctionReturn(PETSC_SUCCESS);
  if (l->n + 1 >= l->cap) {
    l->cap = 2 * l->cap + 256;
    PetscCall(PetscRealloc(l->cap * sizeof(char *), &l->name));
  }
  PetscCall(PetscStrallocpy(name, &l->name[l->n++]));
  l->name[l->n] = NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode NamesDestroy(Names *l)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < l->n; k++) PetscCall(PetscFree(l->name[k]));
  PetscCall(PetscFree(l->name));
  l->n = l->cap = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static void Append(char buf[], size_t len, const char fmt[], ...) PETSC_ATTRIBUTE_FORMAT(3, 4);
static void Append(char buf[], size_t len, const char fmt[], ...)
{
  size_t  used = strlen(buf);
  va_list ap;

  if (used + 1 >= len) return;
  va_start(ap, fmt);
  vsnprintf(buf + used, len - used, fmt, ap);
  va_end(ap);
}

/* At most this many options are described in one message (PETSc keeps error messages short). */
#define PERI_OPTIONS_LISTED 8

/* Raises the error for the options in msg, or, with -options_unused_ok, prints it as a warning
 * (rank 0 of comm) and marks the options read so that the late check does not repeat them. Frees
 * opts either way. */
static PetscErrorCode Conclude(MPI_Comm comm, const char msg[], const char rule[], Names *opts)
{
  PetscBool ok = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-options_unused_ok", &ok, NULL));
  if (!opts->n)
    ok = PETSC_TRUE; /* nothing to say */
  else if (ok)
    PetscCall(PetscFPrintf(comm, PETSC_STDERR, "perilin: warning: %s; ignored (-options_unused_ok)\n", msg));
  for (PetscInt k = 0; ok && k < opts->n; k++) {
    PetscBool set;
    PetscCall(PetscOptionsHasName(NULL, NULL, opts->name[k], &set));
  }
  PetscCall(NamesDestroy(opts));
  PetscCheck(ok, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s; nothing was written.%s Pass -options_unused_ok to ignore options meant for other tools.", msg, rule);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* This rank's options that nothing read, with their '-'. */
static PetscErrorCode UnreadHere(Names *unread)
{
  PetscInt N;
  char   **left, **values, name[PERI_OPTION_LEN + 2];

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsLeftGet(NULL, &N, &left, &values));
  for (PetscInt k = 0; k < N; k++) {
    PetscCall(PetscSNPrintf(name, sizeof(name), "-%s", left[k]));
    PetscCall(NamesAdd(unread, name));
  }
  PetscCall(PetscOptionsLeftRestore(NULL, &N, &left, &values));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOptionsCheckScene - every option that names the scene (-material_..., -bc_..., -dim) must set
  one of its keys: a scalar or list of the file, or a documented key (src/scene/scene.c). Call it right
  after the scene is read: the overrides have read every option they use, and nothing was computed
  yet. The same error on every rank (they all read the same scene and options); with
  -options_unused_ok a warning printed by rank 0 of comm.
@*/
PetscErrorCode PeriOptionsCheckScene(MPI_Comm comm, PeriScene scene)
{
  Names  unread = {NULL, 0, 0}, bad = {NULL, 0, 0};
  char **scene_names, msg[1600]     = "";

  PetscFunctionBeginUser;
  PetscCall(UnreadHere(&unread));
  PetscCall(PeriSceneOptionNames(scene, &scene_names));
  for (PetscInt k = 0; k < unread.n; k++) {
    char      why[256], hint[2 * PERI_OPTION_LEN];
    PetscBool is, exact, exists;
    PetscCall(PeriSceneOptionIsScene(scene, unread.name[k], &is));
    if (!is) continue;
    PetscCall(NamesAdd(&bad, unread.name[k]));
    if (bad.n > PERI_OPTIONS_LISTED) continue;
    PetscCall(PeriSceneOptionExplain(scene, unread.name[k], why, sizeof(why), &exists));
    PeriSuggest(unread.name[k], scene_names, hint, sizeof(hint), &exact);
    if (exists) hint[0] = 0; /* it names a key of the file: the explanation is the whole story */
    Append(msg, sizeof(msg), "%sunknown option %s (%s%s%s)", bad.n > 1 ? "; " : "", unread.name[k], why, hint[0] ? "; " : "", hint);
  }
  if (bad.n > PERI_OPTIONS_LISTED) Append(msg, sizeof(msg), "; and %" PetscInt_FMT " more", bad.n - PERI_OPTIONS_LISTED);
  PetscCall(PetscStrArrayDestroy(&scene_names));
  PetscCall(NamesDestroy(&unread));
  PetscCall(Conclude(comm, msg, " Options set only the keys present in the scene file and the documented keys (perilin -help).", &bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The options that no rank read: rank 0's unread options, less those another rank read. The same
 * list on every rank. Collective. */
static PetscErrorCode UnreadEverywhere(MPI_Comm comm, Names *unread)
{
  Names       here = {NULL, 0, 0};
  PetscMPIInt rank, len = 0, n = 0;
  char       *buf, *c;
  int        *read;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) PetscCall(UnreadHere(&here));
  for (PetscInt k = 0; k < here.n; k++) len += (PetscMPIInt)strlen(here.name[k]) + 1;
  PetscCallMPI(MPI_Bcast(&len, 1, MPI_INT, 0, comm));
  PetscCall(PetscMalloc1(len + 1, &buf));
  for (PetscInt k = 0, at = 0; k < here.n; k++) {
    PetscCall(PetscStrcpy(buf + at, here.name[k]));
    at += (PetscInt)strlen(here.name[k]) + 1;
  }
  PetscCall(NamesDestroy(&here));
  PetscCallMPI(MPI_Bcast(buf, len, MPI_CHAR, 0, comm));
  for (c = buf; c < buf + len; c += strlen(c) + 1) n++;
  PetscCall(PetscCalloc1(n + 1, &read));
  n = 0;
  for (c = buf; c < buf + len; c += strlen(c) + 1) {
    PetscBool used;
    PetscCall(PetscOptionsUsed(NULL, c + 1, &used)); /* the database keeps names without the '-' */
    for (PetscInt k = 0; read_later[k]; k++)
      if (!strcasecmp(c + 1, read_later[k])) used = PETSC_TRUE;
    read[n++] = used;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, read, n, MPI_INT, MPI_LOR, comm));
  n = 0;
  for (c = buf; c < buf + len; c += strlen(c) + 1)
    if (!read[n++]) PetscCall(NamesAdd(unread, c));
  PetscCall(PetscFree(read));
  PetscCall(PetscFree(buf));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What PETSc prints while the objects below set themselves from the options under -help: the lines
 * of PetscHelpPrintf, and those of PetscFPrintf (PETSc 3.18 prints the choices of a type option,
 * -ksp_type, with PetscFPrintf on rank 0). Gathered here instead of printed. */
static char  *help_text;
static size_t help_len, help_cap;

static PetscErrorCode GatherV(FILE *fd, const char fmt[], va_list ap)
{
  va_list again;
  int     n;

  PetscFunctionBeginUser;
  (void)fd;
  va_copy(again, ap);
  n = vsnprintf(NULL, 0, fmt, again);
  va_end(again);
  if (n <= 0) PetscFunctionReturn(PETSC_SUCCESS);
  if (help_len + (size_t)n + 1 > help_cap) {
    help_cap = 2 * (help_len + (size_t)n + 1);
    PetscCall(PetscRealloc(help_cap, &help_text));
  }
  vsnprintf(help_text + help_len, (size_t)n + 1, fmt, ap);
  help_len += (size_t)n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode GatherHelp(MPI_Comm comm, const char fmt[], ...)
{
  va_list ap;

  PetscFunctionBeginUser;
  (void)comm;
  va_start(ap, fmt);
  PetscCall(GatherV(NULL, fmt, ap));
  va_end(ap);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A KSP of the given types (either may be "" for the default) set from the options. */
static PetscErrorCode KSPFromOptions(MPI_Comm comm, const char prefix[], const char ksp_type[], const char pc_type[])
{
  KSP ksp;
  PC  pc;

  PetscFunctionBeginUser;
  PetscCall(KSPCreate(comm, &ksp));
  if (prefix) PetscCall(KSPSetOptionsPrefix(ksp, prefix));
  if (ksp_type[0]) PetscCall(KSPSetType(ksp, ksp_type));
  PetscCall(KSPGetPC(ksp, &pc));
  if (pc_type[0]) PetscCall(PCSetType(pc, pc_type));
  PetscCall(KSPSetFromOptions(ksp));
  PetscCall(KSPDestroy(&ksp));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Fresh objects of the kinds and types the run used, set from the options: under -help they print
 * every option they read. Collective. */
static PetscErrorCode ObjectsFromOptions(const PeriRunSolvers *p)
{
  Vec       v;
  Mat       A;
  PetscBool mg;

  PetscFunctionBeginUser;
  PetscCall(VecCreate(p->comm, &v));
  PetscCall(VecSetSizes(v, 1, PETSC_DECIDE));
  PetscCall(VecSetFromOptions(v));
  PetscCall(VecDestroy(&v));
  PetscCall(MatCreate(p->comm, &A));
  PetscCall(MatSetSizes(A, 1, 1, PETSC_DETERMINE, PETSC_DETERMINE));
  if (p->mat_type[0]) PetscCall(MatSetType(A, p->mat_type));
  PetscCall(MatSetFromOptions(A));
  PetscCall(MatDestroy(&A));
  /* the analysis' own solvers (an eigensolver's spectral transformation, say), when it says */
  if (p->solvers_from_options) {
    PetscCall(p->solvers_from_options(p->comm, p->ksp_type, p->pc_type));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(KSPFromOptions(p->comm, NULL, p->ksp_type, p->pc_type));
  /* multigrid levels exist only once set up: their solvers' options come from stand-ins */
  PetscCall(PetscStrbeginswith(p->pc_type, PCMG, &mg));
  if (!mg) PetscCall(PetscStrcmp(p->pc_type, PCGAMG, &mg));
  if (mg) {
    PetscCall(KSPFromOptions(p->comm, "mg_levels_", KSPCHEBYSHEV, PCJACOBI));
    PetscCall(KSPFromOptions(p->comm, "mg_coarse_", KSPPREONLY, PCBJACOBI));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The option names the run's objects print under -help ("  -ksp_rtol <1e-10>: ..."). PETSc prints
 * an object's options once per run (PetscOptionsHelpPrintedSingleton remembers): a fresh record
 * for these, then the run's is restored, with PetscHelpPrintf and the database as they were.
 * Collective; used on the error path only. */
static PetscErrorCode PetscNames(const PeriRunSolvers *p, Names *names)
{
  PetscErrorCode (*help)(MPI_Comm, const char[], ...)     = PetscHelpPrintf;
  PetscErrorCode (*vprint)(FILE *, const char[], va_list) = PetscVFPrintf;
  PetscOptionsHelpPrinted printed                         = PetscOptionsHelpPrintedSingleton;
  PetscErrorCode          ierr;

  PetscFunctionBeginUser;
  PetscOptionsHelpPrintedSingleton = NULL;
  PetscHelpPrintf                  = GatherHelp;
  PetscVFPrintf                    = GatherV;
  PetscCall(PetscOptionsSetValue(NULL, "-help", NULL));
  /* a failure here costs only suggestions, and must not replace the error being raised */
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = ObjectsFromOptions(p);
  PetscCall(PetscPopErrorHandler());
  PetscHelpPrintf = help;
  PetscVFPrintf   = vprint;
  PetscCall(PetscOptionsClearValue(NULL, "-help"));
  PetscCall(PetscOptionsHelpPrintedDestroy(&PetscOptionsHelpPrintedSingleton));
  PetscOptionsHelpPrintedSingleton = printed;
  for (char *line = help_text; !ierr && line && line < help_text + help_len; line = strchr(line, '\n')) {
    char   name[PERI_OPTION_LEN + 2];
    size_t k = 0;
    while (*line == '\n' || *line == ' ' || *line == '\t') line++;
    if (line[0] != '-' || !isalpha((unsigned char)line[1])) continue;
    while (k < sizeof(name) - 1 && (isalnum((unsigned char)line[k]) || line[k] == '_' || (k == 0 && line[k] == '-'))) {
      name[k] = line[k];
      k++;
    }
    name[k] = 0;
    PetscCall(NamesAdd(names, name));
  }
  PetscCall(PetscFree(help_text));
  help_len = help_cap = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOptionsCheckUnused - every option given must have been read by some rank (PETSc's
  options-left machinery), except the few PETSc reads only at the end (read_later). Call it after
  the analysis and before any output. The error lists each unread option with the closest names
  among the scene's and those of the run's PETSc objects; the same error on every rank. With
  -options_unused_ok a warning printed by rank 0. Collective.
@*/
PetscErrorCode PeriOptionsCheckUnused(const PeriRunSolvers *p)
{
  Names     unread = {NULL, 0, 0}, cand = {NULL, 0, 0};
  char    **scene_names, msg[1600]      = "";
  PetscBool ok = PETSC_FALSE, said = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-options_unused_ok", &ok, NULL)); /* read: not unread itself */
  PetscCall(UnreadEverywhere(p->comm, &unread));
  if (!unread.n) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscNames(p, &cand));
  PetscCall(PeriSceneOptionNames(p->scene, &scene_names));
  for (PetscInt k = 0; scene_names[k]; k++) PetscCall(NamesAdd(&cand, scene_names[k]));
  for (PetscInt k = 0; more_names[k]; k++) PetscCall(NamesAdd(&cand, more_names[k]));
  PetscCall(PetscStrArrayDestroy(&scene_names));
  for (PetscInt k = 0; k < PetscMin(unread.n, PERI_OPTIONS_LISTED); k++) {
    char      hint[2 * PERI_OPTION_LEN];
    PetscBool exact;
    PeriSuggest(unread.name[k], cand.name, hint, sizeof(hint), &exact);
    if (hint[0])
      Append(msg, sizeof(msg), "%sunknown option %s (%s)", k ? "; " : "", unread.name[k], hint);
    else {
      Append(msg, sizeof(msg), "%soption %s was read by nothing in this run", k ? "; " : "", unread.name[k]);
      /* a real option for a solver the run did not use, or a misspelling: say what the run used */
      if (!said && p->ksp_type[0]) Append(msg, sizeof(msg), " (its linear solves used -%sksp_type %s -%spc_type %s)", p->prefix ? p->prefix : "", p->ksp_type, p->prefix ? p->prefix : "", p->pc_type);
      said = PETSC_TRUE;
    }
  }
  if (unread.n > PERI_OPTIONS_LISTED) Append(msg, sizeof(msg), "; and %" PetscInt_FMT " more", unread.n - PERI_OPTIONS_LISTED);
  PetscCall(NamesDestroy(&cand));
  /* the choices of type options reach rank 0 only (above): its message is everyone's */
  PetscCallMPI(MPI_Bcast(msg, sizeof(msg), MPI_CHAR, 0, p->comm));
  PetscCall(Conclude(p->comm, msg, "", &unread));
  PetscFunctionReturn(PETSC_SUCCESS);
}
