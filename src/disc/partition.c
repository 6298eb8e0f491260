/* Partitioning: METIS k-way on rank 0, broadcast; particles are then renumbered so that each rank
 * owns a contiguous range (PETSc's row ownership). METIS sees the nearest-neighbour graph (bonds up
 * to 1.5 spacings): a horizon of m spacings only adds edges between particles that graph already
 * links through short paths, so it gives the same parts for a fraction of the graph size and search
 * time (docs/performance.md measures both). */
#include "perilin/private/disc.h"
#include <metis.h>

static PetscErrorCode MetisPartition(const PeriParticles *p, PetscReal radius, PetscMPIInt nparts, PetscInt part[])
{
  PeriBonds g;
  idx_t    *xadj, *adjncy, *where, nv = (idx_t)p->n, ncon = 1, np = nparts, objval = 0, options[METIS_NOPTIONS];
  PetscInt  ne = 0;
  int       status;

  PetscFunctionBeginUser;
  PetscCall(PeriNeighborSearch(p, radius, PERI_PARTIAL_VOLUME_NONE, 0, p->n, PETSC_FALSE, &g));
  PetscCall(PetscMalloc3(p->n + 1, &xadj, g.nbonds, &adjncy, p->n, &where));
  /* METIS wants each edge once per direction: drop repeated periodic images of a pair */
  xadj[0] = 0;
  for (PetscInt i = 0; i < p->n; i++) {
    PetscInt s = ne;
    for (PetscInt k = g.offset[i]; k < g.offset[i + 1]; k++) adjncy[ne++] = (idx_t)g.j[k];
    PetscCall(PetscSortInt(ne - s, (PetscInt *)&adjncy[s]));
    {
      PetscInt m = s;
      for (PetscInt k = s; k < ne; k++)
        if (k == s || adjncy[k] != adjncy[m - 1]) adjncy[m++] = adjncy[k];
      ne = m;
    }
    xadj[i + 1] = (idx_t)ne;
  }
  PetscCall(PeriBondsDestroy(&g));
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  status                     = METIS_PartGraphKway(&nv, &ncon, xadj, adjncy, NULL, NULL, NULL, &np, NULL, NULL, options, &objval, where);
  PetscCheck(status == METIS_OK, PETSC_COMM_SELF, PETSC_ERR_LIB, "METIS_PartGraphKway failed with status %d on %" PetscInt_FMT " particles and %d parts", status, p->n, (int)nparts);
  for (PetscInt i = 0; i < p->n; i++) part[i] = (PetscInt)where[i];
  PetscCall(PetscFree3(xadj, adjncy, where));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriPartition - partitions the particles over the ranks of comm. perm[k] is the old index of new
  particle k; rank r owns new particles range[r]..range[r+1]-1. Collective.
@*/
PetscErrorCode PeriPartition(MPI_Comm comm, const PeriParticles *p, PetscReal delta, PetscInt **perm, PetscInt **range)
{
  PetscMPIInt rank, size;
  PetscInt   *part, *fill;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscMalloc1(p->n, perm));
  PetscCall(PetscCalloc1(size + 1, range));
  PetscCall(PetscCalloc1(p->n, &part));
  if (size > 1) {
    PetscCheck(p->n >= size, comm, PETSC_ERR_USER_INPUT, "%" PetscInt_FMT " particles cannot be shared by %d ranks", p->n, size);
    PetscReal hmax = 0;
    for (PetscInt i = 0; i < p->n; i++) hmax = PetscMax(hmax, p->spacing[i]);
    if (rank == 0) PetscCall(MetisPartition(p, PetscMin(delta, 1.5 * hmax), size, part));
    PetscCallMPI(MPI_Bcast(part, (PetscMPIInt)p->n, MPIU_INT, 0, comm));
  }
  for (PetscInt i = 0; i < p->n; i++) (*range)[part[i] + 1]++;
  for (PetscMPIInt r = 0; r < size; r++) (*range)[r + 1] += (*range)[r];
  PetscCall(PetscMalloc1(size, &fill));
  PetscCall(PetscArraycpy(fill, *range, size));
  for (PetscInt i = 0; i < p->n; i++) (*perm)[fill[part[i]]++] = i;
  PetscCall(PetscFree(fill));
  PetscCall(PetscFree(part));
  PetscFunctionReturn(PETSC_SUCCESS);
}
