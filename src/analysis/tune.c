/* analysis.type: tune. The scene's static problem solved under each of a list of solver
 * configurations (strings of PETSc options, -solver_operator choosing how K is applied), each
 * timed, measured and checked by its true residual like a static run's solve; tune.csv and a
 * ranked table, the winner's option line, and the winner's solution as the static result
 * (docs/tuning.md).
 *
 * A configuration's options live in a PetscOptions database of its own: the global options under
 * the configuration's, made the default (PetscOptionsPush) while the configuration builds its
 * operator and solves, so that the static solve's code reads them where it reads the command
 * line, no configuration leaks into the next, and the program's unused-option check sees only the
 * command line's (a global option a configuration read counts as read). */
#include "perilin/private/analysis.h"
#include <ctype.h>

#define PERI_TUNE_REASON_LEN 256

/* One configuration's outcome: times are the median over analysis.repeat runs, the rest the last
 * run's. */
typedef struct {
  char              *config;
  PetscBool          converged, refused;
  KSPConvergedReason ksp_reason;
  char               reason[PERI_TUNE_REASON_LEN]; /* why not converged ("" when converged) */
  PetscInt           iterations;
  PetscReal          operator_s, setup_s, solve_s; /* building the operator, the PC's set-up, KSPSolve */
  PetscReal          memory_mb;                    /* heap held once solved, above the level before the operator, all ranks */
  PetscReal          residual, residual_tol;       /* true relative residual and the largest accepted */
  PetscReal          u_max;                        /* max |u| over the DOFs: the solutions compared */
} TuneRow;

typedef struct {
  PetscInt  n, repeat;
  TuneRow  *rows;
  PetscInt *order;  /* rows ranked: converged first, by total time */
  PetscInt  winner; /* index of rows, or -1 */
  PetscInt  ran;    /* rows measured (fewer when interrupted) */
} Tune;

#define TUNE(an) ((Tune *)(an)->data)

static PetscReal Total(const TuneRow *r)
{
  return r->operator_s + r->setup_s + r->solve_s;
}

/* A database with the global options, then config's over them. */
static PetscErrorCode ConfigOptionsCreate(const char config[], PetscOptions *opts)
{
  char *all;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsCreate(opts));
  PetscCall(PetscOptionsGetAll(NULL, &all));
  PetscCall(PetscOptionsInsertString(*opts, all));
  PetscCall(PetscFree(all));
  PetscCall(PetscOptionsInsertString(*opts, config));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A configuration's -solver_operator (kind unchanged when it has none), or in why (len bytes) the
 * value that is none of PeriOperatorKinds. Read as a string and matched here: PETSc 3.18's
 * PetscOptionsGetEList leaks its copy of the list on a value outside it (docs/reliability.md). */
static PetscErrorCode ConfigOperatorKind(PetscOptions opts, PetscInt *kind, char why[], size_t len)
{
  char      value[64];
  PetscBool set;

  PetscFunctionBeginUser;
  why[0] = 0;
  PetscCall(PetscOptionsGetString(opts, NULL, "-solver_operator", value, sizeof(value), &set));
  if (!set) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; PeriOperatorKinds[k]; k++) {
    PetscBool same;
    PetscCall(PetscStrcmp(value, PeriOperatorKinds[k], &same));
    if (same) {
      *kind = k;
      PetscFunctionReturn(PETSC_SUCCESS);
    }
  }
  PetscCall(PetscSNPrintf(why, len, "-solver_operator %s is none of auto, assembled, matrix_free", value));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What a configuration sets up with the options pushed: a KSP and its PC from the options. Errors
 * are returned, not raised (ValidateConfiguration). */
static PetscErrorCode TrySetUp(MPI_Comm comm, KSP *ksp)
{
  PetscFunctionBeginUser;
  PetscCall(KSPCreate(comm, ksp));
  PetscCall(KSPSetFromOptions(*ksp));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A configuration whose types or values PETSc refuses (an unknown -pc_type, a -ksp_rtol that is
 * no number) is an input error, found before any particle exists: its KSP is set up from its
 * options with PETSc's errors returned, and PETSc's message is the error's. */
static PetscErrorCode ValidateConfiguration(PeriAnalysis an, PeriScene s, PeriNode node, const char config[])
{
  PetscOptions   opts;
  PetscErrorCode ierr;
  KSP            ksp  = NULL;
  PetscInt       kind = 0;
  char          *msg = NULL, copy[PERI_TUNE_REASON_LEN] = "", types[4096];

  PetscFunctionBeginUser;
  /* an unknown type is refused before PETSc's own refusal, which leaks its copy of the name */
  PetscCall(PeriOptionsCheckTypesString(config, types, sizeof(types)));
  PeriInputCheck(!types[0], s, node, NULL, "configuration '%s' cannot be set up: %s", config, types);
  PetscCall(ConfigOptionsCreate(config, &opts));
  PetscCall(ConfigOperatorKind(opts, &kind, types, sizeof(types)));
  if (types[0]) PetscCall(PetscOptionsDestroy(&opts));
  PeriInputCheck(!types[0], s, node, NULL, "configuration '%s' cannot be set up: %s", config, types);
  PetscCall(PetscOptionsPush(opts));
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = TrySetUp(an->comm, &ksp);
  PetscCall(PetscPopErrorHandler());
  if (ierr) {
    PetscCall(PetscErrorMessage(ierr, NULL, &msg));
    PetscCall(PetscStrncpy(copy, msg ? msg : "PETSc refused it", sizeof(copy)));
  }
  PetscCall(KSPDestroy(&ksp));
  PetscCall(PetscOptionsPop());
  PetscCall(PetscOptionsDestroy(&opts));
  PeriInputCheck(!ierr, s, node, NULL, "configuration '%s' cannot be set up: %s", config, copy);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.configurations (each checked now) and analysis.repeat. */
static PetscErrorCode SetFromScene_Tune(PeriAnalysis an, PeriScene s, PeriNode a)
{
  Tune    *T;
  PeriNode list;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&T));
  an->data  = T;
  T->winner = -1;
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_TRUE, &a));
  PetscCall(PeriSceneGetInt(s, a, "repeat", PETSC_FALSE, &T->repeat, NULL));
  PetscCall(PeriSceneGetNode(a, "configurations", &list));
  if (!list) PetscFunctionReturn(PETSC_SUCCESS); /* the model's list, at set-up */
  PeriInputCheck(list->kind == PERI_NODE_SEQ && list->n >= 1, s, list, NULL, "a list of one or more configurations, each a string of PETSc options (\"-ksp_type cg -pc_type gamg\")");
  T->n = list->n;
  PetscCall(PetscCalloc1(T->n, &T->rows));
  for (PetscInt k = 0; k < T->n; k++) {
    PeriNode c = list->child[k];
    PeriInputCheck(c->kind == PERI_NODE_SCALAR && c->value[0] == '-', s, c, NULL, "a configuration is a string of PETSc options, such as \"-ksp_type cg -pc_type gamg\"");
    PetscCall(ValidateConfiguration(an, s, c, c->value));
    PetscCall(PetscStrallocpy(c->value, &T->rows[k].config));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The built-in list: CG with GAMG, hypre's BoomerAMG, Jacobi and block Jacobi (ILU(0) blocks: K is symmetric, so CG, not GMRES), a
 * direct Cholesky (MUMPS's on several ranks) on an assembled K, and GAMG and Jacobi on a
 * matrix-free K where the model and scene allow one, with the geometric multigrid on a grid body. */
static PetscErrorCode DefaultConfigurations(PeriAnalysis an)
{
  Tune       *T  = TUNE(an);
  const char *as = PeriMatrixFreeWhyNot(an->sys) ? "" : " -solver_operator assembled";
  char        line[10][128];
  PetscInt    n = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(line[n++], sizeof(line[0]), "-ksp_type cg -pc_type gamg%s", as));
  if (as[0]) PetscCall(PetscSNPrintf(line[n++], sizeof(line[0]), "-ksp_type cg -pc_type gamg -solver_operator matrix_free"));
#if defined(PETSC_HAVE_HYPRE)
  PetscCall(PetscSNPrintf(line[n++], sizeof(line[0]), "-ksp_type cg -pc_type hypre -pc_hypre_type boomeramg%s", as));
#endif
  PetscCall(PetscSNPrintf(line[n++], sizeof(line[0]), "-ksp_type cg -pc_type jacobi%s", as));
  if (as[0]) PetscCall(PetscSNPrintf(line[n++], sizeof(line[0]), "-ksp_type cg -pc_type jacobi -solver_operator matrix_free"));
  if (as[0] && !PeriMultigridWhyNotBody(an->sys)) PetscCall(PetscSNPrintf(line[n++], sizeof(line[0]), "-ksp_type cg -pc_type mg -solver_operator matrix_free"));
  PetscCall(PetscSNPrintf(line[n++], sizeof(line[0]), "-ksp_type cg -pc_type bjacobi%s", as));
#if !defined(PETSC_HAVE_MUMPS)
  if (an->sys->size == 1)
#endif
    PetscCall(PetscSNPrintf(line[n++], sizeof(line[0]), "-ksp_type preonly -pc_type cholesky%s", as));
  T->n = n;
  PetscCall(PetscCalloc1(T->n, &T->rows));
  for (PetscInt k = 0; k < n; k++) PetscCall(PetscStrallocpy(line[k], &T->rows[k].config));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode SetUp_Tune(PeriAnalysis an)
{
  PetscInt nc;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&an->sys->conditions.nconstrained, &nc, 1, MPIU_INT, MPI_SUM, an->comm));
  PetscCheck(nc < an->sys->disc.N * an->sys->model->dofs, an->comm, PETSC_ERR_USER_INPUT, "%s: every DOF is prescribed: there is no linear system to tune", an->sys->scene->file);
  if (!TUNE(an)->n) PetscCall(DefaultConfigurations(an));
  PetscCall(PetscMalloc1(TUNE(an)->n, &TUNE(an)->order));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The global options that nothing read yet but the configuration's database did are read: the
 * unused-option check (src/scene/options.c) looks at the global database only. */
static PetscErrorCode MarkGlobalRead(PetscOptions opts)
{
  PetscInt N;
  char   **names, **values, name[258];

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsLeftGet(NULL, &N, &names, &values));
  for (PetscInt k = 0; k < N; k++) {
    PetscBool used, set;
    PetscCall(PetscOptionsUsed(opts, names[k], &used));
    if (!used) continue;
    PetscCall(PetscSNPrintf(name, sizeof(name), "-%s", names[k]));
    PetscCall(PetscOptionsHasName(NULL, NULL, name, &set)); /* marks it read */
  }
  PetscCall(PetscOptionsLeftRestore(NULL, &N, &names, &values));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The configuration's first option that no rank read (a misspelling, or an option of a solver it
 * does not use): its measurement is then of another solver than the one written, so the row is
 * not converged. Collective. */
static PetscErrorCode UnreadOption(MPI_Comm comm, PetscOptions opts, const char config[], TuneRow *row)
{
  int    argc;
  char **args;

  PetscFunctionBeginUser;
  PetscCall(PetscStrToArray(config, ' ', &argc, &args));
  for (int k = 0; k < argc; k++) {
    PetscBool used = PETSC_TRUE;
    if (args[k][0] == '-' && isalpha((unsigned char)args[k][1])) PetscCall(PetscOptionsUsed(opts, args[k] + 1, &used));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &used, 1, MPIU_BOOL, MPI_LOR, comm));
    if (used) continue;
    row->converged = PETSC_FALSE;
    PetscCall(PetscSNPrintf(row->reason, sizeof(row->reason), "option %s was read by nothing (misspelt, or not an option of this solver)", args[k]));
    break;
  }
  PetscCall(PetscStrToArrayDestroy(argc, args));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One static solve with the pushed options, on an operator built for it (the previous one freed
 * first, so that its heap is measured alone): the times, the heap held with the KSP alive, and
 * the checks of a static run. */
static PetscErrorCode SolveOnce(PeriAnalysis an, PetscInt nhold, const PetscInt hold[], const PetscReal held[], TuneRow *row)
{
  PeriSystem         sys = an->sys;
  KSP                ksp = NULL;
  KSPConvergedReason reason;
  PetscLogDouble     t0, t1;
  PetscReal          heap0, heap1;

  PetscFunctionBeginUser;
  PetscCall(PeriStiffnessDestroy(&sys->stiffness));
  PetscCall(VecDestroy(&sys->fields.u));
  heap0 = PeriHeapInUseMB();
  PetscCall(PetscTime(&t0));
  PetscCall(PeriStaticDefaultMatType(sys->stiffness.mat_type, sizeof(sys->stiffness.mat_type)));
  PetscCall(PeriSystemAssemble(sys));
  PetscCall(PeriStaticSolve(sys, &ksp, 1.0, PETSC_TRUE, nhold, hold, held, &reason));
  PetscCall(PetscTime(&t1));
  heap1 = PeriHeapInUseMB() - heap0;
  PetscCallMPI(MPI_Allreduce(&heap1, &row->memory_mb, 1, MPIU_REAL, MPI_SUM, an->comm));
  PetscCall(PeriStaticConverged(sys, ksp, reason, &row->converged));
  PetscCall(VecNorm(sys->fields.u, NORM_INFINITY, &row->u_max));
  PetscCall(KSPDestroy(&ksp));
  row->setup_s      = sys->fields.solve.setup_s;
  row->solve_s      = sys->fields.solve.ksp_solve_s;
  row->operator_s   = PetscMax(0, (t1 - t0) - row->setup_s - row->solve_s);
  row->iterations   = sys->fields.solve.iterations;
  row->residual     = sys->fields.solve.residual_norm;
  row->residual_tol = sys->fields.solve.residual_tol;
  row->reason[0]    = 0;
  row->ksp_reason   = reason;
  if (reason <= 0)
    PetscCall(PetscSNPrintf(row->reason, sizeof(row->reason), "%s after %" PetscInt_FMT " iterations", KSPConvergedReasons[reason], row->iterations));
  else if (!row->converged)
    PetscCall(PetscSNPrintf(row->reason, sizeof(row->reason), "true relative residual %.3g > tolerance %.3g although KSP reported %s", (double)row->residual, (double)row->residual_tol, KSPConvergedReasons[reason]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One run of configuration config into row: refused with a reason when its operator cannot apply
 * to this system, else solved with its options pushed. */
static PetscErrorCode RunConfiguration(PeriAnalysis an, const char config[], PetscInt nhold, const PetscInt hold[], const PetscReal held[], TuneRow *row)
{
  PeriSystem             sys   = an->sys;
  const PeriOperatorKind scene = sys->stiffness.operator_kind;
  PetscInt               kind  = scene;
  const char            *why;
  PetscOptions           opts;

  PetscFunctionBeginUser;
  PetscCall(ConfigOptionsCreate(config, &opts));
  PetscCall(ConfigOperatorKind(opts, &kind, row->reason, sizeof(row->reason))); /* checked at the set-up */
  why          = kind == PERI_OPERATOR_MATRIX_FREE ? PeriMatrixFreeWhyNot(sys) : NULL;
  row->refused = (PetscBool) !!why;
  if (why) {
    row->converged = PETSC_FALSE;
    PetscCall(PetscSNPrintf(row->reason, sizeof(row->reason), "refused: matrix_free cannot apply here: %s", why));
  } else {
    sys->stiffness.operator_kind = (PeriOperatorKind)kind;
    PetscCall(PetscOptionsPush(opts));
    PetscCall(SolveOnce(an, nhold, hold, held, row));
    PetscCall(PetscOptionsPop());
    sys->stiffness.operator_kind = scene;
    PetscCall(UnreadOption(an->comm, opts, config, row));
  }
  PetscCall(MarkGlobalRead(opts));
  PetscCall(PetscOptionsDestroy(&opts));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Median(PetscInt n, PetscReal v[], PetscReal *m)
{
  PetscFunctionBeginUser;
  PetscCall(PetscSortReal(n, v));
  *m = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Configuration k analysis.repeat times: the times' medians. Returns early when a signal came. */
static PetscErrorCode MeasureConfiguration(PeriAnalysis an, PetscInt k, PetscInt nhold, const PetscInt hold[], const PetscReal held[])
{
  Tune      *T   = TUNE(an);
  TuneRow   *row = &T->rows[k];
  PetscReal *t;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(3 * T->repeat, &t));
  for (PetscInt r = 0; r < T->repeat; r++) {
    PetscCall(RunConfiguration(an, row->config, nhold, hold, held, row));
    t[r]                 = row->operator_s;
    t[T->repeat + r]     = row->setup_s;
    t[2 * T->repeat + r] = row->solve_s;
    PetscCall(PeriSignalReceived(an->comm, &an->sys->run.interrupted));
    if (an->sys->run.interrupted || row->refused) break; /* refused: nothing to repeat */
  }
  if (!an->sys->run.interrupted && !row->refused) {
    PetscCall(Median(T->repeat, t, &row->operator_s));
    PetscCall(Median(T->repeat, t + T->repeat, &row->setup_s));
    PetscCall(Median(T->repeat, t + 2 * T->repeat, &row->solve_s));
  }
  PetscCall(PetscFree(t));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* T->order: the converged rows by total time, then the others in their order. */
static PetscErrorCode Rank(Tune *T)
{
  PetscInt   nc = 0;
  PetscReal *key;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(T->ran, &key));
  for (PetscInt k = 0; k < T->ran; k++) {
    T->order[k] = k;
    key[k]      = T->rows[k].converged ? Total(&T->rows[k]) : 1e30 + 1e15 * k; /* after every time, in their order */
    nc += T->rows[k].converged;
  }
  PetscCall(PetscSortRealWithArrayInt(T->ran, key, T->order));
  T->winner = nc ? T->order[0] : -1;
  PetscCall(PetscFree(key));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every configuration measured, ranked; the winner solved once more for the state the output
 * shows, with a static run's checks. No converged configuration is an error. */
static PetscErrorCode Run_Tune(PeriAnalysis an)
{
  Tune      *T = TUNE(an);
  PetscInt   nhold, *hold;
  PetscReal *held;
  TuneRow    last = {NULL};

  PetscFunctionBeginUser;
  PetscCall(VecDestroy(&an->sys->fields.u));
  PetscCall(PeriStaticPieces(an->sys, &nhold, &hold, &held));
  /* a configuration a signal cut short is no measurement: the rows are those that finished */
  for (T->ran = 0; T->ran < T->n; T->ran++) {
    PetscCall(PeriProgressUpdate(an->sys->run.progress, PERI_PROGRESS_ANALYSIS, "configuration %" PetscInt_FMT "/%" PetscInt_FMT, T->ran + 1, T->n));
    PetscCall(MeasureConfiguration(an, T->ran, nhold, hold, held));
    if (an->sys->run.interrupted) break;
  }
  PetscCall(Rank(T));
  if (!an->sys->run.interrupted && T->winner >= 0) {
    PetscCall(RunConfiguration(an, T->rows[T->winner].config, nhold, hold, held, &last));
    PetscCall(PeriSignalReceived(an->comm, &an->sys->run.interrupted));
  }
  PetscCall(PetscFree2(hold, held)); /* before the refusal below: the Python module lives on after it */
  PetscCheck(an->sys->run.interrupted || T->winner >= 0, an->comm, PETSC_ERR_NOT_CONVERGED, "%s: no configuration of the %" PetscInt_FMT " converged (first: %s: %s): try a direct solver (\"-ksp_type preonly -pc_type cholesky -solver_operator assembled\"), raise -ksp_max_it, or check the constraints", an->sys->scene->file, T->n, T->rows[0].config, T->rows[0].reason);
  if (an->sys->run.interrupted) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriStaticCheckConverged(an->sys, last.ksp_reason));
  an->sys->run.log.solve_s = Total(&last);
  PetscCall(PeriSystemEvaluateEnergy(an->sys));
  PetscCall(PeriSystemEvaluateReactions(an->sys, 1.0));
  PetscCall(PeriReferenceEvaluate(an->sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A configuration in a CSV field: quoted, its quotes doubled. */
static int WriteQuoted(FILE *fp, const char s[])
{
  int bad = fputc('"', fp) == EOF;
  for (; *s; s++) bad |= (*s == '"' && fputc('"', fp) == EOF) || fputc(*s, fp) == EOF;
  return bad | (fputc('"', fp) == EOF);
}

/* tune.csv, ranked: one row per configuration measured. Rank 0 writes. */
static PetscErrorCode Files_Tune(PeriAnalysis an, const char dir[])
{
  Tune *T = TUNE(an);
  char  path[PETSC_MAX_PATH_LEN], tmp[PETSC_MAX_PATH_LEN];
  FILE *fp;
  int   bad = 0;

  PetscFunctionBeginUser;
  if (an->rank || !T || !T->ran) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/tune.csv", dir));
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "rank,configuration,converged,iterations,operator_s,setup_s,solve_s,total_s,memory_mb,residual,residual_tol,u_max,reason\n") < 0;
  for (PetscInt i = 0; i < T->ran; i++) {
    const TuneRow *r = &T->rows[T->order[i]];
    bad |= fprintf(fp, "%" PetscInt_FMT ",", i + 1) < 0;
    bad |= WriteQuoted(fp, r->config);
    bad |= fprintf(fp, ",%s,%" PetscInt_FMT ",%.6f,%.6f,%.6f,%.6f,%.3f,%.6e,%.3e,%.10e,", r->converged ? "true" : "false", r->iterations, (double)r->operator_s, (double)r->setup_s, (double)r->solve_s, (double)Total(r), (double)r->memory_mb, (double)r->residual, (double)r->residual_tol, (double)r->u_max) < 0;
    bad |= WriteQuoted(fp, r->reason);
    bad |= fputc('\n', fp) == EOF;
  }
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Summary_Tune(PeriAnalysis an, PeriJSON j)
{
  Tune *T = TUNE(an);

  PetscFunctionBeginUser;
  if (!T || !T->ran) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "tune"));
  if (T->winner >= 0) PetscCall(PeriJSONString(j, "winner", T->rows[T->winner].config));
  PetscCall(PeriJSONInt(j, "repeat", T->repeat));
  PetscCall(PeriJSONBeginArray(j, "configurations"));
  for (PetscInt i = 0; i < T->ran; i++) {
    const TuneRow *r = &T->rows[T->order[i]];
    PetscCall(PeriJSONBeginObject(j, NULL));
    PetscCall(PeriJSONString(j, "configuration", r->config));
    PetscCall(PeriJSONBool(j, "converged", r->converged));
    if (r->reason[0]) PetscCall(PeriJSONString(j, "reason", r->reason));
    PetscCall(PeriJSONInt(j, "iterations", r->iterations));
    PetscCall(PeriJSONReal(j, "operator_s", r->operator_s));
    PetscCall(PeriJSONReal(j, "setup_s", r->setup_s));
    PetscCall(PeriJSONReal(j, "solve_s", r->solve_s));
    PetscCall(PeriJSONReal(j, "memory_mb", r->memory_mb));
    PetscCall(PeriJSONReal(j, "residual", r->residual));
    PetscCall(PeriJSONReal(j, "u_max", r->u_max));
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONEndArray(j));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The ranked table, the winner's option line to paste, and the static result. */
static PetscErrorCode Report_Tune(PeriAnalysis an)
{
  Tune *T = TUNE(an);

  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(an->comm, "perilin: tune: %" PetscInt_FMT " configurations, ranked by operator + set-up + solve time (s, the median of %" PetscInt_FMT " run%s)\n", T->ran, T->repeat, T->repeat > 1 ? "s" : ""));
  PetscCall(PetscPrintf(an->comm, "  rank conv   its operator   setup   solve   total  mem_MB residual  configuration\n"));
  for (PetscInt i = 0; i < T->ran; i++) {
    const TuneRow *r = &T->rows[T->order[i]];
    PetscCall(PetscPrintf(an->comm, "  %4" PetscInt_FMT " %-4s %5" PetscInt_FMT " %8.4f %7.4f %7.4f %7.4f %7.2f %8.1e  %s%s%s%s\n", i + 1, r->converged ? "yes" : "no", r->iterations, (double)r->operator_s, (double)r->setup_s, (double)r->solve_s, (double)Total(r), (double)r->memory_mb, (double)r->residual, r->config, r->reason[0] ? " (" : "", r->reason, r->reason[0] ? ")" : ""));
  }
  if (T->winner >= 0) PetscCall(PetscPrintf(an->comm, "perilin: fastest: %.4f s; its options, to paste after the scene file of a static run:\n  %s\n", (double)Total(&T->rows[T->winner]), T->rows[T->winner].config));
  PetscCall(PetscPrintf(an->comm, "perilin: strain energy %g (the fastest configuration's solution); results in %s/\n", an->sys->fields.strain_energy, an->output_dir));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Destroy_Tune(PeriAnalysis an)
{
  Tune *T = TUNE(an);

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < T->n; k++) PetscCall(PetscFree(T->rows[k].config));
  PetscCall(PetscFree(T->rows));
  PetscCall(PetscFree(T->order));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static const PeriKey tune_keys[] = {
    {"configurations", PERI_KEY_LIST, "the model's list (docs/tuning.md)", NULL, NULL, NULL, "the solver configurations tried, each a string of PETSc options (\"-ksp_type cg -pc_type gamg\"; -solver_operator assembled or matrix_free chooses how K is applied)"},
    {"repeat", PERI_KEY_INT, "1", "[1, inf)", NULL, NULL, "runs of each configuration: its times are their median"},
    {NULL},
};
static const PeriSchema  tune_schema[] = {{"analysis", tune_keys}, {NULL}};
static const char *const tune_files[]  = {"tune.csv", NULL};

const PeriAnalysisType PeriAnalysis_Tune = {
    .name          = "tune",
    .help          = "the static problem under each of a list of solver configurations, timed and checked: tune.csv, the fastest's options and solution",
    .schema        = tune_schema,
    .option_prefix = "",
    .files         = tune_files,
    .needs         = {.matrix_free = PETSC_TRUE, .static_solver = PETSC_TRUE},
    .ops           = {.setfromscene = SetFromScene_Tune, .setup = SetUp_Tune, .run = Run_Tune, .files = Files_Tune, .summary = Summary_Tune, .report = Report_Tune, .destroy = Destroy_Tune},
};
