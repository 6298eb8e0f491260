/* A sparse all-to-all exchange (issue 25): each rank sends each of its items to one rank and
 * receives what the others send to it, without an O(P) all-to-all. The ranks that send to a rank
 * are learned with PetscCommBuildTwoSided; a PetscSF from the items sent (grouped by destination)
 * to the items received then carries any number of arrays. Used by the ghosts (halo.c), the
 * migration of particles (migrate.c) and the dead bonds of state-based families (failure.c). */
#include "perilin/private/disc.h"

/* The items in the order sent (grouped by destination rank, stably), the ranks sent to and, per
 * rank, the count and the offset of its items in that order. */
static PetscErrorCode GroupByDestination(MPI_Comm comm, PetscInt n, const PetscMPIInt dest[], PeriExchange *ex, PetscMPIInt *nto, PetscMPIInt **to, PetscInt **todata)
{
  PetscMPIInt size;
  PetscInt   *start;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscCalloc1(size + 1, &start));
  for (PetscInt k = 0; k < n; k++) {
    PetscCheck(dest[k] >= 0 && dest[k] < size, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "item %" PetscInt_FMT ": destination rank %d of %d", k, dest[k], size);
    start[dest[k] + 1]++;
  }
  *nto = 0;
  for (PetscMPIInt q = 0; q < size; q++) *nto += start[q + 1] > 0;
  PetscCall(PetscMalloc2(*nto, to, 2 * *nto, todata));
  for (PetscMPIInt q = 0, t = 0; q < size; q++) {
    if (start[q + 1] > 0) {
      (*to)[t]             = q;
      (*todata)[2 * t]     = start[q + 1];
      (*todata)[2 * t + 1] = start[q];
      t++;
    }
    start[q + 1] += start[q];
  }
  ex->nsend = n;
  PetscCall(PetscMalloc1(n, &ex->order));
  for (PetscInt k = 0; k < n; k++) ex->order[start[dest[k]]++] = k;
  PetscCall(PetscFree(start));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The senders in ascending rank, where their items start in what this rank receives, and each
 * received item's root: (sender, offset of the item in the sender's order). */
static PetscErrorCode ReceiveGraph(PeriExchange *ex, PetscMPIInt nfrom, PetscMPIInt from[], const PetscInt fromdata[], PetscSFNode **remote)
{
  PetscMPIInt *perm;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(nfrom, &perm));
  for (PetscMPIInt i = 0; i < nfrom; i++) perm[i] = i;
  PetscCall(PetscSortMPIIntWithArray(nfrom, from, perm));
  ex->nfrom = nfrom;
  ex->from  = from;
  PetscCall(PetscMalloc1(nfrom + 1, &ex->fromstart));
  ex->fromstart[0] = 0;
  for (PetscMPIInt i = 0; i < nfrom; i++) ex->fromstart[i + 1] = ex->fromstart[i] + fromdata[2 * perm[i]];
  ex->nrecv = ex->fromstart[nfrom];
  PetscCall(PetscMalloc1(ex->nrecv, remote));
  for (PetscMPIInt i = 0; i < nfrom; i++)
    for (PetscInt c = ex->fromstart[i]; c < ex->fromstart[i + 1]; c++) {
      (*remote)[c].rank  = from[i];
      (*remote)[c].index = fromdata[2 * perm[i] + 1] + c - ex->fromstart[i];
    }
  PetscCall(PetscFree(perm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriExchangeCreate - plans sending item k (0 <= k < n) of this rank to rank dest[k]. Each rank
  receives ex->nrecv items, ordered by the sending rank and, within it, by the sender's order:
  those from rank ex->from[i] (ascending) are ex->fromstart[i]..ex->fromstart[i+1]-1. A rank may
  send nothing, receive nothing, or send to itself. PeriExchangeSend then moves arrays.
  Collective: one sparse rendezvous (PetscCommBuildTwoSided); no O(P) communication.
@*/
PetscErrorCode PeriExchangeCreate(MPI_Comm comm, PetscInt n, const PetscMPIInt dest[], PeriExchange *ex)
{
  PetscMPIInt  nto, *to, nfrom, *from;
  PetscInt    *todata, *fromdata;
  PetscSFNode *remote;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(ex, sizeof(*ex)));
  PetscCall(GroupByDestination(comm, n, dest, ex, &nto, &to, &todata));
  PetscCall(PetscCommBuildTwoSided(comm, 2, MPIU_INT, nto, to, todata, &nfrom, &from, &fromdata));
  PetscCall(PetscFree2(to, todata));
  PetscCall(ReceiveGraph(ex, nfrom, from, fromdata, &remote));
  PetscCall(PetscFree(fromdata));
  PetscCall(PetscSFCreate(comm, &ex->sf));
  PetscCall(PetscSFSetGraph(ex->sf, ex->nsend, ex->nrecv, NULL, PETSC_COPY_VALUES, remote, PETSC_OWN_POINTER));
  PetscCall(PetscSFSetUp(ex->sf));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriExchangeSend - sends count values of type base per item of send (n items, in the order given
  to PeriExchangeCreate) and receives count values per received item into recv (ex->nrecv items).
  base is a predefined type. Collective.
@*/
PetscErrorCode PeriExchangeSend(const PeriExchange *ex, MPI_Datatype base, PetscInt count, const void *send, void *recv)
{
  MPI_Datatype unit = base;
  MPI_Aint     lb, extent;
  size_t       bytes;
  char        *buf;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Type_get_extent(base, &lb, &extent));
  bytes = (size_t)count * (size_t)extent;
  PetscCall(PetscMalloc1(ex->nsend * bytes, &buf));
  for (PetscInt s = 0; s < ex->nsend; s++) PetscCall(PetscMemcpy(buf + s * bytes, (const char *)send + ex->order[s] * bytes, bytes));
  if (count > 1) {
    PetscCallMPI(MPI_Type_contiguous((PetscMPIInt)count, base, &unit));
    PetscCallMPI(MPI_Type_commit(&unit));
  }
  PetscCall(PetscSFBcastBegin(ex->sf, unit, buf, recv, MPI_REPLACE));
  PetscCall(PetscSFBcastEnd(ex->sf, unit, buf, recv, MPI_REPLACE));
  if (count > 1) PetscCallMPI(MPI_Type_free(&unit));
  PetscCall(PetscFree(buf));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriExchangeDestroy(PeriExchange *ex)
{
  PetscFunctionBeginUser;
  PetscCall(PetscSFDestroy(&ex->sf));
  PetscCall(PetscFree(ex->order));
  PetscCall(PetscFree(ex->from));
  PetscCall(PetscFree(ex->fromstart));
  PetscCall(PetscMemzero(ex, sizeof(*ex)));
  PetscFunctionReturn(PETSC_SUCCESS);
}
