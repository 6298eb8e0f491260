/* PeriSystem: the discretized physics of one scene (particles, bonds, model, conditions, K).
 * Its set-up reads every scene section but analysis and output. */
#include "perilin/private/system.h"
#include "perilin/private/sys.h"
#include "perilin/private/model_registry.h"

/* The sections read below: model (the core's keys; each model type declares its own), horizon,
 * corrections, solver. */
static const char *const planes[]     = {"stress", "strain", NULL};
static const PeriKey     model_keys[] = {
        {"type", PERI_KEY_STRING, "required", NULL, NULL, NULL, "the bond model (docs/models/)"},
        {"plane", PERI_KEY_CHOICE, "stress", NULL, NULL, planes, "2D only: plane stress or plane strain"},
        {"calibration", PERI_KEY_CHOICE, NULL, NULL, NULL, PeriCalibrationKinds, "lattice: each particle's discrete family reproduces the continuum's moments, so every homogeneous strain has the target energy, at surfaces too (docs/models/lattice.md; the default of pds, mppd, gerstle; lps weighs each family by its own particle's multipliers, docs/models/lps.md); patch: lattice, then every bond corrected so that on any cloud (graded, stochastic) affine fields are equilibria and dilations have the target energy at every interior particle (bond-based central-force models; docs/mesh.md, \"Patch tests\"); continuum: micromoduli from the continuous horizon (the papers'; the default of the others)"},
        {NULL},
};
static const PeriKey horizon_keys[] = {
    {"m", PERI_KEY_REAL, NULL, "[1, inf)", NULL, NULL, "the horizon as a multiple of the spacing: delta = m dx (may be fractional); m, delta or neighbors is required"},
    {"delta", PERI_KEY_REAL, NULL, NULL, "[length]", NULL, "the horizon radius, instead of m"},
    {"neighbors", PERI_KEY_INT, NULL, "[2, 1000]", NULL, NULL, "instead of m or delta: each particle's horizon holds this many neighbours (the midpoint of its k-th and (k+1)-th nearest distances; Ganzenmüller et al. take 30 on stochastic tetrahedral meshes), a pair bonded within the larger of its two horizons; pmb and npmb; docs/mesh.md"},
    {"spacing", PERI_KEY_CHOICE, "mean", NULL, NULL, PeriHorizonSpacings, "the spacing m multiplies: mean (one horizon for the body) or own (each particle's own spacing: a horizon per particle, for graded and stochastic meshes; a pair is bonded within the larger of its two horizons; pmb and npmb; docs/mesh.md)"},
    {NULL},
};
static const PeriKey corrections_keys[] = {
    {"partial_volume", PERI_KEY_CHOICE, "linear_continued", NULL, NULL, PeriPartialVolumes, "partial volumes of the particles the horizon cuts: none, linear (alpha ramp cut at delta), linear_continued (the ramp continued to delta + dx/2)"},
    {"surface", PERI_KEY_CHOICE, "none", NULL, NULL, PeriSurfaceCorrections, "surface correction: volume (lambda = 2 V0 / (V(H_i) + V(H_j))); energy (antiplane models, Oterkus & Madenci eq. 53); each model names those it takes"},
    {NULL},
};
const char *const    PeriOperatorKinds[] = {"auto", "assembled", "matrix_free", NULL};
static const PeriKey solver_keys[]       = {
          {"operator", PERI_KEY_CHOICE, "auto", NULL, NULL, PeriOperatorKinds, "how K is applied: assembled, or matrix_free (central-force, pds, mppd and gerstle bonds and lps's states: K u bond by bond, AMG on a short-range stiffness; in the dynamic analysis the explicit step and the implicit step's Jacobian too); auto: matrix_free where it applies and the preconditioner is GAMG (the default)"},
          {"pc_radius", PERI_KEY_REAL, "1.75", "[1, inf)", NULL, NULL, "matrix_free: the bonds no longer than pc_radius times the 2 dim-th shortest bond of either end (on a grid: its nearest neighbours) make the preconditioning matrix"},
          {"residual_tol", PERI_KEY_REAL, "0", "[0, 1)", NULL, NULL, "largest true relative residual ||b - A x|| / ||b|| accepted from any linear solve, and ||K x - lambda M x|| / (|lambda| ||M x||) from any mode; 0: min(max(100 rtol, 1e-6), 1e-3)"},
          {NULL},
};
const PeriSchema PeriSystemSchema[] = {
    {"model", model_keys},
    {"horizon", horizon_keys},
    {"corrections", corrections_keys},
    {"solver", solver_keys},
    {NULL},
};

/* horizon.neighbors: k. Until the search gives each particle its horizon (SetLocalView), delta and
 * horizon_m hold the ball of k particles of the largest spacing: the partition's radius. */
static PetscErrorCode ReadNeighborsHorizon(PeriSystem sys, PeriNode h, PetscReal hmax)
{
  PeriScene s = sys->scene;
  PetscInt  k = 0, dim = sys->disc.particles.dim, N = sys->disc.particles.n;
  PetscBool has;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetInt(s, h, "neighbors", PETSC_FALSE, &k, &has));
  if (!has) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &N, 1, MPIU_INT, MPI_SUM, sys->comm)); /* the ranks' blocks */
  PeriInputCheck(k < N, s, h, "neighbors", "%" PetscInt_FMT " neighbours per horizon need more than %" PetscInt_FMT " particles; the body has %" PetscInt_FMT, k, k, N);
  PeriInputCheck(sys->model->takes_own_horizon, s, h, "neighbors", "model %s calibrates its springs on one horizon for the whole body; per-particle horizons are derived for pmb and npmb (docs/mesh.md, \"Per-particle horizons\"): use one of them or horizon.m", sys->model->type);
  PeriInputCheck(sys->model->calibration == PERI_CALIBRATION_CONTINUUM || !PeriModelHasFamilies(sys->model), s, h, "neighbors", "model %s with model.calibration: lattice calibrates its families on one horizon for the whole body: use model.calibration: continuum with per-particle horizons", sys->model->type);
  sys->disc.horizon_k = k;
  sys->disc.horizon_m = dim == 3 ? PetscCbrtReal(3.0 * k / (4 * PETSC_PI)) : PetscSqrtReal(k / PETSC_PI);
  sys->disc.delta     = sys->disc.horizon_m * hmax;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* horizon.spacing: own: each particle's horizon is m times its own spacing, for the models that
 * calibrate per particle; delta becomes the largest. */
static PetscErrorCode ReadOwnHorizon(PeriSystem sys, PeriNode h, PetscBool hasm, PetscReal m, PetscReal hmax)
{
  PeriScene s   = sys->scene;
  PetscInt  own = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetChoice(s, h, "spacing", PeriHorizonSpacings, &own, NULL));
  if (!own) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(hasm, s, h, "spacing", "own needs horizon.m (the multiple of each particle's spacing), not horizon.delta");
  PeriInputCheck(sys->model->takes_own_horizon, s, h, "spacing", "model %s calibrates its springs on one horizon for the whole body; per-particle horizons are derived for pmb and npmb (docs/mesh.md, \"Per-particle horizons\"): use one of them or horizon.spacing: mean", sys->model->type);
  PeriInputCheck(sys->model->calibration == PERI_CALIBRATION_CONTINUUM || !PeriModelHasFamilies(sys->model), s, h, "spacing", "model %s with model.calibration: lattice calibrates its families on one horizon for the whole body: use model.calibration: continuum with per-particle horizons", sys->model->type);
  sys->disc.horizon_m = m;
  sys->disc.delta     = m * hmax;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ReadHorizon(PeriSystem sys)
{
  PeriScene s = sys->scene;
  PeriNode  h, kn, sp;
  PetscReal m = 0, hmax = 0;
  PetscBool hasm, hasd;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "horizon", PETSC_TRUE, &h));
  PetscCall(PeriSceneCheckSection(s, h, "horizon"));
  PetscCall(PeriSceneGetReal(s, h, "m", PETSC_FALSE, &m, &hasm));
  PetscCall(PeriSceneGetReal(s, h, "delta", PETSC_FALSE, &sys->disc.delta, &hasd));
  PetscCall(PeriSceneGetNode(h, "neighbors", &kn));
  PeriInputCheck(hasm || hasd || kn, s, h, "m", "is required (or give horizon.delta or horizon.neighbors)");
  PeriInputCheck(!(hasm && hasd), s, h, "delta", "give horizon.m or horizon.delta, not both");
  PeriInputCheck(!kn || !(hasm || hasd), s, h, "neighbors", "give horizon.neighbors alone: it sets each particle's horizon, as m or delta would");
  PetscCall(PeriSceneGetNode(h, "spacing", &sp));
  PeriInputCheck(!kn || !sp, s, h, "spacing", "horizon.neighbors gives every particle its own horizon already; spacing goes with m");
  if (hasm) {
    sys->disc.delta = m * sys->disc.particles.mean_spacing;
  } else if (hasd)
    sys->disc.delta *= PetscPowInt(2, s->coarsen); /* a multigrid level keeps m */
  for (PetscInt k = 0; k < sys->disc.particles.n; k++) hmax = PetscMax(hmax, sys->disc.particles.spacing[k]);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &hmax, 1, MPIU_REAL, MPI_MAX, sys->comm)); /* the ranks' blocks */
  PetscCall(ReadOwnHorizon(sys, h, hasm, m, hmax));
  PetscCall(ReadNeighborsHorizon(sys, h, hmax));
  if (kn) PetscFunctionReturn(PETSC_SUCCESS); /* each particle's horizon is a search's result */
  {
    /* beyond the body's diagonal every particle bonds with every other: N^2 bonds, no locality */
    PetscReal diag2 = 0;
    for (PetscInt d = 0; d < sys->disc.particles.dim; d++) diag2 += PetscSqr(sys->disc.particles.upper[d] - sys->disc.particles.lower[d]);
    PeriInputCheck(sys->disc.delta <= PetscSqrtReal(diag2), s, h, hasm ? "m" : "delta", "the horizon %g exceeds the body's size (its diagonal %g): every particle would bond with every other; a horizon is a few spacings (m = 3 is usual)", (double)sys->disc.delta, (double)PetscSqrtReal(diag2));
  }
  PeriInputCheck(sys->disc.delta >= hmax * (1 - 1e-10), s, h, hasm ? "m" : "delta", "the horizon %g is smaller than the particle spacing %g: particles would have no bonds", (double)sys->disc.delta, (double)hmax);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ReadCorrections(PeriSystem sys)
{
  PeriScene s = sys->scene;
  PeriNode  c;
  PetscInt  pv = PERI_PARTIAL_VOLUME_LINEAR_CONTINUED, sc = PERI_SURFACE_NONE;
  PetscBool found;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "corrections", PETSC_FALSE, &c));
  PetscCall(PeriSceneCheckSection(s, c, "corrections"));
  PetscCall(PeriSceneGetChoice(s, c, "partial_volume", PeriPartialVolumes, &pv, NULL));
  PetscCall(PeriSceneGetChoice(s, c, "surface", PeriSurfaceCorrections, &sc, &found));
  PeriInputCheck(sc == PERI_SURFACE_NONE || sys->model->calibration == PERI_CALIBRATION_CONTINUUM, s, c, "surface", "the lattice calibration (model.calibration; the default of pds, mppd and gerstle) makes every particle's family reproduce the continuum, at surfaces too, which a surface correction would count twice: use surface: none, or model.calibration: continuum to keep this correction (the papers' calibration)");
  PeriInputCheck(sc == PERI_SURFACE_NONE || sys->model->allows_surface_correction, s, c, "surface", "model %s normalizes each particle's micromodulus by its own family volume, which already corrects surfaces: use surface: none", sys->model->type);
  {
    static const char *const defaults[] = {"none", "volume", NULL};
    const char *const       *allowed    = sys->model->surface_corrections ? sys->model->surface_corrections : defaults;
    char                     list[128]  = "";
    PetscBool                ok         = PETSC_FALSE;
    for (PetscInt k = 0; allowed[k]; k++) {
      ok = (PetscBool)(ok || !strcmp(allowed[k], PeriSurfaceCorrections[sc]));
      PeriListAppend(list, sizeof(list), allowed[k]);
    }
    PeriInputCheck(ok, s, c, "surface", "model %s takes %s, not %s", sys->model->type, list, PeriSurfaceCorrections[sc]);
  }
  sys->disc.partial_volume = (PeriPartialVolume)pv;
  sys->disc.surface        = (PeriSurfaceCorrection)sc;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* solver.residual_tol: every solve's true relative residual must lie below it. */
static PetscErrorCode ReadSolver(PeriSystem sys)
{
  PeriScene s = sys->scene;
  PeriNode  node;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "solver", PETSC_FALSE, &node));
  PetscCall(PeriSceneCheckSection(s, node, "solver"));
  /* from the root, so that an absent solver: takes the declared defaults and ranges too */
  PetscCall(PeriSceneGetReal(s, s->root, "solver.residual_tol", PETSC_FALSE, &sys->stiffness.residual_tol, NULL));
  {
    PetscInt kind = PERI_OPERATOR_AUTO;
    PetscCall(PeriSceneGetChoice(s, s->root, "solver.operator", PeriOperatorKinds, &kind, NULL));
    sys->stiffness.operator_kind = (PeriOperatorKind)kind;
  }
  PetscCall(PeriSceneGetReal(s, s->root, "solver.pc_radius", PETSC_FALSE, &sys->stiffness.pc_radius, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* model.* against the chosen model's schema (s->owners holds every plug-in's); a model registered
 * at run time has no schema, and takes type and plane only. */
static PetscErrorCode CheckModelKeys(PeriScene s, PeriNode m, const char type[])
{
  PeriSchemaOwner        none   = {"model", type, NULL};
  const PeriSchemaOwner *active = &none;

  PetscFunctionBeginUser;
  for (PetscInt o = 0; o < s->nowners; o++)
    if (!strcmp(s->owners[o].kind, "model") && !strcmp(s->owners[o].name, type)) active = &s->owners[o];
  PetscCall(PeriSceneCheckKeysSchema(s, m, "model", active));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CreateModel(PeriSystem sys)
{
  PeriScene s = sys->scene;
  PeriNode  m;
  PetscInt  dim = 0, plane = 0;
  char      type[PERI_NAME_LEN];
  PetscBool found;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetInt(s, s->root, "dim", PETSC_TRUE, &dim, NULL));
  PetscCall(PeriSceneGetMap(s, s->root, "model", PETSC_TRUE, &m));
  PetscCall(PeriSceneGetString(s, m, "type", PETSC_TRUE, type, sizeof(type), NULL));
  if (dim == 2)
    PetscCall(PeriSceneGetChoice(s, m, "plane", planes, &plane, NULL));
  else
    PetscCall(PeriSceneCheckAbsent(s, m, "plane", "applies to 2D scenes only"));
  PetscCall(PeriModelTypeRegistered(type, &found));
  if (!found) {
    char list[256];
    PetscCall(PeriModelListTypes(list, sizeof(list)));
    PeriInputCheck(PETSC_FALSE, s, m, "type", "unknown model '%s'; registered models: %s", type, list);
  }
  PetscCall(PeriModelCreate(type, dim, plane == 1 ? PETSC_TRUE : PETSC_FALSE, &sys->model));
  PetscCall(CheckModelKeys(s, m, type));
  {
    PetscInt kind = sys->model->calibration; /* the model's default */
    PetscCall(PeriSceneGetChoice(s, m, "calibration", PeriCalibrationKinds, &kind, NULL));
    PeriInputCheck(kind == PERI_CALIBRATION_CONTINUUM || sys->model->takes_lattice, s, m, "calibration", "model %s has no lattice calibration (pmb, npmb, cpmb, pds, mppd, gerstle, antiplane and lps have; antiplane_os is exact for every homogeneous strain with corrections.surface: energy): use continuum", type);
    PeriInputCheck(kind != PERI_CALIBRATION_PATCH || (sys->model->central_force && !PeriModelHasFamilies(sys->model)), s, m, "calibration", "patch corrects the springs of bond-based central-force models (pmb, npmb, cpmb); model %s has more kinds of springs or states: use lattice", type);
    sys->model->calibration = (PeriCalibrationKind)kind;
  }
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

static PetscReal ShearModulusAt(PeriSystem sys, PetscInt nr, PeriRegion *const reg[], const PetscReal val[], const PetscReal X[])
{
  PetscReal Y[3], mu = sys->model->material.G;
  FoldIntoBody(&sys->disc.particles, X, Y);
  for (PetscInt k = 0; k < nr; k++)
    if (PeriRegionContains(reg[k], Y)) mu = val[k];
  return mu;
}

static int CompareReal(const void *a, const void *b)
{
  PetscReal x = *(const PetscReal *)a, y = *(const PetscReal *)b;
  return x < y ? -1 : x > y;
}

/* The modulus of the bond X -> X + xi across materials, 1/mu_b = sum over its pieces of (length
 * fraction / mu of the piece): the series combination, which is eq. 60's harmonic mean when the
 * interface halves the bond, and exact for box regions: the bond is cut where it crosses a
 * region's or the body's faces. A cut within two region tolerances of an end is no cut: that end
 * lies on the face (an interface through a row of particles), and the sliver between the widened
 * box and the face would give the bond a piece of the other material (at a contrast of 1e6, a
 * 1e-7 piece of a stiff bond made it 10 % softer). cut[] holds 6 (nr + 1) + 2 reals. */
static PetscReal BondShearModulus(PeriSystem sys, PetscInt nr, PeriRegion *const reg[], const PetscReal val[], const PetscReal X[], const PetscReal xi[], PetscReal cut[])
{
  const PeriParticles *pt  = &sys->disc.particles;
  const PetscReal      tol = 2 * PeriRegionTolerance(pt);
  PetscInt             nc  = 0;
  PetscReal            inv = 0;

  cut[nc++] = 0;
  for (PetscInt r = 0; r <= nr; r++)
    for (PetscInt d = 0; d < pt->dim; d++) {
      PetscReal lo = r < nr ? reg[r]->lower[d] : pt->lower[d], hi = r < nr ? reg[r]->upper[d] : pt->upper[d];
      if (xi[d] == 0) continue;
      for (PetscInt e = 0; e < 2; e++) {
        PetscReal t = ((e ? hi : lo) - X[d]) / xi[d], a = t * PetscAbsReal(xi[d]);
        if (t > 0 && t < 1 && a > tol && PetscAbsReal(xi[d]) - a > tol) cut[nc++] = t;
      }
    }
  cut[nc++] = 1;
  qsort(cut, (size_t)nc, sizeof(PetscReal), CompareReal);
  for (PetscInt c = 0; c + 1 < nc; c++) {
    PetscReal Y[3], t = 0.5 * (cut[c] + cut[c + 1]);
    for (PetscInt d = 0; d < 3; d++) Y[d] = X[d] + t * xi[d];
    inv += (cut[c + 1] - cut[c]) / ShearModulusAt(sys, nr, reg, val, Y);
  }
  return 1 / inv;
}

/* material.mu_by_region's regions and moduli (map: one region name to one modulus > 0). */
static PetscErrorCode RegionModuli(PeriSystem sys, PeriNode map, PeriRegion **reg, PetscReal val[])
{
  PeriScene s = sys->scene;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < map->n; k++) {
    PetscCall(PeriRegionFind(s, map->child[k], NULL, sys->disc.nregions, sys->disc.regions, &reg[k]));
    PetscCall(PeriSceneGetReal(s, map, map->child[k]->key, PETSC_TRUE, &val[k], NULL));
    PeriInputCheck(val[k] > 0, s, map, map->child[k]->key, "must be positive, got %g", (double)val[k]);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* material.mu_by_region: the shear modulus of every particle (later entries win), and of every
 * bond (BondShearModulus). */
static PetscErrorCode ReadShearModuli(PeriSystem sys)
{
  PeriScene            s  = sys->scene;
  const PeriParticles *pt = &sys->disc.particles;
  const PeriBonds     *b  = &sys->disc.bonds;
  PeriNode             mat, map;
  PeriRegion         **reg;
  PetscReal           *val, *cut;
  PetscInt             nr;
  PetscErrorCode       ierr;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "material", PETSC_TRUE, &mat));
  PetscCall(PeriSceneGetMap(s, mat, "mu_by_region", PETSC_FALSE, &map));
  if (!map) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(PeriModelOutOfPlane(sys->model), s, map, NULL, "applies to the cross-section models (antiplane, antiplane_os), not %s", sys->model->type);
  nr = map->n;
  PetscCall(PetscMalloc3(nr, &reg, nr, &val, 6 * (nr + 1) + 2, &cut));
  ierr = RegionModuli(sys, map, reg, val);
  if (ierr) PetscCall(PetscFree3(reg, val, cut)); /* refused: the Python module lives on after it */
  PetscCall(ierr);
  PetscCall(PetscMalloc1(pt->n, &sys->materials.mu));
  for (PetscInt i = 0; i < pt->n; i++) sys->materials.mu[i] = ShearModulusAt(sys, nr, reg, val, &pt->x[3 * i]);
  PetscCall(PetscMalloc1(b->nbonds, &sys->materials.bond_mu));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) sys->materials.bond_mu[k] = BondShearModulus(sys, nr, reg, val, &pt->x[3 * i], &b->xi[3 * k], cut);
  PetscCall(PetscFree3(reg, val, cut));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CreateLevel(PeriSystem, PetscInt, PeriSystem *);

PetscErrorCode PeriSystemCreate(MPI_Comm comm, PeriScene scene, PeriSystem *system)
{
  PeriSystem sys;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&sys));
  sys->comm  = comm;
  sys->scene = scene;
  PetscCallMPI(MPI_Comm_rank(comm, &sys->rank));
  PetscCallMPI(MPI_Comm_size(comm, &sys->size));
  PetscCall(PeriProgressCreate(comm, &sys->run.progress));
  sys->stiffness.levels.create  = CreateLevel;
  sys->stiffness.levels.destroy = PeriSystemDestroy;
  *system                       = sys;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemSetFromScene - the cheap part of the set-up: the model (dim, model.*), solver.* and
  material.thickness, and the memory estimate, so that these errors come before any large
  allocation. Collective.
@*/
/* The model (dim, model.*), solver.* and material.thickness. */
static PetscErrorCode ReadModel(PeriSystem sys)
{
  PeriScene s = sys->scene;
  PeriNode  mat;

  PetscFunctionBeginUser;
  PetscCall(CreateModel(sys));
  PetscCall(ReadSolver(sys));
  PetscCall(PeriSceneGetMap(s, s->root, "material", PETSC_TRUE, &mat));
  PetscCall(PeriSceneGetReal(s, mat, "thickness", PETSC_FALSE, &sys->materials.thickness, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSystemSetFromScene(PeriSystem sys)
{
  PetscFunctionBeginUser;
  PetscCall(ReadModel(sys));
  /* before any large allocation: a scene that cannot fit is refused with its size */
  PetscCall(PeriParticlesCheckMemory(sys->comm, sys->scene, sys->model, &sys->stiffness.needs));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* horizon.neighbors, before the ghosts exist: each owned particle's horizon among this rank's
 * particles alone, and its (k+1)-th nearest distance there, which bounds the true one (more
 * candidates only bring it nearer): the largest bound is a ghost radius that brings every
 * particle's k + 1 nearest. On one rank the horizons are final. Kept (horizons, then bounds) in
 * disc.horizon for SetHorizons; disc.delta becomes the largest bound. */
static PetscErrorCode NeighborsHorizonBound(PeriSystem sys, const PeriParticles *owned)
{
  PetscReal bound = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(2 * owned->n + 1, &sys->disc.horizon));
  PetscCall(PeriHorizonsByNeighbors(owned, owned->n, sys->disc.horizon_k, sys->disc.horizon, sys->disc.horizon + owned->n));
  for (PetscInt k = 0; k < owned->n; k++) bound = PetscMax(bound, sys->disc.horizon[owned->n + k]);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bound, 1, MPIU_REAL, MPI_MAX, sys->comm));
  sys->disc.delta = bound;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Each local particle's horizon (the ghosts' too: a pair's horizon is the larger of its two):
 * m times its own spacing, or (horizon.neighbors) the one holding k neighbours: on several ranks
 * searched again among the owned particles and the ghosts from the bounds NeighborsHorizonBound
 * left, the ghosts' copied from their owners; delta the largest. */
static PetscErrorCode SetHorizons(PeriSystem sys)
{
  PeriDisc  *d     = &sys->disc;
  PetscReal *first = d->horizon;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(d->particles.n, &d->horizon));
  if (d->horizon_k) {
    if (sys->size == 1)
      PetscCall(PetscArraycpy(d->horizon, first, d->nowned));
    else {
      PetscCall(PetscArraycpy(d->horizon, first + d->nowned, d->nowned));
      PetscCall(PeriHorizonsByNeighbors(&d->particles, d->nowned, d->horizon_k, d->horizon, NULL));
    }
    PetscCall(PeriDiscOwnersToGhosts(d, MPIU_REAL, 1, d->horizon));
    d->delta = 0;
    for (PetscInt k = 0; k < d->nowned; k++) d->delta = PetscMax(d->delta, d->horizon[k]);
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &d->delta, 1, MPIU_REAL, MPI_MAX, sys->comm));
  } else
    for (PetscInt k = 0; k < d->particles.n; k++) d->horizon[k] = d->horizon_m * d->particles.spacing[k];
  PetscCall(PetscFree(first));
  d->horizon_min = PETSC_MAX_REAL;
  for (PetscInt k = 0; k < d->particles.n; k++) d->horizon_min = PetscMin(d->horizon_min, d->horizon[k]);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &d->horizon_min, 1, MPIU_REAL, MPI_MIN, sys->comm));
  sys->model->horizon = d->horizon;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* This rank's local view: its owned particles, partitioned (-peri_partition) from the blocks each
 * rank created (PeriParticlesCreateBlock, PeriPartitionBlocks, PeriParticlesMigrate), with the
 * fictitious layer particles that mirror them, then the ghosts within the bonds' search radius. */
static PetscErrorCode SetLocalView(PeriSystem sys)
{
  PeriParticles owned;
  PetscMPIInt  *target;
  PetscReal     hmax = 0, margin;

  PetscFunctionBeginUser;
  PetscCall(PeriPartitionBlocks(sys->comm, &sys->disc.particles, sys->disc.delta, &target));
  if (sys->size > 1) PetscCall(PeriParticlesMigrate(sys->comm, &sys->disc.particles, target));
  PetscCall(PetscFree(target));
  PetscCall(PeriLayersAddParticles(sys));
  owned = sys->disc.particles;
  PetscCall(PetscMemzero(&sys->disc.particles, sizeof(sys->disc.particles)));
  for (PetscInt k = 0; k < owned.n; k++) hmax = PetscMax(hmax, owned.spacing[k]);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &hmax, 1, MPIU_REAL, MPI_MAX, sys->comm));
  if (sys->disc.horizon_k) PetscCall(NeighborsHorizonBound(sys, &owned));
  PetscCall(PeriContactGhostMargin(sys, &margin));
  PetscCall(PeriDiscSetLocalView(sys->comm, &sys->disc, &owned, PeriSearchRadius(sys->disc.partial_volume, sys->disc.delta, hmax) + margin));
  if (sys->disc.horizon_m > 0) PetscCall(SetHorizons(sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the pair list is searched without its vectors, lengths and partial-volume factors (40
 * of the 53 bytes a bond; PeriBonds.no_geometry): they are the coordinates' differences for one
 * horizon without periodic axes, and every reader in such a run (the central-force models'
 * kernels through PeriSystemBondGeometry; the family volumes, the operator, the short range,
 * damage and stress through PeriDiscBondGeometry) recomputes them, to the bit. Kept where readers
 * still take the stored arrays (the lattice and patch calibrations, families, cracks, fictitious
 * layers) and in runs with failure, whose every step reads each bond's geometry;
 * -peri_release_bond_geometry false keeps them always. */
static PetscErrorCode BondsWithoutGeometry(PeriSystem sys, PetscBool *lean)
{
  const PeriDisc *d = &sys->disc;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemBondsLean(sys->scene, sys->model, (PetscBool)(d->horizon != NULL), (PetscBool)(d->particles.periodic[0] || d->particles.periodic[1] || d->particles.periodic[2]), (PetscBool)(sys->conditions.layers.nfaces > 0), lean));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bonds of the owned particles (and their families for state-based models), searched in the
 * local view. */
static PetscErrorCode SearchBonds(PeriSystem sys)
{
  PeriDisc *d    = &sys->disc;
  PetscBool lean = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(BondsWithoutGeometry(sys, &lean));
  PetscCall(PeriNeighborSearch(&d->particles, d->delta, d->horizon, d->partial_volume, 0, d->nowned, PETSC_TRUE, (PetscBool)!lean, &d->bonds));
  /* a state-based particle's energy needs its whole family, including the bonds stored elsewhere */
  if (PeriModelHasFamilies(sys->model)) PetscCall(PeriNeighborSearch(&d->particles, d->delta, d->horizon, d->partial_volume, 0, d->nowned, PETSC_FALSE, PETSC_TRUE, &d->family));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Partition, local view, neighbour search (bonds, and families for state-based models), cracks,
 * family volumes and the surface correction; counts of bonds and of bonds between ranks. */
static PetscErrorCode SetUpBonds(PeriSystem sys)
{
  PeriDisc      *d   = &sys->disc;
  PetscInt       cut = 0;
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscCall(PetscLogEventBegin(PERI_EVENT_Partition, 0, 0, 0, 0));
  PetscCall(SetLocalView(sys));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Partition, 0, 0, 0, 0));

  PetscCall(PetscLogEventBegin(PERI_EVENT_Neighbors, 0, 0, 0, 0));
  PetscCall(SearchBonds(sys));
  PetscCall(PetscMalloc2(d->particles.n, &d->family_volume, d->particles.n, &d->neighbor_count));
  /* a crack is geometry: the family volumes, the surface correction and the calibration see it */
  PetscCall(PeriCracksApply(sys));
  PetscCall(PeriNeighborhoodVolumes(d, d->family_volume, d->neighbor_count));
  PetscCall(PeriSurfaceCorrectionApply(d->surface, &d->particles, d->delta, d->horizon, d->family_volume, &d->bonds));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Neighbors, 0, 0, 0, 0));
  PetscCall(PetscTime(&t1));
  sys->run.log.neighbors_s = t1 - t0;
  PetscCallMPI(MPI_Allreduce(&d->bonds.nbonds, &sys->run.log.nbonds_total, 1, MPIU_INT, MPI_SUM, sys->comm));
  for (PetscInt k = 0; k < d->bonds.nbonds; k++) cut += d->bonds.j[k] >= d->nowned;
  PetscCallMPI(MPI_Allreduce(&cut, &sys->run.log.edge_cut, 1, MPIU_INT, MPI_SUM, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The calibration's combine (PeriCalibrationData): every copy of a particle gets the op of all
 * copies' values. */
static PetscErrorCode CombineCopies(const PeriCalibrationData *data, MPI_Datatype base, PetscInt count, MPI_Op op, void *values)
{
  const PeriDisc *d = (const PeriDisc *)data->ctx;

  PetscFunctionBeginUser;
  PetscCall(PeriDiscGhostsToOwners(d, base, count, op, values));
  PetscCall(PeriDiscOwnersToGhosts(d, base, count, values));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The model's constants from the material and the discrete families. */
static PetscErrorCode Calibrate(PeriSystem sys)
{
  PeriCalibrationData cal;

  PetscFunctionBeginUser;
  cal.n             = sys->disc.particles.n;
  cal.nowned        = sys->disc.nowned;
  cal.N             = sys->disc.N;
  cal.family_volume = sys->disc.family_volume;
  cal.mu            = sys->materials.mu;
  cal.comm          = sys->comm;
  cal.particles     = &sys->disc.particles;
  cal.bonds         = &sys->disc.bonds;
  cal.surface       = sys->disc.surface;
  cal.combine       = CombineCopies;
  cal.ctx           = &sys->disc;
  PetscCall(sys->model->ops.calibrate(sys->model, &cal));
  /* a multigrid level's calibration repeats the scene's: its warning was given already */
  if (sys->model->warning[0] && !sys->scene->coarsen) PetscCall(PetscPrintf(sys->comm, "perilin: warning: %s\n", sys->model->warning));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What stands on the particles and bonds: shear moduli, calibration, probes, failure, reference,
 * conditions, layers, contact, loads and the checks that need them (the one for mechanisms, the
 * costliest, unless the body passed it already with these bonds and held DOFs: mechanisms_known). */
static PetscErrorCode SetUpOnBonds(PeriSystem sys, PetscBool mechanisms_known)
{
  PetscFunctionBeginUser;
  PetscCall(PeriCheckBonded(sys)); /* the regions name where */
  PetscCall(ReadShearModuli(sys));
  PetscCall(Calibrate(sys));
  PetscCall(PeriReadProbes(sys));
  PetscCall(PeriMassSetFromScene(sys));
  PetscCall(PeriFailureSetUp(sys));
  PetscCall(PeriReferenceSetUp(sys));
  PetscCall(PeriBoundarySetUp(sys));
  PetscCall(PeriLayersSetUp(sys));
  PetscCall(PeriContactSetUp(sys));
  /* the loads too, so that a bad load is reported before any solve */
  PetscCall(PeriSystemCreateVec(sys, &sys->fields.f));
  PetscCall(PeriLoadsAssemble(sys, sys->fields.f));
  /* after the bcs, which may hold what the bonds do not, and the loads, which tell held pieces */
  PetscCall(PeriCheckHeld(sys));
  if (mechanisms_known) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscLogEventBegin(PERI_EVENT_Mechanisms, 0, 0, 0, 0));
  PetscCall(PeriCheckMechanisms(sys)); /* pieces of many particles, after the single ones */
  PetscCall(PetscLogEventEnd(PERI_EVENT_Mechanisms, 0, 0, 0, 0));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemSetUp - particles, partition, bonds, corrections, calibration, regions, probes and
  boundary conditions, with every input check. After PeriSystemSetFromScene. Collective.
@*/
PetscErrorCode PeriSystemSetUp(PeriSystem sys)
{
  PeriScene s = sys->scene;

  PetscFunctionBeginUser;
  PetscCall(PeriParticlesCreateBlock(sys->comm, s, sys->model->dim, sys->materials.thickness, &sys->disc.particles, &sys->disc.N));
  PetscCall(PeriParticlesCheckMemoryRead(sys->comm, s, sys->model, &sys->stiffness.needs, sys->disc.N, sys->disc.particles.mean_spacing));
  PetscCall(ReadHorizon(sys));
  PetscCall(PeriModelSetFromScene(sys->model, s, sys->disc.delta));
  PetscCall(ReadCorrections(sys));
  PetscCall(SetUpBonds(sys));
  PetscCall(PeriRegionsCreateFromScene(sys->comm, s, &sys->disc.particles, sys->disc.nowned, sys->disc.delta, &sys->disc.nregions, &sys->disc.regions));
  PetscCall(SetUpOnBonds(sys, PETSC_FALSE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemCanReuse - whether sys's particles, regions and bonds (its disc) can serve a system of
  the same scene whose other keys (material, loads, bc, analysis, solver) changed
  (PeriSystemSetUpFrom); why not (static text) otherwise: its bonds carry a run's state (a scene
  with failure breaks and softens them), its particles' set-up read conditions (fictitious layers,
  torsion), or its horizons came from a neighbour count. Collective.
@*/
PetscErrorCode PeriSystemCanReuse(PeriSystem sys, PetscBool *can, const char **why)
{
  const PeriDisc *d   = &sys->disc;
  PetscInt        bad = 0;

  PetscFunctionBeginUser;
  *why = NULL;
  if (d->bonds.cause || d->bonds.intact)
    bad = 1;
  else if (sys->conditions.layers.nfaces || sys->conditions.torsion.active)
    bad = 2;
  else if (d->horizon_k)
    bad = 3;
  else if (!d->particles.n)
    bad = 4;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_MAX, sys->comm));
  *can = (PetscBool)!bad;
  if (bad == 1) *why = "its bonds may break or soften (failure)";
  if (bad == 2) *why = "its fictitious layers and torsion are read with the particles";
  if (bad == 3) *why = "horizon.neighbors: each horizon is a search's result";
  if (bad == 4) *why = "it has no particles";
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The disc goes from one system to another (a failed set-up gives it back). */
static PetscErrorCode MoveDisc(PeriSystem to, PeriSystem from)
{
  PetscFunctionBeginUser;
  to->disc                 = from->disc;
  to->run.log.nbonds_total = from->run.log.nbonds_total;
  to->run.log.edge_cut     = from->run.log.edge_cut;
  PetscCall(PetscMemzero(&from->disc, sizeof(from->disc)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemSetUpFrom - PeriSystemSetUp on old's particles, regions and bonds, which sys takes
  (PeriSystemCanReuse must have said yes; sys's scene differs from old's in keys the particles
  and bonds do not read): the model's constants, calibration, conditions and loads are set up
  again, no particle is created and no bond searched; with mechanisms_known (the caller knows the
  change cannot turn old's body into a mechanism) neither is the check for mechanisms run. On an
  error old gets its disc back, as it was. After PeriSystemSetFromScene. Collective.
@*/
PetscErrorCode PeriSystemSetUpFrom(PeriSystem sys, PeriSystem old, PetscBool mechanisms_known)
{
  PeriDisc      *d = &sys->disc;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(MoveDisc(sys, old));
  /* a run may have released the bonds' geometry (PeriSystemReleaseBondGeometry) */
  ierr                = d->bonds.xi || !d->bonds.nbonds ? PETSC_SUCCESS : PeriBondsRestoreGeometry(&d->particles, d->delta, d->horizon, d->partial_volume, &d->bonds);
  sys->model->horizon = d->horizon;
  /* delta as the first set-up gave it: without horizon.neighbors the local view keeps it */
  if (!ierr) ierr = PeriModelSetFromScene(sys->model, sys->scene, d->delta);
  if (!ierr) ierr = ReadCorrections(sys);
  if (!ierr) ierr = SetUpOnBonds(sys, mechanisms_known);
  if (ierr) PetscCall(PeriSystemGiveBackDisc(sys, old));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemGiveBackDisc - after PeriSystemSetUpFrom(sys, old), old's disc goes back to old as it
  was (the failure arrays sys's set-up added are freed: old had none). Not collective.
@*/
PetscErrorCode PeriSystemGiveBackDisc(PeriSystem sys, PeriSystem old)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(sys->disc.bonds.cause));
  PetscCall(PetscFree(sys->disc.bonds.intact));
  sys->model->horizon = NULL;
  PetscCall(MoveDisc(old, sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemSetNeeds - what the analysis asks of the stiffness (its type's needs), before
  PeriSystemSetUp: the memory estimate of the set-up reads it. Not collective.
@*/
PetscErrorCode PeriSystemSetNeeds(PeriSystem sys, const PeriSystemNeeds *needs)
{
  PetscFunctionBeginUser;
  sys->stiffness.needs = *needs;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSystemDestroy(PeriSystem *system)
{
  PeriSystem sys = *system;

  PetscFunctionBeginUser;
  if (!sys) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriStiffnessDestroy(&sys->stiffness));
  PetscCall(PeriMassDestroy(&sys->mass));
  PetscCall(PeriFieldsDestroy(&sys->fields));
  PetscCall(PeriBondStateDestroy(&sys->bond_state));
  PetscCall(PeriContactDestroy(&sys->contact));
  PetscCall(PeriConditionsDestroy(&sys->conditions));
  PetscCall(PeriModelDestroy(&sys->model));
  PetscCall(PeriDiscDestroy(&sys->disc));
  PetscCall(PetscFree(sys->materials.mu));
  PetscCall(PetscFree(sys->materials.bond_mu));
  PetscCall(PeriProgressDestroy(&sys->run.progress));
  PetscCall(PetscFree(sys->scene_view)); /* the struct only: its trees are the problem scene's */
  PetscCall(PetscFree(sys));
  *system = NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A multigrid level of the scene (scene->coarsen > 0: the grid at 2^coarsen times the spacing,
 * src/system/multigrid.c): the model, particles, partition, bonds, corrections and calibration,
 * without regions, conditions, probes or checks, which the level does not use (its held DOFs
 * come from the finer level's). Collective. */
static PetscErrorCode SetUpCoarse(PeriSystem sys)
{
  PeriScene s = sys->scene;

  PetscFunctionBeginUser;
  PetscCall(ReadModel(sys));
  PetscCall(PeriParticlesCreateBlock(sys->comm, s, sys->model->dim, sys->materials.thickness, &sys->disc.particles, &sys->disc.N));
  PetscCall(ReadHorizon(sys));
  PetscCall(PeriModelSetFromScene(sys->model, s, sys->disc.delta));
  PetscCall(ReadCorrections(sys));
  PetscCall(SetUpBonds(sys));
  PetscCall(Calibrate(sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The system's level factory (PeriLevelFactory): level l of fine's scene, set up. The level reads
 * its own view of the scene (the same keys, coarsen = l, not sealed; the system owns it), so the
 * public scene is neither edited nor read after its set-up. Collective. */
static PetscErrorCode CreateLevel(PeriSystem fine, PetscInt l, PeriSystem *c)
{
  PeriScene view;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&view));
  *view         = *fine->scene; /* shares the key tree, the owners and the resolved tree */
  view->coarsen = l;
  view->sealed  = PETSC_FALSE;
  PetscCall(PeriSystemCreate(fine->comm, view, c));
  (*c)->scene_view      = view;
  (*c)->stiffness.needs = fine->stiffness.needs;
  PetscCall(SetUpCoarse(*c));
  fine->scene->resolved = view->resolved; /* a default first resolved by the level: the tree is the fine scene's to free */
  PetscFunctionReturn(PETSC_SUCCESS);
}
