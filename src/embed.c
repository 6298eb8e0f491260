/* perilin in another program's PETSc session (the Python module, python/perilin_ext.c): a scene
 * with its overrides, the operators of the system as PETSc objects, the solution, the summary and
 * the resolved scene as text. See include/perilin.h, "Embedding", and docs/python.md. */
#include "perilin/private/problem.h"
#include "perilin/private/system.h"
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

/*@C
  PeriInitializeEmbedded - perilin's registries and allocator settings in a process whose SLEPc (and
  PETSc) another program started (petsc4py and slepc4py). Installs no signal handler: the host's
  stay. Call it after SlepcInitialize; it may be called again. Not collective.
@*/
PetscErrorCode PeriInitializeEmbedded(void)
{
  static PetscBool once = PETSC_FALSE;

  PetscFunctionBeginUser;
  if (!once) {
    PetscCall(PeriMallocInitialize());
    PetscCall(PeriBLASThreadsInitialize());
    once = PETSC_TRUE;
  }
  PetscCall(PeriInitializePackage());
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The overrides as options of a database of their own (-material_E for material.E): only they
 * override the scene, whatever the host's options hold. */
static PetscErrorCode OverridesToOptions(PetscInt n, const char *const keys[], const char *const values[], PetscOptions *opts)
{
  PetscFunctionBeginUser;
  PetscCall(PetscOptionsCreate(opts));
  for (PetscInt k = 0; k < n; k++) {
    char opt[512];
    PetscCheck(keys[k] && keys[k][0], PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "an override without a key");
    PeriSceneOptionName(keys[k], opt, sizeof(opt));
    PetscCall(PetscOptionsSetValue(*opts, opt, values[k]));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every override sets a scene key: one that nothing read (no key of the file, no documented key)
 * is an error, named as the command line names an unknown option, with the override's key. */
static PetscErrorCode CheckOverridesUsed(PeriProblem p, PetscOptions opts, PetscInt n, const char *const keys[])
{
  char **names;
  char   msg[1600] = "";

  PetscFunctionBeginUser;
  PetscCall(PeriSceneOptionNames(p->scene, &names));
  for (PetscInt k = 0; k < n; k++) {
    char      opt[512], hint[1100];
    size_t    used = strlen(msg);
    PetscBool read, exact;
    PeriSceneOptionName(keys[k], opt, sizeof(opt));
    PetscCall(PetscOptionsUsed(opts, opt + 1, &read)); /* the database keeps names without the '-' */
    if (read) continue;
    PeriSuggest(opt, names, hint, sizeof(hint), &exact);
    PetscCall(PetscSNPrintf(msg + used, sizeof(msg) - used, "%sunknown option %s (the override '%s'%s%s)", used ? "; " : "", opt, keys[k], hint[0] ? "; " : "", hint));
  }
  PetscCall(PetscStrArrayDestroy(&names));
  PetscCheck(!msg[0], PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s. Overrides set only the keys present in the scene file and the documented keys (perilin -help).", msg);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemLoadOverrides - reads the scene file and applies the n overrides keys[k] = values[k]
  (dotted scene keys, "material.E", "bc.0.region"; values as the command line takes them) instead
  of the options database; an override that names no scene key is an input error with the command
  line's message (PeriProblemCheckOptions). Collective.
@*/
PetscErrorCode PeriProblemLoadOverrides(PeriProblem p, const char file[], PetscInt n, const char *const keys[], const char *const values[])
{
  PetscOptions   opts = NULL;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(OverridesToOptions(n, keys, values, &opts));
  PetscCall(PetscOptionsPush(opts));
  ierr = PeriProblemLoad(p, file);
  if (!ierr) ierr = PeriProblemCheckOptions(p);
  if (!ierr) ierr = CheckOverridesUsed(p, opts, n, keys);
  PetscCall(PetscOptionsPop());
  PetscCall(PetscOptionsDestroy(&opts));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemSetOutputDir - where PeriProblemWriteOutput writes the output set, instead of the
  scene's output.dir. Call it after PeriProblemSetUp. Not collective (call it on every rank).
@*/
PetscErrorCode PeriProblemSetOutputDir(PeriProblem p, const char dir[])
{
  PetscFunctionBeginUser;
  PetscCheck(dir && dir[0], PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "an output directory needs a name");
  PetscCall(PetscStrncpy(p->output_dir, dir, sizeof(p->output_dir)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetStiffness - a new assembled stiffness K of the body as it stands (live bonds), in
  the global DOF layout (particle-major: DOF d of global particle i is row i dofs + d), before any
  condition or fictitious layer is applied; the caller destroys it. Collective, after
  PeriProblemSetUp.
@*/
PetscErrorCode PeriProblemGetStiffness(PeriProblem p, Mat *K)
{
  PetscFunctionBeginUser;
  PetscCheck(p->sys, p->comm, PETSC_ERR_ORDER, "the stiffness of a problem before its set-up");
  if (!p->sys->stiffness.mat_type[0]) PetscCall(PetscStrncpy(p->sys->stiffness.mat_type, MATBAIJ, sizeof(p->sys->stiffness.mat_type)));
  PetscCall(PeriAssembleStiffness(p->sys, K));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetLoads - a new vector with the loads f of the scene (the reference loads, load
  factor 1), in K's layout; the caller destroys it. Collective, after PeriProblemSetUp.
@*/
PetscErrorCode PeriProblemGetLoads(PeriProblem p, Vec *f)
{
  PetscFunctionBeginUser;
  PetscCheck(p->sys && p->sys->fields.f, p->comm, PETSC_ERR_ORDER, "the loads of a problem before its set-up");
  PetscCall(VecDuplicate(p->sys->fields.f, f));
  PetscCall(VecCopy(p->sys->fields.f, *f));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetMass - a new vector with the lumped mass per DOF (the diagonal mass matrix), in K's
  layout; the caller destroys it. Collective, after PeriProblemSetUp.
@*/
PetscErrorCode PeriProblemGetMass(PeriProblem p, Vec *m)
{
  Vec d;

  PetscFunctionBeginUser;
  PetscCheck(p->sys, p->comm, PETSC_ERR_ORDER, "the mass of a problem before its set-up");
  PetscCall(PeriMassGetDiagonal(p->sys, &d));
  PetscCall(VecDuplicate(d, m));
  PetscCall(VecCopy(d, *m));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetSolution - the present solution u in K's layout (borrowed; NULL before a run), and
  whether it describes a solution. Not collective.
@*/
PetscErrorCode PeriProblemGetSolution(PeriProblem p, Vec *u, PetscBool *solved)
{
  PetscFunctionBeginUser;
  *u      = p->sys ? p->sys->fields.u : NULL;
  *solved = (PetscBool)(p->sys && p->sys->fields.u && p->sys->fields.has_solution);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetConstraints - this rank's prescribed DOFs (global rows, sorted) and their values
  (borrowed): the bc items and the components the model holds at 0. Not collective.
@*/
PetscErrorCode PeriProblemGetConstraints(PeriProblem p, PetscInt *n, const PetscInt *rows[], const PetscReal *values[])
{
  PetscFunctionBeginUser;
  PetscCheck(p->sys, PETSC_COMM_SELF, PETSC_ERR_ORDER, "the constraints of a problem before its set-up");
  *n      = p->sys->conditions.nconstrained;
  *rows   = p->sys->conditions.constrained;
  *values = p->sys->conditions.constrained_value;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetLayout - the body's sizes and this rank's owned particles: dim, DOFs per particle
  and their names (borrowed), the particles of the whole body, this rank's first global particle
  and its count, and their positions (3 per particle, borrowed). Not collective.
@*/
PetscErrorCode PeriProblemGetLayout(PeriProblem p, PetscInt *dim, PetscInt *dofs, const char *const **components, PetscInt *N, PetscInt *rstart, PetscInt *nowned, const PetscReal *x[])
{
  PetscFunctionBeginUser;
  PetscCheck(p->sys, PETSC_COMM_SELF, PETSC_ERR_ORDER, "the particles of a problem before its set-up");
  *dim        = p->sys->disc.particles.dim;
  *dofs       = p->sys->model->dofs;
  *components = p->sys->model->components;
  *N          = p->sys->disc.N;
  *rstart     = p->sys->disc.bonds.rstart;
  *nowned     = p->sys->disc.bonds.rend - p->sys->disc.bonds.rstart;
  *x          = p->sys->disc.particles.x;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rank 0's text (NULL elsewhere) on every rank of comm, allocated with malloc. */
static PetscErrorCode BcastText(MPI_Comm comm, PetscMPIInt rank, char **text)
{
  long len = rank == 0 ? (long)strlen(*text) : 0;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Bcast(&len, 1, MPI_LONG, 0, comm));
  if (rank) {
    *text = (char *)malloc((size_t)len + 1);
    PetscCheck(*text, PETSC_COMM_SELF, PETSC_ERR_MEM, "no memory for %ld characters", len);
  }
  PetscCallMPI(MPI_Bcast(*text, (int)len + 1, MPI_CHAR, 0, comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The whole of a file, allocated with malloc. */
static PetscErrorCode ReadWhole(const char path[], char **text)
{
  FILE  *fp = fopen(path, "rb");
  long   len;
  size_t got;

  PetscFunctionBeginUser;
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot read %s", path);
  fseek(fp, 0, SEEK_END);
  len = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  *text = (char *)malloc((size_t)(len > 0 ? len : 0) + 1);
  if (!*text) fclose(fp);
  PetscCheck(*text, PETSC_COMM_SELF, PETSC_ERR_MEM, "no memory for %s", path);
  got          = len > 0 ? fread(*text, 1, (size_t)len, fp) : 0;
  (*text)[got] = 0;
  fclose(fp);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* summary.json written into a temporary directory by rank 0 and read back. */
static PetscErrorCode SummaryText(PeriProblem p, char **text)
{
  char           dir[PETSC_MAX_PATH_LEN], path[PETSC_MAX_PATH_LEN + 16];
  const char    *tmp = getenv("TMPDIR");
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(dir, sizeof(dir), "%s/perilin-summary-XXXXXX", tmp && tmp[0] ? tmp : "/tmp"));
  PetscCheck(mkdtemp(dir), PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot create a temporary directory %s for the summary", dir);
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/summary.json", dir));
  ierr = PeriWriteSummary(p, path);
  if (!ierr) ierr = ReadWhole(path, text);
  (void)unlink(path);
  (void)rmdir(dir);
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetSummary - what summary.json would hold now, as JSON text on every rank; free it
  with free(). Collective.
@*/
PetscErrorCode PeriProblemGetSummary(PeriProblem p, char **text)
{
  PetscErrorCode ierr = PETSC_SUCCESS;

  PetscFunctionBeginUser;
  PetscCheck(p->sys && p->analysis, p->comm, PETSC_ERR_ORDER, "the summary of a problem before its set-up");
  *text = NULL;
  if (p->rank == 0) ierr = SummaryText(p, text);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &ierr, 1, MPI_INT, MPI_MAX, p->comm));
  PetscCheck(!ierr, p->comm, ierr, "writing the summary failed");
  PetscCall(BcastText(p->comm, p->rank, text));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetScene - the resolved scene (what scene.yaml holds: every key read, with the value
  used) as YAML text; free it with free(). Not collective.
@*/
PetscErrorCode PeriProblemGetScene(PeriProblem p, char **text)
{
  size_t         len = 0;
  FILE          *fp;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  *text = NULL;
  fp    = open_memstream(text, &len);
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_MEM, "cannot open a memory stream for the scene");
  ierr = PeriSceneWriteResolved(p->scene, NULL, fp);
  fclose(fp);
  if (ierr) {
    free(*text);
    *text = NULL;
  }
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetOperator - a new MATSHELL applying the body's K (the live bonds) bond by bond, in
  K's layout, without conditions: the run's matrix-free operator where it has one, else one built
  from the bonds for this shell (which keeps it). MatMult equals PeriProblemGetStiffness's K times x
  to round-off. An error for the models whose bonds the operator cannot apply (a family model, a
  3D shear bond, the patch calibration's negative springs). Collective, after PeriProblemSetUp.
@*/
PetscErrorCode PeriProblemGetOperator(PeriProblem p, Mat *A)
{
  PeriOperator   op;
  const char    *why;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCheck(p->sys, p->comm, PETSC_ERR_ORDER, "the operator of a problem before its set-up");
  if (p->sys->stiffness.op) {
    PetscCall(PeriOperatorCreateMat(p->sys, A));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  why = PeriOperatorWhyNotModel(p->sys->model);
  if (!why && p->sys->model->calibration == PERI_CALIBRATION_PATCH) why = "the patch calibration may make springs negative, which the operator cannot apply";
  PetscCheck(!why, p->comm, PETSC_ERR_SUP, "%s: no matrix-free operator for model %s: %s (stiffness() is the assembled K)", p->scene->file, p->sys->model->type, why);
  PetscCall(PeriOperatorCreate(p->sys, p->sys->stiffness.pc_radius, &op));
  /* PeriOperatorCreateMat takes the system's operator: lent for the call, so the run's choice of
     K (solver.operator) stays as it was; the shell holds its own reference */
  p->sys->stiffness.op = op;
  ierr                 = PeriOperatorCreateMat(p->sys, A);
  p->sys->stiffness.op = NULL;
  PetscCall(PeriOperatorDestroy(&op));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetModes - the modes of a modal scene's run: their number (0 before the run) and how
  many of the first have a shape (PeriProblemGetMode). An error for another analysis. Not
  collective.
@*/
PetscErrorCode PeriProblemGetModes(PeriProblem p, PetscInt *n, PetscInt *nshapes)
{
  const PeriMode  *modes;
  const PetscReal *shapes;

  PetscFunctionBeginUser;
  PetscCheck(p->analysis, PETSC_COMM_SELF, PETSC_ERR_ORDER, "the modes of a problem before its set-up");
  PetscCall(PeriAnalysisGetModes(p->analysis, n, &modes, nshapes, &shapes));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetMode - mode k (0-based, by rising frequency): its frequency in Hz, its relative
  residual ||K x - omega^2 M x|| / (omega^2 ||M x||) on the free DOFs, its kind ("flexural", ...;
  borrowed) and this rank's owned DOFs of its shape in K's layout, scaled to max |u| = 1 (borrowed;
  NULL for the modes past the shapes kept). Not collective.
@*/
PetscErrorCode PeriProblemGetMode(PeriProblem p, PetscInt k, PetscReal *f_hz, PetscReal *residual, const char **kind, const PetscReal **shape)
{
  const PeriMode  *modes;
  const PetscReal *shapes;
  PetscInt         n, nshapes, nl;

  PetscFunctionBeginUser;
  PetscCheck(p->analysis, PETSC_COMM_SELF, PETSC_ERR_ORDER, "the modes of a problem before its set-up");
  PetscCall(PeriAnalysisGetModes(p->analysis, &n, &modes, &nshapes, &shapes));
  PetscCheck(k >= 0 && k < n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "mode %" PetscInt_FMT " of %" PetscInt_FMT, k, n);
  nl        = (p->sys->disc.bonds.rend - p->sys->disc.bonds.rstart) * p->sys->model->dofs;
  *f_hz     = modes[k].f_hz;
  *residual = modes[k].residual;
  *kind     = modes[k].kind;
  *shape    = k < nshapes ? &shapes[k * nl] : NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The analysis' table written by rank 0 into memory (NULL when it has none yet). */
static PetscErrorCode TableText(PeriProblem p, char **text)
{
  size_t         len = 0;
  FILE          *fp  = open_memstream(text, &len);
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_MEM, "cannot open a memory stream for the table");
  ierr = p->analysis->type->ops.table(p->analysis, fp);
  fclose(fp);
  if (ierr || !len) {
    free(*text);
    *text = NULL;
  }
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetTable - the analysis' table of rows as the output set's CSV file holds it (steps.csv
  of the quasi-static analysis, history.csv of the dynamic one): the file's name (NULL: the
  analysis has no table) and its text on every rank (NULL before the run); free it with free().
  Collective.
@*/
PetscErrorCode PeriProblemGetTable(PeriProblem p, const char **name, char **text)
{
  PetscErrorCode ierr = PETSC_SUCCESS;
  PetscInt       has  = 0;

  PetscFunctionBeginUser;
  PetscCheck(p->analysis, p->comm, PETSC_ERR_ORDER, "the table of a problem before its set-up");
  *name = p->analysis->type->ops.table ? p->analysis->type->table : NULL;
  *text = NULL;
  if (!*name) PetscFunctionReturn(PETSC_SUCCESS);
  if (p->rank == 0) ierr = TableText(p, text);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &ierr, 1, MPI_INT, MPI_MAX, p->comm));
  PetscCheck(!ierr, p->comm, ierr, "writing the table %s failed", *name);
  has = *text != NULL;
  PetscCallMPI(MPI_Bcast(&has, 1, MPIU_INT, 0, p->comm));
  if (has) PetscCall(BcastText(p->comm, p->rank, text));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether a changed key leaves the particles, regions and bonds as they are: the material (but its
 * thickness, which sets the particles' volumes), the loads, the bc items, the analysis' keys (but
 * its type, whose needs the set-up's memory estimate reads), the solver's and the output's keys.
 * Every other key (grid, particles, horizon, corrections, regions, cracks, model, dim, ...) may
 * change them. */
static PetscBool KeepsBonds(const char key[])
{
  static const char *const keep[] = {"material.", "loads.", "bc.", "analysis.", "solver.", "output.", NULL};

  if (!strcmp(key, "material.thickness") || !strcmp(key, "analysis.type")) return PETSC_FALSE;
  if (!strcmp(key, "loads") || !strcmp(key, "bc")) return PETSC_TRUE;
  for (PetscInt k = 0; keep[k]; k++)
    if (!strncmp(key, keep[k], strlen(keep[k]))) return PETSC_TRUE;
  return PETSC_FALSE;
}

/* Whether a changed key, besides keeping the bonds, leaves the check for mechanisms' verdict as it
 * was: the verdict depends on the bonds, the held DOFs (bc) and which bond stiffnesses vanish, and
 * E and rho only scale stiffness and mass (a positive E everywhere, as the input checks hold);
 * loads, the analysis' keys, the solver's and the output's touch neither. Every other material key
 * (nu, K, G, the micropolar constants) may zero a stiffness and bc items may free DOFs. */
static PetscBool KeepsMechanisms(const char key[])
{
  static const char *const keep[] = {"loads.", "analysis.", "solver.", "output.", NULL};

  if (!strcmp(key, "material.E") || !strcmp(key, "material.rho") || !strcmp(key, "loads")) return PETSC_TRUE;
  for (PetscInt k = 0; keep[k]; k++)
    if (!strncmp(key, keep[k], strlen(keep[k]))) return PETSC_TRUE;
  return PETSC_FALSE;
}

/* q's resolved scene starts as p's (the keys q's set-up does not read again: grid, horizon,
 * regions, ...), without the changed keys' stale values. */
static PetscErrorCode TakeResolved(PeriScene q, PeriScene p, PetscInt n, const char *const changed[])
{
  PetscFunctionBeginUser;
  PetscCall(PeriNodeDestroy(&q->resolved));
  PetscCall(PeriNodeDuplicate(p->resolved, &q->resolved));
  for (PetscInt k = 0; k < n && q->resolved; k++) PetscCall(PeriNodeRemovePath(q->resolved, changed[k]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemSetUpFrom - PeriProblemSetUp of q (loaded: p's scene file with the overrides, of which
  the keys changed[] differ from p's) on p's particles, regions and bonds where the changed keys
  leave them as they are (material but its thickness, loads, bc, analysis but its type, solver,
  output) and p's system can lend them (PeriSystemCanReuse): then q takes them, and sets up again
  only the model's constants and calibration, the conditions, the loads and the analysis (and the
  check for mechanisms only when a changed key may alter its verdict: KeepsMechanisms); p keeps
  its scene and analysis but has no particles left, and is to be destroyed. Otherwise a whole
  PeriProblemSetUp. *reused says which. On an error p is as it was. Collective.
@*/
PetscErrorCode PeriProblemSetUpFrom(PeriProblem q, PeriProblem p, PetscInt n, const char *const changed[], PetscBool *reused)
{
  PetscBool      keep = (PetscBool)(p && p->sys), known = PETSC_TRUE;
  const char    *why = NULL;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < n; k++) keep = (PetscBool)(keep && KeepsBonds(changed[k]));
  for (PetscInt k = 0; k < n; k++) known = (PetscBool)(known && KeepsMechanisms(changed[k]));
  if (keep) PetscCall(PeriSystemCanReuse(p->sys, &keep, &why));
  *reused = keep;
  if (!keep) {
    PetscCall(PeriProblemSetUp(q));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscLogStagePush(PERI_STAGE_Setup));
  PetscCall(TakeResolved(q->scene, p->scene, n, changed));
  PetscCall(PeriProblemSetFromScene(q));
  PetscCall(PeriSystemSetUpFrom(q->sys, p->sys, known));
  ierr = PeriAnalysisSetUp(q->analysis, q->sys);
  if (ierr) PetscCall(PeriSystemGiveBackDisc(q->sys, p->sys));
  PetscCall(ierr);
  q->sys->run.log.memory_phase_mb[0] = PeriPeakMemoryMB();
  PetscCall(PetscLogStagePop());
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemGetBonds - this rank's bond storage (its address, for identity only: a set-up that
  reused another problem's bonds has the same) and its count. Not collective.
@*/
PetscErrorCode PeriProblemGetBonds(PeriProblem p, const void **id, PetscInt *nbonds)
{
  PetscFunctionBeginUser;
  PetscCheck(p->sys, PETSC_COMM_SELF, PETSC_ERR_ORDER, "the bonds of a problem before its set-up");
  *id     = (const void *)p->sys->disc.bonds.offset;
  *nbonds = p->sys->disc.bonds.nbonds;
  PetscFunctionReturn(PETSC_SUCCESS);
}
