/* PeriProblem: one run from scene to output. Each stage is one call; see include/perilin.h. */
#include "perilin/private/problem.h"

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

/* -restart and -peri_checkpoint_every: the analysis reads them when its type writes checkpoints;
 * another refuses -restart, naming the types that do. */
static PetscErrorCode ReadCheckpointOptions(PeriProblem p)
{
  const PeriAnalysisType *const *types;
  PetscInt                       ntypes;
  PetscBool                      given;
  char                           list[128] = "";

  PetscFunctionBeginUser;
  if (p->analysis->type->checkpoints) {
    PetscCall(PeriAnalysisCheckpointSetFromOptions(p->analysis));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscOptionsHasName(NULL, NULL, "-restart", &given));
  PetscCall(PeriAnalysisGetTypes(&ntypes, &types));
  for (PetscInt k = 0; k < ntypes; k++)
    if (types[k]->checkpoints) PeriListAppend(list, sizeof(list), types[k]->name);
  PetscCheck(!given, p->comm, PETSC_ERR_USER_INPUT, "-restart continues a run from its checkpoint, and analysis.type %s writes none (those that do: %s): run it from the start", p->analysis_type, list);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* output.every in a scene whose analysis writes no series (static, modal): not read, but a value out
 * of the declared range is refused all the same, naming the key (issue 40, item 6). Not collective. */
static PetscErrorCode CheckUnreadEvery(PeriScene s)
{
  PeriNode          out = NULL, node = NULL;
  const PeriSchema *sec;
  const PeriKey    *decl;
  PetscReal         v;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "output", PETSC_FALSE, &out));
  if (out) PetscCall(PeriSceneGetNode(out, "every", &node));
  if (!node) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneParseReal(s, node, &v));
  PetscCall(PeriSceneFindKey(s, out, "every", &sec, &decl));
  PetscCall(PeriSceneCheckRange(s, node, sec, decl, v, node->value));
  PetscFunctionReturn(PETSC_SUCCESS);
}
/* analysis.type, checked against the registered types; analysis.* against that analysis' schema
 * (p->scene->owners holds every plug-in's), then read by the analysis itself: every analysis key
 * is checked before any particle exists. */
static PetscErrorCode ReadAnalysis(PeriProblem p)
{
  PeriScene               s      = p->scene;
  const PeriSchemaOwner  *active = NULL;
  const PeriAnalysisType *type;
  PeriNode                a;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_FALSE, &a));
  /* from the root, so that an absent analysis: takes the declared default too */
  PetscCall(PeriSceneGetString(s, s->root, "analysis.type", PETSC_FALSE, p->analysis_type, sizeof(p->analysis_type), NULL));
  PetscCall(PeriAnalysisFind(p->analysis_type, &type));
  if (!type) {
    char list[256];
    PetscCall(PeriAnalysisListTypes(list, sizeof(list)));
    PeriInputCheck(PETSC_FALSE, s, a, "type", "unknown analysis '%s'; available: %s", p->analysis_type, list);
  }
  for (PetscInt o = 0; o < s->nowners; o++)
    if (!strcmp(s->owners[o].kind, "analysis") && !strcmp(s->owners[o].name, p->analysis_type)) active = &s->owners[o];
  /* an analysis without a schema (setup, the dry run) accepts every analysis' keys, so that any
     scene can be checked with -analysis_type setup */
  if (active && !active->schema) active = NULL;
  PetscCall(PeriSceneCheckKeysSchema(s, a, "analysis", active));
  /* output.every: only the analyses that write series declare it, and only they read it (so that
     scene.yaml has it only for them) */
  if (PeriSchemaFindKey(type->schema, "output", "every"))
    PetscCall(PeriSceneGetInt(s, s->root, "output.every", PETSC_FALSE, &p->output_every, NULL));
  else
    PetscCall(CheckUnreadEvery(s));
  PetscCall(PeriAnalysisCreate(p->comm, type, &p->analysis));
  PetscCall(PeriAnalysisSetFromScene(p->analysis, s));
  PetscCall(ReadCheckpointOptions(p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* output.*, then the analysis; output.every is read with the analysis, whose key it is. */
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
  /* absolute in scene.yaml: run again from anywhere, it writes here again (unless -output_dir) */
  PetscCall(PeriSceneResolvePath(s, s->root, "output.dir", p->output_dir));
  PetscCall(PeriSceneGetBool(s, s->root, "output.vtk", &p->vtk, NULL));
  PetscCall(PeriSceneGetBool(s, s->root, "output.stress", &p->stress_output, NULL));
  PetscCall(PeriSceneGetBool(s, s->root, "output.plots", &p->plots, NULL));
  PetscCall(ReadAnalysis(p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemSetFromScene - the first part of PeriProblemSetUp: the root, output, analysis and
  model keys checked and read, the system created, no particle yet (the scene fuzzer,
  tests/fuzz/fuzz_scene.c, stops here). Collective.
@*/
PetscErrorCode PeriProblemSetFromScene(PeriProblem p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriSceneCheckSection(p->scene, p->scene->root, ""));
  /* the output and the analysis first: their keys are checked before any particle exists */
  PetscCall(ReadOutput(p, p->scene->file));
  PetscCall(PeriSystemCreate(p->comm, p->scene, &p->sys));
  p->sys->fields.stress_output = p->stress_output;
  PetscCall(PeriSystemSetNeeds(p->sys, &p->analysis->needs));
  PetscCall(PeriProgressUpdate(p->sys->run.progress, PERI_PROGRESS_PHASE, "setup"));
  PetscCall(PeriSystemSetFromScene(p->sys));
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
  PetscCall(PeriProblemSetFromScene(p));
  if (p->write_output) PetscCall(PeriOutputSetOpen(p->comm, p->output_dir, sizeof(p->output_dir), p->staging_dir, sizeof(p->staging_dir)));
  PetscCall(PeriSystemSetUp(p->sys));
  PetscCall(PeriAnalysisSetUp(p->analysis, p->sys));
  p->sys->run.log.memory_phase_mb[0] = PeriPeakMemoryMB();
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_scene_sealed", &p->scene->sealed, NULL));
  PetscCall(PetscLogStagePop());
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The analysis' output-directory callback: the staging directory of the output set, opened here
 * if the run has not opened it yet (a test drives the library without it). */
static PetscErrorCode OutputDir(void *ctx, const char **dir)
{
  PeriProblem p = (PeriProblem)ctx;

  PetscFunctionBeginUser;
  if (!p->staging_dir[0]) PetscCall(PeriOutputSetOpen(p->comm, p->output_dir, sizeof(p->output_dir), p->staging_dir, sizeof(p->staging_dir)));
  *dir = p->staging_dir;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The analysis' snapshot callback: the system's present state as BASE.vtu (BASE.pvtu on several
 * ranks) in the output set. */
static PetscErrorCode WriteSnapshot(void *ctx, const char base[])
{
  PeriProblem p   = (PeriProblem)ctx;
  const char *dir = NULL;

  PetscFunctionBeginUser;
  PetscCall(OutputDir(ctx, &dir));
  PetscCall(PeriSystemWriteParticles(p->sys, p->sys->fields.u_owned, dir, base));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemRun - runs the scene's analysis (analysis.type), found by name. Collective.
@*/
PetscErrorCode PeriProblemRun(PeriProblem p)
{
  PetscReal      mb;
  PetscLogDouble t;

  PetscFunctionBeginUser;
  p->analysis->vtk           = p->vtk;
  p->analysis->every         = p->output_every;
  p->analysis->plots.enabled = p->plots;
  p->analysis->output_dir    = p->output_dir;
  p->analysis->snapshot      = WriteSnapshot;
  p->analysis->outputdir     = OutputDir;
  p->analysis->snapshotctx   = p;
  /* the scene as every run of it has read it by now: what ties a checkpoint to its scene */
  if (p->analysis->type->checkpoints) PetscCall(PeriSceneFingerprint(p->scene, &p->analysis->fingerprint));
  /* a signal during the set-up: no analysis, only the summary saying so */
  PetscCall(PeriSignalReceived(p->comm, &p->sys->run.interrupted));
  PetscCall(PetscLogStagePush(PERI_STAGE_Solve));
  if (!p->sys->run.interrupted) PetscCall(PeriAnalysisRun(p->analysis));
  PetscCall(PetscLogStagePop());
  PetscCall(PetscTime(&t));
  p->sys->run.log.total_s            = t - p->t_start;
  mb                                 = PeriPeakMemoryMB();
  p->sys->run.log.memory_phase_mb[2] = mb;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, p->sys->run.log.memory_phase_mb, 3, MPIU_REAL, MPI_MAX, p->comm));
  PetscCallMPI(MPI_Allreduce(&mb, &p->sys->run.log.memory_mb, 1, MPIU_REAL, MPI_SUM, p->comm));
  PetscCallMPI(MPI_Allreduce(&mb, &p->sys->run.log.memory_mb_max_rank, 1, MPIU_REAL, MPI_MAX, p->comm));
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
  if (sys->fields.u_owned) PetscCall(PeriFieldListAddSolution(fl, "", sys->model->dofs, sys->model->components, sys->model->axis, sys->fields.u_owned));
  if (p->analysis && p->analysis->type->ops.fields) PetscCall(p->analysis->type->ops.fields(p->analysis, fl));
  PetscCall(PeriSystemAddFields(sys, fl));
  PetscCall(PeriWriteParticles(p->comm, fl, p->staging_dir, "particles"));
  PetscCall(PeriFieldListDestroy(&fl));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemWriteOutput - writes the output set (summary.json, scene.yaml, particles.vtu and the
  analysis' files) into the staging directory and swaps it in for the output directory as a whole.
  Collective.
@*/
PetscErrorCode PeriProblemWriteOutput(PeriProblem p)
{
  char path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PERI_STAGE_Output));
  PetscCall(PeriProgressUpdate(p->sys->run.progress, PERI_PROGRESS_ANALYSIS, NULL));
  PetscCall(PeriProgressUpdate(p->sys->run.progress, PERI_PROGRESS_PHASE, "output"));
  if (!p->staging_dir[0]) PetscCall(PeriOutputSetOpen(p->comm, p->output_dir, sizeof(p->output_dir), p->staging_dir, sizeof(p->staging_dir)));
  /* an analysis stopped before it had a state writes no fields: only the summary saying so */
  if (p->vtk && (!p->sys->run.interrupted || p->sys->fields.u_owned)) {
    PetscCall(WriteParticles(p));
  }
  /* a signal asks to stop soon: no pictures (summary.json says why) */
  if (p->analysis && p->sys->run.interrupted) PetscCall(PetscStrncpy(p->analysis->plots.error, "the run was interrupted", sizeof(p->analysis->plots.error)));
  if (p->analysis && p->analysis->type->ops.files) PetscCall(p->analysis->type->ops.files(p->analysis, p->staging_dir));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/scene.yaml", p->staging_dir));
  PetscCall(PeriWriteScene(p, path));
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
  PetscCall(PeriOptionsCheckTypes(p->comm));    /* before PETSc's leaking refusal of an unknown type */
  PetscCall(PeriOptionsCheckOwnBools(p->comm)); /* before a reader refuses a value without naming the option */
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemCheckUnusedOptions(PeriProblem p)
{
  PeriRunSolvers run = {p->comm, p->scene, p->sys->stiffness.mat_type, p->sys->fields.solve.ksp_type, p->sys->fields.solve.pc_type, p->analysis->type->option_prefix, p->analysis->type->ops.solvers_from_options};

  PetscFunctionBeginUser;
  /* -mat_type sets the type of the assembled matrix: K, or with a matrix-free K its preconditioner */
  if (p->sys->stiffness.Kpc)
    PetscCall(MatGetType(p->sys->stiffness.Kpc, &run.mat_type));
  else if (p->sys->stiffness.K)
    PetscCall(MatGetType(p->sys->stiffness.K, &run.mat_type));
  PetscCall(PeriOptionsCheckUnused(&run));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemInterrupted(PeriProblem p, int *signal)
{
  PetscFunctionBeginUser;
  *signal = p->sys ? p->sys->run.interrupted : 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The displacements a static result is read by: the largest of each component, and the probes'
 * (the first few; summary.json has them all). */
#define PERI_REPORT_PROBES 6
static PetscErrorCode ReportDisplacements(PeriProblem p)
{
  PeriSystem sys = p->sys;
  PeriModel  m   = sys->model;

  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(p->comm, "perilin: largest displacement"));
  for (PetscInt c = 0; c < m->dofs; c++) PetscCall(PetscPrintf(p->comm, "%s |%s| %g", c ? "," : "", m->components[c], (double)sys->fields.max_abs_u[c]));
  PetscCall(PetscPrintf(p->comm, "\n"));
  for (PetscInt k = 0; k < PetscMin(sys->fields.nprobes, PERI_REPORT_PROBES); k++) {
    const PeriProbe *q     = &sys->fields.probes[k];
    char             z[32] = "";
    if (sys->disc.particles.dim == 3) PetscCall(PetscSNPrintf(z, sizeof(z), ", %g", (double)q->particle_x[2]));
    PetscCall(PetscPrintf(p->comm, "perilin: probe %s at (%g, %g%s):", q->name, (double)q->particle_x[0], (double)q->particle_x[1], z));
    for (PetscInt c = 0; c < m->dofs; c++) PetscCall(PetscPrintf(p->comm, " %s %g", m->components[c], (double)q->u[c]));
    PetscCall(PetscPrintf(p->comm, "\n"));
  }
  if (sys->fields.nprobes > PERI_REPORT_PROBES) PetscCall(PetscPrintf(p->comm, "perilin: ... and %" PetscInt_FMT " more probes in summary.json\n", sys->fields.nprobes - PERI_REPORT_PROBES));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The one-paragraph report on stdout: what ran, what it cost, the main results. */
PetscErrorCode PeriProblemReport(PeriProblem p)
{
  PeriSystem sys = p->sys;

  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(p->comm, "perilin: %s, model %s, %" PetscInt_FMT " particles, %" PetscInt_FMT " bonds, %" PetscInt_FMT " dofs on %d rank(s)\n", p->analysis_type, sys->model->type, sys->disc.N, sys->run.log.nbonds_total, sys->disc.N * sys->model->dofs, p->size));
  if (sys->fields.solve.ksp_type[0])
    PetscCall(PetscPrintf(p->comm, "perilin: neighbours %.3f s, assembly %.3f s, solve %.3f s (%s/%s%s, %" PetscInt_FMT " iterations, %s, %s %.2g), peak memory %.1f MB\n", sys->run.log.neighbors_s, sys->run.log.assembly_s, sys->run.log.solve_s, sys->fields.solve.ksp_type, sys->fields.solve.pc_type, sys->stiffness.op ? " matrix-free" : "", sys->fields.solve.iterations, sys->fields.solve.converged_reason, sys->fields.solve.checked[0] ? sys->fields.solve.checked : "true relative residual",
                          (double)(sys->fields.solve.checked[0] ? sys->fields.solve.checked_value : sys->fields.solve.residual_norm), sys->run.log.memory_mb));
  else
    PetscCall(PetscPrintf(p->comm, "perilin: neighbours %.3f s, no solve, peak memory %.1f MB\n", sys->run.log.neighbors_s, sys->run.log.memory_mb));
  if (sys->run.interrupted) {
    PetscCall(PetscPrintf(p->comm, "perilin: interrupted by %s: %s; summary.json says \"complete\": false; results in %s/\n", PeriSignalName(sys->run.interrupted), sys->fields.u_owned ? "the last complete state was written" : "no result was reached", p->output_dir));
  } else if (p->analysis && p->analysis->type->ops.report) {
    PetscCall(p->analysis->type->ops.report(p->analysis));
  } else {
    const PeriTorsion   *t = &sys->conditions.torsion;
    const PeriReference *r = &sys->reference;
    if (r->evaluated) {
      PetscCall(PetscPrintf(p->comm, "perilin: against the exact %s field: relative error %.3g (L2), %.3g (max) over %" PetscInt_FMT " interior particles", PeriReferenceTypes[r->type], (double)r->error_l2_rel, (double)r->error_max_rel, r->interior_particles));
      /* the effective constants this stress state defines (0: not defined) */
      if (r->effective_E > 0) PetscCall(PetscPrintf(p->comm, "; effective E %g, nu %g", (double)r->effective_E, (double)r->effective_nu));
      if (r->effective_G > 0) PetscCall(PetscPrintf(p->comm, "; effective G %g", (double)r->effective_G));
      PetscCall(PetscPrintf(p->comm, "\n"));
    }
    if (t->active) PetscCall(PetscPrintf(p->comm, "perilin: torsion: torque %g per unit length, J = %g (solid rectangle exact %g, %+.2f %%), max shear stress %g at (%g, %g)\n", (double)t->torque, (double)t->J, (double)t->J_rectangle, 100 * (double)(t->J / t->J_rectangle - 1), (double)t->max_stress, (double)t->max_at[0], (double)t->max_at[1]));
    if (sys->fields.u_owned) PetscCall(ReportDisplacements(p));
    PetscCall(PetscPrintf(p->comm, "perilin: strain energy %g; results in %s/: summary.json, scene.yaml%s (docs/summary.md)\n", sys->fields.strain_energy, p->output_dir, !p->vtk ? "" : p->size > 1 ? ", particles.pvtu"
                                                                                                                                                                                                     : ", particles.vtu"));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}
