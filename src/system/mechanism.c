/* Mechanisms (issue 28, item 9): pieces of the body that their bonds join to the rest too weakly
 * to hold, such as two blocks joined by one bond, or by one particle about which one block can
 * turn. K is then singular; a direct solver says so, but CG with GAMG may converge to some answer.
 * The check decides from the bonds, not from a solver:
 *   1. Each rank grows rigid pieces over its owned particles and their bonds among themselves: a
 *      seed of mutually bonded particles whose rigid modes are independent (two in 2D, a triangle
 *      in 3D for central bonds; one particle where its own DOFs carry the modes), then every
 *      particle whose bonds into the piece hold it on their own (its summed block of those bonds
 *      is nonsingular, the test of holding.c). Such a piece moves only rigidly in any motion
 *      without energy. What joins no piece stays a point with its own DOFs.
 *   2. K restricted to piecewise rigid motions, K_red = V^T K V (V: the pieces' rigid modes and
 *      the points' DOFs), has exactly as many zero eigenvalues as K (K is the sum of positive
 *      semi-definite bond blocks), and needs only the bonds between pieces. Its blocks are summed
 *      per pair of pieces, gathered to rank 0 (a few pieces per rank on a sound body), with the
 *      held DOFs as springs to the ground.
 *   3. Rank 0 counts K_red's zero eigenvalues and those that are rigid motions of a whole
 *      connected part (the free rigid motions, which the static solve handles): more zeros than
 *      those is a mechanism, refused with the count and the moving piece. */
#include "perilin/private/system.h"
#include <petscblaslapack.h>
#include <petsc/private/hashmapij.h>

/* A seed's modes are independent when their scaled Gram matrix's eigenvalues are within this
 * ratio: a nearly degenerate seed (three nearly collinear particles) is left to others. */
#define PERI_MECH_SEED 1e-6
/* Zero eigenvalues of the Jacobi-scaled K_red: below this times the largest. */
#define PERI_MECH_ZERO 1e-10
/* K_red no larger than this many DOFs (a dense eigensolve on rank 0); beyond, the check is skipped
 * with a note: the body did not reduce to few rigid pieces. */
#define PERI_MECH_MAX_DOFS 1500

/* The owned-owned live bonds seen from both ends. A bond is stored once, in its row (the smaller
 * global index), so a particle's own row gives one end; the other end is indexed here: for
 * particle p, rnbr[roff[p] .. roff[p+1]-1] are the rows whose bond reaches p. 4 bytes a bond (a
 * full two-ended copy with bond numbers and twins took 40: 256 MB on a 641,601-particle plate). */
typedef struct {
  PetscInt *roff, *rnbr;
} Adjacency;

/* Whether bond k of owned particle i joins two owned, real particles and is live. */
static PetscBool Eligible(PeriSystem sys, PetscInt i, PetscInt k)
{
  const PeriBonds     *b  = &sys->disc.bonds;
  const PeriParticles *pt = &sys->disc.particles;

  return (PetscBool)(b->live[k] && b->j[k] != i && b->j[k] < sys->disc.nowned && !PeriParticleIsFictitious(pt, i) && !PeriParticleIsFictitious(pt, b->j[k]));
}

static PetscErrorCode AdjacencyCreate(PeriSystem sys, Adjacency *a)
{
  const PeriBonds *b  = &sys->disc.bonds;
  const PetscInt   no = sys->disc.nowned;
  PetscInt        *fill;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(no + 1, &a->roff));
  for (PetscInt i = 0; i < no; i++)
    for (PetscInt k = b->offset[i]; k < b->offset[i + 1]; k++)
      if (Eligible(sys, i, k)) a->roff[b->j[k] + 1]++;
  for (PetscInt i = 0; i < no; i++) a->roff[i + 1] += a->roff[i];
  PetscCall(PetscMalloc1(a->roff[no], &a->rnbr));
  PetscCall(PetscMalloc1(no, &fill));
  PetscCall(PetscArraycpy(fill, a->roff, no));
  for (PetscInt i = 0; i < no; i++)
    for (PetscInt k = b->offset[i]; k < b->offset[i + 1]; k++)
      if (Eligible(sys, i, k)) a->rnbr[fill[b->j[k]]++] = i;
  PetscCall(PetscFree(fill));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode AdjacencyDestroy(Adjacency *a)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(a->rnbr));
  PetscCall(PetscFree(a->roff));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A walk over the neighbours of p: its own row's eligible bonds, then the rows that reach it. */
typedef struct {
  PetscInt p, k, s;
} Walk;

static Walk WalkStart(PeriSystem sys, const Adjacency *a, PetscInt p)
{
  Walk w = {p, sys->disc.bonds.offset[p], a->roff[p]};
  return w;
}

/* The next neighbour q of the walk's particle; *row is the row that stores their bond. */
static PetscBool WalkNext(PeriSystem sys, const Adjacency *a, Walk *w, PetscInt *q, PetscInt *row)
{
  const PeriBonds *b = &sys->disc.bonds;

  for (; w->k < b->offset[w->p + 1]; w->k++)
    if (Eligible(sys, w->p, w->k)) {
      *q   = b->j[w->k++];
      *row = w->p;
      return PETSC_TRUE;
    }
  if (w->s == a->roff[w->p + 1]) return PETSC_FALSE;
  *q = *row = a->rnbr[w->s++];
  return PETSC_TRUE;
}

/* The block of the bond between p and q at q's end (bs x bs), added to A; row is the bond's row. */
static PetscErrorCode AddBlockAt(PeriSystem sys, PetscInt p, PetscInt q, PetscInt row, PetscReal A[])
{
  const PeriBonds *b  = &sys->disc.bonds;
  const PetscInt   bs = sys->model->dofs, nb = 2 * bs, e = (q == row) ? 0 : 1, other = (q == row) ? p : q;
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF];
  PeriBondGeometry g;
  PetscInt         k = b->offset[row];

  PetscFunctionBeginUser;
  while (b->j[k] != other) k++; /* one bond per pair (periodic bodies are not checked) */
  PetscCall(PeriBondStiffness(sys, row, k, 1, &g, Ke));
  for (PetscInt r = 0; r < bs; r++)
    for (PetscInt c = 0; c < bs; c++) A[r * bs + c] += Ke[(e * bs + r) * nb + e * bs + c];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The rigid modes at local particle p, R[c * nm + m] (the DOFs of p by the modes), with the box's
 * centre as origin; inactive components are 0, as in the modes of the solver. Returns nm. */
static PetscInt ModesAt(PeriSystem sys, PetscInt p, PetscReal R[])
{
  const PeriParticles *pt = &sys->disc.particles;
  PeriModel            m  = sys->model;
  PetscReal            X[3], vals[PERI_MAX_MODES][PERI_MAX_DOF];
  PetscInt             nm;

  for (PetscInt d = 0; d < 3; d++) X[d] = pt->x[3 * p + d] - 0.5 * (pt->lower[d] + pt->upper[d]);
  nm = m->ops.rigid_modes(m, X, vals);
  for (PetscInt c = 0; c < m->dofs; c++)
    for (PetscInt k = 0; k < nm; k++) R[c * nm + k] = m->inactive[c] ? 0 : vals[k][c];
  return nm;
}

/* Whether the modes at the particles set[0..n-1] are independent: the smallest eigenvalue of their
 * Gram matrix, scaled to a unit diagonal, at least PERI_MECH_SEED times the largest. An LDL^T
 * pivot test is not enough: two particles close together in 3D (modes of rank 5, not 6) gave a
 * last pivot of rounding noise above the threshold, and the seed's spurious spin about its axis
 * then counted as a mechanism on 3 and 4 ranks (tests/mesh: bar_tet). */
static PetscBool ModesIndependent(PeriSystem sys, PetscInt n, const PetscInt set[])
{
  PetscReal    G[PERI_MAX_MODES * PERI_MAX_MODES] = {0}, R[PERI_MAX_DOF * PERI_MAX_MODES], w[PERI_MAX_MODES], work[34 * PERI_MAX_MODES], sc[PERI_MAX_MODES];
  PetscInt     nm                                 = 0;
  PetscBLASInt bn, lwork = 34 * PERI_MAX_MODES, info;

  for (PetscInt s = 0; s < n; s++) {
    nm = ModesAt(sys, set[s], R);
    for (PetscInt c = 0; c < sys->model->dofs; c++)
      for (PetscInt k = 0; k < nm; k++)
        for (PetscInt l = 0; l < nm; l++) G[k * nm + l] += R[c * nm + k] * R[c * nm + l];
  }
  for (PetscInt k = 0; k < nm; k++) {
    if (!(G[k * nm + k] > 0)) return PETSC_FALSE;
    sc[k] = 1 / PetscSqrtReal(G[k * nm + k]);
  }
  for (PetscInt k = 0; k < nm; k++)
    for (PetscInt l = 0; l < nm; l++) G[k * nm + l] *= sc[k] * sc[l];
  bn = (PetscBLASInt)nm;
  LAPACKsyev_("N", "U", &bn, G, &bn, w, work, &lwork, &info);
  return (PetscBool)(!info && nm > 0 && w[0] >= PERI_MECH_SEED * w[nm - 1]);
}

/* Whether local particles p and q share a bond of the adjacency. */
static PetscBool Bonded(PeriSystem sys, const Adjacency *a, PetscInt p, PetscInt q)
{
  Walk     w = WalkStart(sys, a, p);
  PetscInt n, row;

  while (WalkNext(sys, a, &w, &n, &row))
    if (n == q) return PETSC_TRUE;
  return PETSC_FALSE;
}

/* A seed of a rigid piece at particle p: p and unassigned neighbours bonded to every member, until
 * the modes at the members are independent (a pair in 2D, a triangle in 3D for central bonds; p
 * alone where its DOFs carry every mode). Returns the members (0: no seed here). */
static PetscInt Seed(PeriSystem sys, const Adjacency *a, const PetscInt piece[], PetscInt p, PetscInt seed[])
{
  seed[0] = p;
  if (ModesIndependent(sys, 1, seed)) return 1;
  for (PetscInt n = 1; n <= sys->model->dim; n++) {
    PetscInt next = -1, q, row;
    Walk     w    = WalkStart(sys, a, p);
    while (WalkNext(sys, a, &w, &q, &row)) {
      PetscBool ok = (PetscBool)(piece[q] < 0);
      for (PetscInt t = 0; t < n && ok; t++) ok = (PetscBool)(seed[t] != q && Bonded(sys, a, seed[t], q));
      if (!ok) continue;
      seed[n] = q;
      if (ModesIndependent(sys, n + 1, seed)) return n + 1;
      if (next < 0) next = q; /* a member that is not enough alone: look for one more */
    }
    if (next < 0) return 0;
    seed[n] = next;
  }
  return 0;
}

typedef struct {
  PetscInt  *piece, *tag, *queue; /* per owned particle: its piece (-1: none); the piece acc is for */
  PetscReal *acc;                 /* per owned particle: the summed blocks of its bonds into the piece */
  PetscBool  active[PERI_MAX_DOF];
} Growth;

/* Grows piece b from its seed: a particle joins when its bonds into the piece hold it. */
static PetscErrorCode Grow(PeriSystem sys, const Adjacency *a, Growth *w, PetscInt b, PetscInt n, const PetscInt seed[])
{
  const PetscInt bs   = sys->model->dofs;
  PetscInt       head = 0, tail = 0;

  PetscFunctionBeginUser;
  for (PetscInt t = 0; t < n; t++) {
    w->piece[seed[t]] = b;
    w->queue[tail++]  = seed[t];
  }
  while (head < tail) {
    PetscInt p  = w->queue[head++], q, row;
    Walk     it = WalkStart(sys, a, p);
    while (WalkNext(sys, a, &it, &q, &row)) {
      if (w->piece[q] >= 0) continue;
      if (w->tag[q] != b) {
        PetscCall(PetscArrayzero(&w->acc[q * bs * bs], bs * bs));
        w->tag[q] = b;
      }
      PetscCall(AddBlockAt(sys, p, q, row, &w->acc[q * bs * bs]));
      if (PeriBlockHolds(bs, &w->acc[q * bs * bs], w->active)) {
        w->piece[q]      = b;
        w->queue[tail++] = q;
      }
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The rigid pieces of this rank's owned particles: piece[p] (-1: a point); *npieces. */
static PetscErrorCode Pieces(PeriSystem sys, const Adjacency *a, PetscInt piece[], PetscInt *npieces)
{
  const PetscInt no = sys->disc.nowned, bs = sys->model->dofs;
  Growth         w;
  PetscInt       seed[4], n;

  PetscFunctionBeginUser;
  w.piece = piece;
  for (PetscInt c = 0; c < bs; c++) w.active[c] = (PetscBool)!sys->model->inactive[c];
  PetscCall(PetscMalloc3(no, &w.tag, no, &w.queue, no * bs * bs, &w.acc));
  for (PetscInt p = 0; p < no; p++) piece[p] = w.tag[p] = -1;
  *npieces = 0;
  for (PetscInt p = 0; p < no; p++) {
    if (piece[p] >= 0 || PeriParticleIsFictitious(&sys->disc.particles, p)) continue;
    if (!(n = Seed(sys, a, piece, p, seed))) continue;
    PetscCall(Grow(sys, a, &w, (*npieces)++, n, seed));
  }
  PetscCall(PetscFree3(w.tag, w.queue, w.acc));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The reduced problem: each rank's groups (its pieces, then its points) and the blocks of K_red
 * between them, keyed by pairs of global group numbers (a <= b: the a rows, the b columns). */
typedef struct {
  PetscInt    ng, gstart, nm;     /* this rank's groups, the first one's global number, the modes */
  PetscInt   *G;                  /* per local particle (owned and ghosts): 2 x its global group + 1 in a piece (-1: none) */
  PetscInt   *gdofs, *gfirst;     /* per group: DOFs (nm or bs); its first particle (by position, local) */
  PetscReal  *gx;                 /* per group: the first particle's position */
  PetscInt   *gcount, *gpiece;    /* per group: particles; 1 for a piece, 0 for a point */
  PetscHMapIJ map;                /* (a, b) -> the block's index in blk */
  PetscInt    nblk, capblk, *key; /* 2 per block */
  PetscReal  *blk;                /* 36 per block, leading dimension 6 */
} Reduced;

/* The block of the pair (a, b), created as zero. */
static PetscErrorCode Block(Reduced *r, PetscInt a, PetscInt b, PetscReal **B)
{
  PetscHashIJKey k = {a, b};
  PetscInt       v;

  PetscFunctionBeginUser;
  PetscCall(PetscHMapIJGet(r->map, k, &v));
  if (v < 0) {
    if (r->nblk == r->capblk) {
      r->capblk = PetscMax(64, 2 * r->capblk);
      PetscCall(PetscRealloc(sizeof(PetscReal) * 36 * r->capblk, &r->blk));
      PetscCall(PetscRealloc(sizeof(PetscInt) * 2 * r->capblk, &r->key));
    }
    v = r->nblk++;
    PetscCall(PetscArrayzero(&r->blk[36 * v], 36));
    r->key[2 * v]     = a;
    r->key[2 * v + 1] = b;
    PetscCall(PetscHMapIJSet(r->map, k, v));
  }
  *B = &r->blk[36 * v];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* V at local particle p (bs x d, row-major): the modes in a piece, I for a point. Returns d. */
static PetscInt BasisAt(PeriSystem sys, PetscBool piece, PetscInt p, PetscReal V[])
{
  const PetscInt bs = sys->model->dofs;

  if (piece) return ModesAt(sys, p, V);
  for (PetscInt c = 0; c < bs * bs; c++) V[c] = (c / bs == c % bs) ? 1 : 0;
  return bs;
}

/* Numbers the groups: pieces first, then a point per owned particle in none; G of the ghosts too. */
static PetscErrorCode Groups(PeriSystem sys, Reduced *r, const PetscInt piece[], PetscInt npieces)
{
  const PeriParticles *pt = &sys->disc.particles;
  const PetscInt       no = sys->disc.nowned;
  PetscInt             np = 0;

  PetscFunctionBeginUser;
  for (PetscInt p = 0; p < no; p++) np += piece[p] < 0 && !PeriParticleIsFictitious(pt, p);
  r->ng = npieces + np;
  PetscCallMPI(MPI_Exscan(&r->ng, &r->gstart, 1, MPIU_INT, MPI_SUM, sys->comm));
  if (sys->rank == 0) r->gstart = 0;
  PetscCall(PetscMalloc6(pt->n, &r->G, r->ng, &r->gdofs, r->ng, &r->gfirst, 3 * r->ng, &r->gx, r->ng, &r->gcount, r->ng, &r->gpiece));
  for (PetscInt l = 0; l < pt->n; l++) r->G[l] = -1;
  for (PetscInt g = 0; g < r->ng; g++) {
    r->gdofs[g]  = g < npieces ? r->nm : sys->model->dofs;
    r->gpiece[g] = g < npieces;
    r->gfirst[g] = -1;
    r->gcount[g] = 0;
  }
  np = npieces;
  for (PetscInt p = 0; p < no; p++) {
    PetscInt g;
    if (PeriParticleIsFictitious(pt, p)) continue;
    g       = piece[p] >= 0 ? piece[p] : np++;
    r->G[p] = 2 * (r->gstart + g) + (piece[p] >= 0);
    r->gcount[g]++;
    if (r->gfirst[g] < 0 || PeriPointBefore(&pt->x[3 * p], &pt->x[3 * r->gfirst[g]])) r->gfirst[g] = p;
  }
  for (PetscInt g = 0; g < r->ng; g++)
    for (PetscInt d = 0; d < 3; d++) r->gx[3 * g + d] = pt->x[3 * r->gfirst[g] + d];
  PetscCall(PeriDiscOwnersToGhosts(&sys->disc, MPIU_INT, 1, r->G));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* B += V_e^T Ke_ef V_f: the part of a bond's block between its ends e and f (0: i, 1: j). */
static void AddPart(PetscInt bs, const PetscReal Ke[], PetscReal V[2][PERI_MAX_DOF * PERI_MAX_MODES], const PetscInt d[], PetscInt e, PetscInt f, PetscReal B[])
{
  for (PetscInt x = 0; x < d[e]; x++)
    for (PetscInt y = 0; y < d[f]; y++) {
      PetscReal v = 0;
      for (PetscInt u = 0; u < bs; u++)
        for (PetscInt w = 0; w < bs; w++) v += V[e][u * d[e] + x] * Ke[(e * bs + u) * 2 * bs + f * bs + w] * V[f][w * d[f] + y];
      B[x * 6 + y] += v;
    }
}

/* Adds bond k of owned particle i to K_red: V^T Ke V, into the blocks of the two groups (one
 * block when both ends are in one group, which a rotation-invariant model skips: zero). */
static PetscErrorCode AddBond(PeriSystem sys, Reduced *r, PetscInt i, PetscInt k, PetscReal *scale)
{
  const PetscInt   bs = sys->model->dofs, nb = 2 * bs, p[2] = {i, sys->disc.bonds.j[k]};
  const PetscInt   g[2] = {r->G[p[0]] >> 1, r->G[p[1]] >> 1};
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF], V[2][PERI_MAX_DOF * PERI_MAX_MODES], *B;
  PetscInt         d[2];
  PeriBondGeometry geo;

  PetscFunctionBeginUser;
  PetscCall(PeriBondStiffness(sys, i, k, 1, &geo, Ke));
  for (PetscInt c = 0; c < nb; c++) *scale = PetscMax(*scale, PetscAbsReal(Ke[c * nb + c]));
  for (PetscInt e = 0; e < 2; e++) d[e] = BasisAt(sys, (PetscBool)(r->G[p[e]] & 1), p[e], V[e]);
  if (g[0] == g[1]) {
    PetscCall(Block(r, g[0], g[0], &B));
    for (PetscInt e = 0; e < 2; e++)
      for (PetscInt f = 0; f < 2; f++) AddPart(bs, Ke, V, d, e, f, B);
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  for (PetscInt e = 0; e < 2; e++) {
    PetscCall(Block(r, g[e], g[e], &B));
    AddPart(bs, Ke, V, d, e, e, B);
  }
  PetscCall(Block(r, PetscMin(g[0], g[1]), PetscMax(g[0], g[1]), &B));
  if (g[0] < g[1])
    AddPart(bs, Ke, V, d, 0, 1, B);
  else
    AddPart(bs, Ke, V, d, 1, 0, B);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* K_red's blocks on this rank: every live bond of an owned particle between two groups (and
 * inside one for models whose rotations store energy), then the held DOFs as springs of the
 * bonds' largest stiffness to the ground. Collective. */
static PetscErrorCode Assemble(PeriSystem sys, Reduced *r, PetscBool invariant)
{
  const PeriBonds *b     = &sys->disc.bonds;
  const PetscInt   bs    = sys->model->dofs;
  PetscReal        scale = 0, V[PERI_MAX_DOF * PERI_MAX_MODES], *B;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->disc.nowned; i++)
    for (PetscInt k = b->offset[i]; k < b->offset[i + 1]; k++) {
      if (!b->live[k] || b->j[k] == i || r->G[i] < 0 || r->G[b->j[k]] < 0) continue;
      if (invariant && r->G[i] == r->G[b->j[k]] && (r->G[i] & 1)) continue; /* a rigid motion of the piece: no energy */
      PetscCall(AddBond(sys, r, i, k, &scale));
    }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &scale, 1, MPIU_REAL, MPI_MAX, sys->comm));
  if (!(scale > 0)) scale = 1;
  for (PetscInt s = 0; s < sys->conditions.nconstrained; s++) {
    PetscInt p = sys->conditions.constrained[s] / bs - sys->disc.rstart, c = sys->conditions.constrained[s] % bs, d;
    if (r->G[p] < 0) continue;
    d = BasisAt(sys, (PetscBool)(r->G[p] & 1), p, V);
    PetscCall(Block(r, r->G[p] >> 1, r->G[p] >> 1, &B));
    for (PetscInt x = 0; x < d; x++)
      for (PetscInt y = 0; y < d; y++) B[x * 6 + y] += scale * V[c * d + x] * V[c * d + y];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Everything rank 0 needs, gathered: per group its DOFs, particles, first position; the blocks. */
typedef struct {
  PetscInt   N, nblk, ndof;                         /* groups, blocks, DOFs of K_red */
  PetscInt  *gdofs, *gcount, *gpiece, *key, *start; /* start: each group's first DOF */
  PetscReal *gx, *blk;
} Gathered;

/* Rank 0 gets every rank's n x per values of type t (bytes each), in rank order; *total: the rows. */
static PetscErrorCode GatherRows(MPI_Comm comm, PetscInt n, const void *mine, PetscInt per, MPI_Datatype t, size_t bytes, void **all, PetscInt *total)
{
  PetscMPIInt size, rank, *cnt, *dsp, m = (PetscMPIInt)(n * per);

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(PetscMalloc2(size, &cnt, size + 1, &dsp));
  PetscCallMPI(MPI_Gather(&m, 1, MPI_INT, cnt, 1, MPI_INT, 0, comm));
  dsp[0] = 0;
  if (!rank)
    for (PetscMPIInt q = 0; q < size; q++) dsp[q + 1] = dsp[q] + cnt[q];
  if (total) *total = rank ? 0 : dsp[size] / per;
  PetscCall(PetscMalloc(bytes * (rank ? 0 : dsp[size]), all));
  PetscCallMPI(MPI_Gatherv(mine, m, t, *all, cnt, dsp, t, 0, comm));
  PetscCall(PetscFree2(cnt, dsp));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Gather(PeriSystem sys, const Reduced *r, Gathered *g)
{
  PetscFunctionBeginUser;
  PetscCall(GatherRows(sys->comm, r->ng, r->gdofs, 1, MPIU_INT, sizeof(PetscInt), (void **)&g->gdofs, &g->N));
  PetscCall(GatherRows(sys->comm, r->ng, r->gcount, 1, MPIU_INT, sizeof(PetscInt), (void **)&g->gcount, NULL));
  PetscCall(GatherRows(sys->comm, r->ng, r->gpiece, 1, MPIU_INT, sizeof(PetscInt), (void **)&g->gpiece, NULL));
  PetscCall(GatherRows(sys->comm, r->ng, r->gx, 3, MPIU_REAL, sizeof(PetscReal), (void **)&g->gx, NULL));
  PetscCall(GatherRows(sys->comm, r->nblk, r->key, 2, MPIU_INT, sizeof(PetscInt), (void **)&g->key, &g->nblk));
  PetscCall(GatherRows(sys->comm, r->nblk, r->blk, 36, MPIU_REAL, sizeof(PetscReal), (void **)&g->blk, NULL));
  PetscCall(PetscMalloc1(g->N + 1, &g->start));
  g->start[0] = 0;
  for (PetscInt a = 0; a < g->N; a++) g->start[a + 1] = g->start[a] + g->gdofs[a];
  g->ndof = g->start[g->N];
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode GatheredDestroy(Gathered *g)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(g->gdofs));
  PetscCall(PetscFree(g->gcount));
  PetscCall(PetscFree(g->gpiece));
  PetscCall(PetscFree(g->gx));
  PetscCall(PetscFree(g->key));
  PetscCall(PetscFree(g->blk));
  PetscCall(PetscFree(g->start));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The eigenvalues w (ascending) and, in A, the eigenvectors (columns) of the symmetric n x n A. */
static PetscErrorCode Eigen(PetscInt n, PetscReal A[], PetscReal w[])
{
  PetscBLASInt bn, lwork, info;
  PetscReal   *work;

  PetscFunctionBeginUser;
  if (!n) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscBLASIntCast(n, &bn));
  PetscCall(PetscBLASIntCast(34 * n, &lwork));
  PetscCall(PetscMalloc1(lwork, &work));
  PetscCallBLAS("LAPACKsyev", LAPACKsyev_("V", "U", &bn, A, &bn, w, work, &lwork, &info));
  PetscCall(PetscFree(work));
  PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_LIB, "LAPACK syev failed (info %d) on the reduced stiffness", (int)info);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscInt Find(PetscInt parent[], PetscInt a)
{
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

/* W: the rigid motions of each connected part of K_red's groups, Jacobi-scaled (sq: sqrt of K's
 * diagonal), orthonormalized (Gram-Schmidt; a dependent one dropped) into the columns of Q. */
static PetscErrorCode WholeMotions(PeriSystem sys, const Gathered *g, const PetscReal sq[], PetscReal **Q, PetscInt *nq)
{
  const PetscInt n = g->ndof, bs = sys->model->dofs;
  PetscInt      *parent, ncomp = 0, *comp, nm = 0;
  PetscReal      vals[PERI_MAX_MODES][PERI_MAX_DOF], X[3], *q;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(g->N, &parent, g->N, &comp));
  for (PetscInt a = 0; a < g->N; a++) parent[a] = a;
  for (PetscInt e = 0; e < g->nblk; e++) parent[Find(parent, g->key[2 * e])] = Find(parent, g->key[2 * e + 1]);
  for (PetscInt a = 0; a < g->N; a++) comp[a] = -1;
  for (PetscInt a = 0; a < g->N; a++)
    if (comp[Find(parent, a)] < 0) comp[Find(parent, a)] = ncomp++;
  X[0] = X[1] = X[2] = 0;
  nm                 = sys->model->ops.rigid_modes(sys->model, X, vals);
  PetscCall(PetscCalloc1(n * ncomp * nm, Q));
  *nq = 0;
  for (PetscInt c = 0; c < ncomp; c++)
    for (PetscInt m = 0; m < nm; m++) {
      PetscReal before = 0, after = 0;
      q = &(*Q)[n * *nq];
      for (PetscInt a = 0; a < g->N; a++) {
        if (comp[Find(parent, a)] != c) continue;
        if (g->gpiece[a])
          q[g->start[a] + m] = 1;
        else {
          PetscReal      R[PERI_MAX_DOF * PERI_MAX_MODES];
          PeriParticles *pt = &sys->disc.particles;
          for (PetscInt d = 0; d < 3; d++) X[d] = g->gx[3 * a + d] - 0.5 * (pt->lower[d] + pt->upper[d]);
          sys->model->ops.rigid_modes(sys->model, X, vals);
          for (PetscInt u = 0; u < bs; u++) R[u] = sys->model->inactive[u] ? 0 : vals[m][u];
          for (PetscInt u = 0; u < g->gdofs[a]; u++) q[g->start[a] + u] = R[u];
        }
      }
      for (PetscInt k = 0; k < n; k++) {
        q[k] *= sq[k];
        before += q[k] * q[k];
      }
      for (PetscInt l = 0; l < *nq; l++) {
        PetscReal dot = 0;
        for (PetscInt k = 0; k < n; k++) dot += q[k] * (*Q)[n * l + k];
        for (PetscInt k = 0; k < n; k++) q[k] -= dot * (*Q)[n * l + k];
      }
      for (PetscInt k = 0; k < n; k++) after += q[k] * q[k];
      if (!(after > 1e-16 * before)) continue;
      for (PetscInt k = 0; k < n; k++) q[k] /= PetscSqrtReal(after);
      (*nq)++;
    }
  PetscCall(PetscFree2(parent, comp));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rank 0: the number of motions of K_red without energy beyond the rigid motions of whole
 * connected parts (*count), and the group that moves most in them (*moving). */
static PetscErrorCode Decide(PeriSystem sys, const Gathered *g, PetscInt *count, PetscInt *moving)
{
  const PetscInt n = g->ndof;
  PetscReal     *K, *w, *sq, *Q, *M, *wm, *move, tol, best = -1;
  PetscInt       n0 = 0, n1 = 0, nq = 0;

  PetscFunctionBeginUser;
  *count  = 0;
  *moving = -1;
  if (!n) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscCalloc3(n * n, &K, n, &w, n, &sq));
  for (PetscInt e = 0; e < g->nblk; e++) {
    PetscInt a = g->key[2 * e], b = g->key[2 * e + 1];
    for (PetscInt x = 0; x < g->gdofs[a]; x++)
      for (PetscInt y = 0; y < g->gdofs[b]; y++) {
        PetscReal v = g->blk[36 * e + 6 * x + y];
        if (a == b)
          K[(g->start[a] + x) * n + g->start[b] + y] += v;
        else {
          K[(g->start[a] + x) * n + g->start[b] + y] += v;
          K[(g->start[b] + y) * n + g->start[a] + x] += v;
        }
      }
  }
  for (PetscInt k = 0; k < n; k++) sq[k] = K[k * n + k] > 0 ? PetscSqrtReal(K[k * n + k]) : 1;
  for (PetscInt k = 0; k < n; k++)
    for (PetscInt l = 0; l < n; l++) K[k * n + l] /= sq[k] * sq[l];
  PetscCall(WholeMotions(sys, g, sq, &Q, &nq));
  /* M = Q^T K Q before K is overwritten by its eigenvectors */
  PetscCall(PetscCalloc3(nq * nq, &M, nq, &wm, g->N, &move));
  for (PetscInt b = 0; b < nq; b++)
    for (PetscInt k = 0; k < n; k++) {
      PetscReal kq = 0;
      for (PetscInt l = 0; l < n; l++) kq += K[k * n + l] * Q[b * n + l];
      for (PetscInt a = 0; a < nq; a++) M[a * nq + b] += Q[a * n + k] * kq;
    }
  PetscCall(Eigen(n, K, w));
  tol = PERI_MECH_ZERO * PetscMax(w[n - 1], 1);
  for (PetscInt k = 0; k < n; k++) n0 += PetscAbsReal(w[k]) <= tol;
  PetscCall(Eigen(nq, M, wm));
  for (PetscInt k = 0; k < nq; k++) n1 += PetscAbsReal(wm[k]) <= tol;
  *count = n0 - n1;
  if (*count > 0) {
    /* the null vectors' parts outside the whole motions: how much each group moves in them */
    for (PetscInt v = 0; v < n0; v++) {
      PetscReal *x = &K[n * v];
      for (PetscInt a = 0; a < nq; a++) {
        PetscReal dot = 0;
        for (PetscInt k = 0; k < n; k++) dot += x[k] * Q[a * n + k];
        for (PetscInt k = 0; k < n; k++) x[k] -= dot * Q[a * n + k];
      }
      for (PetscInt a = 0; a < g->N; a++)
        for (PetscInt u = g->start[a]; u < g->start[a + 1]; u++) move[a] += x[u] * x[u];
    }
    for (PetscInt a = 0; a < g->N; a++)
      if (move[a] > best) {
        best    = move[a];
        *moving = a;
      }
  }
  PetscCall(PetscFree3(M, wm, move));
  PetscCall(PetscFree(Q));
  PetscCall(PetscFree3(K, w, sq));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Refuses the scene: the count, and the moving group's size, first particle and region (from its
 * owner), the same message on every rank. Collective. */
static PetscErrorCode Refuse(PeriSystem sys, const Reduced *r, PetscInt count, PetscInt moving, PetscInt size, const PetscReal x[])
{
  char        region[128] = "";
  PetscMPIInt owner       = -1, mine;
  const char *plural      = count == 1 ? "" : "s";

  PetscFunctionBeginUser;
  mine = (moving >= r->gstart && moving < r->gstart + r->ng) ? sys->rank : -1;
  PetscCallMPI(MPI_Allreduce(&mine, &owner, 1, MPI_INT, MPI_MAX, sys->comm));
  if (owner == sys->rank) PetscCall(PetscStrncpy(region, PeriRegionOf(sys, r->gfirst[moving - r->gstart]), sizeof(region)));
  PetscCallMPI(MPI_Bcast(region, sizeof(region), MPI_CHAR, owner, sys->comm));
  SETERRQ(sys->comm, PETSC_ERR_USER_INPUT,
          "%s: the body is a mechanism: %" PetscInt_FMT " motion%s without energy besides the free rigid motions: a piece of %" PetscInt_FMT " particle%s (the first at (%g, %g, %g)%s%s%s) is joined to the rest by bonds that cannot hold it (%s), so K is singular: a direct solver stops, an iterative one may return a meaningless answer. Join the piece by more material (a wider connection, a larger horizon.m or horizon.delta) or hold it by a bc",
          sys->scene->file, count, plural, size, size == 1 ? "" : "s", (double)x[0], (double)x[1], (double)x[2], region[0] ? " in region '" : "", region, region[0] ? "'" : "",
          sys->model->central_force ? (sys->model->dim == 2 ? "central bonds that all pass through one point, or all parallel, let it turn or slide" : "central bonds that all meet one line let it turn about it") : "its bonds to the rest leave it a rigid motion");
}

/*@C
  PeriCheckMechanisms - refuses a scene whose body is a mechanism: a piece joined to the rest by
  bonds that cannot hold it (two blocks joined by one bond, or by one particle about which one can
  turn), which leaves K singular beyond the free rigid motions that the static solve handles.
  Decided from the bonds (rigid pieces grown on each rank, K restricted to their rigid motions
  gathered to rank 0), not by a solver. Skipped, with a note, when the body does not reduce to
  few rigid pieces (more than PERI_MECH_MAX_DOFS reduced DOFs); not run for state-based models,
  fictitious layers and periodic bodies. After PeriCheckHeld. Collective.
@*/
PetscErrorCode PeriCheckMechanisms(PeriSystem sys)
{
  const PeriModelType *desc;
  Adjacency            adj;
  Reduced              r = {0};
  Gathered             g = {0};
  PetscInt            *piece, npieces = 0, ndof = 0, res[2] = {0, -1};
  PetscReal            X[3] = {0, 0, 0}, vals[PERI_MAX_MODES][PERI_MAX_DOF], at[4] = {0, 0, 0, 0};

  PetscFunctionBeginUser;
  if (sys->model->ops.family_stiffness || sys->disc.particles.nfictitious || sys->conditions.layers.T) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt d = 0; d < 3; d++)
    if (sys->disc.particles.periodic[d]) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriModelTypeGet(sys->model->type, &desc));
  r.nm = sys->model->ops.rigid_modes(sys->model, X, vals);
  PetscCall(AdjacencyCreate(sys, &adj));
  PetscCall(PetscMalloc1(sys->disc.nowned, &piece));
  PetscCall(Pieces(sys, &adj, piece, &npieces));
  PetscCall(AdjacencyDestroy(&adj));
  PetscCall(Groups(sys, &r, piece, npieces));
  PetscCall(PetscFree(piece));
  for (PetscInt a = 0; a < r.ng; a++) ndof += r.gdofs[a];
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &ndof, 1, MPIU_INT, MPI_SUM, sys->comm));
  if (ndof > PERI_MECH_MAX_DOFS) {
    PetscCall(PetscPrintf(sys->comm, "perilin: note: the check for mechanisms was skipped: the body reduces to %" PetscInt_FMT " rigid DOFs (at most %d are checked)\n", ndof, PERI_MECH_MAX_DOFS));
  } else {
    PetscCall(PetscHMapIJCreate(&r.map));
    PetscCall(Assemble(sys, &r, desc->rotation_invariant));
    PetscCall(PetscHMapIJDestroy(&r.map));
    PetscCall(Gather(sys, &r, &g));
    if (!sys->rank) {
      PetscCall(Decide(sys, &g, &res[0], &res[1]));
      if (res[0] > 0) {
        at[0] = (PetscReal)g.gcount[res[1]];
        for (PetscInt d = 0; d < 3; d++) at[1 + d] = g.gx[3 * res[1] + d];
      }
    }
    PetscCall(GatheredDestroy(&g));
    PetscCallMPI(MPI_Bcast(res, 2, MPIU_INT, 0, sys->comm));
    PetscCallMPI(MPI_Bcast(at, 4, MPIU_REAL, 0, sys->comm));
  }
  PetscCall(PetscFree(r.blk));
  PetscCall(PetscFree(r.key));
  if (res[0] > 0) {
    PetscErrorCode ierr = Refuse(sys, &r, res[0], res[1], (PetscInt)at[0], &at[1]);
    PetscCall(PetscFree6(r.G, r.gdofs, r.gfirst, r.gx, r.gcount, r.gpiece));
    PetscCall(ierr);
  }
  PetscCall(PetscFree6(r.G, r.gdofs, r.gfirst, r.gx, r.gcount, r.gpiece));
  PetscFunctionReturn(PETSC_SUCCESS);
}
