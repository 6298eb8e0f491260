/* Ghost particles (src/disc/halo.c) against brute force: on grids in 2D and 3D, with and without a
 * periodic axis, for a block partition and a scattered one (every rank's box covers the whole
 * body), each rank's ghosts must be exactly the other ranks' particles within the radius of one of
 * its own (minimum image, all pairs checked), in ascending global index, with their positions,
 * volumes and spacings; PeriHaloUpdate must deliver the owners' values. PeriParticlesMigrate from
 * blocks to the scattered owners must deliver exactly their particles in order. Any number of ranks. */
#include "testing.h"

typedef struct {
  PeriTestGrid g;        /* the grid and its owners (tests/testing.c) */
  PetscBool    migrated; /* scattered: reached by PeriParticlesMigrate from contiguous blocks */
} Case;

/* Blocks migrated to the scattered owners must arrive as PeriTestGridOwned() builds them: same particles, same order. */
static PetscErrorCode Migrated(const Case *c, PetscMPIInt rank, PetscMPIInt size, PetscInt N, const PetscReal x[], const PetscMPIInt owner[], PeriParticles *p)
{
  PetscMPIInt  *blocks, *target;
  PeriParticles q;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(N, &blocks));
  for (PetscInt k = 0; k < N; k++) blocks[k] = (PetscMPIInt)(k * size / N);
  PetscCall(PeriTestGridOwned(&c->g, rank, N, x, blocks, p));
  PetscCall(PetscMalloc1(p->n, &target));
  for (PetscInt i = 0; i < p->n; i++) target[i] = owner[p->source_line[i]];
  PetscCall(PeriParticlesMigrate(PETSC_COMM_WORLD, p, target));
  PetscCall(PeriTestGridOwned(&c->g, rank, N, x, owner, &q));
  PetscCheck(q.n == p->n, PETSC_COMM_SELF, PETSC_ERR_PLIB, "migrate: rank %d holds %" PetscInt_FMT " particles, expected %" PetscInt_FMT, rank, p->n, q.n);
  for (PetscInt i = 0; i < q.n; i++) {
    PetscBool same = (PetscBool)(q.source_line[i] == p->source_line[i] && q.volume[i] == p->volume[i] && q.spacing[i] == p->spacing[i]);
    for (PetscInt d = 0; d < 3; d++) same = (PetscBool)(same && q.x[3 * i + d] == p->x[3 * i + d]);
    PetscCheck(same, PETSC_COMM_SELF, PETSC_ERR_PLIB, "migrate: rank %d, particle %" PetscInt_FMT " is %" PetscInt_FMT ", expected %" PetscInt_FMT, rank, i, p->source_line[i], q.source_line[i]);
  }
  PetscCall(PeriParticlesDestroy(&q));
  PetscCall(PetscFree(target));
  PetscCall(PetscFree(blocks));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The brute-force ghost list, ascending by new global number. */
static PetscErrorCode Expected(const Case *c, PetscMPIInt rank, PetscInt N, const PetscReal x[], const PetscMPIInt owner[], const PetscInt number[], PetscReal r, PetscInt *ng, PetscInt **g)
{
  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(N, g));
  *ng = 0;
  for (PetscInt j = 0; j < N; j++) {
    PetscBool near = PETSC_FALSE;
    if (owner[j] == rank) continue;
    for (PetscInt i = 0; i < N && !near; i++) near = (PetscBool)(owner[i] == rank && PeriTestGridDistance(&c->g, &x[3 * i], &x[3 * j]) <= r);
    if (near) (*g)[(*ng)++] = number[j];
  }
  PetscCall(PetscSortInt(*ng, *g));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The ghosts' data against the whole grid, found by their original index (source_line). */
static PetscErrorCode CheckGhostData(const PeriParticles *p, const PeriHalo *h, const PetscReal x[], const PetscInt number[])
{
  PetscReal *vol;

  PetscFunctionBeginUser;
  for (PetscInt g = 0; g < h->nghost; g++) {
    PetscInt l = h->nowned + g, k = p->source_line[l];
    PetscCheck(number[k] == h->global[g], PETSC_COMM_SELF, PETSC_ERR_PLIB, "ghost %" PetscInt_FMT ": global %" PetscInt_FMT " but its data is particle %" PetscInt_FMT "'s (global %" PetscInt_FMT ")", g, h->global[g], k, number[k]);
    for (PetscInt d = 0; d < 3; d++) PetscCheck(p->x[3 * l + d] == x[3 * k + d], PETSC_COMM_SELF, PETSC_ERR_PLIB, "ghost %" PetscInt_FMT ": position differs", g);
    PetscCheck(p->volume[l] == 1 + k && p->spacing[l] == 0.1, PETSC_COMM_SELF, PETSC_ERR_PLIB, "ghost %" PetscInt_FMT ": volume or spacing differs", g);
  }
  /* an update of a field known in closed form: 2.5 x the global number */
  PetscCall(PetscMalloc1(p->n, &vol));
  for (PetscInt i = 0; i < h->nowned; i++) vol[i] = 2.5 * (h->rstart + i);
  PetscCall(PeriHaloUpdate(h, MPIU_REAL, vol, vol + h->nowned));
  for (PetscInt g = 0; g < h->nghost; g++) PetscCheck(vol[h->nowned + g] == 2.5 * h->global[g], PETSC_COMM_SELF, PETSC_ERR_PLIB, "update: ghost %" PetscInt_FMT " got %g", g, (double)vol[h->nowned + g]);
  PetscCall(PetscFree(vol));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode RunCase(const Case *c, PetscReal r)
{
  PetscMPIInt   rank, size, *owner;
  PetscInt      N, *number, ng, *g, total = 0;
  PetscReal    *x;
  PeriParticles p;
  PeriHalo      h;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PeriTestGridCreate(&c->g, size, &N, &x, &owner, &number));
  if (c->migrated)
    PetscCall(Migrated(c, rank, size, N, x, owner, &p));
  else
    PetscCall(PeriTestGridOwned(&c->g, rank, N, x, owner, &p));
  PetscCall(PeriHaloCreate(PETSC_COMM_WORLD, &p, r, &h));
  PetscCheck(h.N == N && p.n == h.nowned + h.nghost, PETSC_COMM_SELF, PETSC_ERR_PLIB, "counts: N %" PetscInt_FMT " (expected %" PetscInt_FMT "), local %" PetscInt_FMT, h.N, N, p.n);
  PetscCheck(h.nowned == 0 || number[p.source_line[0]] == h.rstart, PETSC_COMM_SELF, PETSC_ERR_PLIB, "rstart %" PetscInt_FMT, h.rstart);
  PetscCall(Expected(c, rank, N, x, owner, number, r, &ng, &g));
  PetscCheck(ng == h.nghost, PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: %" PetscInt_FMT " ghosts, brute force finds %" PetscInt_FMT, rank, h.nghost, ng);
  for (PetscInt k = 0; k < ng; k++) PetscCheck(g[k] == h.global[k], PETSC_COMM_SELF, PETSC_ERR_PLIB, "rank %d: ghost %" PetscInt_FMT " is %" PetscInt_FMT ", expected %" PetscInt_FMT, rank, k, h.global[k], g[k]);
  PetscCall(CheckGhostData(&p, &h, x, number));
  PetscCallMPI(MPI_Allreduce(&h.nghost, &total, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %" PetscInt_FMT "D %s%s%s, %" PetscInt_FMT " particles, radius %g: %" PetscInt_FMT " ghosts on %d ranks, as brute force\n", c->g.dim, c->g.scattered ? "scattered" : "blocks", c->migrated ? " (migrated from blocks)" : "", c->g.periodic[0] ? ", periodic x" : "", N, (double)r, total, size));
  PetscCall(PetscFree(g));
  PetscCall(PeriHaloDestroy(&h));
  PetscCall(PeriParticlesDestroy(&p));
  PetscCall(PetscFree3(x, owner, number));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const Case cases[] = {
      {{2, {24, 17, 1}, {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}, PETSC_FALSE}, PETSC_FALSE},
      {{2, {24, 17, 1}, {PETSC_TRUE, PETSC_FALSE, PETSC_FALSE}, PETSC_FALSE}, PETSC_FALSE},
      {{2, {13, 11, 1}, {PETSC_TRUE, PETSC_FALSE, PETSC_FALSE}, PETSC_TRUE}, PETSC_FALSE},
      {{2, {13, 11, 1}, {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}, PETSC_TRUE}, PETSC_TRUE},
      {{3, {9, 8, 7}, {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}, PETSC_FALSE}, PETSC_FALSE},
      {{3, {6, 5, 7}, {PETSC_TRUE, PETSC_FALSE, PETSC_FALSE}, PETSC_TRUE}, PETSC_TRUE},
  };

  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
    PetscCall(RunCase(&cases[k], 0.3 * (1 + 1e-10)));
    PetscCall(RunCase(&cases[k], 0.15));
  }
  PetscCall(PetscFinalize());
  return 0;
}
