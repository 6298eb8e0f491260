/* PeriDisc: the one owner of the particle data (the local view, its halo and numbering, regions,
 * bonds, family volumes). Set up by the system (src/system/system.c), which interleaves the
 * cracks between the neighbour search and the volumes; freed here. */
#include "perilin/private/disc.h"

PetscErrorCode PeriDiscDestroy(PeriDisc *disc)
{
  PetscFunctionBeginUser;
  PetscCall(PeriBondsDestroy(&disc->bonds));
  PetscCall(PeriBondsDestroy(&disc->family));
  PetscCall(PeriParticlesDestroy(&disc->particles));
  PetscCall(PeriHaloDestroy(&disc->halo));
  PetscCall(PetscFree(disc->range));
  PetscCall(PetscFree(disc->horizon));
  PetscCall(PetscFree(disc->regions));
  PetscCall(PetscFree2(disc->family_volume, disc->neighbor_count));
  disc->nregions = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriDiscSetLocalView - owned holds this rank's particles (numbered globally after the lower
  ranks'); they become disc->particles with, after them, the ghosts within radius of one of them
  (PeriHaloCreate), and the numbering: N, nowned, rstart and range; the mesh groups keep the
  local view's particles only.
  owned is emptied. Collective.
@*/
PetscErrorCode PeriDiscSetLocalView(MPI_Comm comm, PeriDisc *disc, PeriParticles *owned, PetscReal radius)
{
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PeriHaloCreate(comm, owned, radius, &disc->halo));
  disc->ghost_radius = radius;
  disc->particles    = *owned;
  PetscCall(PetscMemzero(owned, sizeof(*owned)));
  PetscCall(PeriMeshGroupsRestrict(&disc->particles));
  disc->N      = disc->halo.N;
  disc->nowned = disc->halo.nowned;
  disc->rstart = disc->halo.rstart;
  disc->size   = size;
  PetscCall(PetscMalloc1(size + 1, &disc->range));
  PetscCallMPI(MPI_Allgather(&disc->rstart, 1, MPIU_INT, disc->range, 1, MPIU_INT, comm));
  disc->range[size] = disc->N;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The rank owning global particle g: the last r with range[r] <= g < range[r + 1] (a rank that owns
 * nothing has range[r] == range[r + 1]), by bisection: O(log P) per call. */
PetscMPIInt PeriDiscOwner(const PeriDisc *disc, PetscInt g)
{
  PetscMPIInt lo = 0, hi = disc->size; /* range has size + 1 entries */
  while (hi - lo > 1) {
    PetscMPIInt mid = (lo + hi) / 2;
    if (disc->range[mid] <= g)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

/* The local index of global particle g, or -1 when this rank holds no copy of it. */
PetscInt PeriDiscLocal(const PeriDisc *disc, PetscInt g)
{
  PetscInt loc;
  if (g >= disc->rstart && g < disc->rstart + disc->nowned) return g - disc->rstart;
  PetscFindInt(g, disc->halo.nghost, disc->halo.global, &loc);
  return loc < 0 ? -1 : disc->nowned + loc;
}

/* One unit of count values of type base (a committed contiguous type when count > 1). */
static PetscErrorCode UnitCreate(MPI_Datatype base, PetscInt count, MPI_Datatype *unit)
{
  PetscFunctionBeginUser;
  *unit = base;
  if (count == 1) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCallMPI(MPI_Type_contiguous((PetscMPIInt)count, base, unit));
  PetscCallMPI(MPI_Type_commit(unit));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode UnitDestroy(MPI_Datatype base, MPI_Datatype *unit)
{
  PetscFunctionBeginUser;
  if (*unit != base) PetscCallMPI(MPI_Type_free(unit));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriDiscGhostsToOwners - combines, with op, every ghost's entry of values (count of type base per
  local particle) into its owner's entry: the contributions a rank accumulated for particles it
  does not own reach their owners. The ghosts' entries are left as they were. Collective.
@*/
PetscErrorCode PeriDiscGhostsToOwners(const PeriDisc *disc, MPI_Datatype base, PetscInt count, MPI_Op op, void *values)
{
  MPI_Datatype unit;
  MPI_Aint     lb, extent;

  PetscFunctionBeginUser;
  PetscCall(UnitCreate(base, count, &unit));
  PetscCallMPI(MPI_Type_get_extent(unit, &lb, &extent));
  PetscCall(PetscSFReduceBegin(disc->halo.sf, unit, (char *)values + extent * disc->nowned, values, op));
  PetscCall(PetscSFReduceEnd(disc->halo.sf, unit, (char *)values + extent * disc->nowned, values, op));
  PetscCall(UnitDestroy(base, &unit));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The owners' entries of values (count of type base per local particle) copied to the ghosts'.
 * Collective. */
PetscErrorCode PeriDiscOwnersToGhosts(const PeriDisc *disc, MPI_Datatype base, PetscInt count, void *values)
{
  MPI_Datatype unit;
  MPI_Aint     lb, extent;

  PetscFunctionBeginUser;
  PetscCall(UnitCreate(base, count, &unit));
  PetscCallMPI(MPI_Type_get_extent(unit, &lb, &extent));
  PetscCall(PeriHaloUpdate(&disc->halo, unit, values, (char *)values + extent * disc->nowned));
  PetscCall(UnitDestroy(base, &unit));
  PetscFunctionReturn(PETSC_SUCCESS);
}
