/* Moving particles between ranks (issue 17, docs/distributed.md): each rank sends each of its
 * particles to the rank a partition names, with one all-to-all exchange per array; no rank sees
 * more than what it sends and receives. */
#include "perilin/private/disc.h"

typedef struct {
  PetscMPIInt *sc, *sd, *rc, *rd; /* per rank: particles sent and received, and their offsets */
  PetscInt    *order;             /* local particles sorted by target rank (stable) */
  PetscInt     nrecv;
} Plan;

static PetscErrorCode PlanCreate(MPI_Comm comm, PetscInt n, const PetscMPIInt target[], Plan *pl)
{
  PetscMPIInt size;
  PetscInt   *fill;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscCalloc4(size, &pl->sc, size + 1, &pl->sd, size, &pl->rc, size + 1, &pl->rd));
  for (PetscInt k = 0; k < n; k++) {
    PetscCheck(target[k] >= 0 && target[k] < size, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "particle %" PetscInt_FMT ": target rank %d of %d", k, target[k], size);
    pl->sc[target[k]]++;
  }
  PetscCallMPI(MPI_Alltoall(pl->sc, 1, MPI_INT, pl->rc, 1, MPI_INT, comm));
  for (PetscMPIInt q = 0; q < size; q++) {
    pl->sd[q + 1] = pl->sd[q] + pl->sc[q];
    pl->rd[q + 1] = pl->rd[q] + pl->rc[q];
  }
  pl->nrecv = pl->rd[size];
  PetscCall(PetscMalloc1(n, &pl->order));
  PetscCall(PetscMalloc1(size, &fill));
  for (PetscMPIInt q = 0; q < size; q++) fill[q] = pl->sd[q];
  for (PetscInt k = 0; k < n; k++) pl->order[fill[target[k]]++] = k;
  PetscCall(PetscFree(fill));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PlanDestroy(Plan *pl)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree4(pl->sc, pl->sd, pl->rc, pl->rd));
  PetscCall(PetscFree(pl->order));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sends bs units per particle of in (in the plan's order) and receives them into out. */
static PetscErrorCode Send(MPI_Comm comm, const Plan *pl, PetscInt n, PetscInt bs, MPI_Datatype unit, size_t usize, const void *in, void *out)
{
  PetscMPIInt size, *c;
  char       *buf;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscMalloc1(n * bs * usize, &buf));
  for (PetscInt s = 0; s < n; s++) PetscCall(PetscMemcpy(buf + s * bs * usize, (const char *)in + pl->order[s] * bs * usize, bs * usize));
  PetscCall(PetscMalloc1(4 * size, &c));
  for (PetscMPIInt q = 0; q < size; q++) {
    c[q]            = (PetscMPIInt)bs * pl->sc[q];
    c[size + q]     = (PetscMPIInt)bs * pl->sd[q];
    c[2 * size + q] = (PetscMPIInt)bs * pl->rc[q];
    c[3 * size + q] = (PetscMPIInt)bs * pl->rd[q];
  }
  PetscCallMPI(MPI_Alltoallv(buf, c, c + size, unit, out, c + 2 * size, c + 3 * size, unit, comm));
  PetscCall(PetscFree(c));
  PetscCall(PetscFree(buf));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesMigrate - sends particle k of this rank to rank target[k]. Afterwards p holds the
  particles received, ordered by the sending rank and, within it, by the sender's order (so a
  partition of contiguous ranges keeps the global order). Only positions, volumes, spacings and
  source lines travel: call it before fictitious layers exist. Collective.
@*/
PetscErrorCode PeriParticlesMigrate(MPI_Comm comm, PeriParticles *p, const PetscMPIInt target[])
{
  Plan       pl;
  PetscReal *x, *vol, *sp;
  PetscInt  *line;

  PetscFunctionBeginUser;
  PetscCheck(!p->image && !p->global, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "only owned particles without fictitious layers migrate");
  PetscCall(PlanCreate(comm, p->n, target, &pl));
  PetscCall(PetscCalloc1(3 * pl.nrecv, &x));
  PetscCall(PetscMalloc3(pl.nrecv, &vol, pl.nrecv, &sp, pl.nrecv, &line));
  PetscCall(Send(comm, &pl, p->n, 3, MPIU_REAL, sizeof(PetscReal), p->x, x));
  PetscCall(Send(comm, &pl, p->n, 1, MPIU_REAL, sizeof(PetscReal), p->volume, vol));
  PetscCall(Send(comm, &pl, p->n, 1, MPIU_REAL, sizeof(PetscReal), p->spacing, sp));
  PetscCall(Send(comm, &pl, p->n, 1, MPIU_INT, sizeof(PetscInt), p->source_line, line));
  PetscCall(PetscFree(p->x));
  PetscCall(PetscFree3(p->volume, p->spacing, p->source_line));
  p->x           = x;
  p->volume      = vol;
  p->spacing     = sp;
  p->source_line = line;
  p->n           = pl.nrecv;
  PetscCall(PlanDestroy(&pl));
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
