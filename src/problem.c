/* PeriProblem: one run from scene to output. Each stage is one call; see include/perilin.h. */
#include "perilin.h"
#include <sys/resource.h>

PetscLogEvent PERI_EVENT_Neighbors, PERI_EVENT_Partition, PERI_EVENT_Assembly, PERI_EVENT_Solve;
PetscLogStage PERI_STAGE_Setup, PERI_STAGE_Assembly, PERI_STAGE_Solve, PERI_STAGE_Output;

static PetscBool PeriPackageInitialized = PETSC_FALSE;

/* PetscFinalize drops the log events and stages: a second PetscInitialize must register them again. */
static PetscErrorCode PeriFinalizePackage(void)
{
  PetscFunctionBeginUser;
  PeriPackageInitialized = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriInitializePackage(void)
{
  PetscClassId id;

  PetscFunctionBeginUser;
  if (PeriPackageInitialized) PetscFunctionReturn(PETSC_SUCCESS);
  PeriPackageInitialized = PETSC_TRUE;
  PetscCall(PetscRegisterFinalize(PeriFinalizePackage));
  PetscCall(PetscClassIdRegister("perilin", &id));
  PetscCall(PetscLogEventRegister("PeriPartition", id, &PERI_EVENT_Partition));
  PetscCall(PetscLogEventRegister("PeriNeighbors", id, &PERI_EVENT_Neighbors));
  PetscCall(PetscLogEventRegister("PeriAssembly", id, &PERI_EVENT_Assembly));
  PetscCall(PetscLogEventRegister("PeriSolve", id, &PERI_EVENT_Solve));
  PetscCall(PetscLogStageRegister("Peri setup", &PERI_STAGE_Setup));
  PetscCall(PetscLogStageRegister("Peri assembly", &PERI_STAGE_Assembly));
  PetscCall(PetscLogStageRegister("Peri solve", &PERI_STAGE_Solve));
  PetscCall(PetscLogStageRegister("Peri output", &PERI_STAGE_Output));
  /* the registries are filled here, once, so that neither calls back into the package */
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
  {
    /* beyond the body's diagonal every particle bonds with every other: N^2 bonds, no locality */
    PetscReal diag2 = 0;
    for (PetscInt d = 0; d < p->particles.dim; d++) diag2 += PetscSqr(p->particles.upper[d] - p->particles.lower[d]);
    PeriInputCheck(p->delta <= PetscSqrtReal(diag2), s, h, hasm ? "m" : "delta", "the horizon %g exceeds the body's size (its diagonal %g): every particle would bond with every other; a horizon is a few spacings (m = 3 is usual)", (double)p->delta, (double)PetscSqrtReal(diag2));
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
  {
    static const char *const defaults[] = {"none", "volume", NULL};
    const char *const       *allowed    = p->model->surface_corrections ? p->model->surface_corrections : defaults;
    char                     list[128]  = "";
    PetscBool                ok         = PETSC_FALSE;
    for (PetscInt k = 0; allowed[k]; k++) {
      ok = (PetscBool)(ok || !strcmp(allowed[k], PeriSurfaceCorrections[sc]));
      PeriListAppend(list, sizeof(list), allowed[k]);
    }
    PeriInputCheck(ok, s, c, "surface", "model %s takes %s, not %s", p->model->type, list, PeriSurfaceCorrections[sc]);
  }
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
      if (PeriParticleIsFictitious(pt, i)) continue;
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
  static const char *const keys[] = {"dir", "vtk", "every", NULL};
  PeriScene                s      = p->scene;
  PeriNode                 o;
  char                     base[PETSC_MAX_PATH_LEN], *slash, *dot;
  static const char *const akeys[] = {"type", "nev", "target_hz", "load_factor_max", "load_factor_step", "min_step", "adaptive", "break", "break_fraction", "max_iterations", "reuse_preconditioner", "control_probe", "runaway_fraction", NULL};
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
  PetscCall(PeriSceneGetInt(s, o, "every", PETSC_FALSE, &p->output_every, NULL));
  PeriInputCheck(p->output_every >= 0, s, o, "every", "must not be negative (0: only the end), got %" PetscInt_FMT, p->output_every);
  PetscCall(PetscStrncpy(p->analysis, "static", sizeof(p->analysis)));
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_FALSE, &a));
  PetscCall(PeriSceneCheckKeys(s, a, akeys));
  PetscCall(PeriSceneGetString(s, a, "type", PETSC_FALSE, p->analysis, sizeof(p->analysis), NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* solver.residual_tol: every solve's true relative residual must lie below it. */
static PetscErrorCode ReadSolver(PeriProblem p)
{
  static const char *const keys[] = {"residual_tol", NULL};
  PeriScene                s      = p->scene;
  PeriNode                 node;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "solver", PETSC_FALSE, &node));
  PetscCall(PeriSceneCheckKeys(s, node, keys));
  PetscCall(PeriSceneGetReal(s, node, "residual_tol", PETSC_FALSE, &p->residual_tol, NULL));
  PeriInputCheck(p->residual_tol >= 0 && p->residual_tol < 1, s, node, "residual_tol", "must lie in [0, 1) (0: the default, max(100 rtol, 1e-6)), got %g", (double)p->residual_tol);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriResidualTolerance - the largest true relative residual a solve run with relative tolerance
  rtol may leave: solver.residual_tol, or by default max(100 rtol, 1e-6), but never above 1e-3.
  The factor 100 leaves room for the preconditioned norm that some KSPs monitor; the floor, for
  round-off in K; the cap keeps a loose -ksp_rtol from passing a wrong answer (an answer that
  crude must be asked for with solver.residual_tol).
@*/
PetscReal PeriResidualTolerance(PeriProblem p, PetscReal rtol)
{
  return p->residual_tol > 0 ? p->residual_tol : PetscMin(PetscMax(100 * rtol, 1e-6), 1e-3);
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
  static const char *const keys[] = {"dim", "model", "material", "grid", "particles", "horizon", "corrections", "regions", "bc", "loads", "probes", "analysis", "output", "reference", "boundary_layers", "torsion", "failure", "cracks", "solver", NULL};

  PetscFunctionBeginUser;
  PetscCall(PeriSceneCheckKeys(s, s->root, keys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The point X folded back into the body's box through the faces it lies beyond: a fictitious
 * layer particle has the material of its mirror image. */
static void FoldIntoBody(const PeriParticles *pt, const PetscReal X[], PetscReal Y[])
{
  for (PetscInt d = 0; d < 3; d++) {
    Y[d] = X[d];
    if (d >= pt->dim) continue;
    if (Y[d] < pt->lower[d]) Y[d] = 2 * pt->lower[d] - Y[d];
    if (Y[d] > pt->upper[d]) Y[d] = 2 * pt->upper[d] - Y[d];
  }
}

static PetscReal ShearModulusAt(PeriProblem p, PetscInt nr, PeriRegion *const reg[], const PetscReal val[], const PetscReal X[])
{
  PetscReal Y[3], mu = p->model->material.G;
  FoldIntoBody(&p->particles, X, Y);
  for (PetscInt k = 0; k < nr; k++)
    if (PeriRegionContains(reg[k], Y)) mu = val[k];
  return mu;
}

static int CompareReal(const void *a, const void *b)
{
  PetscReal x = *(const PetscReal *)a, y = *(const PetscReal *)b;
  return x < y ? -1 : x > y;
}

/* material.mu_by_region: the shear modulus of every particle, and of every bond that crosses an
 * interface, the harmonic mean over its length (Oterkus & Madenci eq. 60), exact for box regions:
 * the bond is cut where it crosses a region's or the body's faces. */
static PetscErrorCode ReadShearModuli(PeriProblem p)
{
  PeriScene            s  = p->scene;
  const PeriParticles *pt = &p->particles;
  const PeriBonds     *b  = &p->bonds;
  PeriNode             mat, map;
  PeriRegion         **reg;
  PetscReal           *val, *cut;
  PetscInt             nr;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "material", PETSC_TRUE, &mat));
  PetscCall(PeriSceneGetMap(s, mat, "mu_by_region", PETSC_FALSE, &map));
  if (!map) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(p->model->antiplane, s, map, NULL, "applies to the cross-section models (antiplane, antiplane_os), not %s", p->model->type);
  nr = map->n;
  PetscCall(PetscMalloc3(nr, &reg, nr, &val, 6 * (nr + 1) + 2, &cut));
  for (PetscInt k = 0; k < nr; k++) {
    PetscCall(PeriRegionFind(s, map->child[k], NULL, p->nregions, p->regions, &reg[k]));
    PetscCall(PeriSceneGetReal(s, map, map->child[k]->key, PETSC_TRUE, &val[k], NULL));
    PeriInputCheck(val[k] > 0, s, map, map->child[k]->key, "must be positive, got %g", (double)val[k]);
  }
  PetscCall(PetscMalloc1(pt->n, &p->mu));
  for (PetscInt i = 0; i < pt->n; i++) p->mu[i] = ShearModulusAt(p, nr, reg, val, &pt->x[3 * i]);
  PetscCall(PetscMalloc1(b->nbonds, &p->bond_mu));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      const PetscReal *X = &pt->x[3 * i], *xi = &b->xi[3 * k];
      PetscInt         nc  = 0;
      PetscReal        inv = 0;
      /* the parameters t in (0, 1) where X + t xi crosses a face */
      cut[nc++] = 0;
      for (PetscInt r = 0; r <= nr; r++)
        for (PetscInt d = 0; d < pt->dim; d++) {
          PetscReal lo = r < nr ? reg[r]->lower[d] : pt->lower[d], hi = r < nr ? reg[r]->upper[d] : pt->upper[d];
          if (xi[d] == 0) continue;
          for (PetscInt e = 0; e < 2; e++) {
            PetscReal t = ((e ? hi : lo) - X[d]) / xi[d];
            if (t > 0 && t < 1) cut[nc++] = t;
          }
        }
      cut[nc++] = 1;
      qsort(cut, (size_t)nc, sizeof(PetscReal), CompareReal);
      for (PetscInt c = 0; c + 1 < nc; c++) {
        PetscReal Y[3], t = 0.5 * (cut[c] + cut[c + 1]);
        for (PetscInt d = 0; d < 3; d++) Y[d] = X[d] + t * xi[d];
        inv += (cut[c + 1] - cut[c]) / ShearModulusAt(p, nr, reg, val, Y);
      }
      p->bond_mu[k] = 1 / inv;
    }
  PetscCall(PetscFree3(reg, val, cut));
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
  PetscCall(ReadOutput(p, s->file));
  PetscCall(ReadSolver(p));
  /* a bad output.dir is found before anything is computed */
  if (p->write_output) PetscCall(PeriOutputSetOpen(p->comm, p->output_dir, sizeof(p->output_dir), p->staging_dir, sizeof(p->staging_dir)));
  PetscCall(PeriSceneGetMap(s, s->root, "material", PETSC_TRUE, &mat));
  PetscCall(PeriSceneGetReal(s, mat, "thickness", PETSC_FALSE, &thickness, NULL));
  PeriInputCheck(thickness > 0, s, mat, "thickness", "must be positive, got %g", (double)thickness);
  /* before any large allocation: a scene that cannot fit is refused with its size */
  PetscCall(PeriParticlesCheckMemory(p->comm, s, p->model));
  PetscCall(PeriParticlesCreateFromScene(s, p->model->dim, thickness, &p->particles));
  PetscCall(ReadHorizon(p));
  PetscCall(PeriModelSetFromScene(p->model, s, p->delta));
  PetscCall(ReadCorrections(p));
  PetscCall(PeriLayersAddParticles(p));

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
  /* a state-based particle's energy needs its whole family, including the bonds stored elsewhere */
  if (p->model->ops.family_stiffness) PetscCall(PeriNeighborSearch(&p->particles, p->delta, p->partial_volume, range[p->rank], range[p->rank + 1], PETSC_FALSE, &p->family));
  PetscCall(PetscMalloc2(p->particles.n, &p->family_volume, p->particles.n, &p->neighbor_count));
  /* a crack is geometry: the family volumes, the surface correction and the calibration see it */
  PetscCall(PeriCracksApply(p));
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
  PetscCall(PeriRegionsCreateFromScene(s, &p->particles, p->delta, &p->nregions, &p->regions));
  PetscCall(ReadShearModuli(p));
  cal.n             = p->particles.n;
  cal.family_volume = p->family_volume;
  cal.mu            = p->mu;
  cal.comm          = p->comm;
  cal.particles     = &p->particles;
  cal.bonds         = &p->bonds;
  cal.surface       = p->surface;
  PetscCall(p->model->ops.calibrate(p->model, &cal));
  if (p->model->warning[0]) PetscCall(PetscPrintf(p->comm, "perilin: warning: %s\n", p->model->warning));

  PetscCall(ReadProbes(p));
  PetscCall(PeriFailureSetUp(p));
  PetscCall(PeriReferenceSetUp(p));
  PetscCall(PeriBoundarySetUp(p));
  PetscCall(PeriLayersSetUp(p));
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

/* The kernel's view of bond k of owned particle i in the list b (bond_mu: per bond, or NULL). */
static void FillGeometry(const PeriParticles *pt, const PeriBonds *b, const PetscReal bond_mu[], PetscInt i, PetscInt k, PeriBondGeometry *g)
{
  g->i = i;
  g->j = b->j[k];
  for (PetscInt d = 0; d < 3; d++) g->xi[d] = b->xi[3 * k + d];
  g->length = b->length[k];
  g->Vi     = pt->volume[i];
  g->Vj     = pt->volume[g->j];
  g->weight = b->alpha[k] * b->lambda[k] * (b->intact ? b->intact[k] : 1);
  g->mu     = bond_mu ? bond_mu[k] : 0;
}

/* The kernel's view of local bond k of owned particle i. */
PetscErrorCode PeriProblemBondGeometry(PeriProblem p, PetscInt i, PetscInt k, PeriBondGeometry *g)
{
  PetscFunctionBeginUser;
  FillGeometry(&p->particles, &p->bonds, p->bond_mu, i, k, g);
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
  PetscCall(PeriAnalysisFind(p->analysis, &run));
  if (!run) {
    PeriNode a;
    char     list[256];
    PetscCall(PeriSceneGetNode(p->scene->root, "analysis", &a));
    PetscCall(PeriAnalysisListTypes(list, sizeof(list)));
    PeriInputCheck(PETSC_FALSE, p->scene, a, "type", "unknown analysis '%s'; available: %s", p->analysis, list);
  }
  /* a signal during the set-up: no analysis, only the summary saying so */
  PetscCall(PeriSignalReceived(p->comm, &p->interrupted));
  PetscCall(PetscLogStagePush(PERI_STAGE_Solve));
  if (!p->interrupted) PetscCall((*run)(p));
  PetscCall(PetscLogStagePop());
  PetscCall(PetscTime(&t));
  p->results.total_s = t - p->t_start;
  getrusage(RUSAGE_SELF, &ru);
  mb = (PetscReal)ru.ru_maxrss / 1024.0; /* kilobytes on Linux */
  PetscCallMPI(MPI_Allreduce(&mb, &p->results.memory_mb, 1, MPIU_REAL, MPI_SUM, p->comm));
  PetscCallMPI(MPI_Allreduce(&mb, &p->results.memory_mb_max_rank, 1, MPIU_REAL, MPI_MAX, p->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Gathers the family of owned particle i from p->family (state-based models). */
PetscErrorCode PeriProblemFamilyGeometry(PeriProblem p, PetscInt i, PetscInt *n, PeriBondGeometry fam[])
{
  const PeriBonds     *b  = &p->family;
  const PeriParticles *pt = &p->particles;

  PetscFunctionBeginUser;
  *n = 0;
  for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++)
    if (b->live[k]) FillGeometry(pt, b, NULL, i, k, &fam[(*n)++]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Largest family in p->family, for workspace. */
PetscInt PeriProblemMaxFamily(PeriProblem p)
{
  PetscInt nmax = 0;
  for (PetscInt i = p->family.rstart; i < p->family.rend; i++) nmax = PetscMax(nmax, p->family.offset[i - p->family.rstart + 1] - p->family.offset[i - p->family.rstart]);
  return nmax;
}

/* Energy of the state-based particles' families: W_i V_i = u^T K_i u / 2 of each owned particle. */
static PetscErrorCode FamilyEnergy(PeriProblem p, const PetscScalar u[], PetscReal W[], PetscReal *energy)
{
  PeriModel         m  = p->model;
  const PetscInt    bs = m->dofs, nmax = PeriProblemMaxFamily(p);
  PeriBondGeometry *fam;
  PetscReal        *Ke, *ue;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc3(nmax, &fam, PetscSqr((nmax + 1) * bs), &Ke, (nmax + 1) * bs, &ue));
  for (PetscInt i = p->family.rstart; i < p->family.rend; i++) {
    PetscInt  n, N;
    PetscReal e = 0;
    PetscCall(PeriProblemFamilyGeometry(p, i, &n, fam));
    N = (n + 1) * bs;
    PetscCall(m->ops.family_stiffness(m, n, fam, Ke));
    for (PetscInt c = 0; c < bs; c++) {
      ue[c] = PetscRealPart(u[i * bs + c]);
      for (PetscInt t = 0; t < n; t++) ue[(t + 1) * bs + c] = PetscRealPart(u[fam[t].j * bs + c]);
    }
    for (PetscInt a = 0; a < N; a++)
      for (PetscInt c = 0; c < N; c++) e += 0.5 * ue[a] * Ke[a * N + c] * ue[c];
    W[i] += e / p->particles.volume[i];
    if (!PeriParticleIsFictitious(&p->particles, i)) *energy += e;
  }
  PetscCall(PetscFree3(fam, Ke, ue));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Antiplane models: the corrected shear angles grad uz = M^-1 R with M = sum w alpha xi xi^T V_j
 * and R = sum w alpha (u_j - u_i) xi V_j (w = 1/|xi|^2), exact for every linear field (eq. 53 with
 * the full 2x2 moment, so also at corners), and tau = mu (grad uz + twist terms). Rank 0 gets
 * tau_xz, tau_yz and |tau| of every particle. */
static PetscErrorCode ShearStresses(PeriProblem p, const PetscScalar u[])
{
  const PeriBonds     *b  = &p->bonds;
  const PeriParticles *pt = &p->particles;
  const PetscInt       n  = pt->n;
  PetscReal           *acc; /* per particle: M00 M01 M11 R0 R1 */

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(5 * n, &acc));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscInt         j  = b->j[k];
      const PetscReal *xi = &b->xi[3 * k];
      PetscReal        w = b->alpha[k] / (b->length[k] * b->length[k]), e = PetscRealPart(u[j] - u[i]);
      if (!b->live[k] || j == i) continue;
      for (PetscInt end = 0; end < 2; end++) {
        PetscReal *A = &acc[5 * (end ? j : i)], V = pt->volume[end ? i : j];
        A[0] += w * xi[0] * xi[0] * V;
        A[1] += w * xi[0] * xi[1] * V;
        A[2] += w * xi[1] * xi[1] * V;
        A[3] += w * e * xi[0] * V;
        A[4] += w * e * xi[1] * V;
      }
    }
  PetscCallMPI(MPI_Reduce(p->rank ? acc : MPI_IN_PLACE, acc, (PetscMPIInt)(5 * n), MPIU_REAL, MPI_SUM, 0, p->comm));
  PetscCall(PetscFree(p->tau));
  if (p->rank == 0) {
    PetscCall(PetscMalloc1(3 * n, &p->tau));
    for (PetscInt i = 0; i < n; i++) {
      const PetscReal *A   = &acc[5 * i];
      PetscReal        det = A[0] * A[2] - A[1] * A[1], gx = 0, gy = 0, mu = p->mu ? p->mu[i] : p->model->material.G;
      if (det > 1e-12 * PetscSqr(A[0] + A[2])) {
        gx = (A[2] * A[3] - A[1] * A[4]) / det;
        gy = (A[0] * A[4] - A[1] * A[3]) / det;
      } else if (A[0] + A[2] > 0) { /* a one-dimensional family (a row of particles): along it only */
        gx = A[0] > 0 ? A[3] / A[0] : 0;
        gy = A[2] > 0 ? A[4] / A[2] : 0;
      }
      if (p->torsion.active) {
        gx -= p->torsion.twist * (pt->x[3 * i + 1] - p->torsion.center[1]);
        gy += p->torsion.twist * (pt->x[3 * i] - p->torsion.center[0]);
      }
      p->tau[3 * i]     = mu * gx;
      p->tau[3 * i + 1] = mu * gy;
      p->tau[3 * i + 2] = mu * PetscSqrtReal(gx * gx + gy * gy);
    }
  }
  PetscCall(PetscFree(acc));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriProblemEvaluateEnergy - from the solution p->u: the strain energy of the body, the energy
  density W_i = (1/2) sum_j (pair energy) / V_i of every particle (rank 0), the displacements of
  all particles (rank 0), the probes, the largest displacement per component, and for antiplane
  models the shear stresses and the torsion results. Collective.
@*/
PetscErrorCode PeriProblemEvaluateEnergy(PeriProblem p)
{
  VecScatter           scatter;
  Vec                  all;
  const PetscScalar   *u;
  PeriModel            m  = p->model;
  const PeriParticles *pt = &p->particles;
  const PetscInt       n = pt->n, bs = m->dofs, nb = 2 * bs;
  PetscReal           *W, energy = 0, Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF], umax[PERI_MAX_DOF] = {0, 0, 0};

  PetscFunctionBeginUser;
  PetscCall(VecScatterCreateToAll(p->u, &scatter, &all));
  PetscCall(VecScatterBegin(scatter, p->u, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(scatter, p->u, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGetArrayRead(all, &u));
  PetscCall(PetscCalloc1(n, &W));
  if (m->ops.family_stiffness)
    PetscCall(FamilyEnergy(p, u, W, &energy));
  else
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
        /* each end owns half of the pair; fictitious particles are not part of the body */
        if (!PeriParticleIsFictitious(pt, i)) energy += 0.5 * e;
        if (!PeriParticleIsFictitious(pt, g.j)) energy += 0.5 * e;
        W[i] += 0.5 * e / g.Vi;
        W[g.j] += 0.5 * e / g.Vj;
      }
  for (PetscInt i = p->bonds.rstart; i < p->bonds.rend; i++)
    for (PetscInt c = 0; c < bs && !PeriParticleIsFictitious(pt, i); c++) umax[c] = PetscMax(umax[c], PetscAbsReal(PetscRealPart(u[i * bs + c])));
  PetscCallMPI(MPI_Allreduce(umax, p->results.max_abs_u, (PetscMPIInt)bs, MPIU_REAL, MPI_MAX, p->comm));
  PetscCallMPI(MPI_Allreduce(&energy, &p->results.strain_energy, 1, MPIU_REAL, MPI_SUM, p->comm));
  PetscCallMPI(MPI_Reduce(p->rank ? W : MPI_IN_PLACE, W, (PetscMPIInt)n, MPIU_REAL, MPI_SUM, 0, p->comm));
  if (m->antiplane) PetscCall(ShearStresses(p, u));
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
    PetscCall(PeriTorsionEvaluate(p));
  } else
    PetscCall(PetscFree(W));
  if (p->torsion.active) PetscCallMPI(MPI_Bcast(&p->torsion.torque, 6, MPIU_REAL, 0, p->comm));
  PetscCall(VecRestoreArrayRead(all, &u));
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
  PeriProblemWriteOutput - writes the output set (summary.json, particles.vtu and the analysis'
  files) into the staging directory and swaps it in for the output directory as a whole.
  Collective.
@*/
PetscErrorCode PeriProblemWriteOutput(PeriProblem p)
{
  char path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PERI_STAGE_Output));
  if (!p->staging_dir[0]) PetscCall(PeriOutputSetOpen(p->comm, p->output_dir, sizeof(p->output_dir), p->staging_dir, sizeof(p->staging_dir)));
  /* an analysis stopped before it had a state writes no fields: only the summary saying so */
  if (p->vtk && (!p->interrupted || p->u_all)) {
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/particles.vtu", p->staging_dir));
    PetscCall(PeriWriteVTU(p, path));
  }
  if (p->quasistatic) {
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/steps.csv", p->staging_dir));
    PetscCall(PeriWriteStepsCSV(p, path));
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/particles.pvd", p->staging_dir));
    PetscCall(PeriWriteSnapshotsPVD(p, path));
  }
  if (p->modal) {
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/modes.csv", p->staging_dir));
    PetscCall(PeriWriteModesCSV(p, path));
    if (p->vtk) PetscCall(PeriWriteModeShapes(p, p->staging_dir));
  }
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
  PetscCall(MatDestroy(&p->K));
  PetscCall(VecDestroy(&p->u));
  PetscCall(VecDestroy(&p->f));
  PetscCall(PeriModelDestroy(&p->model));
  PetscCall(PeriBondsDestroy(&p->bonds));
  PetscCall(PeriBondsDestroy(&p->family));
  PetscCall(PeriLayersDestroy(&p->layers));
  PetscCall(PetscFree(p->mu));
  PetscCall(PetscFree(p->bond_mu));
  PetscCall(PetscFree(p->tau));
  PetscCall(PetscFree(p->damage));
  if (p->quasistatic) {
    PetscCall(PetscFree(p->quasistatic->steps));
    PetscCall(PetscFree(p->quasistatic->trial_damage));
    PetscCall(PetscFree(p->quasistatic));
  }
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
