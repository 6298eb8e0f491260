/* PeriProblem: one run from scene to output. Each stage is one call; see include/perilin.h. */
#include "perilin/private/problem.h"
#include <signal.h>

PetscErrorCode PeriProblemCreate(MPI_Comm comm, PeriProblem *problem)
{
  PeriProblem p;

  PetscFunctionBeginUser;
  PetscCall(PeriInitializePackage());
  PetscCall(PetscNew(&p));
  p->comm = comm;
  PetscCallMPI(MPI_Comm_rank(comm, &p->rank));
  PetscCallMPI(MPI_Comm_size(comm, &p->size));
  PetscCall(PetscTime(&p->t_start));
  *problem = p;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemLoad - reads the scene file (every rank reads it) and applies option overrides. Collective.
@*/
PetscErrorCode PeriProblemLoad(PeriProblem p, const char file[])
{
  PeriSchemaOwner owners[PERI_MAX_SCHEMA_OWNERS];
  PetscInt        n;

  PetscFunctionBeginUser;
  PetscCall(PeriSchemaOwners(PERI_MAX_SCHEMA_OWNERS, owners, &n));
  PetscCall(PeriSceneCreateFromFile(file, n, owners, &p->scene));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The root keys, in the order "allowed here" lists them, and the core's keys of analysis and
 * output (the analyses declare theirs). */
static const PeriKey root_keys[] = {
    {"dim", PERI_KEY_INT, "required", "{2, 3}", NULL, NULL, "the space dimension"},
    {"model", PERI_KEY_MAP, "required", NULL, NULL, NULL, "the bond model and its constants"},
    {"material", PERI_KEY_MAP, "required", NULL, NULL, NULL, "the elastic constants and the density"},
    {"grid", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "particles on a regular grid filling a box (or particles)"},
    {"particles", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "particles read from a CSV file (or grid)"},
    {"horizon", PERI_KEY_MAP, "required", NULL, NULL, NULL, "the horizon radius"},
    {"corrections", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "partial-volume and surface corrections"},
    {"regions", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "named boxes and boundary layers"},
    {"bc", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "boundary conditions, applied in order"},
    {"loads", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "forces, tractions and body forces"},
    {"probes", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "named points reported after the solve"},
    {"analysis", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "what to compute"},
    {"output", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "where and what to write"},
    {"reference", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "an exact plane elasticity field to compare with"},
    {"boundary_layers", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "fictitious layers outside the faces (cross-section models)"},
    {"torsion", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "the twist of a bar (cross-section models)"},
    {"failure", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "bond failure criteria"},
    {"cracks", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "pre-existing cracks"},
    {"solver", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "checks of the linear solves"},
    {NULL},
};
static const PeriKey analysis_keys[] = {
    {"type", PERI_KEY_STRING, "static", NULL, NULL, NULL, "the analysis"},
    {NULL},
};
static const PeriKey output_keys[] = {
    {"dir", PERI_KEY_STRING, "<scene file name without directory and last extension>-out", NULL, NULL, NULL, "output directory"},
    {"vtk", PERI_KEY_BOOL, "true", NULL, NULL, NULL, "write particles.vtu"},
    {"stress", PERI_KEY_BOOL, "false", NULL, NULL, NULL, "per-particle stress and strain (vector models): arrays stress, strain, elastic_stress in particles.vtu and sigma, epsilon, sigma_elastic in the probes (docs/stress.md); costs a pass over the bonds and 27 numbers per particle"},
    {NULL},
};
const PeriSchema PeriProblemSchema[] = {
    {"", root_keys},
    {"analysis", analysis_keys},
    {"output", output_keys},
    {NULL},
};

/* analysis.type, and analysis.* against that analysis' schema (p->scene->owners holds every
 * plug-in's). An unknown type allows every analysis' keys here: PeriProblemRun reports it with
 * the list of types. */
static PetscErrorCode ReadAnalysis(PeriProblem p)
{
  PeriScene              s      = p->scene;
  const PeriSchemaOwner *active = NULL;
  PeriNode               a;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_FALSE, &a));
  /* from the root, so that an absent analysis: takes the declared default too */
  PetscCall(PeriSceneGetString(s, s->root, "analysis.type", PETSC_FALSE, p->analysis_type, sizeof(p->analysis_type), NULL));
  for (PetscInt o = 0; o < s->nowners; o++)
    if (!strcmp(s->owners[o].kind, "analysis") && !strcmp(s->owners[o].name, p->analysis_type)) active = &s->owners[o];
  /* an analysis without a schema (setup, the dry run) accepts every analysis' keys, so that any
     scene can be checked with -analysis_type setup */
  if (active && !active->schema) active = NULL;
  PetscCall(PeriSceneCheckKeysSchema(s, a, "analysis", active));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* output.*; output.every is quasistatic's key (its schema), read here with the others for now. */
static PetscErrorCode ReadOutput(PeriProblem p, const char file[])
{
  PeriScene s = p->scene;
  PeriNode  o;
  char      base[PETSC_MAX_PATH_LEN], *slash, *dot;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(base, (slash = strrchr(file, '/')) ? slash + 1 : file, sizeof(base)));
  if ((dot = strrchr(base, '.'))) *dot = 0;
  PetscCall(PetscSNPrintf(p->output_dir, sizeof(p->output_dir), "%s-out", base));
  PetscCall(PeriSceneGetMap(s, s->root, "output", PETSC_FALSE, &o));
  PetscCall(PeriSceneCheckSection(s, o, "output"));
  /* from the root, so that an absent output: takes the declared defaults too */
  PetscCall(PeriSceneGetString(s, s->root, "output.dir", PETSC_FALSE, p->output_dir, sizeof(p->output_dir), NULL));
  PetscCall(PeriSceneGetBool(s, s->root, "output.vtk", &p->vtk, NULL));
  PetscCall(PeriSceneGetBool(s, s->root, "output.stress", &p->sys->stress_output, NULL));
  PetscCall(PeriSceneGetInt(s, s->root, "output.every", PETSC_FALSE, &p->output_every, NULL));
  PetscCall(ReadAnalysis(p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemSetUp - the system (particles, bonds, model, conditions) with every input check, and
  the output set, opened before any large computation so that a bad output.dir costs nothing.
  Collective.
@*/
PetscErrorCode PeriProblemSetUp(PeriProblem p)
{
  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PERI_STAGE_Setup));
  PetscCall(PeriSceneCheckSection(p->scene, p->scene->root, ""));
  PetscCall(PeriSystemCreate(p->comm, p->scene, &p->sys));
  PetscCall(PeriProgressUpdate(p->sys->progress, PERI_PROGRESS_PHASE, "setup"));
  PetscCall(PeriSystemSetFromScene(p->sys));
  PetscCall(ReadOutput(p, p->scene->file));
  if (p->write_output) PetscCall(PeriOutputSetOpen(p->comm, p->output_dir, sizeof(p->output_dir), p->staging_dir, sizeof(p->staging_dir)));
  PetscCall(PeriSystemSetUp(p->sys));
  p->sys->log.memory_phase_mb[0] = PeriPeakMemoryMB();
  PetscCall(PetscLogStagePop());
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The analysis' snapshot callback: the system's present state as BASE.vtu (BASE.pvtu on several
 * ranks) in the output set, which is opened here if the run has not opened it yet (a test drives
 * the library without it). */
static PetscErrorCode WriteSnapshot(void *ctx, const char base[])
{
  PeriProblem p = (PeriProblem)ctx;

  PetscFunctionBeginUser;
  if (!p->staging_dir[0]) PetscCall(PeriOutputSetOpen(p->comm, p->output_dir, sizeof(p->output_dir), p->staging_dir, sizeof(p->staging_dir)));
  PetscCall(PeriSystemWriteParticles(p->sys, p->sys->u_owned, p->staging_dir, base));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemRun - runs the scene's analysis (analysis.type), found by name. Collective.
@*/
PetscErrorCode PeriProblemRun(PeriProblem p)
{
  const PeriAnalysisType *type;
  PetscReal               mb;
  PetscLogDouble          t;

  PetscFunctionBeginUser;
  PetscCall(PeriAnalysisFind(p->analysis_type, &type));
  if (!type) {
    PeriNode a;
    char     list[256];
    PetscCall(PeriSceneGetNode(p->scene->root, "analysis", &a));
    PetscCall(PeriAnalysisListTypes(list, sizeof(list)));
    PeriInputCheck(PETSC_FALSE, p->scene, a, "type", "unknown analysis '%s'; available: %s", p->analysis_type, list);
  }
  PetscCall(PeriAnalysisCreate(type, p->sys, &p->analysis));
  p->analysis->vtk         = p->vtk;
  p->analysis->every       = p->output_every;
  p->analysis->output_dir  = p->output_dir;
  p->analysis->snapshot    = WriteSnapshot;
  p->analysis->snapshotctx = p;
  /* a signal during the set-up: no analysis, only the summary saying so */
  PetscCall(PeriSignalReceived(p->comm, &p->sys->interrupted));
  PetscCall(PetscLogStagePush(PERI_STAGE_Solve));
  if (!p->sys->interrupted) PetscCall(type->ops.run(p->analysis));
  PetscCall(PetscLogStagePop());
  PetscCall(PetscTime(&t));
  p->sys->log.total_s            = t - p->t_start;
  mb                             = PeriPeakMemoryMB();
  p->sys->log.memory_phase_mb[2] = mb;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, p->sys->log.memory_phase_mb, 3, MPIU_REAL, MPI_MAX, p->comm));
  PetscCallMPI(MPI_Allreduce(&mb, &p->sys->log.memory_mb, 1, MPIU_REAL, MPI_SUM, p->comm));
  PetscCallMPI(MPI_Allreduce(&mb, &p->sys->log.memory_mb_max_rank, 1, MPIU_REAL, MPI_MAX, p->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles.vtu (particles.pvtu and its pieces on several ranks): the solution, the analysis'
 * fields (mode shapes), the system's fields, each rank its own particles'. Collective. */
static PetscErrorCode WriteParticles(PeriProblem p)
{
  PeriSystem    sys = p->sys;
  PeriFieldList fl;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemFieldListCreate(sys, &fl));
  if (sys->u_owned) PetscCall(PeriFieldListAddSolution(fl, "", sys->model->dofs, sys->model->components, sys->u_owned));
  if (p->analysis && p->analysis->type->ops.fields) PetscCall(p->analysis->type->ops.fields(p->analysis, fl));
  PetscCall(PeriSystemAddFields(sys, fl));
  PetscCall(PeriWriteParticles(p->comm, fl, p->staging_dir, "particles"));
  PetscCall(PeriFieldListDestroy(&fl));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemWriteOutput - writes the output set (summary.json, particles.vtu and the analysis'
  files) into the staging directory and swaps it in for the output directory as a whole.
  Collective.
@*/
PetscErrorCode PeriProblemWriteOutput(PeriProblem p)
{
  char path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PERI_STAGE_Output));
  PetscCall(PeriProgressUpdate(p->sys->progress, PERI_PROGRESS_ANALYSIS, NULL));
  PetscCall(PeriProgressUpdate(p->sys->progress, PERI_PROGRESS_PHASE, "output"));
  if (!p->staging_dir[0]) PetscCall(PeriOutputSetOpen(p->comm, p->output_dir, sizeof(p->output_dir), p->staging_dir, sizeof(p->staging_dir)));
  /* an analysis stopped before it had a state writes no fields: only the summary saying so */
  if (p->vtk && (!p->sys->interrupted || p->sys->u_owned)) {
    PetscCall(WriteParticles(p));
  }
  if (p->analysis && p->analysis->type->ops.files) PetscCall(p->analysis->type->ops.files(p->analysis, p->staging_dir));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/summary.json", p->staging_dir));
  PetscCall(PeriWriteSummary(p, path));
  PetscCall(PeriOutputSetCommit(p->comm, p->staging_dir, p->output_dir));
  p->staging_dir[0] = 0;
  PetscCall(PetscLogStagePop());
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemDestroy(PeriProblem *problem)
{
  PeriProblem p = *problem;

  PetscFunctionBeginUser;
  if (!p) PetscFunctionReturn(PETSC_SUCCESS);
  if (p->staging_dir[0] && p->rank == 0) PeriOutputSetDiscard(); /* never committed: the previous results stay */
  PetscCall(PeriSystemDestroy(&p->sys));
  PetscCall(PeriAnalysisDestroy(&p->analysis));
  PetscCall(PeriSceneDestroy(&p->scene));
  PetscCall(PetscFree(p));
  *problem = NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemSetWriteOutput(PeriProblem p, PetscBool write)
{
  PetscFunctionBeginUser;
  p->write_output = write;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemCheckOptions(PeriProblem p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriOptionsCheckScene(p->comm, p->scene));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemCheckUnusedOptions(PeriProblem p)
{
  PeriRunSolvers run = {p->comm, p->scene, p->sys->mat_type, p->sys->solve.ksp_type, p->sys->solve.pc_type, p->analysis ? p->analysis->type->eigensolver : PETSC_FALSE};

  PetscFunctionBeginUser;
  /* -mat_type sets the type of the assembled matrix: K, or with a matrix-free K its preconditioner */
  if (p->sys->Kpc)
    PetscCall(MatGetType(p->sys->Kpc, &run.mat_type));
  else if (p->sys->K)
    PetscCall(MatGetType(p->sys->K, &run.mat_type));
  PetscCall(PeriOptionsCheckUnused(&run));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemInterrupted(PeriProblem p, int *signal)
{
  PetscFunctionBeginUser;
  *signal = p->sys ? p->sys->interrupted : 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The one-paragraph report on stdout: what ran, what it cost, the main results. */
PetscErrorCode PeriProblemReport(PeriProblem p)
{
  PeriSystem sys = p->sys;

  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(p->comm, "perilin: %s, model %s, %" PetscInt_FMT " particles, %" PetscInt_FMT " bonds, %" PetscInt_FMT " dofs on %d rank(s)\n", p->analysis_type, sys->model->type, sys->disc.N, sys->log.nbonds_total, sys->disc.N * sys->model->dofs, p->size));
  if (sys->solve.ksp_type[0])
    PetscCall(PetscPrintf(p->comm, "perilin: neighbours %.3f s, assembly %.3f s, solve %.3f s (%s/%s%s, %" PetscInt_FMT " iterations, %s, true relative residual %.2g), peak memory %.1f MB\n", sys->log.neighbors_s, sys->log.assembly_s, sys->log.solve_s, sys->solve.ksp_type, sys->solve.pc_type, sys->op ? " matrix-free" : "", sys->solve.iterations, sys->solve.converged_reason, (double)sys->solve.residual_norm, sys->log.memory_mb));
  else
    PetscCall(PetscPrintf(p->comm, "perilin: neighbours %.3f s, no solve, peak memory %.1f MB\n", sys->log.neighbors_s, sys->log.memory_mb));
  if (sys->interrupted) {
    PetscCall(PetscPrintf(p->comm, "perilin: interrupted by %s: %s; summary.json says \"complete\": false; results in %s/\n", sys->interrupted == SIGTERM ? "SIGTERM" : "SIGINT", sys->u_owned ? "the last complete state was written" : "no result was reached", p->output_dir));
  } else if (p->analysis && p->analysis->type->ops.report) {
    PetscCall(p->analysis->type->ops.report(p->analysis));
  } else {
    const PeriTorsion *t = &sys->torsion;
    if (t->active) PetscCall(PetscPrintf(p->comm, "perilin: torsion: torque %g per unit length, J = %g (solid rectangle exact %g, %+.2f %%), max shear stress %g at (%g, %g)\n", (double)t->torque, (double)t->J, (double)t->J_rectangle, 100 * (double)(t->J / t->J_rectangle - 1), (double)t->max_stress, (double)t->max_at[0], (double)t->max_at[1]));
    PetscCall(PetscPrintf(p->comm, "perilin: strain energy %g; results in %s/\n", sys->strain_energy, p->output_dir));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}
