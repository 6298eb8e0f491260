/* Bond storage (PeriBonds): what it and the particles take (the memory estimates' counts),
 * growing it, adding a bond with its partial-volume factor, freeing and restoring its geometry;
 * the partial-volume rule itself. The searches (neighbors.c, levels.c) call these. */
#include "perilin/private/disc.h"

const char *const PeriPartialVolumes[] = {"none", "linear", "linear_continued", NULL};

/* Bonds of length within this relative slack of delta are inside the horizon: m = 3 gives
 * |xi| = 3 dx in floating point that must count whatever the rounding. */
#define PERI_HORIZON_SLACK 1e-10

/* The partial-volume factor of a bond of length r for horizon delta and spacing h: the share of
 * the neighbour's cell inside the horizon, a linear ramp that is 1/2 at delta (Diana & Casolo
 * eq. 9 with its sign corrected, see docs/theory.md). "linear" cuts the ramp at delta;
 * "linear_continued" lets it reach zero at delta + h/2. */
PetscReal PeriPartialVolumeFactor(PeriPartialVolume pv, PetscReal r, PetscReal delta, PetscReal h)
{
  const PetscReal rin = delta * (1 + PERI_HORIZON_SLACK);
  switch (pv) {
  case PERI_PARTIAL_VOLUME_NONE:
    return r <= rin ? 1.0 : 0.0;
  case PERI_PARTIAL_VOLUME_LINEAR:
    if (r > rin) return 0.0;
    break;
  case PERI_PARTIAL_VOLUME_LINEAR_CONTINUED:
    if (r >= delta + h / 2) return 0.0;
    break;
  }
  if (r <= delta - h / 2) return 1.0;
  return PetscMin(1.0, (delta + h / 2 - r) / h);
}

PetscReal PeriSearchRadius(PeriPartialVolume pv, PetscReal delta, PetscReal hmax)
{
  return pv == PERI_PARTIAL_VOLUME_LINEAR_CONTINUED ? delta + hmax / 2 : delta * (1 + PERI_HORIZON_SLACK);
}

/*@C
  PeriBondsBallCount - the lattice points within r spacings of a particle, itself excluded: its
  bonds at a search radius of r spacings, as the memory estimates count them (a grid's, a read
  file's and mesh's in src/system/memory.c; particles.refine's in mesh.c). Not collective.
@*/
PetscReal PeriBondsBallCount(PetscInt dim, PetscReal r)
{
  return (dim == 2 ? PETSC_PI * r * r : 4.0 / 3.0 * PETSC_PI * r * r * r) - 1;
}

/*@C
  PeriBondsBytesPerParticle - the bytes one particle's bonds take, ball of them within its search
  radius (PeriBondsBallCount), kept here beside the storage they count so that the estimates
  follow its layout: the neighbour search reserves 1.05 ball / 2 bonds (a half list) of j, xi,
  length, alpha and live (PeriBondsReserve), of which the share found (the faces leave fewer)
  each get their lambda; without stored geometry (lean, PeriBonds.no_geometry) j, live and the
  lambda of a surface correction. Not collective.
@*/
PetscReal PeriBondsBytesPerParticle(PetscReal ball, PetscReal share, PetscBool lean)
{
  if (lean) return ball / 2 * (1.05 * (sizeof(PetscInt) + 1) + share * sizeof(PetscReal));
  return ball / 2 * (1.05 * (sizeof(PetscInt) + 5 * sizeof(PetscReal) + 1) + share * sizeof(PetscReal));
}

/*@C
  PeriParticlesBytesPerParticle - the bytes of the arrays every particle holds with dofs
  displacement components, for the memory estimates (src/system/memory.c, mesh.c's of
  particles.refine; here beside the bonds' count, below both readers): coordinates, volume,
  spacing, line, family volume, neighbour count, the cell list, the local view's displacements
  and energy densities. Not collective.
@*/
PetscReal PeriParticlesBytesPerParticle(PetscInt dofs)
{
  return (8 + 2 * dofs + 1) * sizeof(PetscReal) + 6 * sizeof(PetscInt);
}

/* Growable bond storage. */
PetscErrorCode PeriBondsReserve(PeriBonds *b, PetscInt need, PetscInt *cap)
{
  PetscFunctionBeginUser;
  if (need <= *cap) PetscFunctionReturn(PETSC_SUCCESS);
  {
    PetscInt       nc = PetscMax(2 * *cap, need + 1024);
    PetscInt      *j;
    PetscReal     *xi, *len, *alpha;
    unsigned char *live;
    const PetscInt ng = b->no_geometry ? 0 : nc;
    PetscCall(PetscMalloc1(nc, &j));
    PetscCall(PetscMalloc1(3 * ng, &xi));
    PetscCall(PetscMalloc1(ng, &len));
    PetscCall(PetscMalloc1(ng, &alpha));
    PetscCall(PetscMalloc1(nc, &live));
    PetscCall(PetscArraycpy(j, b->j, b->nbonds));
    if (ng) PetscCall(PetscArraycpy(xi, b->xi, 3 * b->nbonds));
    if (ng) PetscCall(PetscArraycpy(len, b->length, b->nbonds));
    if (ng) PetscCall(PetscArraycpy(alpha, b->alpha, b->nbonds));
    PetscCall(PetscArraycpy(live, b->live, b->nbonds));
    PetscCall(PetscFree(b->j));
    PetscCall(PetscFree(b->xi));
    PetscCall(PetscFree(b->length));
    PetscCall(PetscFree(b->alpha));
    PetscCall(PetscFree(b->live));
    b->j      = j;
    b->xi     = xi;
    b->length = len;
    b->alpha  = alpha;
    b->live   = live;
    *cap      = nc;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriBondsAdd - appends the bond of i to j (x = X_j - X_i, image shift included) for horizon delta
  when its partial-volume factor is positive. Errors on coincident particles. Not collective.
@*/
PetscErrorCode PeriBondsAdd(const PeriParticles *p, PetscInt i, PetscInt j, const PetscReal x[], PetscReal delta, PeriPartialVolume pv, PeriBonds *b, PetscInt *cap)
{
  PetscReal len = PetscSqrtReal(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), h = 0.5 * (p->spacing[i] + p->spacing[j]), alpha;

  PetscFunctionBeginUser;
  PetscCheck(len > 1e-8 * h, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "particles %" PetscInt_FMT " and %" PetscInt_FMT " coincide at (%g, %g, %g)%s (distance %g, spacing %g)", p->source_line[i] ? p->source_line[i] : i, p->source_line[j] ? p->source_line[j] : j, (double)p->x[3 * i], (double)p->x[3 * i + 1], (double)p->x[3 * i + 2], p->source_line[i] ? " (the numbers are lines of particles.file)" : "", (double)len, (double)h);
  alpha = PeriPartialVolumeFactor(pv, len, delta, h);
  if (alpha <= 0) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriBondsReserve(b, b->nbonds + 1, cap));
  b->j[b->nbonds]    = j;
  b->live[b->nbonds] = 1;
  if (b->no_geometry) {
    b->nbonds++;
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  for (PetscInt d = 0; d < 3; d++) b->xi[3 * b->nbonds + d] = x[d];
  b->length[b->nbonds] = len;
  b->alpha[b->nbonds]  = alpha;
  b->nbonds++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriBondsDestroy(PeriBonds *b)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(b->offset));
  PetscCall(PetscFree(b->j));
  PetscCall(PetscFree(b->xi));
  PetscCall(PetscFree(b->length));
  PetscCall(PetscFree(b->alpha));
  PetscCall(PetscFree(b->lambda));
  PetscCall(PetscFree(b->live));
  PetscCall(PetscFree(b->intact));
  PetscCall(PetscFree(b->cause));
  b->nbonds = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriBondsReleaseGeometry - frees the bond vectors, lengths and partial-volume factors (40 of the
  53 bytes a bond holds), and the surface factors when all are 1 (8 more), while nothing reads
  them; PeriBondsRestoreGeometry recomputes them. Only for bodies without periodic axes, whose
  bonds never join images (*released says whether it freed them). Not collective.
@*/
PetscErrorCode PeriBondsReleaseGeometry(const PeriParticles *p, PeriBonds *b, PetscBool *released)
{
  PetscFunctionBeginUser;
  *released = PETSC_FALSE;
  for (PetscInt d = 0; d < 3; d++)
    if (p->periodic[d]) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscFree(b->xi));
  PetscCall(PetscFree(b->length));
  PetscCall(PetscFree(b->alpha));
  if (b->lambda) {
    PetscInt k = 0;
    while (k < b->nbonds && b->lambda[k] == 1) k++;
    if (k == b->nbonds) PetscCall(PetscFree(b->lambda));
  }
  *released = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The geometry of the bond from particle i to j of p without an image shift, with the search's
 * arithmetic (ParticleBonds: x_j + wrap L - x_i with wrap = 0; + 0.0 keeps the sign of a zero
 * alike), so that every value is the same to the bit. */
static void BondGeometryFromCoordinates(const PeriParticles *p, PetscReal delta, const PetscReal horizon[], PeriPartialVolume pv, PetscInt i, PetscInt j, PetscReal xi[], PetscReal *len, PetscReal *alpha)
{
  PetscReal len2 = 0;
  for (PetscInt d = 0; d < 3; d++) {
    xi[d] = p->x[3 * j + d] + 0.0 - p->x[3 * i + d];
    len2 += xi[d] * xi[d];
  }
  *len   = PetscSqrtReal(len2);
  *alpha = PeriPartialVolumeFactor(pv, *len, horizon ? PetscMax(horizon[i], horizon[j]) : delta, 0.5 * (p->spacing[i] + p->spacing[j]));
}

/*@C
  PeriBondsRestoreGeometry - recomputes what PeriBondsReleaseGeometry freed (or a search without
  geometry left out), with the arithmetic of the search (ParticleBonds with no image shift), so
  every value is the same to the bit; the arrays are sized to the bonds exactly. Not collective.
@*/
PetscErrorCode PeriBondsRestoreGeometry(const PeriParticles *p, PetscReal delta, const PetscReal horizon[], PeriPartialVolume pv, PeriBonds *b)
{
  PetscFunctionBeginUser;
  if (!b->lambda) {
    PetscCall(PetscMalloc1(b->nbonds, &b->lambda));
    for (PetscInt k = 0; k < b->nbonds; k++) b->lambda[k] = 1;
  }
  PetscCall(PetscMalloc1(3 * b->nbonds, &b->xi));
  PetscCall(PetscMalloc1(b->nbonds, &b->length));
  PetscCall(PetscMalloc1(b->nbonds, &b->alpha));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) BondGeometryFromCoordinates(p, delta, horizon, pv, i, b->j[k], &b->xi[3 * k], &b->length[k], &b->alpha[k]);
  b->no_geometry = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriDiscBondGeometryFromCoordinates - PeriDiscBondGeometry's recomputation, where d's pair list
  does not store the geometry. Not collective.
@*/
void PeriDiscBondGeometryFromCoordinates(const PeriDisc *d, PetscInt i, PetscInt k, PetscReal xi[], PetscReal *len, PetscReal *alpha)
{
  BondGeometryFromCoordinates(&d->particles, d->delta, d->horizon, d->partial_volume, i, d->bonds.j[k], xi, len, alpha);
}
