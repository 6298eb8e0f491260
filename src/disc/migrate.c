/* Moving particles between ranks (issue 17, docs/distributed.md): each rank sends each of its
 * particles to the rank a partition names, through one sparse exchange (PeriExchange) for all the
 * arrays; no rank sees more than what it sends and receives. */
#include "perilin/private/disc.h"

/*@C
  PeriParticlesMigrate - sends particle k of this rank to rank target[k]. Afterwards p holds the
  particles received, ordered by the sending rank and, within it, by the sender's order (so a
  partition of contiguous ranges keeps the global order). Only positions, volumes, spacings and
  source lines travel: call it before fictitious layers exist. Collective.
@*/
PetscErrorCode PeriParticlesMigrate(MPI_Comm comm, PeriParticles *p, const PetscMPIInt target[])
{
  PeriExchange ex;
  PetscReal   *x, *vol, *sp;
  PetscInt    *line;

  PetscFunctionBeginUser;
  PetscCheck(!p->image && !p->global, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "only owned particles without fictitious layers migrate");
  PetscCall(PeriExchangeCreate(comm, p->n, target, &ex));
  PetscCall(PetscCalloc1(3 * ex.nrecv, &x));
  PetscCall(PetscMalloc3(ex.nrecv, &vol, ex.nrecv, &sp, ex.nrecv, &line));
  PetscCall(PeriExchangeSend(&ex, MPIU_REAL, 3, p->x, x));
  PetscCall(PeriExchangeSend(&ex, MPIU_REAL, 1, p->volume, vol));
  PetscCall(PeriExchangeSend(&ex, MPIU_REAL, 1, p->spacing, sp));
  PetscCall(PeriExchangeSend(&ex, MPIU_INT, 1, p->source_line, line));
  PetscCall(PetscFree(p->x));
  PetscCall(PetscFree3(p->volume, p->spacing, p->source_line));
  p->x           = x;
  p->volume      = vol;
  p->spacing     = sp;
  p->source_line = line;
  p->n           = ex.nrecv;
  PetscCall(PeriExchangeDestroy(&ex));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Gathers bs units per particle of every rank's in to rank 0's out, in rank order. */
static PetscErrorCode GatherArray(MPI_Comm comm, const PetscMPIInt count[], PetscInt n, PetscInt bs, MPI_Datatype unit, const void *in, void *out)
{
  PetscMPIInt rank, size, *c = NULL, *displ = NULL;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (rank == 0) {
    PetscCall(PetscMalloc2(size, &c, size, &displ));
    for (PetscMPIInt q = 0; q < size; q++) {
      c[q]     = (PetscMPIInt)bs * count[q];
      displ[q] = q ? displ[q - 1] + c[q - 1] : 0;
    }
  }
  PetscCallMPI(MPI_Gatherv(in, (PetscMPIInt)(bs * n), unit, out, c, displ, unit, 0, comm));
  if (rank == 0) PetscCall(PetscFree2(c, displ));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesGather - whole (on rank 0) holds every rank's particles of p, in rank order, with
  p's description of the body (box, periodic axes, thickness, mean spacing); on the other ranks
  it holds that description and no particles. The whole body on one rank: for what is inherently
  serial (METIS) on small runs. Collective.
@*/
PetscErrorCode PeriParticlesGather(MPI_Comm comm, const PeriParticles *p, PeriParticles *whole)
{
  PetscMPIInt rank, size, n = (PetscMPIInt)p->n, *count = NULL;
  PetscInt    N = 0;

  PetscFunctionBeginUser;
  PetscCheck(!p->image && !p->global, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "only owned particles without fictitious layers are gathered");
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (rank == 0) PetscCall(PetscMalloc1(size, &count));
  PetscCallMPI(MPI_Gather(&n, 1, MPI_INT, count, 1, MPI_INT, 0, comm));
  for (PetscMPIInt q = 0; rank == 0 && q < size; q++) N += count[q];
  PetscCall(PeriParticlesSlice(p, 0, 0, whole)); /* the body's description, no particles */
  PetscCall(PetscFree(whole->x));
  PetscCall(PetscFree3(whole->volume, whole->spacing, whole->source_line));
  PetscCall(PeriParticlesAllocate(whole, N));
  PetscCall(GatherArray(comm, count, p->n, 3, MPIU_REAL, p->x, whole->x));
  PetscCall(GatherArray(comm, count, p->n, 1, MPIU_REAL, p->volume, whole->volume));
  PetscCall(GatherArray(comm, count, p->n, 1, MPIU_REAL, p->spacing, whole->spacing));
  PetscCall(GatherArray(comm, count, p->n, 1, MPIU_INT, p->source_line, whole->source_line));
  PetscCall(PetscFree(count));
  PetscFunctionReturn(PETSC_SUCCESS);
}
