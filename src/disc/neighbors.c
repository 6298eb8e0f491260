/* Neighbour search with cell lists: O(N), periodic axes by explicit images (a short periodic
 * axis gives several bonds to images of the same particle, as the continuum would). */
#include "perilin/private/disc.h"

typedef struct {
  PetscInt  ncell[3], reach[3];
  PetscReal lower[3], size[3], length[3];
  PetscInt *start; /* ncells + 1 */
  PetscInt *item;  /* particles sorted by cell */
} CellList;

static PetscInt CellOfPoint(const CellList *cl, const PetscReal x[], PetscInt d)
{
  PetscInt c = (PetscInt)PetscFloorReal((x[d] - cl->lower[d]) / cl->size[d]);
  return PetscMin(PetscMax(c, 0), cl->ncell[d] - 1);
}

static PetscInt CellOf(const CellList *cl, const PeriParticles *p, PetscInt k, PetscInt d)
{
  return CellOfPoint(cl, &p->x[3 * k], d);
}

static PetscInt CellIndex(const CellList *cl, const PetscInt c[3])
{
  return (c[2] * cl->ncell[1] + c[1]) * cl->ncell[0] + c[0];
}

/* Cells of size >= r over the box lower..upper (the body's box; on a periodic axis it must be, so
 * that a wrap shifts by whole cells). */
static PetscErrorCode CellListCreate(const PeriParticles *p, const PetscReal lower[], const PetscReal upper[], PetscReal r, CellList *cl)
{
  PetscInt ncells = 1, *cellof;

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) {
    cl->lower[d]  = lower[d];
    cl->length[d] = d < p->dim ? upper[d] - lower[d] : 0;
    cl->ncell[d]  = d < p->dim ? PetscMax(1, (PetscInt)PetscFloorReal(cl->length[d] / r)) : 1;
    /* cap the cell count so a huge box with few particles cannot exhaust memory */
    while (d < p->dim && cl->ncell[d] > 1 && (PetscReal)ncells * cl->ncell[d] > 8.0 * p->n + 64) cl->ncell[d] = (cl->ncell[d] + 1) / 2;
    cl->size[d]  = d < p->dim ? cl->length[d] / cl->ncell[d] : 1;
    cl->reach[d] = d < p->dim ? (PetscInt)PetscCeilReal(r / cl->size[d]) : 0;
    ncells *= cl->ncell[d];
  }
  PetscCall(PetscCalloc1(ncells + 1, &cl->start));
  PetscCall(PetscMalloc1(p->n, &cl->item));
  PetscCall(PetscMalloc1(p->n, &cellof));
  for (PetscInt k = 0; k < p->n; k++) {
    PetscInt c[3];
    for (PetscInt d = 0; d < 3; d++) c[d] = d < p->dim ? CellOf(cl, p, k, d) : 0;
    cellof[k] = CellIndex(cl, c);
    cl->start[cellof[k] + 1]++;
  }
  for (PetscInt c = 0; c < ncells; c++) cl->start[c + 1] += cl->start[c];
  {
    PetscInt *fill;
    PetscCall(PetscMalloc1(ncells, &fill));
    PetscCall(PetscArraycpy(fill, cl->start, ncells));
    for (PetscInt k = 0; k < p->n; k++) cl->item[fill[cellof[k]]++] = k;
    PetscCall(PetscFree(fill));
  }
  PetscCall(PetscFree(cellof));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CellListDestroy(CellList *cl)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(cl->start));
  PetscCall(PetscFree(cl->item));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Is the image shift positive in lexicographic order? Of the two images of a particle's
 * self-bond (+shift, -shift) only one is stored. */
static PetscBool ShiftPositive(const PetscInt w[3])
{
  for (PetscInt d = 0; d < 3; d++)
    if (w[d]) return w[d] > 0 ? PETSC_TRUE : PETSC_FALSE;
  return PETSC_FALSE;
}

/* The cell at offset o from cell ci, wrapped across periodic axes (wrap: the images crossed per
 * axis), or -1 beyond a non-periodic face. */
static PetscInt NeighborCell(const PeriParticles *p, const CellList *cl, const PetscInt ci[], const PetscInt o[], PetscInt wrap[])
{
  PetscInt c[3];
  for (PetscInt d = 0; d < 3; d++) {
    c[d]    = ci[d] + o[d];
    wrap[d] = 0;
    if (c[d] >= 0 && c[d] < cl->ncell[d]) continue;
    if (!p->periodic[d]) return -1;
    wrap[d] = (PetscInt)PetscFloorReal((PetscReal)c[d] / cl->ncell[d]);
    c[d] -= wrap[d] * cl->ncell[d];
  }
  return CellIndex(cl, c);
}

/* Appends the bonds of particle i (those with j >= i when half) to b. */
static PetscErrorCode ParticleBonds(const PeriParticles *p, const CellList *cl, PetscReal delta, PeriPartialVolume pv, PetscReal r, PetscInt i, PetscBool half, PeriBonds *b, PetscInt *cap)
{
  const PetscReal *xi = &p->x[3 * i];
  PetscInt         ci[3], o[3];

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) ci[d] = d < p->dim ? CellOf(cl, p, i, d) : 0;
  for (o[2] = -cl->reach[2]; o[2] <= cl->reach[2]; o[2]++)
    for (o[1] = -cl->reach[1]; o[1] <= cl->reach[1]; o[1]++)
      for (o[0] = -cl->reach[0]; o[0] <= cl->reach[0]; o[0]++) {
        PetscInt wrap[3], cell = NeighborCell(p, cl, ci, o, wrap);
        if (cell < 0) continue;
        for (PetscInt s = cl->start[cell]; s < cl->start[cell + 1]; s++) {
          PetscInt  j = cl->item[s], self = (j == i);
          PetscReal x[3], len2            = 0;
          /* the row of the smaller global index holds the pair, whichever rank that is */
          if (half && (PeriParticleGlobal(p, j) < PeriParticleGlobal(p, i) || (self && !ShiftPositive(wrap)))) continue;
          if (self && !wrap[0] && !wrap[1] && !wrap[2]) continue;
          if (!half && self) continue;
          for (PetscInt d = 0; d < 3; d++) {
            x[d] = p->x[3 * j + d] + wrap[d] * cl->length[d] - xi[d];
            len2 += x[d] * x[d];
          }
          if (len2 > r * r) continue;
          PetscCall(PeriBondsAdd(p, i, j, x, delta, pv, b, cap));
        }
      }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ParticlesBox(const PeriParticles *, PetscReal, PetscReal[], PetscReal[]);

/*@C
  PeriNeighborSearch - finds the bonds of particles rstart..rend-1 of p with cell lists. With half,
  each pair is stored once, in the row of its smaller global index; otherwise every neighbour is
  listed (the graph for partitioning). p may be the whole body or a rank's local view (owned
  particles, then ghosts): the bonds' rows and j are indices into p (p->global maps them to global
  indices). With horizon (each particle's own, horizon.spacing: own) a pair is bonded within the
  larger of its two horizons and the cells are those of PeriNeighborSearchLevels; delta is then the
  largest. Without geometry the bonds' vectors, lengths and partial-volume factors are not stored
  (b->no_geometry; one horizon and no periodic axis: they are the coordinates' differences), nor
  the surface factors (NULL: all 1). Not collective. Errors on coincident particles.
@*/
PetscErrorCode PeriNeighborSearch(const PeriParticles *p, PetscReal delta, const PetscReal horizon[], PeriPartialVolume pv, PetscInt rstart, PetscInt rend, PetscBool half, PetscBool geometry, PeriBonds *b)
{
  CellList       cl;
  PetscReal      hmax = 0, r;
  PetscInt       cap  = 0;
  PetscErrorCode ierr = PETSC_SUCCESS;
  PetscBool      lean = (PetscBool)!geometry;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(b, sizeof(*b)));
  b->no_geometry = lean;
  PetscCheck(!lean || (!horizon && !p->periodic[0] && !p->periodic[1] && !p->periodic[2]), PETSC_COMM_SELF, PETSC_ERR_PLIB, "bonds without stored geometry need one horizon and no periodic axis");
  if (horizon) {
    PetscCall(PeriNeighborSearchLevels(p, horizon, pv, rstart, rend, half, b));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  for (PetscInt k = 0; k < p->n; k++) hmax = PetscMax(hmax, p->spacing[k]);
  r = PeriSearchRadius(pv, delta, hmax);
  if (p->global) { /* a rank's local view: cells over its particles only */
    PetscReal lo[3], hi[3];
    PetscCall(ParticlesBox(p, r, lo, hi));
    PetscCall(CellListCreate(p, lo, hi, r, &cl));
  } else
    PetscCall(CellListCreate(p, p->lower, p->upper, r, &cl));
  {
    /* reserve what a full horizon holds, so the arrays are rarely copied while they grow */
    PetscReal vmean = 0, ball = p->dim == 2 ? PETSC_PI * r * r * p->thickness : 4.0 / 3.0 * PETSC_PI * r * r * r;
    for (PetscInt k = 0; k < p->n; k++) vmean += p->volume[k] / p->n;
    PetscCall(PeriBondsReserve(b, (PetscInt)(1.05 * (rend - rstart) * ball / vmean / (half ? 2 : 1)) + 16, &cap));
  }
  b->rstart = rstart;
  b->rend   = rend;
  PetscCall(PetscMalloc1(rend - rstart + 1, &b->offset));
  b->offset[0] = 0;
  /* coincident particles are an input error: the cell list is freed before it is passed on */
  for (PetscInt i = rstart; i < rend && !ierr; i++) {
    ierr                      = ParticleBonds(p, &cl, delta, pv, r, i, half, b, &cap);
    b->offset[i - rstart + 1] = b->nbonds;
  }
  PetscCall(CellListDestroy(&cl));
  PetscCall(ierr);
  if (lean) PetscFunctionReturn(PETSC_SUCCESS); /* every surface factor 1 until a correction sets them */
  PetscCall(PetscMalloc1(b->nbonds, &b->lambda));
  for (PetscInt k = 0; k < b->nbonds; k++) b->lambda[k] = 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The box the cells of a search over p cover: on a periodic axis the body's (a wrap shifts by
 * whole cells), else the particles' own extent, so that a rank holding a small part of a large
 * body has cells of its part only. */
static PetscErrorCode ParticlesBox(const PeriParticles *p, PetscReal r, PetscReal lo[], PetscReal hi[])
{
  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) {
    lo[d] = p->periodic[d] ? p->lower[d] : PETSC_MAX_REAL;
    hi[d] = p->periodic[d] ? p->upper[d] : PETSC_MIN_REAL;
    for (PetscInt k = 0; k < p->n && !p->periodic[d]; k++) {
      lo[d] = PetscMin(lo[d], p->x[3 * k + d]);
      hi[d] = PetscMax(hi[d], p->x[3 * k + d]);
    }
    if (hi[d] - lo[d] < r) hi[d] = lo[d] + r; /* one cell along a thin (or flat) extent */
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Is any particle of cl (of p) within r of the point y, on the minimum image? */
static PetscBool PointNear(const PeriParticles *p, const CellList *cl, PetscReal r, const PetscReal y[])
{
  PetscInt ci[3], o[3];

  for (PetscInt d = 0; d < 3; d++) ci[d] = d < p->dim ? CellOfPoint(cl, y, d) : 0;
  for (o[2] = -cl->reach[2]; o[2] <= cl->reach[2]; o[2]++)
    for (o[1] = -cl->reach[1]; o[1] <= cl->reach[1]; o[1]++)
      for (o[0] = -cl->reach[0]; o[0] <= cl->reach[0]; o[0]++) {
        PetscInt wrap[3], cell = NeighborCell(p, cl, ci, o, wrap);
        if (cell < 0) continue;
        for (PetscInt s = cl->start[cell]; s < cl->start[cell + 1]; s++) {
          PetscInt  j    = cl->item[s];
          PetscReal len2 = 0;
          for (PetscInt d = 0; d < 3; d++) {
            PetscReal x = p->x[3 * j + d] + wrap[d] * cl->length[d] - y[d];
            len2 += x * x;
          }
          if (len2 <= r * r) return PETSC_TRUE;
        }
      }
  return PETSC_FALSE;
}

/*@C
  PeriParticlesNear - near[k] says whether any of the n particles of p lies within r of the point
  y[3k..3k+2] (minimum image on periodic axes). The cells cover the particles' own bounding box,
  not the body's, so a rank holding a small part of a large body searches only its part. Not
  collective.
@*/
PetscErrorCode PeriParticlesNear(const PeriParticles *p, PetscReal r, PetscInt m, const PetscReal y[], PetscBool near[])
{
  CellList  cl;
  PetscReal lo[3], hi[3];

  PetscFunctionBeginUser;
  if (!p->n) {
    for (PetscInt k = 0; k < m; k++) near[k] = PETSC_FALSE;
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(ParticlesBox(p, r, lo, hi));
  PetscCall(CellListCreate(p, lo, hi, r, &cl));
  for (PetscInt k = 0; k < m; k++) near[k] = PointNear(p, &cl, r, &y[3 * k]);
  PetscCall(CellListDestroy(&cl));
  PetscFunctionReturn(PETSC_SUCCESS);
}
