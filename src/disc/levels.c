/* Neighbour search for per-particle horizons (horizon.spacing: own), O(N log N) at any ratio of
 * the largest horizon to the smallest.
 *
 * A pair is bonded within the larger of its two horizons. One cell list sized by the largest reach
 * puts a whole coarse horizon's worth of fine particles in every cell; sized by the smallest, a
 * coarse particle visits (ratio)^dim cells. So the particles are sorted into levels by their reach
 * rho (their horizon plus what the partial volume adds): level L holds rho in [2^L, 2^(L+1)) times
 * the smallest, and its cells are half of C_L = 2^(L+1) rho_min wide. A particle of level L finds
 *  - the particles of levels <= L in the cumulative cells of its own level: their pair's radius is
 *    its own reach, below C_L, so two cells either way hold them;
 *  - the particles of each coarser level L' in that level's own cells: the pair's radius is theirs,
 *    below C_L'.
 * Each level's cells are sparse: the occupied ones sorted by key and found by bisection, so memory
 * stays O(N levels) however large the box is in fine cells. */
#include "perilin/private/disc.h"

#define LEVELS_REACH 2 /* cells of C_L / 2: two cells either way cover C_L */
#define LEVELS_MAX   40

typedef struct {
  PetscReal  size, lower[3];
  PetscInt   ncell[3];
  PetscInt   nkeys;
  PetscReal *key;   /* sorted keys of the occupied cells (integers held exactly in a double) */
  PetscInt  *start; /* nkeys + 1 */
  PetscInt  *item;  /* the particles, by cell */
} SparseCells;

static PetscReal CellKey(const SparseCells *sc, const PetscInt c[3])
{
  return (PetscReal)c[0] + (PetscReal)sc->ncell[0] * ((PetscReal)c[1] + (PetscReal)sc->ncell[1] * (PetscReal)c[2]);
}

/* The cell of x, unclamped: a periodic image of a query may lie outside the box. The particles'
 * own cells are within 0 .. ncell - 1 since ncell covers the box with one cell to spare. */
static void CellCoords(const SparseCells *sc, PetscInt dim, const PetscReal x[], PetscInt c[3])
{
  for (PetscInt d = 0; d < 3; d++) c[d] = d < dim ? (PetscInt)PetscFloorReal((x[d] - sc->lower[d]) / sc->size) : 0;
}

typedef struct {
  PetscReal key;
  PetscInt  item;
} KeyItem;

/* by cell, then by particle: the order is the same on every run */
static int CompareKeyItem(const void *a, const void *b)
{
  const KeyItem *x = (const KeyItem *)a, *y = (const KeyItem *)b;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  return (x->item > y->item) - (x->item < y->item);
}

/* The sparse cells of size over the m particles list[] of p, lower..upper their box (libc's qsort:
 * PETSc's quicksort slows to a crawl on the many equal keys of a cell). */
static PetscErrorCode SparseCellsCreate(const PeriParticles *p, const PetscReal lower[], const PetscReal upper[], PetscReal size, PetscInt m, const PetscInt list[], SparseCells *sc)
{
  PetscReal *key, total = 1;

  PetscFunctionBeginUser;
  sc->size = size;
  for (PetscInt d = 0; d < 3; d++) {
    sc->lower[d] = lower[d];
    sc->ncell[d] = d < p->dim ? (PetscInt)PetscFloorReal((upper[d] - lower[d]) / size) + 1 : 1;
    total *= sc->ncell[d];
  }
  PetscCheck(total < 4e15, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "the body spans %g cells of its smallest horizon: too many to number exactly; is a particle's spacing or a coordinate wrong?", (double)total);
  PetscCall(PetscMalloc3(m, &key, m, &sc->item, m + 1, &sc->start));
  {
    KeyItem *ki;
    PetscCall(PetscMalloc1(m, &ki));
    for (PetscInt s = 0; s < m; s++) {
      PetscInt c[3];
      CellCoords(sc, p->dim, &p->x[3 * list[s]], c);
      ki[s].key  = CellKey(sc, c);
      ki[s].item = list[s];
    }
    if (m) qsort(ki, (size_t)m, sizeof(*ki), CompareKeyItem);
    for (PetscInt s = 0; s < m; s++) {
      key[s]      = ki[s].key;
      sc->item[s] = ki[s].item;
    }
    PetscCall(PetscFree(ki));
  }
  sc->nkeys = 0;
  for (PetscInt s = 0; s < m; s++)
    if (!s || key[s] != key[s - 1]) {
      key[sc->nkeys]         = key[s];
      sc->start[sc->nkeys++] = s;
    }
  sc->start[sc->nkeys] = m;
  sc->key              = key; /* the first nkeys entries are the unique keys */
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode SparseCellsDestroy(SparseCells *sc)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree3(sc->key, sc->item, sc->start));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The first occupied cell of sc whose key is at least k. */
static PetscInt LowerBound(const SparseCells *sc, PetscReal k)
{
  PetscInt lo = 0, hi = sc->nkeys;
  while (lo < hi) {
    PetscInt mid = lo + (hi - lo) / 2;
    if (sc->key[mid] < k)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* Is the image shift w positive in lexicographic order? Of the two images of a particle's
 * self-bond (+w, -w) only one is stored. */
static PetscBool ImagePositive(const PetscInt w[3])
{
  for (PetscInt d = 0; d < 3; d++)
    if (w[d]) return w[d] > 0 ? PETSC_TRUE : PETSC_FALSE;
  return PETSC_FALSE;
}

/* Is the pair (i, j) at image w stored in i's row? Once per pair and image: in the row of the
 * smaller global index (half), and a particle's bond to its own image once, at +w; a full list
 * leaves self-images out (it is the partitioner's graph). */
static PetscBool PairStored(const PeriParticles *p, PetscInt i, PetscInt j, const PetscInt w[3], PetscBool half)
{
  if (j == i) return half && ImagePositive(w);
  return !half || PeriParticleGlobal(p, j) > PeriParticleGlobal(p, i);
}

/* Appends the bonds of i with the particles of sc within LEVELS_REACH cells of i's image at
 * X_i - w L (the bond vector X_j - X_i + w L, L the periodic lengths). The cells of one row along
 * x have consecutive keys: one bisection per row finds the first, and the row is walked from
 * there. */
static PetscErrorCode CellsBonds(const PeriParticles *p, const PetscReal horizon[], const PetscReal reach[], PeriPartialVolume pv, const SparseCells *sc, PetscInt i, const PetscInt w[3], PetscBool half, PeriBonds *b, PetscInt *cap)
{
  PetscInt  ci[3], c[3], r[3];
  PetscReal shift[3], y[3];

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) {
    shift[d] = w[d] ? w[d] * (p->upper[d] - p->lower[d]) : 0;
    y[d]     = p->x[3 * i + d] - shift[d];
    r[d]     = d < p->dim ? LEVELS_REACH : 0;
  }
  CellCoords(sc, p->dim, y, ci);
  for (c[2] = ci[2] - r[2]; c[2] <= ci[2] + r[2]; c[2]++)
    for (c[1] = ci[1] - r[1]; c[1] <= ci[1] + r[1]; c[1]++) {
      PetscInt  lo[3] = {PetscMax(ci[0] - r[0], 0), c[1], c[2]}, hi[3] = {PetscMin(ci[0] + r[0], sc->ncell[0] - 1), c[1], c[2]};
      PetscReal khi;
      if (c[1] < 0 || c[1] >= sc->ncell[1] || c[2] < 0 || c[2] >= sc->ncell[2] || lo[0] > hi[0]) continue;
      khi = CellKey(sc, hi);
      for (PetscInt loc = LowerBound(sc, CellKey(sc, lo)); loc < sc->nkeys && sc->key[loc] <= khi; loc++)
        for (PetscInt s = sc->start[loc]; s < sc->start[loc + 1]; s++) {
          const PetscInt  j = sc->item[s];
          const PetscReal R = PetscMax(reach[i], reach[j]);
          PetscReal       x[3];
          if (!PairStored(p, i, j, w, half) || (j == i && !w[0] && !w[1] && !w[2])) continue;
          for (PetscInt d = 0; d < 3; d++) x[d] = p->x[3 * j + d] - p->x[3 * i + d] + shift[d];
          if (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] > R * R) continue; /* beyond both reaches: no bond */
          PetscCall(PeriBondsAdd(p, i, j, x, PetscMax(horizon[i], horizon[j]), pv, b, cap));
        }
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bonds of i with the particles of sc whose pair radius is below cut, at every periodic image
 * of i that comes within cut of the body's box (w = 0 alone without periodic axes). */
static PetscErrorCode ImagesBonds(const PeriParticles *p, const PetscReal horizon[], const PetscReal reach[], PeriPartialVolume pv, const SparseCells *sc, PetscReal cut, PetscInt i, PetscBool half, PeriBonds *b, PetscInt *cap)
{
  PetscInt n[3], w[3];

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) n[d] = p->periodic[d] ? (PetscInt)PetscCeilReal(cut / (p->upper[d] - p->lower[d])) : 0;
  for (w[2] = -n[2]; w[2] <= n[2]; w[2]++)
    for (w[1] = -n[1]; w[1] <= n[1]; w[1]++)
      for (w[0] = -n[0]; w[0] <= n[0]; w[0]++) {
        PetscBool near = PETSC_TRUE;
        for (PetscInt d = 0; d < 3 && near; d++) { /* the image's distance to the box along d */
          PetscReal L = p->upper[d] - p->lower[d], y = p->x[3 * i + d] - w[d] * L;
          near = (PetscBool)(!w[d] || (y < p->lower[d] ? p->lower[d] - y : y - p->upper[d]) <= cut);
        }
        if (near) PetscCall(CellsBonds(p, horizon, reach, pv, sc, i, w, half, b, cap));
      }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Each particle's reach (its horizon plus what the partial volume adds), its level by it, the
 * number of levels and the smallest reach. */
static PetscErrorCode Levels(const PeriParticles *p, const PetscReal horizon[], PeriPartialVolume pv, PetscReal reach[], PetscInt level[], PetscInt *nl, PetscReal *rmin)
{
  PetscFunctionBeginUser;
  *rmin = PETSC_MAX_REAL;
  *nl   = 1;
  for (PetscInt k = 0; k < p->n; k++) {
    reach[k] = PeriSearchRadius(pv, horizon[k], p->spacing[k]);
    *rmin    = PetscMin(*rmin, reach[k]);
  }
  for (PetscInt k = 0; k < p->n; k++) {
    level[k] = PetscMax((PetscInt)PetscFloorReal(PetscLog2Real(reach[k] / *rmin)), 0);
    PetscCheck(level[k] < LEVELS_MAX, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "the horizons range over a factor above 2^%d: is a particle's volume wrong?", LEVELS_MAX);
    *nl = PetscMax(*nl, level[k] + 1);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The box of the local view: the body's on periodic axes (the images' cells are then whole). */
static void Box(const PeriParticles *p, PetscReal lo[], PetscReal hi[])
{
  for (PetscInt d = 0; d < 3; d++) {
    lo[d] = p->periodic[d] ? p->lower[d] : PETSC_MAX_REAL;
    hi[d] = p->periodic[d] ? p->upper[d] : PETSC_MIN_REAL;
    for (PetscInt k = 0; k < p->n; k++) {
      lo[d] = PetscMin(lo[d], p->x[3 * k + d]);
      hi[d] = PetscMax(hi[d], p->x[3 * k + d]);
    }
  }
}

/* C_L: the largest pair radius that the cells of level L serve. */
static PetscReal LevelCut(PetscReal rmin, PetscInt L)
{
  return PetscPowRealInt(2.0, L + 1) * rmin;
}

/* The cells of every level: cum[L] over the particles of levels <= L, own[L] over those of L. */
static PetscErrorCode LevelCells(const PeriParticles *p, const PetscInt level[], PetscInt nl, PetscReal rmin, SparseCells cum[], SparseCells own[])
{
  PetscInt *list;
  PetscReal lo[3], hi[3];

  PetscFunctionBeginUser;
  Box(p, lo, hi);
  PetscCall(PetscMalloc1(p->n, &list));
  for (PetscInt L = 0; L < nl; L++) {
    PetscReal size = LevelCut(rmin, L) / LEVELS_REACH;
    PetscInt  m    = 0;
    for (PetscInt k = 0; k < p->n; k++)
      if (level[k] <= L) list[m++] = k;
    PetscCall(SparseCellsCreate(p, lo, hi, size, m, list, &cum[L]));
    m = 0;
    for (PetscInt k = 0; k < p->n; k++)
      if (level[k] == L) list[m++] = k;
    PetscCall(SparseCellsCreate(p, lo, hi, size, m, list, &own[L]));
  }
  PetscCall(PetscFree(list));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriNeighborSearchLevels - PeriNeighborSearch for per-particle horizons (horizon[k] of each
  particle of p): a pair is bonded when its partial-volume factor for the larger of the two
  horizons is positive, at every periodic image (a short periodic axis may give a pair several
  bonds, as the one-horizon search does). Not collective.
@*/
PetscErrorCode PeriNeighborSearchLevels(const PeriParticles *p, const PetscReal horizon[], PeriPartialVolume pv, PetscInt rstart, PetscInt rend, PetscBool half, PeriBonds *b)
{
  PetscFunctionBeginUser;
  PetscCall(PeriNeighborSearchLevelsRows(p, horizon, pv, rend - rstart, NULL, rstart, half, b));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriNeighborSearchLevelsRows - PeriNeighborSearchLevels for the rows rows[0..nrows-1] of p, or
  (rows NULL) rstart..rstart+nrows-1: row r of b is particle rows[r]. Not collective.
@*/
PetscErrorCode PeriNeighborSearchLevelsRows(const PeriParticles *p, const PetscReal horizon[], PeriPartialVolume pv, PetscInt nrows, const PetscInt rows[], PetscInt rstart, PetscBool half, PeriBonds *b)
{
  SparseCells    cum[LEVELS_MAX], own[LEVELS_MAX];
  PetscInt      *level, nl, cap = 0;
  PetscReal      rmin, *reach;
  PetscErrorCode ierr = PETSC_SUCCESS;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(b, sizeof(*b)));
  PetscCall(PetscMalloc2(p->n, &level, p->n, &reach));
  PetscCall(Levels(p, horizon, pv, reach, level, &nl, &rmin));
  PetscCall(LevelCells(p, level, nl, rmin, cum, own));
  b->rstart = rows ? 0 : rstart;
  b->rend   = b->rstart + nrows;
  PetscCall(PetscMalloc1(nrows + 1, &b->offset));
  b->offset[0] = 0;
  /* coincident particles are an input error: the cells are freed before it is passed on */
  for (PetscInt r = 0; r < nrows && !ierr; r++) {
    const PetscInt i = rows ? rows[r] : rstart + r;
    ierr             = ImagesBonds(p, horizon, reach, pv, &cum[level[i]], LevelCut(rmin, level[i]), i, half, b, &cap);
    for (PetscInt L = level[i] + 1; L < nl && !ierr; L++) ierr = ImagesBonds(p, horizon, reach, pv, &own[L], LevelCut(rmin, L), i, half, b, &cap);
    b->offset[r + 1] = b->nbonds;
  }
  for (PetscInt L = 0; L < nl; L++) {
    PetscCall(SparseCellsDestroy(&cum[L]));
    PetscCall(SparseCellsDestroy(&own[L]));
  }
  PetscCall(PetscFree2(level, reach));
  PetscCall(ierr);
  PetscCall(PetscMalloc1(b->nbonds, &b->lambda));
  for (PetscInt k = 0; k < b->nbonds; k++) b->lambda[k] = 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}
