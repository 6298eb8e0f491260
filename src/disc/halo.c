/* Ghost (halo) particles: each rank holds its own particles and, after them, copies of the other
 * ranks' particles within a radius of its own (issue 17; docs/distributed.md). No rank sees the
 * whole body: a rank sends a particle to another when it lies within the radius of that rank's
 * bounding box (a superset, one exchange), and the receiver keeps those within the radius of one
 * of its particles. A PetscSF from the owners to the ghosts then refreshes ghost data. */
#include "perilin/private/disc.h"

/* Distance from x to the interval lo..hi along one axis of length L (periodic when L > 0). */
static PetscReal AxisGap(PetscReal x, PetscReal lo, PetscReal hi, PetscReal L)
{
  PetscReal best = PETSC_MAX_REAL;
  for (PetscInt k = L > 0 ? -1 : 0; k <= (L > 0 ? 1 : 0); k++) {
    PetscReal y = x + k * L, g = y < lo ? lo - y : y > hi ? y - hi
                                                          : 0;
    best = PetscMin(best, g);
  }
  return best;
}

/* Is x within r of the box lo..hi (an empty box has lo > hi and is near nothing)? */
static PetscBool NearBox(const PeriParticles *p, const PetscReal x[], const PetscReal box[], PetscReal r)
{
  PetscReal g2 = 0;
  for (PetscInt d = 0; d < p->dim; d++) {
    PetscReal g;
    if (box[d] > box[3 + d]) return PETSC_FALSE;
    g = AxisGap(x[d], box[d], box[3 + d], p->periodic[d] ? p->upper[d] - p->lower[d] : 0);
    g2 += g * g;
  }
  return g2 <= r * r ? PETSC_TRUE : PETSC_FALSE;
}

/* Every rank's bounding box of its particles: 6 reals per rank, lower then upper. */
static PetscErrorCode Boxes(MPI_Comm comm, const PeriParticles *p, PetscReal **boxes)
{
  PetscReal   mine[6];
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  for (PetscInt d = 0; d < 3; d++) {
    mine[d]     = PETSC_MAX_REAL;
    mine[3 + d] = PETSC_MIN_REAL;
  }
  for (PetscInt k = 0; k < p->n; k++)
    for (PetscInt d = 0; d < 3; d++) {
      mine[d]     = PetscMin(mine[d], p->x[3 * k + d]);
      mine[3 + d] = PetscMax(mine[3 + d], p->x[3 * k + d]);
    }
  PetscCall(PetscMalloc1(6 * size, boxes));
  PetscCallMPI(MPI_Allgather(mine, 6, MPIU_REAL, *boxes, 6, MPIU_REAL, comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Which owned particles go to which rank (those within r of the rank's box): the exchange, and
 * the local index of each particle sent, grouped by rank. */
static PetscErrorCode PlanSends(MPI_Comm comm, const PeriParticles *p, PetscReal r, PeriExchange *ex, PetscInt **sidx)
{
  PetscReal  *boxes;
  PetscMPIInt rank, size, *dest;
  PetscInt    nsend = 0;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(Boxes(comm, p, &boxes));
  for (PetscMPIInt q = 0; q < size; q++)
    for (PetscInt k = 0; k < p->n && q != rank; k++) nsend += NearBox(p, &p->x[3 * k], &boxes[6 * q], r);
  PetscCall(PetscMalloc1(nsend, &dest));
  PetscCall(PetscMalloc1(nsend, sidx));
  for (PetscMPIInt q = 0, s = 0; q < size; q++)
    for (PetscInt k = 0; k < p->n && q != rank; k++)
      if (NearBox(p, &p->x[3 * k], &boxes[6 * q], r)) {
        dest[s]      = q;
        (*sidx)[s++] = k;
      }
  PetscCall(PetscFree(boxes));
  PetscCall(PeriExchangeCreate(comm, nsend, dest, ex));
  PetscCall(PetscFree(dest));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The candidates' positions and their owners' local indices, grouped by owner rank. */
static PetscErrorCode SendCandidates(const PeriParticles *p, const PeriExchange *ex, const PetscInt sidx[], PetscReal **y, PetscInt **from)
{
  PetscReal *sx;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(3 * ex->nsend, &sx));
  for (PetscInt s = 0; s < ex->nsend; s++)
    for (PetscInt d = 0; d < 3; d++) sx[3 * s + d] = p->x[3 * sidx[s] + d];
  PetscCall(PetscMalloc2(3 * ex->nrecv, y, ex->nrecv, from));
  PetscCall(PeriExchangeSend(ex, MPIU_INT, 1, sidx, *from));
  PetscCall(PeriExchangeSend(ex, MPIU_REAL, 3, sx, *y));
  PetscCall(PetscFree(sx));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Fictitious layer particles (src/system/layers.c): the ghosts' mirror images (global indices)
 * and crossed faces, from their owners. */
static PetscErrorCode AppendLayerImages(PeriParticles *p, const PeriHalo *h)
{
  PetscInt      *image;
  unsigned char *crossed;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(h->nowned + h->nghost, &image, h->nowned + h->nghost, &crossed));
  PetscCall(PetscArraycpy(image, p->image, h->nowned));
  PetscCall(PetscArraycpy(crossed, p->crossed, h->nowned));
  PetscCall(PeriHaloUpdate(h, MPIU_INT, image, image + h->nowned));
  PetscCall(PeriHaloUpdate(h, MPI_UNSIGNED_CHAR, crossed, crossed + h->nowned));
  PetscCall(PetscFree2(p->image, p->crossed));
  p->image   = image;
  p->crossed = crossed;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Appends the kept candidates to p as ghosts (positions as received, the rest through the SF). */
static PetscErrorCode AppendGhosts(PeriParticles *p, const PeriHalo *h, const PetscReal y[], const PetscInt kept[])
{
  PetscReal *x, *vol, *sp;
  PetscInt  *line;
  PetscInt   n = h->nowned + h->nghost;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(3 * n, &x));
  PetscCall(PetscMalloc3(n, &vol, n, &sp, n, &line));
  PetscCall(PetscArraycpy(x, p->x, 3 * h->nowned));
  for (PetscInt g = 0; g < h->nghost; g++)
    for (PetscInt d = 0; d < 3; d++) x[3 * (h->nowned + g) + d] = y[3 * kept[g] + d];
  PetscCall(PetscArraycpy(vol, p->volume, h->nowned));
  PetscCall(PetscArraycpy(sp, p->spacing, h->nowned));
  PetscCall(PetscArraycpy(line, p->source_line, h->nowned));
  PetscCall(PeriHaloUpdate(h, MPIU_REAL, vol, vol + h->nowned));
  PetscCall(PeriHaloUpdate(h, MPIU_REAL, sp, sp + h->nowned));
  PetscCall(PeriHaloUpdate(h, MPIU_INT, line, line + h->nowned));
  PetscCall(PetscFree(p->x));
  PetscCall(PetscFree3(p->volume, p->spacing, p->source_line));
  if (p->image) PetscCall(AppendLayerImages(p, h));
  PetscCall(PetscFree(p->global));
  PetscCall(PetscMalloc1(n, &p->global));
  for (PetscInt i = 0; i < h->nowned; i++) p->global[i] = h->rstart + i;
  PetscCall(PetscArraycpy(p->global + h->nowned, h->global, h->nghost));
  p->x           = x;
  p->volume      = vol;
  p->spacing     = sp;
  p->source_line = line;
  p->n           = n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The SF from owners to the kept candidates, and the ghosts' global indices. */
static PetscErrorCode BuildSF(MPI_Comm comm, const PeriExchange *ex, const PetscInt from[], const PetscInt kept[], PeriHalo *h)
{
  PetscSFNode *remote;
  PetscInt    *starts;
  PetscMPIInt  size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscMalloc1(size, &starts));
  PetscCallMPI(MPI_Allgather(&h->rstart, 1, MPIU_INT, starts, 1, MPIU_INT, comm));
  PetscCall(PetscMalloc1(h->nghost, &remote));
  PetscCall(PetscMalloc1(h->nghost, &h->global));
  for (PetscInt g = 0, i = 0; g < h->nghost; g++) { /* kept ascends: so do the senders i */
    PetscInt c = kept[g];
    while (ex->fromstart[i + 1] <= c) i++;
    remote[g].rank  = ex->from[i];
    remote[g].index = from[c];
    h->global[g]    = starts[ex->from[i]] + from[c];
  }
  PetscCall(PetscFree(starts));
  PetscCall(PetscSFCreate(comm, &h->sf));
  PetscCall(PetscSFSetGraph(h->sf, h->nowned, h->nghost, NULL, PETSC_COPY_VALUES, remote, PETSC_OWN_POINTER));
  PetscCall(PetscSFSetUp(h->sf));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriHaloCreate - p holds this rank's particles (owned, numbered globally from the sum of the
  lower ranks' counts); appends as ghosts every other rank's particle within r of one of them
  (minimum image on periodic axes), in ascending global index, sets p->global and describes the
  ghosts in h.
  Collective: one sparse exchange (PeriExchange) and O(P) all-gathers; no array of the whole body.
@*/
PetscErrorCode PeriHaloCreate(MPI_Comm comm, PeriParticles *p, PetscReal r, PeriHalo *h)
{
  PeriExchange ex;
  PetscReal   *y;
  PetscInt    *sidx, *from, *kept;
  PetscBool   *near;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(h, sizeof(*h)));
  h->nowned = p->n;
  PetscCallMPI(MPI_Exscan(&h->nowned, &h->rstart, 1, MPIU_INT, MPI_SUM, comm));
  PetscCallMPI(MPI_Allreduce(&h->nowned, &h->N, 1, MPIU_INT, MPI_SUM, comm));
  {
    PetscMPIInt rank;
    PetscCallMPI(MPI_Comm_rank(comm, &rank));
    if (!rank) h->rstart = 0; /* MPI_Exscan leaves rank 0's result undefined */
  }
  PetscCall(PlanSends(comm, p, r, &ex, &sidx));
  PetscCall(SendCandidates(p, &ex, sidx, &y, &from));
  PetscCall(PetscMalloc2(ex.nrecv, &near, ex.nrecv, &kept));
  PetscCall(PeriParticlesNear(p, r, ex.nrecv, y, near));
  for (PetscInt c = 0; c < ex.nrecv; c++)
    if (near[c]) kept[h->nghost++] = c;
  PetscCall(BuildSF(comm, &ex, from, kept, h));
  PetscCall(AppendGhosts(p, h, y, kept));
  PetscCall(PetscFree2(near, kept));
  PetscCall(PetscFree2(y, from));
  PetscCall(PetscFree(sidx));
  PetscCall(PeriExchangeDestroy(&ex));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriHaloUpdate - copies the owners' values (one unit per owned particle) to the ghosts (one unit
  per ghost, in the order of h->global). Collective.
@*/
PetscErrorCode PeriHaloUpdate(const PeriHalo *h, MPI_Datatype unit, const void *owned, void *ghost)
{
  PetscFunctionBeginUser;
  PetscCall(PetscSFBcastBegin(h->sf, unit, owned, ghost, MPI_REPLACE));
  PetscCall(PetscSFBcastEnd(h->sf, unit, owned, ghost, MPI_REPLACE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriHaloDestroy(PeriHalo *h)
{
  PetscFunctionBeginUser;
  PetscCall(PetscSFDestroy(&h->sf));
  PetscCall(PetscFree(h->global));
  PetscCall(PetscMemzero(h, sizeof(*h)));
  PetscFunctionReturn(PETSC_SUCCESS);
}
