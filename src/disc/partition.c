/* Partitioning: particles are renumbered so that each rank owns a contiguous range (PETSc's row
 * ownership). Three partitioners (-peri_partition):
 *   geometric (default) a Hilbert space-filling curve through the particles, cut into pieces of
 *             equal count by a parallel selection of the P - 1 splitting keys: no graph, the same
 *             parts on every run;
 *   ptscotch  PT-Scotch through PETSc's MatPartitioning, in parallel: each rank starts from a
 *             contiguous block of the particles, builds the graph rows of that block in its local
 *             view (the block and the particles within the graph radius of it, src/disc/halo.c),
 *             and PT-Scotch moves the vertices between ranks (one Scotch thread, its generator
 *             reset: the same parts for the same graph);
 *   metis     METIS k-way on rank 0 over the whole graph (the default before issue 17): the blocks'
 *             particles are gathered to rank 0 for it, so it is for small runs only.
 * Each partitioner reads the body as blocks, rank r holding a contiguous range of the particles
 * (PeriPartitionBlocks), and names each particle's target rank; PeriParticlesMigrate then moves
 * them, or PeriPartition turns the targets into the permutation of the whole body.
 * docs/performance.md ("Partitioners") measured the three: on grids the curve cuts as few bonds
 * as the graph partitioners (within a few per cent either way) in a fraction of the time and
 * memory, on an unstructured mesh with a hole a few per cent more. The graph is the
 * nearest-neighbour graph (bonds up to 1.5 spacings): a horizon of m spacings only adds edges
 * between particles that graph already links through short paths, so it gives the same parts for
 * a fraction of the graph size and search time. */
#include "perilin/private/disc.h"
#include <petscmat.h>
#include <metis.h>
#include <stdint.h>
#include <stdlib.h>

/* from scotch.h, which needs Scotch's integer width to be included: the random generator reset */
void SCOTCH_randomReset(void);

typedef enum {
  PARTITION_METIS,
  PARTITION_PTSCOTCH,
  PARTITION_GEOMETRIC
} PartitionType;

static const char *const PartitionTypes[] = {"metis", "ptscotch", "geometric"};

/* -peri_partition: read on every run (also on one rank, where nothing is partitioned) so that a
 * misspelt value is an error whatever the rank count */
static PetscErrorCode ReadType(MPI_Comm comm, PartitionType *type)
{
  char      name[64] = "geometric";
  PetscBool found    = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-peri_partition", name, sizeof(name), NULL));
  for (int t = 0; t < 3; t++) {
    PetscCall(PetscStrcmp(name, PartitionTypes[t], &found));
    if (found) {
      *type = (PartitionType)t;
      break;
    }
  }
  PetscCheck(found, comm, PETSC_ERR_USER_INPUT, "-peri_partition %s: unknown partitioner; use metis, ptscotch or geometric", name);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sorts the neighbours of each row and drops repeats (the periodic images of one pair): the
 * partitioners want each edge once per direction. Compacts adj in place; offsets are rewritten. */
static PetscErrorCode GraphCompact(PetscInt nrows, PetscInt offset[], PetscInt adj[])
{
  PetscInt ne = 0;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < nrows; i++) {
    PetscInt s = ne, k0 = offset[i], k1 = offset[i + 1];
    for (PetscInt k = k0; k < k1; k++) adj[ne++] = adj[k];
    PetscCall(PetscSortInt(ne - s, &adj[s]));
    {
      PetscInt m = s;
      for (PetscInt k = s; k < ne; k++)
        if (k == s || adj[k] != adj[m - 1]) adj[m++] = adj[k];
      ne = m;
    }
    offset[i + 1] = ne;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode MetisPartition(const PeriParticles *p, PetscReal radius, PetscMPIInt nparts, PetscInt part[])
{
  PeriBonds g;
  idx_t    *xadj, *adjncy, *where, nv = (idx_t)p->n, ncon = 1, np = nparts, objval = 0, options[METIS_NOPTIONS];
  PetscInt *off;
  int       status;

  PetscFunctionBeginUser;
  PetscCall(PeriNeighborSearch(p, radius, NULL, PERI_PARTIAL_VOLUME_NONE, 0, p->n, PETSC_FALSE, PETSC_TRUE, &g));
  PetscCall(PetscMalloc1(p->n + 1, &off));
  PetscCall(PetscArraycpy(off, g.offset, p->n + 1));
  PetscCall(GraphCompact(p->n, off, g.j));
  PetscCall(PetscMalloc3(p->n + 1, &xadj, off[p->n], &adjncy, p->n, &where));
  for (PetscInt i = 0; i <= p->n; i++) xadj[i] = (idx_t)off[i];
  for (PetscInt k = 0; k < off[p->n]; k++) adjncy[k] = (idx_t)g.j[k];
  PetscCall(PetscFree(off));
  PetscCall(PeriBondsDestroy(&g));
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  status                     = METIS_PartGraphKway(&nv, &ncon, xadj, adjncy, NULL, NULL, NULL, &np, NULL, NULL, options, &objval, where);
  PetscCheck(status == METIS_OK, PETSC_COMM_SELF, PETSC_ERR_LIB, "METIS_PartGraphKway failed with status %d on %" PetscInt_FMT " particles and %d parts", status, p->n, (int)nparts);
  for (PetscInt i = 0; i < p->n; i++) part[i] = (PetscInt)where[i];
  PetscCall(PetscFree3(xadj, adjncy, where));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The graph rows of this rank's block: CSR arrays with global column indices, each neighbour once,
 * allocated with PetscMalloc for MatCreateMPIAdj. The block's local view (the block and, as
 * ghosts, the particles within radius of it: src/disc/halo.c) is all it reads of the particles.
 * Collective. */
static PetscErrorCode BlockGraph(MPI_Comm comm, const PeriParticles *b, PetscReal radius, PetscReal hmax, PetscInt **xadj, PetscInt **adjncy)
{
  const PetscInt n = b->n;
  PeriParticles  local;
  PeriHalo       halo;
  PeriBonds      g;

  PetscFunctionBeginUser;
  PetscCall(PeriParticlesSlice(b, 0, n, &local));
  PetscCall(PeriHaloCreate(comm, &local, PeriSearchRadius(PERI_PARTIAL_VOLUME_NONE, radius, hmax), &halo));
  PetscCall(PeriNeighborSearch(&local, radius, NULL, PERI_PARTIAL_VOLUME_NONE, 0, n, PETSC_FALSE, PETSC_TRUE, &g));
  for (PetscInt k = 0; k < g.nbonds; k++) g.j[k] = local.global[g.j[k]]; /* MatCreateMPIAdj's columns are global */
  PetscCall(PeriHaloDestroy(&halo));
  PetscCall(PeriParticlesDestroy(&local));
  PetscCall(GraphCompact(n, g.offset, g.j));
  PetscCall(PetscMalloc1(n + 1, xadj));
  PetscCall(PetscMalloc1(g.offset[n], adjncy));
  PetscCall(PetscArraycpy(*xadj, g.offset, n + 1));
  PetscCall(PetscArraycpy(*adjncy, g.j, g.offset[n]));
  PetscCall(PeriBondsDestroy(&g));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* PT-Scotch over the graph of the blocks: target[] the rank of each particle of this rank's block
 * b (N particles in all). -mat_partitioning_ptscotch_imbalance and _strategy tune it. */
static PetscErrorCode PTScotchPartition(MPI_Comm comm, const PeriParticles *b, PetscInt N, PetscReal radius, PetscReal hmax, PetscMPIInt target[])
{
  PetscInt       *xadj, *adjncy;
  Mat             adj;
  MatPartitioning mp;
  PetscMPIInt     size;
  IS              part;
  const PetscInt *t;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(BlockGraph(comm, b, radius, hmax, &xadj, &adjncy));
  /* the matrix takes xadj and adjncy over */
  PetscCall(MatCreateMPIAdj(comm, b->n, N, xadj, adjncy, NULL, &adj));
  PetscCall(MatPartitioningCreate(comm, &mp));
  PetscCall(MatPartitioningSetAdjacency(mp, adj));
  PetscCall(MatPartitioningSetType(mp, MATPARTITIONINGPTSCOTCH));
  PetscCall(MatPartitioningSetNParts(mp, size));
  PetscCall(MatPartitioningSetFromOptions(mp));
  /* one graph, one partition: Scotch's threads (its own, beside the ranks) split the work in an
   * order that varies from run to run, and its random generator would go on from the last
   * partition. An explicit SCOTCH_PTHREAD_NUMBER wins. */
  if (setenv("SCOTCH_PTHREAD_NUMBER", "1", 0)) SETERRQ(PETSC_COMM_SELF, PETSC_ERR_SYS, "setenv failed");
  SCOTCH_randomReset();
  PetscCall(MatPartitioningApply(mp, &part));
  PetscCall(MatPartitioningDestroy(&mp));
  PetscCall(MatDestroy(&adj));
  PetscCall(ISGetIndices(part, &t));
  for (PetscInt i = 0; i < b->n; i++) target[i] = (PetscMPIInt)t[i];
  PetscCall(ISRestoreIndices(part, &t));
  PetscCall(ISDestroy(&part));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A particle's place on the curve: its Hilbert index (Skilling's transpose form, AIP Conf. Proc.
 * 707, 2004) and, to break ties, its global index. */
typedef struct {
  uint64_t h;
  PetscInt g;
} CurveKey;

/* The Hilbert index of the point with integer coordinates X[0..n-1] of b bits each. */
static uint64_t HilbertIndex(uint64_t X[3], PetscInt n, PetscInt b)
{
  uint64_t M = (uint64_t)1 << (b - 1), t, key = 0;

  /* inverse undo of the rotations and reflections, then Gray encoding */
  for (uint64_t Q = M; Q > 1; Q >>= 1)
    for (PetscInt i = 0; i < n; i++) {
      if (X[i] & Q)
        X[0] ^= Q - 1;
      else {
        t = (X[0] ^ X[i]) & (Q - 1);
        X[0] ^= t;
        X[i] ^= t;
      }
    }
  for (PetscInt i = 1; i < n; i++) X[i] ^= X[i - 1];
  t = 0;
  for (uint64_t Q = M; Q > 1; Q >>= 1)
    if (X[n - 1] & Q) t ^= Q - 1;
  for (PetscInt i = 0; i < n; i++) X[i] ^= t;
  /* the transpose's bits interleaved, most significant first */
  for (PetscInt bit = b - 1; bit >= 0; bit--)
    for (PetscInt i = 0; i < n; i++) key = (key << 1) | ((X[i] >> bit) & 1);
  return key;
}

static int CurveKeyCompare(const void *a, const void *b)
{
  const CurveKey *x = (const CurveKey *)a, *y = (const CurveKey *)b;
  if (x->h != y->h) return x->h < y->h ? -1 : 1;
  return x->g < y->g ? -1 : (x->g > y->g);
}

/* The particles' bounding box (all ranks), and its axes longest first: the curve's first cut is
 * across its first axis, so a bar is cut across its length. */
static PetscErrorCode CurveBox(MPI_Comm comm, const PeriParticles *p, PetscReal lo[3], PetscReal *length, PetscInt axis[3])
{
  PetscReal ext[6], e[3];

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 6; d++) ext[d] = PETSC_MAX_REAL;
  for (PetscInt i = 0; i < p->n; i++)
    for (PetscInt d = 0; d < 3; d++) ext[d] = PetscMin(ext[d], p->x[3 * i + d]), ext[3 + d] = PetscMin(ext[3 + d], -p->x[3 * i + d]);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, ext, 6, MPIU_REAL, MPIU_MIN, comm));
  *length = 0;
  for (PetscInt d = 0; d < 3; d++) {
    lo[d]   = ext[d];
    e[d]    = -ext[3 + d] - ext[d];
    axis[d] = d;
    *length = PetscMax(*length, e[d]);
  }
  if (*length <= 0) *length = 1;
  for (PetscInt d = 1; d < p->dim; d++)
    for (PetscInt k = d; k > 0 && e[axis[k]] > e[axis[k - 1]]; k--) {
      PetscInt t  = axis[k];
      axis[k]     = axis[k - 1];
      axis[k - 1] = t;
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The keys of the block p (global indices from rstart), sorted: the coordinates in the bounding
 * box scaled alike on every axis (a uniform grid stays uniform on the curve), b bits per axis. */
static PetscErrorCode CurveKeys(MPI_Comm comm, const PeriParticles *p, PetscInt rstart, CurveKey key[])
{
  PetscReal lo[3], length = 1;
  PetscInt  axis[3], n = p->dim, b = 63 / p->dim;
  uint64_t  top = ((uint64_t)1 << b) - 1;

  PetscFunctionBeginUser;
  PetscCall(CurveBox(comm, p, lo, &length, axis));
  for (PetscInt i = 0; i < p->n; i++) {
    uint64_t X[3] = {0, 0, 0};
    for (PetscInt d = 0; d < n; d++) {
      PetscReal s = (p->x[3 * i + axis[d]] - lo[axis[d]]) / length;
      X[d]        = (uint64_t)PetscMin((PetscReal)top, PetscMax(0.0, s * (PetscReal)top));
    }
    key[i].h = HilbertIndex(X, n, b);
    key[i].g = rstart + i;
  }
  qsort(key, (size_t)p->n, sizeof(CurveKey), CurveKeyCompare);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* How many of the sorted keys are <= k. */
static PetscInt CountLE(const CurveKey key[], PetscInt n, CurveKey k)
{
  PetscInt lo = 0, hi = n;
  while (lo < hi) {
    PetscInt mid = lo + (hi - lo) / 2;
    if (CurveKeyCompare(&key[mid], &k) <= 0)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* split[q] (q = 1..P-1) becomes the key of the particle of global rank floor(q N / P) along the
 * curve: bisection over the Hilbert index, then over the global index among equal Hilbert
 * indices, every step one reduction of the P - 1 counts. */
static PetscErrorCode CurveSplitters(MPI_Comm comm, PetscInt N, PetscMPIInt P, const CurveKey key[], PetscInt n, CurveKey split[])
{
  uint64_t *lo, *hi;
  PetscInt *count;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc3(P, &lo, P, &hi, P, &count));
  for (PetscInt stage = 0; stage < 2; stage++) {
    for (PetscMPIInt q = 1; q < P; q++) lo[q] = 0, hi[q] = stage ? (uint64_t)(N - 1) : UINT64_MAX;
    for (PetscBool busy = PETSC_TRUE; busy;) {
      busy = PETSC_FALSE;
      for (PetscMPIInt q = 1; q < P; q++) {
        split[q].h = stage ? split[q].h : lo[q] + (hi[q] - lo[q]) / 2;
        split[q].g = stage ? (PetscInt)(lo[q] + (hi[q] - lo[q]) / 2) : PETSC_MAX_INT;
        count[q]   = CountLE(key, n, split[q]);
      }
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &count[1], P - 1, MPIU_INT, MPI_SUM, comm));
      /* the smallest key with more than floor(q N / P) keys at or below it */
      for (PetscMPIInt q = 1; q < P; q++) {
        uint64_t mid = stage ? (uint64_t)split[q].g : split[q].h;
        if (lo[q] == hi[q]) continue;
        if (count[q] > (PetscInt)((PetscInt64)q * N / P))
          hi[q] = mid;
        else
          lo[q] = mid + 1;
        busy = (PetscBool)(busy || lo[q] < hi[q]);
      }
    }
    for (PetscMPIInt q = 1; q < P; q++) {
      if (stage)
        split[q].g = (PetscInt)lo[q];
      else
        split[q].h = lo[q];
    }
  }
  PetscCall(PetscFree3(lo, hi, count));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The Hilbert curve cut into P pieces of floor((q+1) N/P) - floor(q N/P) particles: target[] the
 * piece of each particle of the block b, whose first has global index rstart. */
static PetscErrorCode GeometricPartition(MPI_Comm comm, const PeriParticles *b, PetscInt N, PetscInt rstart, PetscMPIInt target[])
{
  PetscMPIInt size;
  CurveKey   *key, *split;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscMalloc2(b->n, &key, size, &split));
  PetscCall(CurveKeys(comm, b, rstart, key));
  PetscCall(CurveSplitters(comm, N, size, key, b->n, split));
  /* key[k]'s piece: the number of splitters at or below it (splitters are increasing) */
  for (PetscInt k = 0, q = 0; k < b->n; k++) {
    while (q + 1 < size && CurveKeyCompare(&split[q + 1], &key[k]) <= 0) q++;
    target[key[k].g - rstart] = (PetscMPIInt)q;
  }
  PetscCall(PetscFree2(key, split));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* METIS on rank 0: the blocks are gathered there (the whole body on one rank: small runs only),
 * and each rank gets back the parts of its block. */
static PetscErrorCode MetisPartitionGathered(MPI_Comm comm, const PeriParticles *b, PetscReal radius, PetscMPIInt target[])
{
  PeriParticles whole;
  PetscMPIInt   rank, size, n = (PetscMPIInt)b->n, *count = NULL, *displ = NULL, *part = NULL;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PeriParticlesGather(comm, b, &whole));
  if (rank == 0) {
    PetscInt *where;
    PetscCall(PetscMalloc3(size, &count, size + 1, &displ, whole.n, &part));
    PetscCall(PetscMalloc1(whole.n, &where));
    PetscCall(MetisPartition(&whole, radius, size, where));
    for (PetscInt i = 0; i < whole.n; i++) part[i] = (PetscMPIInt)where[i];
    PetscCall(PetscFree(where));
  }
  PetscCallMPI(MPI_Gather(&n, 1, MPI_INT, count, 1, MPI_INT, 0, comm));
  if (rank == 0) {
    displ[0] = 0;
    for (PetscMPIInt r = 0; r < size; r++) displ[r + 1] = displ[r] + count[r];
  }
  PetscCallMPI(MPI_Scatterv(part, count, displ, MPI_INT, target, n, MPI_INT, 0, comm));
  if (rank == 0) PetscCall(PetscFree3(count, displ, part));
  PetscCall(PeriParticlesDestroy(&whole));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriPartitionBlocks - partitions the body over the ranks of comm (-peri_partition) when each rank
  holds a block of it: b holds particles rstart..rstart+b->n-1 of the body, the blocks in rank
  order making it up (b's box, periodic axes and spacing are the body's). *target (allocated here)
  holds the rank each particle of b goes to; the new global order is by target rank, then by old
  index (PeriParticlesMigrate delivers them so). Collective.
@*/
PetscErrorCode PeriPartitionBlocks(MPI_Comm comm, const PeriParticles *b, PetscReal delta, PetscMPIInt **target)
{
  PetscMPIInt   rank, size;
  PartitionType type = PARTITION_GEOMETRIC;
  PetscReal     hmax = 0, radius;
  PetscInt      N, rstart = 0;

  PetscFunctionBeginUser;
  PetscCall(ReadType(comm, &type));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscCalloc1(b->n, target));
  if (size == 1) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCallMPI(MPI_Allreduce(&b->n, &N, 1, MPIU_INT, MPI_SUM, comm));
  PetscCallMPI(MPI_Exscan(&b->n, &rstart, 1, MPIU_INT, MPI_SUM, comm));
  if (rank == 0) rstart = 0; /* MPI leaves rank 0's result undefined */
  PetscCheck(N >= size, comm, PETSC_ERR_USER_INPUT, "%" PetscInt_FMT " particles cannot be shared by %d ranks", N, size);
  for (PetscInt i = 0; i < b->n; i++) hmax = PetscMax(hmax, b->spacing[i]);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &hmax, 1, MPIU_REAL, MPIU_MAX, comm));
  radius = PetscMin(delta, 1.5 * hmax);
  if (type == PARTITION_METIS)
    PetscCall(MetisPartitionGathered(comm, b, radius, *target));
  else if (type == PARTITION_PTSCOTCH)
    PetscCall(PTScotchPartition(comm, b, N, radius, hmax, *target));
  else
    PetscCall(GeometricPartition(comm, b, N, rstart, *target));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* From the target rank of each particle of this rank's block (which starts at global index
 * rstart) to the permutation and ranges of PeriPartition: ranks keep their particles in the old
 * order. The gather of the new numbers is the one step of size N, for the interface of every
 * rank holding all particles. */
static PetscErrorCode PermutationFromTargets(MPI_Comm comm, PetscInt N, PetscInt n, const PetscMPIInt target[], PetscInt perm[], PetscInt range[])
{
  PetscMPIInt rank, size, nm = (PetscMPIInt)n, *recv, *displ;
  PetscInt   *count, *before, *newof, *mine;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscCalloc2(size, &count, size, &before));
  for (PetscInt i = 0; i < n; i++) count[target[i]]++;
  /* before[t]: the particles of lower ranks going to t; range from the totals */
  PetscCallMPI(MPI_Exscan(count, before, (PetscMPIInt)size, MPIU_INT, MPI_SUM, comm));
  if (rank == 0) PetscCall(PetscArrayzero(before, size));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, count, (PetscMPIInt)size, MPIU_INT, MPI_SUM, comm));
  range[0] = 0;
  for (PetscMPIInt r = 0; r < size; r++) range[r + 1] = range[r] + count[r];
  PetscCall(PetscMalloc4(n, &mine, N, &newof, size, &recv, size, &displ));
  for (PetscInt i = 0; i < n; i++) mine[i] = range[target[i]] + before[target[i]]++;
  PetscCallMPI(MPI_Allgather(&nm, 1, MPI_INT, recv, 1, MPI_INT, comm));
  displ[0] = 0;
  for (PetscMPIInt r = 1; r < size; r++) displ[r] = displ[r - 1] + recv[r - 1];
  PetscCallMPI(MPI_Allgatherv(mine, nm, MPIU_INT, newof, recv, displ, MPIU_INT, comm));
  for (PetscInt i = 0; i < N; i++) perm[newof[i]] = i;
  PetscCall(PetscFree4(mine, newof, recv, displ));
  PetscCall(PetscFree2(count, before));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriPartition - partitions the particles over the ranks of comm (-peri_partition) when every rank
  holds the whole body p. perm[k] is the old index of new particle k; rank r owns new particles
  range[r]..range[r+1]-1. Collective.
@*/
PetscErrorCode PeriPartition(MPI_Comm comm, const PeriParticles *p, PetscReal delta, PetscInt **perm, PetscInt **range)
{
  PetscMPIInt   rank, size;
  PetscInt      rstart, rend;
  PeriParticles b;
  PetscMPIInt  *target;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscMalloc1(p->n, perm));
  PetscCall(PetscCalloc1(size + 1, range));
  /* this rank's block of p (for grid particles, x fastest: a slab along the last axis), as a view
   * into p's arrays: nothing is copied, nothing freed */
  rstart = (PetscInt)((PetscInt64)rank * p->n / size);
  rend   = (PetscInt)((PetscInt64)(rank + 1) * p->n / size);
  b      = *p;
  b.n    = rend - rstart;
  b.x += 3 * rstart;
  b.volume += rstart;
  b.spacing += rstart;
  b.source_line += rstart;
  b.global  = NULL;
  b.image   = NULL;
  b.crossed = NULL;
  b.groups  = NULL;
  b.ngroups = 0;
  PetscCall(PeriPartitionBlocks(comm, &b, delta, &target));
  PetscCall(PermutationFromTargets(comm, p->n, b.n, target, *perm, *range));
  PetscCall(PetscFree(target));
  PetscFunctionReturn(PETSC_SUCCESS);
}
