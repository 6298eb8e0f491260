/* PeriDisc: the one owner of the particle data (particles, regions, bonds, family volumes,
 * owners). Set up by the system (src/system/system.c), which interleaves the cracks between the
 * neighbour search and the volumes; freed here. */
#include "perilin/private/disc.h"

PetscErrorCode PeriDiscDestroy(PeriDisc *disc)
{
  PetscFunctionBeginUser;
  PetscCall(PeriBondsDestroy(&disc->bonds));
  PetscCall(PeriBondsDestroy(&disc->family));
  PetscCall(PeriParticlesDestroy(&disc->particles));

  PetscCall(PetscFree(disc->regions));
  PetscCall(PetscFree2(disc->family_volume, disc->neighbor_count));
  PetscCall(PetscFree(disc->owner));
  disc->nregions = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}
