/* Per-particle horizons from a neighbour count (horizon.neighbors: k): Ganzenmüller et al.
 * (sec. 3.1.2) give each particle of a stochastic mesh the horizon whose family holds 30
 * neighbours, since a sliver's own volume says nothing about how far its neighbours are. A
 * particle's horizon is the midpoint between its k-th and (k+1)-th nearest neighbours, so that
 * its own ball holds exactly k of them however the distances round (all of them when several tie
 * at the k-th distance). */
#include "perilin/private/disc.h"

#define HORIZONS_GROWTH 1.6 /* a radius holding too few neighbours grows by this and is searched again */
#define HORIZONS_ROUNDS 60  /* 1.6^60 ~ 1e12: beyond it the particle is alone in the body */

static int CompareReal(const void *a, const void *b)
{
  const PetscReal x = *(const PetscReal *)a, y = *(const PetscReal *)b;
  return (x > y) - (x < y);
}

/* From the bonds of row i within radius r (the search's pairs within the larger of the two
 * radii: those beyond r are the other end's), the midpoint of the k-th and (k+1)-th distances
 * and the (k+1)-th; 0 when fewer than k + 1 lie within r. */
static PetscReal RowHorizon(const PeriBonds *b, PetscInt i, PetscReal r, PetscInt k, PetscReal *buf, PetscReal *kplus1)
{
  PetscInt m = 0;

  for (PetscInt q = b->offset[i]; q < b->offset[i + 1]; q++)
    if (b->length[q] <= r) buf[m++] = b->length[q];
  if (m < k + 1) return 0;
  qsort(buf, (size_t)m, sizeof(*buf), CompareReal);
  *kplus1 = buf[k];
  return 0.5 * (buf[k - 1] + buf[k]);
}

/*@C
  PeriHorizonsByNeighbors - for particles 0..nrows-1 of p, the horizon that holds exactly k of the
  particles of p (the midpoint of the k-th and (k+1)-th nearest distances, periodic images
  included), and bound[] (unless NULL) the (k+1)-th nearest distance: a radius that holds k + 1.
  r[] holds, on entry, a radius per row known to hold k + 1 of them, or 0 for none
  (then the search starts from 1.25 times the radius of the ball of k particles of its own spacing, and grows). Rows
  beyond nrows (a rank's ghosts) are searched from, never for. Not collective; errors when p has
  no k + 1 particles around a row.
@*/
PetscErrorCode PeriHorizonsByNeighbors(const PeriParticles *p, PetscInt nrows, PetscInt k, PetscReal r[], PetscReal bound[])
{
  PetscReal *guess, *buf = NULL, gmin = PETSC_MAX_REAL;
  PetscInt   cap = 0, *pending, npending = nrows;

  PetscFunctionBeginUser;
  if (!nrows) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc2(p->n, &guess, nrows, &pending));
  for (PetscInt i = 0; i < nrows; i++) {
    guess[i]   = r[i] > 0 ? r[i] : 1.25 * PetscPowReal(p->dim == 3 ? 3.0 * k / (4 * PETSC_PI) : k / PETSC_PI, 1.0 / p->dim) * p->spacing[i];
    gmin       = PetscMin(gmin, guess[i]);
    pending[i] = i;
  }
  for (PetscInt i = nrows; i < p->n; i++) guess[i] = gmin; /* the ghosts' only widen the search */
  /* each round searches the rows still short of k + 1 neighbours, with their radii grown */
  for (PetscInt round = 0; npending; round++) {
    PeriBonds b;
    PetscInt  left = 0;
    PetscCheck(round < HORIZONS_ROUNDS, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "horizon.neighbors %" PetscInt_FMT ": a particle has fewer than %" PetscInt_FMT " others within reach (%" PetscInt_FMT " particles here); use fewer neighbours or fewer ranks", k, k + 1, p->n);
    PetscCall(PeriNeighborSearchLevelsRows(p, guess, PERI_PARTIAL_VOLUME_NONE, npending, pending, 0, PETSC_FALSE, &b));
    for (PetscInt q = 0; q < npending; q++) {
      const PetscInt i = pending[q], m = b.offset[q + 1] - b.offset[q];
      if (m > cap) {
        PetscCall(PetscFree(buf));
        cap = 2 * m;
        PetscCall(PetscMalloc1(cap, &buf));
      }
      PetscReal kplus1 = 0;
      r[i]             = RowHorizon(&b, q, guess[i], k, buf, &kplus1);
      if (bound) bound[i] = kplus1;
      if (r[i] > 0) continue;
      guess[i] *= HORIZONS_GROWTH;
      pending[left++] = i;
    }
    PetscCall(PetscInfo(NULL, "horizon.neighbors %" PetscInt_FMT ": round %" PetscInt_FMT " searched %" PetscInt_FMT " rows, %" PetscInt_FMT " short of %" PetscInt_FMT " neighbours\n", k, round, npending, left, k + 1));
    npending = left;
    PetscCall(PeriBondsDestroy(&b));
  }
  PetscCall(PetscFree(buf));
  PetscCall(PetscFree2(guess, pending));
  PetscFunctionReturn(PETSC_SUCCESS);
}
