/* PeriProblem: one run from scene to output. Each stage is one call; see include/perilin.h. */
#include "perilin.h"
#include <sys/resource.h>

PetscLogEvent PERI_EVENT_Neighbors, PERI_EVENT_Partition, PERI_EVENT_Assembly, PERI_EVENT_Solve;
PetscLogStage PERI_STAGE_Setup, PERI_STAGE_Assembly, PERI_STAGE_Solve, PERI_STAGE_Output;

PetscErrorCode PeriInitializePackage(void)
{
  static PetscBool done = PETSC_FALSE;
  PetscClassId     id;

  PetscFunctionBeginUser;
  if (done) PetscFunctionReturn(PETSC_SUCCESS);
  done = PETSC_TRUE;
  PetscCall(PetscClassIdRegister("perilin", &id));
  PetscCall(PetscLogEventRegister("PeriPartition", id, &PERI_EVENT_Partition));
  PetscCall(PetscLogEventRegister("PeriNeighbors", id, &PERI_EVENT_Neighbors));
  PetscCall(PetscLogEventRegister("PeriAssembly", id, &PERI_EVENT_Assembly));
  PetscCall(PetscLogEventRegister("PeriSolve", id, &PERI_EVENT_Solve));
  PetscCall(PetscLogStageRegister("Peri setup", &PERI_STAGE_Setup));
  PetscCall(PetscLogStageRegister("Peri assembly", &PERI_STAGE_Assembly));
  PetscCall(PetscLogStageRegister("Peri solve", &PERI_STAGE_Solve));
  PetscCall(PetscLogStageRegister("Peri output", &PERI_STAGE_Output));
  PetscCall(PeriModelRegisterAll());
  PetscCall(PeriAnalysisRegisterAll());
  PetscFunctionReturn(PETSC_SUCCESS);
}

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
  PetscFunctionBeginUser;
  PetscCall(PeriSceneCreateFromFile(file, &p->scene));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ReadHorizon(PeriProblem p)
{
  static const char *const keys[] = {"m", "delta", NULL};
  PeriScene                s      = p->scene;
  PeriNode                 h;
  PetscReal                m = 0, hmax = 0;
  PetscBool                hasm, hasd;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "horizon", PETSC_TRUE, &h));
  PetscCall(PeriSceneCheckKeys(s, h, keys));
  PetscCall(PeriSceneGetReal(s, h, "m", PETSC_FALSE, &m, &hasm));
  PetscCall(PeriSceneGetReal(s, h, "delta", PETSC_FALSE, &p->delta, &hasd));
  PeriInputCheck(hasm || hasd, s, h, "m", "is required (or give horizon.delta)");
  PeriInputCheck(!(hasm && hasd), s, h, "delta", "give horizon.m or horizon.delta, not both");
  if (hasm) {
    PeriInputCheck(m >= 1, s, h, "m", "must be at least 1 (the horizon may not be smaller than the spacing), got %g", (double)m);
    p->delta = m * p->particles.mean_spacing;
  }
  for (PetscInt k = 0; k < p->particles.n; k++) hmax = PetscMax(hmax, p->particles.spacing[k]);
  PeriInputCheck(p->delta >= hmax * (1 - 1e-10), s, h, hasm ? "m" : "delta", "the horizon %g is smaller than the particle spacing %g: particles would have no bonds", (double)p->delta, (double)hmax);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ReadCorrections(PeriProblem p)
{
  static const char *const keys[] = {"partial_volume", "surface", NULL};
  PeriScene                s      = p->scene;
  PeriNode                 c;
  PetscInt                 pv = PERI_PARTIAL_VOLUME_LINEAR_CONTINUED, sc = PERI_SURFACE_NONE;
  PetscBool                found;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "corrections", PETSC_FALSE, &c));
  PetscCall(PeriSceneCheckKeys(s, c, keys));
  PetscCall(PeriSceneGetChoice(s, c, "partial_volume", PeriPartialVolumes, &pv, NULL));
  PetscCall(PeriSceneGetChoice(s, c, "surface", PeriSurfaceCorrections, &sc, &found));
  PeriInputCheck(sc == PERI_SURFACE_NONE || p->model->allows_surface_correction, s, c, "surface", "model %s normalizes each particle's micromodulus by its own family volume, which already corrects surfaces: use surface: none", p->model->type);
  p->partial_volume = (PeriPartialVolume)pv;
  p->surface        = (PeriSurfaceCorrection)sc;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscBool LexLess(const PetscReal a[], const PetscReal b[])
{
  for (PetscInt d = 0; d < 3; d++)
    if (a[d] != b[d]) return a[d] < b[d] ? PETSC_TRUE : PETSC_FALSE;
  return PETSC_FALSE;
}

static PetscErrorCode ReadProbes(PeriProblem p)
{
  PeriScene            s = p->scene;
  PeriNode             map;
  const PeriParticles *pt = &p->particles;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "probes", PETSC_FALSE, &map));
  if (!map) PetscFunctionReturn(PETSC_SUCCESS);
  p->nprobes = map->n;
  PetscCall(PetscCalloc1(map->n, &p->probes));
  for (PetscInt k = 0; k < map->n; k++) {
    PeriProbe *pr   = &p->probes[k];
    PetscReal  best = PETSC_MAX_REAL;
    PetscInt   n;
    PetscCall(PetscStrncpy(pr->name, map->child[k]->key, sizeof(pr->name)));
    PetscCall(PeriSceneGetRealArray(s, map, map->child[k]->key, PETSC_TRUE, pt->dim, pt->dim, pr->x, &n));
    for (PetscInt i = 0; i < pt->n; i++) {
      PetscReal d2 = 0;
      for (PetscInt d = 0; d < pt->dim; d++) d2 += PetscSqr(pt->x[3 * i + d] - pr->x[d]);
      /* ties go to the lexicographically smallest position, whatever the numbering (ranks) */
      if (d2 < best || (d2 == best && LexLess(&pt->x[3 * i], &pt->x[3 * pr->particle]))) {
        best         = d2;
        pr->particle = i;
      }
    }
    /* inside the body: within the nearest particle's cell (its circumscribed ball) */
    PeriInputCheck(PetscSqrtReal(best) <= 0.5 * PetscSqrtReal((PetscReal)pt->dim) * pt->spacing[pr->particle] * (1 + 1e-9), s, map, map->child[k]->key, "the point lies outside the body (nearest particle at distance %g)", (double)PetscSqrtReal(best));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ReadOutput(PeriProblem p, const char file[])
{
  static const char *const keys[] = {"dir", "vtk", NULL};
  PeriScene                s      = p->scene;
  PeriNode                 o;
  char                     base[PETSC_MAX_PATH_LEN], *slash, *dot;
  static const char *const akeys[] = {"type", "nev", "target_hz", NULL};
  PeriNode                 a;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(base, (slash = strrchr(file, '/')) ? slash + 1 : file, sizeof(base)));
  if ((dot = strrchr(base, '.'))) *dot = 0;
  PetscCall(PetscSNPrintf(p->output_dir, sizeof(p->output_dir), "%s-out", base));
  p->vtk = PETSC_TRUE;
  PetscCall(PeriSceneGetMap(s, s->root, "output", PETSC_FALSE, &o));
  PetscCall(PeriSceneCheckKeys(s, o, keys));
  PetscCall(PeriSceneGetString(s, o, "dir", PETSC_FALSE, p->output_dir, sizeof(p->output_dir), NULL));
  PetscCall(PeriSceneGetBool(s, o, "vtk", &p->vtk, NULL));
  PetscCall(PetscStrncpy(p->analysis, "static", sizeof(p->analysis)));
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_FALSE, &a));
  PetscCall(PeriSceneCheckKeys(s, a, akeys));
  PetscCall(PeriSceneGetString(s, a, "type", PETSC_FALSE, p->analysis, sizeof(p->analysis), NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CreateModel(PeriProblem p)
{
  static const char *const keys[] = {"type", "plane", NULL}, *const planes[] = {"stress", "strain", NULL};
  PeriScene s = p->scene;
  PeriNode  m;
  PetscInt  dim = 0, plane = 0;
  char      type[PERI_NAME_LEN];
  PetscBool found;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetInt(s, s->root, "dim", PETSC_TRUE, &dim, NULL));
  PeriInputCheck(dim == 2 || dim == 3, s, s->root, "dim", "must be 2 or 3, got %" PetscInt_FMT, dim);
  PetscCall(PeriSceneGetMap(s, s->root, "model", PETSC_TRUE, &m));
  PetscCall(PeriSceneGetString(s, m, "type", PETSC_TRUE, type, sizeof(type), NULL));
  PetscCall(PeriSceneGetChoice(s, m, "plane", planes, &plane, &found));
  PeriInputCheck(!found || dim == 2, s, m, "plane", "applies to 2D scenes only");
  PetscCall(PeriModelTypeRegistered(type, &found));
  if (!found) {
    char list[256];
    PetscCall(PeriModelListTypes(list, sizeof(list)));
    PeriInputCheck(PETSC_FALSE, s, m, "type", "unknown model '%s'; registered models: %s", type, list);
  }
  PetscCall(PeriModelCreate(type, dim, plane == 1 ? PETSC_TRUE : PETSC_FALSE, &p->model));
  {
    const char *allowed[16];
    PetscInt    n = 0;
    for (PetscInt k = 0; keys[k]; k++) allowed[n++] = keys[k];
    for (PetscInt k = 0; p->model->keys && p->model->keys[k] && n < 15; k++) allowed[n++] = p->model->keys[k];
    allowed[n] = NULL;
    PetscCall(PeriSceneCheckKeys(s, m, allowed));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CheckRootKeys(PeriScene s)
{
  static const char *const keys[] = {"dim", "model", "material", "grid", "particles", "horizon", "corrections", "regions", "bc", "loads", "probes", "analysis", "output", "reference", NULL};

  PetscFunctionBeginUser;
  PetscCall(PeriSceneCheckKeys(s, s->root, keys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemSetUp - particles, partition, bonds, corrections, calibration, regions, probes and
  boundary conditions, with every input check. Collective.
@*/
PetscErrorCode PeriProblemSetUp(PeriProblem p)
{
  PeriScene           s         = p->scene;
  PetscReal           thickness = 1;
  PetscInt           *perm, *range;
  PeriNode            mat;
  PeriCalibrationData cal;
  PetscLogDouble      t0, t1;

  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PERI_STAGE_Setup));
  PetscCall(CheckRootKeys(s));
  PetscCall(CreateModel(p));
  PetscCall(PeriSceneGetMap(s, s->root, "material", PETSC_TRUE, &mat));
  PetscCall(PeriSceneGetReal(s, mat, "thickness", PETSC_FALSE, &thickness, NULL));
  PeriInputCheck(thickness > 0, s, mat, "thickness", "must be positive, got %g", (double)thickness);
  PetscCall(PeriParticlesCreateFromScene(s, p->model->dim, thickness, &p->particles));
  PetscCall(ReadHorizon(p));
  PetscCall(PeriModelSetFromScene(p->model, s, p->delta));
  PetscCall(ReadCorrections(p));
  PetscCall(ReadOutput(p, s->file));

  PetscCall(PetscTime(&t0));
  PetscCall(PetscLogEventBegin(PERI_EVENT_Partition, 0, 0, 0, 0));
  PetscCall(PeriPartition(p->comm, &p->particles, p->delta, &perm, &range));
  if (p->size > 1) PetscCall(PeriParticlesPermute(&p->particles, perm));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Partition, 0, 0, 0, 0));
  PetscCall(PetscMalloc1(p->particles.n, &p->owner));
  for (PetscMPIInt r = 0; r < p->size; r++)
    for (PetscInt i = range[r]; i < range[r + 1]; i++) p->owner[i] = r;

  PetscCall(PetscLogEventBegin(PERI_EVENT_Neighbors, 0, 0, 0, 0));
  PetscCall(PeriNeighborSearch(&p->particles, p->delta, p->partial_volume, range[p->rank], range[p->rank + 1], PETSC_TRUE, &p->bonds));
  PetscCall(PetscMalloc2(p->particles.n, &p->family_volume, p->particles.n, &p->neighbor_count));
  PetscCall(PeriNeighborhoodVolumes(p->comm, &p->particles, &p->bonds, p->family_volume, p->neighbor_count));
  PetscCall(PeriSurfaceCorrectionApply(p->surface, &p->particles, p->delta, p->family_volume, &p->bonds));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Neighbors, 0, 0, 0, 0));
  PetscCall(PetscTime(&t1));
  p->results.neighbors_s = t1 - t0;
  PetscCallMPI(MPI_Allreduce(&p->bonds.nbonds, &p->results.nbonds_total, 1, MPIU_INT, MPI_SUM, p->comm));
  {
    PetscInt cut = 0;
    for (PetscInt k = 0; k < p->bonds.nbonds; k++) cut += p->owner[p->bonds.j[k]] != p->rank;
    PetscCallMPI(MPI_Allreduce(&cut, &p->results.edge_cut, 1, MPIU_INT, MPI_SUM, p->comm));
  }
  PetscCall(PetscFree(perm));
  PetscCall(PetscFree(range));

  for (PetscInt i = 0; i < p->particles.n; i++)
    PetscCheck(p->neighbor_count[i] > 0, p->comm, PETSC_ERR_USER_INPUT, "%s: particle at (%g, %g, %g) has no bonds: it would move freely (horizon %g, spacing %g)", s->file, (double)p->particles.x[3 * i], (double)p->particles.x[3 * i + 1], (double)p->particles.x[3 * i + 2], (double)p->delta, (double)p->particles.spacing[i]);
  cal.n             = p->particles.n;
  cal.family_volume = p->family_volume;
  PetscCall(p->model->ops.calibrate(p->model, &cal));
  if (p->model->warning[0]) PetscCall(PetscPrintf(p->comm, "perilin: warning: %s\n", p->model->warning));

  PetscCall(PeriRegionsCreateFromScene(s, &p->particles, p->delta, &p->nregions, &p->regions));
  PetscCall(ReadProbes(p));
  PetscCall(PeriReferenceSetUp(p));
  PetscCall(PeriBoundarySetUp(p));
  /* the loads too, so that a bad load is reported before any solve */
  PetscCall(PeriProblemCreateVec(p, &p->f));
  PetscCall(PeriLoadsAssemble(p, p->f));
  PetscCall(PetscLogStagePop());
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A vector with one block of DOFs per owned particle. */
PetscErrorCode PeriProblemCreateVec(PeriProblem p, Vec *v)
{
  PetscFunctionBeginUser;
  PetscCall(VecCreate(p->comm, v));
  PetscCall(VecSetSizes(*v, (p->bonds.rend - p->bonds.rstart) * p->model->dofs, PETSC_DETERMINE));
  PetscCall(VecSetBlockSize(*v, p->model->dofs));
  PetscCall(VecSetFromOptions(*v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The kernel's view of local bond k of owned particle i. */
PetscErrorCode PeriProblemBondGeometry(PeriProblem p, PetscInt i, PetscInt k, PeriBondGeometry *g)
{
  const PeriBonds     *b  = &p->bonds;
  const PeriParticles *pt = &p->particles;

  PetscFunctionBeginUser;
  g->i = i;
  g->j = b->j[k];
  for (PetscInt d = 0; d < 3; d++) g->xi[d] = b->xi[3 * k + d];
  g->length = b->length[k];
  g->Vi     = pt->volume[i];
  g->Vj     = pt->volume[g->j];
  g->weight = b->alpha[k] * b->lambda[k];
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemAssemble(PeriProblem p)
{
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PERI_STAGE_Assembly));
  PetscCall(PetscTime(&t0));
  PetscCall(MatDestroy(&p->K));
  PetscCall(PeriAssembleStiffness(p, &p->K));
  PetscCall(PetscTime(&t1));
  p->results.assembly_s = t1 - t0;
  PetscCall(PetscLogStagePop());
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscFunctionList PeriAnalysisList = NULL;

PetscErrorCode PeriAnalysisRegister(const char name[], PetscErrorCode (*run)(PeriProblem))
{
  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListAdd(&PeriAnalysisList, name, run));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriAnalysisRegisterAll(void)
{
  static PetscBool done = PETSC_FALSE;

  PetscFunctionBeginUser;
  if (done) PetscFunctionReturn(PETSC_SUCCESS);
  done = PETSC_TRUE;
  PetscCall(PeriAnalysisRegister("static", PeriAnalysisRun_Static));
  PetscCall(PeriAnalysisRegister("modal", PeriAnalysisRun_Modal));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemRun - runs the scene's analysis (analysis.type), found by name. Collective.
@*/
PetscErrorCode PeriProblemRun(PeriProblem p)
{
  PetscErrorCode (*run)(PeriProblem) = NULL;
  struct rusage  ru;
  PetscReal      mb;
  PetscLogDouble t;

  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListFind(PeriAnalysisList, p->analysis, &run));
  if (!run) {
    PeriNode a;
    PetscCall(PeriSceneGetNode(p->scene->root, "analysis", &a));
    const char **names;
    char         list[256] = "";
    int          n;
    PetscCall(PetscFunctionListGet(PeriAnalysisList, &names, &n));
    for (int k = 0; k < n; k++)
      if (names[k]) PeriListAppend(list, sizeof(list), names[k]);
    PetscCall(PetscFree(names));
    PeriInputCheck(PETSC_FALSE, p->scene, a, "type", "unknown analysis '%s'; available: %s", p->analysis, list);
  }
  PetscCall(PetscLogStagePush(PERI_STAGE_Solve));
  PetscCall((*run)(p));
  PetscCall(PetscLogStagePop());
  PetscCall(PetscTime(&t));
  p->results.total_s = t - p->t_start;
  getrusage(RUSAGE_SELF, &ru);
  mb = (PetscReal)ru.ru_maxrss / 1024.0; /* kilobytes on Linux */
  PetscCallMPI(MPI_Allreduce(&mb, &p->results.memory_mb, 1, MPIU_REAL, MPI_SUM, p->comm));
  PetscCallMPI(MPI_Allreduce(&mb, &p->results.memory_mb_max_rank, 1, MPIU_REAL, MPI_MAX, p->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemEvaluateEnergy - from the solution p->u: the strain energy, the energy density W_i
  = (1/2) sum_j (pair energy) / V_i of every particle (rank 0), the displacements of all particles
  (rank 0), the probes and the largest displacement per component. Collective.
@*/
PetscErrorCode PeriProblemEvaluateEnergy(PeriProblem p)
{
  VecScatter         scatter;
  Vec                all;
  const PetscScalar *u;
  PeriModel          m = p->model;
  const PetscInt     n = p->particles.n, bs = m->dofs, nb = 2 * bs;
  PetscReal         *W, energy = 0, Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF];

  PetscFunctionBeginUser;
  PetscCall(VecScatterCreateToAll(p->u, &scatter, &all));
  PetscCall(VecScatterBegin(scatter, p->u, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(scatter, p->u, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGetArrayRead(all, &u));
  PetscCall(PetscCalloc1(n, &W));
  for (PetscInt i = p->bonds.rstart; i < p->bonds.rend; i++)
    for (PetscInt k = p->bonds.offset[i - p->bonds.rstart]; k < p->bonds.offset[i - p->bonds.rstart + 1]; k++) {
      PeriBondGeometry g;
      PetscReal        ue[2 * PERI_MAX_DOF], e = 0;
      if (!p->bonds.live[k] || p->bonds.j[k] == i) continue;
      PetscCall(PeriProblemBondGeometry(p, i, k, &g));
      m->ops.bond_stiffness(m, &g, Ke);
      for (PetscInt c = 0; c < bs; c++) {
        ue[c]      = PetscRealPart(u[i * bs + c]);
        ue[bs + c] = PetscRealPart(u[g.j * bs + c]);
      }
      for (PetscInt a = 0; a < nb; a++)
        for (PetscInt c = 0; c < nb; c++) e += 0.5 * ue[a] * Ke[a * nb + c] * ue[c];
      energy += e;
      W[i] += 0.5 * e / g.Vi;
      W[g.j] += 0.5 * e / g.Vj;
    }
  PetscCallMPI(MPI_Allreduce(&energy, &p->results.strain_energy, 1, MPIU_REAL, MPI_SUM, p->comm));
  PetscCallMPI(MPI_Reduce(p->rank ? W : MPI_IN_PLACE, W, (PetscMPIInt)n, MPIU_REAL, MPI_SUM, 0, p->comm));
  PetscCall(PetscFree(p->W));
  PetscCall(PetscFree(p->u_all));
  if (p->rank == 0) {
    p->W = W;
    PetscCall(PetscMalloc1(n * bs, &p->u_all));
    for (PetscInt k = 0; k < n * bs; k++) p->u_all[k] = PetscRealPart(u[k]);
    for (PetscInt k = 0; k < p->nprobes; k++) {
      PeriProbe *pr = &p->probes[k];
      for (PetscInt c = 0; c < bs; c++) pr->u[c] = p->u_all[pr->particle * bs + c];
      pr->W = W[pr->particle];
    }
  } else
    PetscCall(PetscFree(W));
  PetscCall(VecRestoreArrayRead(all, &u));
  for (PetscInt c = 0; c < bs; c++) PetscCall(VecStrideNorm(p->u, c, NORM_INFINITY, &p->results.max_abs_u[c]));
  PetscCall(VecDestroy(&all));
  PetscCall(VecScatterDestroy(&scatter));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemFindProbe(PeriProblem p, const char name[], PeriProbe **probe)
{
  PetscFunctionBeginUser;
  *probe = NULL;
  for (PetscInt k = 0; k < p->nprobes; k++)
    if (!strcmp(p->probes[k].name, name)) *probe = &p->probes[k];
  PetscCheck(*probe, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "no probe named %s", name);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemWriteOutput - writes summary.json (and particles.vtu) into the output directory,
  each file under a temporary name first. Collective.
@*/
PetscErrorCode PeriProblemWriteOutput(PeriProblem p)
{
  char path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PERI_STAGE_Output));
  if (p->rank == 0) PetscCall(PeriOutputDirCreate(p->output_dir));
  if (p->vtk) {
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/particles.vtu", p->output_dir));
    PetscCall(PeriWriteVTU(p, path));
  }
  if (p->modal) {
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/modes.csv", p->output_dir));
    PetscCall(PeriWriteModesCSV(p, path));
  }
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/summary.json", p->output_dir));
  PetscCall(PeriWriteSummary(p, path));
  PetscCall(PetscLogStagePop());
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriProblemDestroy(PeriProblem *problem)
{
  PeriProblem p = *problem;

  PetscFunctionBeginUser;
  if (!p) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(MatDestroy(&p->K));
  PetscCall(VecDestroy(&p->u));
  PetscCall(VecDestroy(&p->f));
  PetscCall(PeriModelDestroy(&p->model));
  PetscCall(PeriBondsDestroy(&p->bonds));
  PetscCall(PeriParticlesDestroy(&p->particles));
  PetscCall(PetscFree(p->regions));
  PetscCall(PetscFree(p->probes));
  PetscCall(PetscFree2(p->family_volume, p->neighbor_count));
  PetscCall(PetscFree(p->owner));
  PetscCall(PetscFree(p->constrained));
  PetscCall(PetscFree(p->constrained_value));
  PetscCall(PetscFree(p->W));
  PetscCall(PetscFree(p->u_all));
  if (p->modal) {
    PetscCall(PetscFree(p->modal->modes));
    PetscCall(PetscFree(p->modal->shapes));
    PetscCall(PetscFree(p->modal));
  }
  PetscCall(PeriSceneDestroy(&p->scene));
  PetscCall(PetscFree(p));
  *problem = NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}
