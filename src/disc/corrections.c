/* Corrections of the discrete horizon: family volumes (for calibration and for the surface
 * correction) and the volume-method surface correction factor of Diana & Casolo eq. (16). */
#include "perilin/private/disc.h"

const char *const PeriSurfaceCorrections[] = {"none", "volume", "energy", NULL};

/*@C
  PeriNeighborhoodVolumes - family volume sum_j alpha_ij V_j (the particle itself excluded) and
  neighbour count of every particle of the local view: each rank sums its bonds into both ends,
  the ghosts' sums reach their owners, and the owners' totals return to the ghosts. Collective.
@*/
PetscErrorCode PeriNeighborhoodVolumes(const PeriDisc *d, PetscReal family[], PetscInt count[])
{
  const PeriParticles *p = &d->particles;
  const PeriBonds     *b = &d->bonds;

  PetscFunctionBeginUser;
  PetscCall(PetscArrayzero(family, p->n));
  PetscCall(PetscArrayzero(count, p->n));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscInt  j = b->j[k];
      PetscReal alpha;
      if (!b->live[k]) continue;
      alpha = PeriDiscBondAlpha(d, i, k);
      /* a stored self-image stands for the pair of images +shift and -shift */
      family[i] += alpha * p->volume[j];
      family[j] += alpha * p->volume[i];
      count[i]++;
      count[j]++;
    }
  PetscCall(PeriDiscGhostsToOwners(d, MPIU_REAL, 1, MPI_SUM, family));
  PetscCall(PeriDiscGhostsToOwners(d, MPIU_INT, 1, MPI_SUM, count));
  PetscCall(PeriDiscOwnersToGhosts(d, MPIU_REAL, 1, family));
  PetscCall(PeriDiscOwnersToGhosts(d, MPIU_INT, 1, count));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The volume of a full continuous horizon of radius delta: pi delta^2 t in 2D, 4/3 pi delta^3 in 3D. */
static PetscReal HorizonVolume(const PeriParticles *p, PetscReal delta)
{
  return p->dim == 2 ? PETSC_PI * delta * delta * p->thickness : 4.0 / 3.0 * PETSC_PI * delta * delta * delta;
}

/*@C
  PeriSurfaceCorrectionApply - sets each bond's lambda. The volume method: lambda = 2 V0 /
  (V(H_i) + V(H_j)), V0 the volume of a full continuous horizon and V(H) the discrete volume of
  the body inside the horizon, the particle's own cell included. With per-particle horizons
  (horizon, else NULL) each end is measured against its own full horizon: lambda = 2 / (V(H_i) /
  V0_i + V(H_j) / V0_j), the same where the two agree. Not collective.
@*/
PetscErrorCode PeriSurfaceCorrectionApply(PeriSurfaceCorrection sc, const PeriParticles *p, PetscReal delta, const PetscReal horizon[], const PetscReal family[], PeriBonds *b)
{
  PetscReal V0 = HorizonVolume(p, delta);

  PetscFunctionBeginUser;
  if (!b->lambda && sc != PERI_SURFACE_VOLUME) PetscFunctionReturn(PETSC_SUCCESS); /* NULL: all 1 */
  if (!b->lambda) PetscCall(PetscMalloc1(b->nbonds, &b->lambda));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscInt j = b->j[k];
      if (sc != PERI_SURFACE_VOLUME)
        b->lambda[k] = 1.0;
      else if (horizon)
        b->lambda[k] = 2 / ((family[i] + p->volume[i]) / HorizonVolume(p, horizon[i]) + (family[j] + p->volume[j]) / HorizonVolume(p, horizon[j]));
      else
        b->lambda[k] = 2 * V0 / (family[i] + p->volume[i] + family[j] + p->volume[j]);
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}
