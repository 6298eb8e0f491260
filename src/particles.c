/* Particles: a cell-centred grid in a box, or a CSV file of positions and volumes. */
#include "perilin.h"
#include <errno.h>

static PetscErrorCode ParticlesAllocate(PeriParticles *p, PetscInt n)
{
  PetscFunctionBeginUser;
  p->n = n;
  PetscCall(PetscCalloc1(3 * n, &p->x));
  PetscCall(PetscMalloc3(n, &p->volume, n, &p->spacing, n, &p->source_line));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode GridCreate(PeriScene scene, PeriNode grid, PetscInt dim, PeriParticles *p)
{
  static const char *const keys[]   = {"lower", "upper", "spacing", "periodic", NULL};
  PetscReal                lower[3] = {0, 0, 0}, upper[3] = {0, 0, 0}, h, cellvol;
  PetscInt                 nl, nu, cells[3] = {1, 1, 1}, n = 1, k = 0;
  PeriNode                 per;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneCheckKeys(scene, grid, keys));
  PetscCall(PeriSceneGetRealArray(scene, grid, "lower", PETSC_TRUE, dim, dim, lower, &nl));
  PetscCall(PeriSceneGetRealArray(scene, grid, "upper", PETSC_TRUE, dim, dim, upper, &nu));
  PetscCall(PeriSceneGetReal(scene, grid, "spacing", PETSC_TRUE, &h, NULL));
  PeriInputCheck(h > 0, scene, grid, "spacing", "must be positive, got %g", (double)h);
  PetscCall(PeriSceneGetNode(grid, "periodic", &per));
  if (per) {
    PeriInputCheck(per->kind == PERI_NODE_SEQ && per->n == dim, scene, per, NULL, "must be a list of %" PetscInt_FMT " booleans, e.g. [false, true]", dim);
    for (PetscInt d = 0; d < dim; d++) PetscCall(PeriSceneParseBool(scene, per->child[d], &p->periodic[d]));
  }
  for (PetscInt d = 0; d < dim; d++) {
    PetscReal L = upper[d] - lower[d], c;
    /* 1e308 - (-1e308) is inf: say so rather than call inf "not a whole number of spacings" */
    PeriInputCheck(!PetscIsInfOrNanReal(L), scene, grid, "upper", "the box is too large for double precision: upper - lower = %g - (%g) overflows along axis %" PetscInt_FMT, (double)upper[d], (double)lower[d], d);
    PeriInputCheck(L > 0, scene, grid, "upper", "must exceed grid.lower in every axis (axis %" PetscInt_FMT ": %g <= %g)", d, (double)upper[d], (double)lower[d]);
    c        = L / h;
    cells[d] = (PetscInt)PetscFloorReal(c + 0.5);
    PeriInputCheck(cells[d] >= 1 && PetscAbsReal(c - cells[d]) < 1e-6 * PetscMax(c, 1), scene, grid, "spacing", "the box length %g along axis %" PetscInt_FMT " is not a whole number of spacings %g", (double)L, d, (double)h);
    PeriInputCheck(cells[d] <= 100000000 / n, scene, grid, "spacing", "gives too many particles");
    n *= cells[d];
    p->lower[d] = lower[d];
    p->upper[d] = upper[d];
  }
  PetscCall(ParticlesAllocate(p, n));
  cellvol = dim == 3 ? h * h * h : h * h * p->thickness;
  for (PetscInt c2 = 0; c2 < cells[2]; c2++)
    for (PetscInt c1 = 0; c1 < cells[1]; c1++)
      for (PetscInt c0 = 0; c0 < cells[0]; c0++, k++) {
        const PetscInt c[3] = {c0, c1, c2};
        for (PetscInt d = 0; d < dim; d++) p->x[3 * k + d] = lower[d] + (c[d] + 0.5) * h;
        p->volume[k]      = cellvol;
        p->spacing[k]     = h;
        p->source_line[k] = 0;
      }
  p->mean_spacing = h;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* x, y[, z], volume[, material]: one particle per line; '#' comments and a header line allowed. */
static PetscErrorCode CSVCreate(PeriScene scene, PeriNode node, PetscInt dim, PeriParticles *p)
{
  static const char *const keys[] = {"file", NULL};
  char                     name[PETSC_MAX_PATH_LEN], path[PETSC_MAX_PATH_LEN], line[1024];
  FILE                    *fp;
  PetscInt                 cap = 1024, n = 0, lineno = 0;
  PetscReal               *x, *vol, sum              = 0;
  PetscInt                *src;
  PetscBool                header = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneCheckKeys(scene, node, keys));
  PetscCall(PeriSceneGetString(scene, node, "file", PETSC_TRUE, name, sizeof(name), NULL));
  if (name[0] == '/')
    PetscCall(PetscStrncpy(path, name, sizeof(path)));
  else
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/%s", scene->dir, name));
  fp = fopen(path, "r");
  PeriInputCheck(fp, scene, node, "file", "cannot open %s: %s", path, strerror(errno));
  PetscCall(PetscMalloc3(3 * cap, &x, cap, &vol, cap, &src));
  while (fgets(line, sizeof(line), fp)) {
    double         v[5];
    int            nf   = 0;
    char          *s    = line, *end;
    PetscErrorCode ierr = PETSC_SUCCESS;

    lineno++;
    while (*s == ' ' || *s == '\t') s++;
    if (*s == '#' || *s == '\n' || *s == '\r' || !*s) continue;
    while (nf < 5) {
      v[nf] = strtod(s, &end);
      if (end == s) break;
      nf++;
      s = end;
      while (*s == ' ' || *s == '\t') s++;
      if (*s == ',') s++;
    }
    while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n') s++;
    if (nf == 0 && n == 0 && !header) { /* a header line before the first particle */
      header = PETSC_TRUE;
      continue;
    }
    if (nf < dim + 1 || nf > dim + 2 || *s)
      ierr = PETSC_ERR_USER_INPUT;
    else if (!(v[dim] > 0))
      ierr = PETSC_ERR_USER_INPUT + 1;
    for (int k = 0; k < nf; k++)
      if (!PetscIsNormalReal((PetscReal)v[k]) && v[k] != 0) ierr = PETSC_ERR_USER_INPUT + 2;
    if (ierr) {
      fclose(fp);
      PetscCall(PetscFree3(x, vol, src));
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%" PetscInt_FMT ": %s (particles.file, referenced from %s)", path, lineno, ierr == PETSC_ERR_USER_INPUT ? (dim == 2 ? "expected x, y, volume[, material]" : "expected x, y, z, volume[, material]") : (ierr == PETSC_ERR_USER_INPUT + 1 ? "the volume must be positive" : "every value must be a finite number"), scene->file);
    }
    if (n == cap) {
      PetscReal *x2, *v2;
      PetscInt  *s2;
      PetscCall(PetscMalloc3(6 * cap, &x2, 2 * cap, &v2, 2 * cap, &s2));
      PetscCall(PetscArraycpy(x2, x, 3 * cap));
      PetscCall(PetscArraycpy(v2, vol, cap));
      PetscCall(PetscArraycpy(s2, src, cap));
      PetscCall(PetscFree3(x, vol, src));
      x   = x2;
      vol = v2;
      src = s2;
      cap *= 2;
    }
    for (PetscInt d = 0; d < 3; d++) x[3 * n + d] = d < dim ? v[d] : 0;
    vol[n] = v[dim];
    src[n] = lineno;
    n++;
  }
  fclose(fp);
  if (!n) PetscCall(PetscFree3(x, vol, src));
  PeriInputCheck(n > 0, scene, node, "file", "%s holds no particles", path);
  PetscCall(ParticlesAllocate(p, n));
  for (PetscInt d = 0; d < 3; d++) {
    p->lower[d] = PETSC_MAX_REAL;
    p->upper[d] = PETSC_MIN_REAL;
  }
  for (PetscInt k = 0; k < n; k++) {
    PetscReal h = dim == 3 ? PetscCbrtReal(vol[k]) : PetscSqrtReal(vol[k] / p->thickness);
    for (PetscInt d = 0; d < 3; d++) p->x[3 * k + d] = x[3 * k + d];
    for (PetscInt d = 0; d < dim; d++) {
      p->lower[d] = PetscMin(p->lower[d], x[3 * k + d] - h / 2);
      p->upper[d] = PetscMax(p->upper[d], x[3 * k + d] + h / 2);
    }
    p->volume[k]      = vol[k];
    p->spacing[k]     = h;
    p->source_line[k] = src[k];
    sum += h;
  }
  for (PetscInt d = dim; d < 3; d++) p->lower[d] = p->upper[d] = 0;
  p->mean_spacing = sum / n;
  PetscCall(PetscFree3(x, vol, src));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesCreateFromScene - generates the particles from the scene's grid or particles
  section. Not collective: every rank builds the same set.
@*/
PetscErrorCode PeriParticlesCreateFromScene(PeriScene scene, PetscInt dim, PetscReal thickness, PeriParticles *p)
{
  PeriNode grid, csv;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(p, sizeof(*p)));
  p->dim       = dim;
  p->thickness = dim == 2 ? thickness : 1;
  PetscCall(PeriSceneGetMap(scene, scene->root, "grid", PETSC_FALSE, &grid));
  PetscCall(PeriSceneGetMap(scene, scene->root, "particles", PETSC_FALSE, &csv));
  PeriInputCheck(grid || csv, scene, scene->root, "grid", "is required (or give particles.file)");
  PeriInputCheck(!(grid && csv), scene, csv, NULL, "give either grid or particles, not both");
  if (grid)
    PetscCall(GridCreate(scene, grid, dim, p));
  else
    PetscCall(CSVCreate(scene, csv, dim, p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Renumbers the particles: new index k holds the old particle perm[k]. */
PetscErrorCode PeriParticlesPermute(PeriParticles *p, const PetscInt perm[])
{
  PeriParticles q = *p;

  PetscFunctionBeginUser;
  PetscCall(ParticlesAllocate(&q, p->n));
  for (PetscInt k = 0; k < p->n; k++) {
    PetscInt o = perm[k];
    for (PetscInt d = 0; d < 3; d++) q.x[3 * k + d] = p->x[3 * o + d];
    q.volume[k]      = p->volume[o];
    q.spacing[k]     = p->spacing[o];
    q.source_line[k] = p->source_line[o];
  }
  if (p->image) {
    PetscInt *inv;
    PetscCall(PetscMalloc1(p->n, &inv));
    for (PetscInt k = 0; k < p->n; k++) inv[perm[k]] = k;
    PetscCall(PetscMalloc2(p->n, &q.image, p->n, &q.crossed));
    for (PetscInt k = 0; k < p->n; k++) {
      PetscInt o   = perm[k];
      q.image[k]   = p->image[o] < 0 ? -1 : inv[p->image[o]];
      q.crossed[k] = p->crossed[o];
    }
    PetscCall(PetscFree(inv));
  }
  PetscCall(PeriParticlesDestroy(p));
  *p = q;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriParticlesDestroy(PeriParticles *p)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(p->x));
  PetscCall(PetscFree3(p->volume, p->spacing, p->source_line));
  PetscCall(PetscFree2(p->image, p->crossed));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* ------------------------------------------------------------------ the memory a run will need */

/* What a run holds at its peak, from the scene alone (docs/performance.md, "Memory"). */
typedef struct {
  PetscReal n, nbonds;  /* particles, bonds (each pair once) */
  PetscReal per_rank;   /* bytes every rank holds: the runtime and the replicated particle arrays */
  PetscReal shared;     /* bytes the ranks share: bonds, stiffness matrix, solver, vectors */
  PetscReal need, have; /* bytes on the node that needs the most, and what it has available */
} MemoryEstimate;

/* Resident size of PETSc, MPI and the libraries before the scene is read. */
#define PERI_MEMORY_RUNTIME 45e6
/* What GAMG and CG add to the matrix, in units of its scalar graph (see Estimate). */
#define PERI_MEMORY_SOLVER 2.4

/* The grid's particle count, spacing, cells per axis and periodic axes, when the scene has a valid
 * grid (else n = 0). */
static PetscErrorCode GridSize(PeriScene s, PetscInt dim, PetscReal *n, PetscReal *h, PetscReal cells[], PetscBool periodic[])
{
  PeriNode  grid, per;
  PetscReal lower[3], upper[3];
  PetscInt  nl, nu;

  PetscFunctionBeginUser;
  *n = 0;
  PetscCall(PeriSceneGetMap(s, s->root, "grid", PETSC_FALSE, &grid));
  if (!grid) PetscFunctionReturn(PETSC_SUCCESS); /* particles.file: counted while it is read */
  PetscCall(PeriSceneGetRealArray(s, grid, "lower", PETSC_TRUE, dim, dim, lower, &nl));
  PetscCall(PeriSceneGetRealArray(s, grid, "upper", PETSC_TRUE, dim, dim, upper, &nu));
  PetscCall(PeriSceneGetReal(s, grid, "spacing", PETSC_TRUE, h, NULL));
  if (!(*h > 0)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetNode(grid, "periodic", &per));
  for (PetscInt d = 0; d < dim; d++) {
    periodic[d] = PETSC_FALSE;
    if (per && per->kind == PERI_NODE_SEQ && per->n == dim) PetscCall(PeriSceneParseBool(s, per->child[d], &periodic[d]));
  }
  *n = 1;
  for (PetscInt d = 0; d < dim; d++) {
    cells[d] = PetscMax(1, PetscFloorReal((upper[d] - lower[d]) / *h + 0.5));
    *n *= cells[d];
  }
  /* beyond GridCreate's limit (or not a number) GridCreate's own message is the clearer one */
  if (!(*n <= 1e8)) *n = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The neighbour search's radius in spacings: horizon.m or horizon.delta / h, plus half a spacing
 * for the continued partial-volume ramp (the default); 0 when the horizon is not valid. */
static PetscErrorCode SearchRadius(PeriScene s, PetscReal h, PetscReal *r)
{
  PeriNode  hz, c;
  PetscReal m = 0, delta = 0;
  PetscInt  pv = PERI_PARTIAL_VOLUME_LINEAR_CONTINUED;
  PetscBool hasm, hasd;

  PetscFunctionBeginUser;
  *r = 0;
  PetscCall(PeriSceneGetMap(s, s->root, "horizon", PETSC_FALSE, &hz));
  if (!hz) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetReal(s, hz, "m", PETSC_FALSE, &m, &hasm));
  PetscCall(PeriSceneGetReal(s, hz, "delta", PETSC_FALSE, &delta, &hasd));
  if (!hasm) m = delta / h;
  if (!(m >= 1)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetMap(s, s->root, "corrections", PETSC_FALSE, &c));
  PetscCall(PeriSceneGetChoice(s, c, "partial_volume", PeriPartialVolumes, &pv, NULL));
  *r = m + (pv == PERI_PARTIAL_VOLUME_LINEAR_CONTINUED ? 0.5 : 0);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.type, when given. */
static PetscErrorCode AnalysisType(PeriScene s, char type[], size_t len)
{
  PeriNode a;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_FALSE, &a));
  if (a) PetscCall(PeriSceneGetString(s, a, "type", PETSC_FALSE, type, len, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Lattice points within r spacings of a particle, itself excluded. */
static PetscReal BallCount(PetscInt dim, PetscReal r)
{
  return (dim == 2 ? PETSC_PI * r * r : 4.0 / 3.0 * PETSC_PI * r * r * r) - 1;
}

/* The share of the lattice's pairs within r spacings that faces leave: a pair spans on average
 * E|dx| = 4r/(3 pi) (2D) or 3r/8 (3D) along an axis, and a box of c cells keeps 1 - E|dx|/c of
 * them along a non-periodic axis. */
static PetscReal SurfaceShare(PetscInt dim, PetscReal r, const PetscReal cells[], const PetscBool periodic[])
{
  PetscReal share = 1, mean = r * (dim == 2 ? 4 / (3 * PETSC_PI) : 3.0 / 8.0);
  for (PetscInt d = 0; d < dim; d++)
    if (!periodic[d]) share *= PetscMax(0.1, 1 - mean / cells[d]);
  return share;
}

/* Bytes of the bonds (include/perilin.h, PeriBonds), the matrix (AIJ for GAMG: 12 bytes per
 * nonzero; BAIJ: 8, and an index per block) and the solver, for n particles of dofs DOFs, a
 * search radius of r spacings and the share of pairs the faces leave. State-based models also list
 * each family in full and couple particles up to 2 delta apart. */
static PetscErrorCode Estimate(PeriModel m, PetscReal n, PetscReal r, PetscReal share, PetscBool failure, const char analysis[], MemoryEstimate *e)
{
  const PetscReal dofs = m->dofs, ball = BallCount(m->dim, r);
  PetscReal       reserved, per_bond, blocks, nnz, matrix;
  char            type[64];
  PetscBool       aij;

  PetscFunctionBeginUser;
  /* a modal K is AIJ; asking the static default would read -pc_type, which must stay unread in a
     modal run so that the unknown-option check reports it */
  PetscCall(PetscStrncpy(type, MATAIJ, sizeof(type)));
  if (strcmp(analysis, "modal")) PetscCall(PeriStaticDefaultMatType(type, sizeof(type)));
  PetscCall(PetscStrcmp(type, MATAIJ, &aij));
  e->n      = n;
  e->nbonds = n * ball / 2 * share;
  /* the search reserves 1.05 ball / 2 per particle of j, xi, length, alpha, live; every bond found
     gets lambda, and with failure the cause and the softening share */
  reserved = 1.05 * n * ball / 2 * (sizeof(PetscInt) + 5 * sizeof(PetscReal) + 1);
  per_bond = sizeof(PetscReal) + (failure ? 1 + sizeof(PetscReal) : 0);
  blocks   = 1 + share * (m->ops.family_stiffness ? BallCount(m->dim, 2 * r) : ball);
  nnz      = n * blocks * dofs * dofs;
  matrix   = aij ? nnz * (sizeof(PetscScalar) + sizeof(PetscInt)) : nnz * sizeof(PetscScalar) + n * blocks * sizeof(PetscInt);
  /* GAMG's scalar graph (matrix / dofs^2), its coarse levels and prolongators and CG's vectors:
     PERI_MEMORY_SOLVER graphs, fitted to the peaks of 2D plates (2 DOFs, 1e4-1e6 particles, where
     the whole run peaks at 2.5x the matrix as in docs/performance.md) and 3D blocks (3 DOFs) */
  e->shared = (reserved + e->nbonds * per_bond) * (m->ops.family_stiffness ? 3 : 1) + matrix * (1 + PERI_MEMORY_SOLVER / (dofs * dofs)) + 10 * n * dofs * sizeof(PetscScalar);
  /* the quasi-static loop solves on a copy of K; the modal shift-and-invert factors K, whose
     nested-dissection fill grew as 0.45 log2(n) matrices (2D lamina, 3,600 to 230,400 particles) */
  if (!strcmp(analysis, "quasistatic")) e->shared += matrix;
  if (!strcmp(analysis, "modal")) e->shared += matrix * 0.45 * PetscLog2Real(n);
  /* coordinates, volume, spacing, line, owner, family volume, neighbour count, the cell list, and
     the gathered displacements and energy densities */
  e->per_rank = PERI_MEMORY_RUNTIME + n * (8 * sizeof(PetscReal) + 6 * sizeof(PetscInt) + (2 * dofs + 1) * sizeof(PetscReal));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Bytes this node can still give: MemAvailable, or the cgroup's limit when lower; 0 if unknown. */
static PetscReal NodeAvailable(void)
{
  PetscReal have = 0;
  char      line[256];
  FILE     *fp = fopen("/proc/meminfo", "r");
  if (fp) {
    while (fgets(line, sizeof(line), fp))
      if (!strncmp(line, "MemAvailable:", 13)) have = 1024.0 * strtod(line + 13, NULL);
    fclose(fp);
  }
  if ((fp = fopen("/sys/fs/cgroup/memory.max", "r"))) {
    double limit = 0, used = 0;
    FILE  *fu = fopen("/sys/fs/cgroup/memory.current", "r");
    if (fscanf(fp, "%lf", &limit) == 1 && fu && fscanf(fu, "%lf", &used) == 1 && limit - used < have) have = limit - used;
    if (fu) fclose(fu);
    fclose(fp);
  }
  return have;
}

/* The need and the memory available on the node whose ratio is the worst, on every rank. */
static PetscErrorCode NodeBalance(MPI_Comm comm, MemoryEstimate *e)
{
  MPI_Comm    node;
  PetscMPIInt size, nlocal, rank;
  struct {
    double ratio;
    int    rank;
  } mine, worst;
  double nh[2];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node));
  PetscCallMPI(MPI_Comm_size(node, &nlocal));
  PetscCallMPI(MPI_Comm_free(&node));
  e->need    = nlocal * (e->per_rank + e->shared / size);
  e->have    = NodeAvailable();
  mine.ratio = e->have > 0 ? e->need / e->have : 0;
  mine.rank  = rank;
  PetscCallMPI(MPI_Allreduce(&mine, &worst, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm));
  nh[0] = e->need;
  nh[1] = e->have;
  PetscCallMPI(MPI_Bcast(nh, 2, MPI_DOUBLE, worst.rank, comm));
  e->need = nh[0];
  e->have = nh[1];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesCheckMemory - estimates, from the scene's grid, horizon and the model, the memory the
  run will need (bonds, matrix, solver, replicated particle arrays) and refuses with an input error
  naming grid.spacing when it exceeds what the nodes have available (MemAvailable shared by the
  node's ranks). Called before any particle is allocated; errors in the grid or horizon are left
  to the readers that report them. Skipped with -peri_memory_check false, and for particles.file.
  Collective.
@*/
PetscErrorCode PeriParticlesCheckMemory(MPI_Comm comm, PeriScene s, PeriModel m)
{
  MemoryEstimate e = {0};
  PetscReal      h = 0, r = 0, cells[3];
  PetscBool      run                     = PETSC_TRUE, failure, periodic[3];
  char           analysis[PERI_NAME_LEN] = "static";
  PeriNode       grid;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_memory_check", &run, NULL));
  if (!run) PetscFunctionReturn(PETSC_SUCCESS);
  /* a bad grid or horizon is reported later, in the order of the other checks: quietly skip here */
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = GridSize(s, m->dim, &e.n, &h, cells, periodic);
  if (!ierr && e.n > 0) ierr = SearchRadius(s, h, &r);
  if (!ierr && r > 0) {
    /* a horizon beyond the body's diagonal is an input error of its own (ReadHorizon) */
    PetscReal diag2 = 0;
    for (PetscInt d = 0; d < m->dim; d++) diag2 += cells[d] * cells[d];
    if (r - 0.5 > PetscSqrtReal(diag2)) r = 0;
  }
  if (!ierr && r > 0) ierr = AnalysisType(s, analysis, sizeof(analysis));
  PetscCall(PetscPopErrorHandler());
  if (ierr || !(e.n > 0) || !(r > 0)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetNode(s->root, "failure", &grid));
  failure = grid ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(Estimate(m, e.n, r, SurfaceShare(m->dim, r, cells, periodic), failure, analysis, &e));
  PetscCall(NodeBalance(comm, &e));
  PetscCall(PeriSceneGetMap(s, s->root, "grid", PETSC_FALSE, &grid));
  PeriInputCheck(!(e.have > 0) || e.need <= e.have, s, grid, "spacing", "this scene needs about %.3g GB (%.3g particles, %.3g bonds), this machine has %.3g GB available: use a coarser grid.spacing, a smaller horizon, or more nodes", (double)(e.need / 1e9), (double)e.n, (double)e.nbonds, (double)(e.have / 1e9));
  PetscCall(PetscInfo(NULL, "memory estimate: %g bytes on the fullest node, %g available (%g particles, %g bonds)\n", (double)e.need, (double)e.have, (double)e.n, (double)e.nbonds));
  PetscFunctionReturn(PETSC_SUCCESS);
}
