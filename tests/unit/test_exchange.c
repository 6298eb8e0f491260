/* The sparse all-to-all exchange (src/disc/exchange.c) against the items every rank can list for
 * itself: an uneven pattern (rank 0 sends nothing, the last rank receives nothing, a rank sends to
 * itself, destinations interleaved), and an exchange where no rank sends anything. Each rank must
 * receive exactly the items sent to it, by sending rank and then in the sender's order, with the
 * senders listed ascending; integer pairs and reals, one and several values per item. Any number
 * of ranks. */
#include "testing.h"

typedef struct {
  const char *name;
  PetscBool   empty; /* no rank sends anything */
} Case;

/* The items rank r sends: how many, and where item k goes. */
static PetscInt Count(const Case *c, PetscMPIInt r, PetscMPIInt size)
{
  if (c->empty || (r == 0 && size > 1)) return 0;
  return 3 * r + 5;
}

static PetscMPIInt Dest(PetscInt k, PetscMPIInt r, PetscMPIInt size)
{
  PetscMPIInt D = size > 1 ? size - 1 : 1; /* never the last rank when there are several */
  return (PetscMPIInt)((7 * k + r) % D);
}

/* What rank me must receive, in order: (sender, item) pairs; and the senders. */
static PetscErrorCode Expected(const Case *c, PetscMPIInt me, PetscMPIInt size, PetscInt *n, PetscInt **items, PetscMPIInt *nfrom, PetscMPIInt **from)
{
  PetscInt total = 0;

  PetscFunctionBeginUser;
  *n = *nfrom = 0;
  for (PetscMPIInt s = 0; s < size; s++) total += Count(c, s, size);
  PetscCall(PetscMalloc1(2 * total, items));
  PetscCall(PetscMalloc1(size, from));
  for (PetscMPIInt s = 0; s < size; s++) {
    PetscInt n0 = *n;
    for (PetscInt k = 0; k < Count(c, s, size); k++)
      if (Dest(k, s, size) == me) {
        (*items)[2 * *n]         = s;
        (*items)[2 * (*n)++ + 1] = k;
      }
    if (*n > n0) (*from)[(*nfrom)++] = s;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The plan's senders against the expected ones. */
static PetscErrorCode CheckPlan(const PeriExchange *ex, PetscMPIInt rank, PetscInt n, const PetscInt items[], PetscMPIInt nfrom, const PetscMPIInt from[])
{
  PetscFunctionBeginUser;
  PetscCheck(ex->nrecv == n, PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d receives %" PetscInt_FMT " items, expected %" PetscInt_FMT, rank, ex->nrecv, n);
  PetscCheck(ex->nfrom == nfrom, PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d has %d senders, expected %d", rank, ex->nfrom, nfrom);
  PetscCheck(ex->fromstart[0] == 0 && ex->fromstart[nfrom] == n, PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: senders' offsets do not cover the items", rank);
  for (PetscMPIInt i = 0; i < nfrom; i++) {
    PetscCheck(ex->from[i] == from[i], PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: sender %d is %d, expected %d", rank, i, ex->from[i], from[i]);
    for (PetscInt c = ex->fromstart[i]; c < ex->fromstart[i + 1]; c++) PetscCheck(items[2 * c] == from[i], PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: item %" PetscInt_FMT " listed under sender %d", rank, c, from[i]);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode RunCase(const Case *c)
{
  PetscMPIInt  rank, size, *dest, nfrom, *from;
  PetscInt     n, *pair, *got, nexp, *items, total = 0;
  PetscReal   *val, *gval, *tri, *gtri;
  PeriExchange ex;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  n = Count(c, rank, size);
  PetscCall(PetscMalloc4(n, &dest, 2 * n, &pair, n, &val, 3 * n, &tri));
  for (PetscInt k = 0; k < n; k++) {
    dest[k]         = Dest(k, rank, size);
    pair[2 * k]     = rank;
    pair[2 * k + 1] = k;
    val[k]          = rank + 0.001 * k + 0.5;
    for (PetscInt d = 0; d < 3; d++) tri[3 * k + d] = -val[k] * (d + 1);
  }
  PetscCall(PeriExchangeCreate(PETSC_COMM_WORLD, n, dest, &ex));
  PetscCall(Expected(c, rank, size, &nexp, &items, &nfrom, &from));
  PetscCall(CheckPlan(&ex, rank, nexp, items, nfrom, from));
  PetscCall(PetscMalloc3(2 * ex.nrecv, &got, ex.nrecv, &gval, 3 * ex.nrecv, &gtri));
  PetscCall(PeriExchangeSend(&ex, MPIU_INT, 2, pair, got));
  PetscCall(PeriExchangeSend(&ex, MPIU_REAL, 1, val, gval));
  PetscCall(PeriExchangeSend(&ex, MPIU_REAL, 3, tri, gtri));
  for (PetscInt i = 0; i < ex.nrecv; i++) {
    PetscReal v = items[2 * i] + 0.001 * items[2 * i + 1] + 0.5;
    PetscCheck(got[2 * i] == items[2 * i] && got[2 * i + 1] == items[2 * i + 1], PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: item %" PetscInt_FMT " is (%" PetscInt_FMT ", %" PetscInt_FMT "), expected (%" PetscInt_FMT ", %" PetscInt_FMT ")", rank, i, got[2 * i], got[2 * i + 1], items[2 * i], items[2 * i + 1]);
    PetscCheck(gval[i] == v, PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: item %" PetscInt_FMT ": value %g, expected %g", rank, i, (double)gval[i], (double)v);
    for (PetscInt d = 0; d < 3; d++) PetscCheck(gtri[3 * i + d] == -v * (d + 1), PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: item %" PetscInt_FMT ": component %" PetscInt_FMT " differs", rank, i, d);
  }
  PetscCallMPI(MPI_Allreduce(&ex.nrecv, &total, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s exchange on %d ranks: %" PetscInt_FMT " items, each where it was sent, in order\n", c->name, size, total));
  PetscCall(PeriExchangeDestroy(&ex));
  PetscCall(PetscFree3(got, gval, gtri));
  PetscCall(PetscFree(items));
  PetscCall(PetscFree(from));
  PetscCall(PetscFree4(dest, pair, val, tri));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const Case cases[] = {
      {"uneven", PETSC_FALSE},
      {"empty", PETSC_TRUE},
  };

  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) PetscCall(RunCase(&cases[k]));
  PetscCall(PetscFinalize());
  return 0;
}
