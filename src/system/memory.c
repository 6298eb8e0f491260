/* The memory estimate of a scene, checked before any large allocation (-peri_memory_check). It
 * needs the grid (disc) and the model's DOFs, so it lives with the system. */
#include "perilin/private/system.h"
#include <unistd.h>
#if defined(__GLIBC__)
#  include <malloc.h>
#endif

/* What a run holds at its peak, from the scene alone (docs/performance.md, "Memory"). */
typedef struct {
  PetscReal n, nbonds;  /* particles, bonds (each pair once) */
  PetscReal per_rank;   /* bytes every rank holds: the runtime */
  PetscReal shared;     /* bytes the ranks share: particles, bonds, stiffness matrix, solver, vectors */
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

/* Whether the run will apply K matrix-free (PeriSystemAssemble's rule, solver.operator): bonds the
 * operator applies, an analysis that allows it (needs.matrix_free), and operator matrix_free, or
 * auto with the default or a diagonal PC. Fictitious layers (which turn it off) are not looked at: the estimate is then
 * low by the matrix. */
static PetscErrorCode MatrixFree(PeriScene s, PeriModel m, const PeriSystemNeeds *needs, PetscBool *mf)
{
  PeriNode solver;
  char     op[32] = "auto", pc[64] = PCGAMG;

  PetscFunctionBeginUser;
  *mf = PETSC_FALSE;
  if (PeriOperatorWhyNotModel(m) || !needs->matrix_free) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetMap(s, s->root, "solver", PETSC_FALSE, &solver));
  if (solver) PetscCall(PeriSceneGetString(s, solver, "operator", PETSC_FALSE, op, sizeof(op), NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-pc_type", pc, sizeof(pc), NULL));
  *mf = (PetscBool)(!strcmp(op, "matrix_free") || (!strcmp(op, "auto") && PeriOperatorServesPC(pc)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether a static solve will run the geometric multigrid (DefaultPC's rule, without the body's
 * thinness, which only the grid's cells tell): a matrix-free K of a grid body, not periodic,
 * without failure, the default PC or -pc_type mg, 2D or 3D from PERI_MG_MIN_PARTICLES_3D. */
static PetscBool Multigrid(PeriModel m, const PeriSystemNeeds *needs, PetscBool mf, PetscBool failure, PetscReal n, const PetscBool periodic[])
{
  char      pc[64] = PCMG;
  PetscBool per    = PETSC_FALSE;

  for (PetscInt d = 0; d < m->dim; d++) per = (PetscBool)(per || periodic[d]);
  if (!mf || failure || per || !needs->static_solver || (m->dim == 3 && n < PERI_MG_MIN_PARTICLES_3D)) return PETSC_FALSE;
  if (PetscOptionsGetString(NULL, NULL, "-pc_type", pc, sizeof(pc), NULL)) return PETSC_FALSE;
  return (PetscBool)!strcmp(pc, PCMG);
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
static PetscErrorCode Estimate(PeriModel m, PetscReal n, PetscReal r, PetscReal share, PetscBool failure, const PeriSystemNeeds *needs, PetscBool mf, PetscBool mg, PetscBool lean, PetscBool periodic, MemoryEstimate *e)
{
  const PetscReal dofs = m->dofs, ball = PeriBondsBallCount(m->dim, r);
  PetscReal       reserved, per_bond, blocks, nnz, matrix;
  char            type[64];
  PetscBool       aij;

  PetscFunctionBeginUser;
  /* K is AIJ unless the static solver's default decides; asking that default would read -pc_type,
     which must stay unread in an eigensolver's run so that the unknown-option check reports it */
  PetscCall(PetscStrncpy(type, MATAIJ, sizeof(type)));
  if (needs->static_solver) PetscCall(PeriStaticDefaultMatType(type, sizeof(type)));
  PetscCall(PetscStrcmp(type, MATAIJ, &aij));
  e->n      = n;
  e->nbonds = n * ball / 2 * share;
  /* the search's reserve and every bond's lambda (the bond storage's count), and with failure each
     bond's cause and softening share */
  reserved = n * PeriBondsBytesPerParticle(ball, share, lean);
  per_bond = failure ? 1 + sizeof(PetscReal) : 0;
  /* a matrix-free K: its matrix is the short-range one (1.75 spacings, PeriOperatorPreconditioner)
     beside the operator's partner and sqrt(k) e per bond */
  blocks = 1 + share * (mf ? PeriBondsBallCount(m->dim, 1.75) : PeriModelHasFamilies(m) ? PeriBondsBallCount(m->dim, 2 * r)
                                                                                        : ball);
  nnz    = n * blocks * dofs * dofs;
  matrix = aij ? nnz * (sizeof(PetscScalar) + sizeof(PetscInt)) : nnz * sizeof(PetscScalar) + n * blocks * sizeof(PetscInt);
  /* the geometric multigrid stores no matrix but the coarsest's: its levels hold a third of the
     finest's bonds, with their geometry, and operator in the vector form, and 15 more vectors
     (docs/performance.md, "Geometric multigrid") */
  if (mg || (mf && needs->operator_only)) matrix = 0; /* the explicit step has no PC */
  if (mg) reserved += e->nbonds / 3 * (PeriBondsBytesPerParticle(2, share, PETSC_FALSE) + sizeof(PetscInt) + dofs * sizeof(PetscReal)) + 15 * n * dofs * sizeof(PetscScalar);
  if (mf) { /* operator.c's forms: the spring form's s (central, no states, no periodic image) */
    PetscBool springs = PETSC_TRUE;
    PetscReal reals   = m->central_force ? dofs : dofs == 2 ? 3
                                                            : 7;
    PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_operator_springs", &springs, NULL));
    if (springs && m->central_force && !PeriModelHasFamilies(m) && !periodic) reals = 1;
    reserved += e->nbonds * (sizeof(PetscInt) + reals * sizeof(PetscReal));
  }
  /* GAMG's scalar graph (matrix / dofs^2), its coarse levels and prolongators and CG's vectors:
     PERI_MEMORY_SOLVER graphs, fitted to the peaks of 2D plates (2 DOFs, 1e4-1e6 particles, where
     the whole run peaks at 2.5x the matrix as in docs/performance.md) and 3D blocks (3 DOFs) */
  e->shared = (reserved + e->nbonds * per_bond) * (PeriModelHasFamilies(m) ? 3 : 1) + matrix * (1 + PERI_MEMORY_SOLVER / (dofs * dofs)) + 10 * n * dofs * sizeof(PetscScalar);
  /* the analysis' copies of K (the quasi-static loop solves on one) and its factorization (the
     modal shift-and-invert: nested-dissection fill grew as 0.45 log2(n) matrices on the 2D lamina,
     3,600 to 230,400 particles) */
  e->shared += matrix * (needs->matrix_copies + needs->factor_fill * PetscLog2Real(n));
  /* the particles' arrays: each rank holds its own particles' (and a thin layer of ghosts), so
     they share out like the rest (docs/distributed.md) */
  e->shared += n * PeriParticlesBytesPerParticle(m->dofs);
  e->per_rank = PERI_MEMORY_RUNTIME;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the set-up will store the bonds without their geometry (PeriSystemBondsLean), from the
 * scene: per-particle horizons (horizon.spacing: own, horizon.neighbors), a periodic axis of a
 * grid (periodic NULL: particles read from a file), fictitious boundary layers. */
static PetscErrorCode Lean(PeriScene s, PeriModel m, const PetscBool periodic[], PetscBool *lean, PetscBool *per)
{
  PeriNode  hz, layers;
  PetscInt  own = 0;
  PetscBool k   = PETSC_FALSE;

  PetscFunctionBeginUser;
  *per = PETSC_FALSE;
  for (PetscInt d = 0; periodic && d < m->dim; d++) *per = (PetscBool)(*per || periodic[d]);
  PetscCall(PeriSceneGetMap(s, s->root, "horizon", PETSC_FALSE, &hz));
  if (hz) {
    PeriNode       nb;
    PetscErrorCode ierr;
    /* a bad spacing is reported later, by its reader, in the order of the other checks */
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    ierr = PeriSceneGetChoice(s, hz, "spacing", PeriHorizonSpacings, &own, NULL);
    PetscCall(PetscPopErrorHandler());
    if (ierr) own = 0;
    PetscCall(PeriSceneGetNode(hz, "neighbors", &nb));
    k = (PetscBool)(nb != NULL);
  }
  PetscCall(PeriSceneGetNode(s->root, "boundary_layers", &layers));
  PetscCall(PeriSystemBondsLean(s, m, (PetscBool)(own || k), *per, (PetscBool)(layers != NULL), lean));
  PetscFunctionReturn(PETSC_SUCCESS);
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
  e->have    = PeriMemoryAvailable();
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

/* The estimate of n particles at a search radius of r spacings, pairs left by the faces share, a
 * grid (multigrid possible; NULL periodic: not a grid) or not, refused with an input error at
 * where.key when the fullest node lacks it. */
static PetscErrorCode CheckEstimate(MPI_Comm comm, PeriScene s, PeriModel m, const PeriSystemNeeds *needs, PetscReal n, PetscReal r, PetscReal share, const PetscBool periodic[], PeriNode where, const char key[], const char what[])
{
  MemoryEstimate  e = {0};
  PeriSystemNeeds at;
  PeriNode        node;
  PetscBool       failure, mf, lean, per;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "failure", &node));
  failure = node ? PETSC_TRUE : PETSC_FALSE;
  at      = *needs;
  PetscCall(Lean(s, m, periodic, &lean, &per));
  PetscCall(PeriSceneGetNode(s->root, "bc", &node));
  /* the sooner iterative default (the modal analysis' auto rule): a held grid body that is not
     periodic (the geometric multigrid's), or a free body of a state-based model */
  if (at.iterative_dofs_grid > 0 && ((periodic && !per && node) || (!node && PeriModelHasFamilies(m)))) at.iterative_dofs = at.iterative_dofs_grid;
  if (at.iterative_dofs > 0 && n * m->dofs >= at.iterative_dofs) {
    /* the analysis' iterative default (a modal LOBPCG): no factor, and K matrix-free where the
       operator applies (solver.operator assembled or a forced factorization then need more) */
    at.factor_fill = 0;
    mf             = (PetscBool)!PeriOperatorWhyNotModel(m);
  } else
    PetscCall(MatrixFree(s, m, &at, &mf));
  if (failure && !m->central_force) mf = PETSC_FALSE; /* PeriMatrixFreeWhyNot */
  PetscCall(Estimate(m, n, r, share, failure, &at, mf, (PetscBool)(periodic && !at.operator_only && Multigrid(m, &at, mf, failure, n, periodic)), lean, per, &e));
  PetscCall(NodeBalance(comm, &e));
  PeriInputCheck(!(e.have > 0) || e.need <= e.have, s, where, key, "this scene needs about %.3g GB (%.3g particles, %.3g bonds), this machine has %.3g GB available: %s", (double)(e.need / 1e9), (double)e.n, (double)e.nbonds, (double)(e.have / 1e9), what);
  PetscCall(PetscInfo(NULL, "memory estimate: %g bytes on the fullest node, %g available (%g particles, %g bonds)\n", (double)e.need, (double)e.have, (double)e.n, (double)e.nbonds));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesCheckMemory - estimates, from the scene's grid, horizon and the model, the memory the
  run will need (bonds, matrix, solver, particle arrays) and refuses with an input error
  naming grid.spacing when it exceeds what the nodes have available (MemAvailable shared by the
  node's ranks). Called before any particle is allocated; errors in the grid or horizon are left
  to the readers that report them. Skipped with -peri_memory_check false, and for particles read
  from a file or mesh (PeriParticlesCheckMemoryRead checks those). Collective.
@*/
PetscErrorCode PeriParticlesCheckMemory(MPI_Comm comm, PeriScene s, PeriModel m, const PeriSystemNeeds *needs)
{
  PetscReal      n = 0, h = 0, r = 0, cells[3];
  PetscBool      run = PETSC_TRUE, periodic[3];
  PeriNode       grid;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_memory_check", &run, NULL));
  if (!run) PetscFunctionReturn(PETSC_SUCCESS);
  /* a bad grid or horizon is reported later, in the order of the other checks: quietly skip here */
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = GridSize(s, m->dim, &n, &h, cells, periodic);
  if (!ierr && n > 0) ierr = SearchRadius(s, h, &r);
  if (!ierr && r > 0) {
    /* a horizon beyond the body's diagonal is an input error of its own (ReadHorizon) */
    PetscReal diag2 = 0;
    for (PetscInt d = 0; d < m->dim; d++) diag2 += cells[d] * cells[d];
    if (r - 0.5 > PetscSqrtReal(diag2)) r = 0;
  }
  PetscCall(PetscPopErrorHandler());
  if (ierr || !(n > 0) || !(r > 0)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetMap(s, s->root, "grid", PETSC_FALSE, &grid));
  PetscCall(CheckEstimate(comm, s, m, needs, n, r, SurfaceShare(m->dim, r, cells, periodic), periodic, grid, "spacing", "use a coarser grid.spacing, a smaller horizon, or more nodes"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesCheckMemoryRead - the same estimate for the N particles read from particles.file or
  particles.mesh (their mean spacing h), made once they are counted and before the bonds are
  searched (the largest allocation): an input error naming the file's key when the nodes lack
  it. Faces are not discounted (an upper bound of the bonds). Skipped with -peri_memory_check
  false and for grids (PeriParticlesCheckMemory). Collective.
@*/
PetscErrorCode PeriParticlesCheckMemoryRead(MPI_Comm comm, PeriScene s, PeriModel m, const PeriSystemNeeds *needs, PetscInt N, PetscReal h)
{
  PetscReal      r   = 0;
  PetscBool      run = PETSC_TRUE;
  PeriNode       particles, file;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_memory_check", &run, NULL));
  PetscCall(PeriSceneGetNode(s->root, "particles", &particles));
  if (!run || !particles || !(h > 0) || N <= 0) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetNode(particles, "file", &file));
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = SearchRadius(s, h, &r);
  PetscCall(PetscPopErrorHandler());
  if (ierr || !(r > 0)) PetscFunctionReturn(PETSC_SUCCESS);
  /* faces not discounted; no particle has more than N - 1 neighbours (a horizon as large as the body) */
  PetscCall(CheckEstimate(comm, s, m, needs, (PetscReal)N, r, PetscMin(1, (N - 1) / PeriBondsBallCount(m->dim, r)), NULL, particles, file ? "file" : "mesh", "use fewer particles (a coarser mesh or file), a smaller horizon, or more nodes"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemReleaseBondGeometry - frees the bonds' vectors, lengths and partial-volume factors
  before a solve on the assembled K, which then reads only K (issue 14, item 4: the solver's
  hierarchy takes their place at the peak). A matrix-free K keeps its own bond data; its
  preconditioning matrix is assembled here first when the PC is GAMG, and with another (the
  default Jacobi may hand over to GAMG, assembling it then) nothing is freed. Kept for
  periodic bodies, fictitious layers, another PC on a matrix-free K and with
  -peri_release_bond_geometry false. *released says whether PeriSystemRestoreBondGeometry must
  give them back. Collective.
@*/
PetscErrorCode PeriSystemReleaseBondGeometry(PeriSystem sys, PetscBool *released)
{
  PetscBool release = PETSC_TRUE;
  char      pc[64];

  PetscFunctionBeginUser;
  *released = PETSC_FALSE;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_release_bond_geometry", &release, NULL));
  PetscCall(PetscStrncpy(pc, sys->stiffness.pc_default, sizeof(pc)));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-pc_type", pc, sizeof(pc), NULL));
  if (!release || !sys->stiffness.K || sys->conditions.layers.T || !sys->disc.bonds.xi) PetscFunctionReturn(PETSC_SUCCESS);
  if (sys->stiffness.op) { /* GAMG reads the short-range stiffness, the multigrid its own levels */
    if (strcmp(pc, PCGAMG) && strcmp(pc, PCMG)) PetscFunctionReturn(PETSC_SUCCESS);
    if (!strcmp(pc, PCGAMG)) PetscCall(PeriOperatorPreconditioner(sys));
  }
  PetscCall(PeriBondsReleaseGeometry(&sys->disc.particles, &sys->disc.bonds, released));
#if defined(__GLIBC__)
  if (*released) malloc_trim(0); /* the freed pages go back, whatever the arrays' sizes */
#endif
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemRestoreBondGeometry - recomputes, bit for bit, what PeriSystemReleaseBondGeometry
  freed (when released). Not collective.
@*/
PetscErrorCode PeriSystemRestoreBondGeometry(PeriSystem sys, PetscBool released)
{
  PetscFunctionBeginUser;
#if defined(__GLIBC__)
  /* the solver's arrays, freed by now, go back to the system first: the geometry takes their
     pages instead of adding its own above the heap's high-water mark */
  if (released) malloc_trim(0);
#endif
  if (released) PetscCall(PeriBondsRestoreGeometry(&sys->disc.particles, sys->disc.delta, sys->disc.horizon, sys->disc.partial_volume, &sys->disc.bonds));
  PetscFunctionReturn(PETSC_SUCCESS);
}
