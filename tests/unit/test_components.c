/* Connected pieces of a distributed body (src/disc/components.c) against a serial union-find over
 * the whole grid, computed on every rank. Each rank builds its local view of a grid (block or
 * scattered ownership, PeriHaloCreate), links its owned particles to every local particle within
 * 1.5 spacings, stores each pair once (in either end's row, chosen at random) or twice, and kills
 * links: a pseudo-random share, every link across the mid-lines (four equal quarters in 2D: a tie
 * for the largest piece), every link of a few isolated particles, or all but those making one
 * snake through the columns (the most rank crossings for blocks). Labels (owned and ghosts), the
 * per-piece sums, maxima and minima, the number of pieces and the largest piece must equal the
 * serial ones exactly, and the exchange rounds stay within 3 + 2 log2 N. Any number of ranks. */
#include "testing.h"

typedef struct {
  PeriTestGrid g;
  PetscReal    kill;    /* share of links killed at random */
  PetscBool    cut;     /* every link across a mid-plane of each axis killed */
  PetscBool    isolate; /* every link of about 5 % of the particles killed */
  PetscBool    snake;   /* 2D: links between columns only in the top or bottom row, alternately */
  PetscBool    twice;   /* every pair in both rows; else in one end's row or both, at random */
} Case;

#define NV 3 /* per-particle values: a sum, a flag (maximum) and a minimum */

/* A deterministic uniform number in [0, 1) of an unordered pair of cells and a salt. */
static PetscReal Uniform(PetscInt a, PetscInt b, PetscInt salt)
{
  uint64_t h = (uint64_t)PetscMin(a, b) * 0x9E3779B97F4A7C15ull ^ (uint64_t)PetscMax(a, b) * 0xC2B2AE3D27D4EB4Full ^ (uint64_t)salt * 0x165667B19E3779F9ull;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 29;
  h *= 0x94D049BB133111EBull;
  h ^= h >> 32;
  return (PetscReal)(h >> 11) / 9007199254740992.0;
}

static void Cell(const PeriTestGrid *g, PetscInt k, PetscInt i[3])
{
  i[0] = k % g->cells[0];
  i[1] = (k / g->cells[0]) % g->cells[1];
  i[2] = k / (g->cells[0] * g->cells[1]);
}

/* Is the link between cells a and b alive? A function of the unordered pair alone, so that both
 * stored copies and the serial reference agree. */
static PetscBool Live(const Case *c, PetscInt a, PetscInt b)
{
  PetscInt ia[3], ib[3];

  Cell(&c->g, a, ia);
  Cell(&c->g, b, ib);
  if (Uniform(a, b, 1) < c->kill) return PETSC_FALSE;
  if (c->isolate && (Uniform(a, a, 2) < 0.05 || Uniform(b, b, 2) < 0.05)) return PETSC_FALSE;
  for (PetscInt d = 0; d < c->g.dim && c->cut; d++)
    if ((ia[d] < c->g.cells[d] / 2) != (ib[d] < c->g.cells[d] / 2)) return PETSC_FALSE;
  if (c->snake && ia[0] != ib[0]) {
    PetscInt lo = PetscMin(ia[0], ib[0]), row = lo % 2 ? 0 : c->g.cells[1] - 1;
    return (PetscBool)(PetscAbsInt(ia[0] - ib[0]) == 1 && ia[1] == row && ib[1] == row);
  }
  return PETSC_TRUE;
}

/* Does the row of local particle i (global gi, cell ki) store its link to l (gl, kl)? */
static PetscBool Stored(const Case *c, PetscInt gi, PetscInt gl, PetscInt ki, PetscInt kl)
{
  PetscReal u = Uniform(ki, kl, 3);
  if (c->twice) return PETSC_TRUE;
  return (PetscBool)(u < 1.0 / 3 ? gi < gl : u < 2.0 / 3 ? gi > gl
                                                         : PETSC_TRUE);
}

/* The CSR of this rank's links: row i (owned) to every stored local particle within r. */
static PetscErrorCode Links(const Case *c, const PeriParticles *p, const PeriHalo *h, PetscReal r, PetscInt **offset, PetscInt **j, unsigned char **live)
{
  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(h->nowned + 1, offset));
  for (PetscInt pass = 0; pass < 2; pass++) {
    PetscInt nz = 0;
    for (PetscInt i = 0; i < h->nowned; i++) {
      for (PetscInt l = 0; l < p->n; l++) {
        PetscInt ki = p->source_line[i], kl = p->source_line[l];
        if (l == i || PeriTestGridDistance(&c->g, &p->x[3 * i], &p->x[3 * l]) > r || !Stored(c, p->global[i], p->global[l], ki, kl)) continue;
        if (pass) {
          (*j)[nz]    = l;
          (*live)[nz] = (unsigned char)Live(c, ki, kl);
        }
        nz++;
      }
      if (!pass) (*offset)[i + 1] = nz;
    }
    if (!pass) PetscCall(PetscMalloc2(nz, j, nz, live));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscInt Find(PetscInt parent[], PetscInt k)
{
  while (parent[k] != k) k = parent[k] = parent[parent[k]];
  return k;
}

/* Serial reference: root[k] = the cell of smallest global number in cell k's piece (all pairs). */
static PetscErrorCode Reference(const Case *c, PetscInt N, const PetscReal x[], const PetscInt number[], PetscReal r, PetscInt root[])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < N; k++) root[k] = k;
  for (PetscInt a = 0; a < N; a++)
    for (PetscInt b = a + 1; b < N; b++) {
      PetscInt ra, rb;
      if (PeriTestGridDistance(&c->g, &x[3 * a], &x[3 * b]) > r || !Live(c, a, b)) continue;
      ra = Find(root, a);
      rb = Find(root, b);
      if (ra == rb) continue;
      if (number[ra] < number[rb])
        root[rb] = ra;
      else
        root[ra] = rb;
    }
  for (PetscInt k = 0; k < N; k++) root[k] = Find(root, k);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static void Values(PetscInt k, PetscInt v[NV])
{
  v[0] = 1 + k % 7;
  v[1] = Uniform(k, k, 4) < 0.1;
  v[2] = 3 + k % 11;
}

/* The serial totals per piece (at its root cell), the number of pieces and the largest one. */
static PetscErrorCode ReferenceTotals(PetscInt N, const PetscInt number[], const PetscInt root[], PetscInt tot[], PetscInt *npieces, PetscInt *largest)
{
  PetscInt *size, big = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(N, &size));
  for (PetscInt k = 0; k < N; k++) {
    tot[NV * k]     = 0;
    tot[NV * k + 1] = PETSC_MIN_INT;
    tot[NV * k + 2] = PETSC_MAX_INT;
  }
  for (PetscInt k = 0; k < N; k++) {
    PetscInt v[NV], *t = &tot[NV * root[k]];
    Values(k, v);
    t[0] += v[0];
    t[1] = PetscMax(t[1], v[1]);
    t[2] = PetscMin(t[2], v[2]);
    size[root[k]]++;
  }
  *npieces = 0;
  *largest = -1;
  for (PetscInt k = 0; k < N; k++) {
    if (root[k] != k) continue;
    (*npieces)++;
    if (size[k] > big || (size[k] == big && number[k] < *largest)) {
      big      = size[k];
      *largest = number[k];
    }
  }
  PetscCall(PetscFree(size));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every local label against the serial pieces. */
static PetscErrorCode CheckLabels(const PeriParticles *p, const PetscInt number[], const PetscInt root[], const PetscInt label[])
{
  PetscFunctionBeginUser;
  for (PetscInt l = 0; l < p->n; l++) {
    PetscInt k = p->source_line[l];
    PetscCheck(label[l] == number[root[k]], PETSC_COMM_SELF, PETSC_ERR_PLIB, "particle %" PetscInt_FMT " (global %" PetscInt_FMT "): label %" PetscInt_FMT ", serial %" PetscInt_FMT, l, p->global[l], label[l], number[root[k]]);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The per-piece totals, the number of pieces and the largest against the serial ones. */
static PetscErrorCode CheckTotals(const PeriHalo *h, const PeriParticles *p, PetscInt N, const PetscInt number[], const PetscInt root[], const PetscInt label[], PetscInt *npieces)
{
  const MPI_Op op[NV] = {MPI_SUM, MPI_MAX, MPI_MIN};
  PetscInt    *tot, *v, largest, en, elargest;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(NV * N, &tot, NV * h->nowned + 1, &v));
  PetscCall(ReferenceTotals(N, number, root, tot, &en, &elargest));
  for (PetscInt i = 0; i < h->nowned; i++) Values(p->source_line[i], &v[NV * i]);
  PetscCall(PeriComponentsReduce(PETSC_COMM_WORLD, h, label, NV, op, v, npieces, &largest));
  for (PetscInt i = 0; i < h->nowned; i++)
    for (PetscInt c = 0; c < NV; c++) {
      PetscInt e = tot[NV * root[p->source_line[i]] + c];
      PetscCheck(v[NV * i + c] == e, PETSC_COMM_SELF, PETSC_ERR_PLIB, "particle %" PetscInt_FMT ": total %" PetscInt_FMT " is %" PetscInt_FMT ", serial %" PetscInt_FMT, h->rstart + i, c, v[NV * i + c], e);
    }
  PetscCheck(*npieces == en && largest == elargest, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%" PetscInt_FMT " pieces, largest %" PetscInt_FMT "; serial %" PetscInt_FMT ", %" PetscInt_FMT, *npieces, largest, en, elargest);
  PetscCall(PetscFree2(tot, v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode RunCase(const Case *c, const char name[])
{
  const PetscReal r = 0.15; /* 1.5 spacings: 8 neighbours in 2D, 18 in 3D */
  PetscMPIInt     rank, size, *owner;
  PetscInt        N, *number, *root, *offset, *j, *label, rounds, npieces;
  unsigned char  *live;
  PetscReal      *x;
  PeriParticles   p;
  PeriHalo        h;
  PetscBool       all = (PetscBool)(c->kill == 0 && !c->cut && !c->isolate && !c->snake);

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PeriTestGridCreate(&c->g, size, &N, &x, &owner, &number));
  PetscCall(PeriTestGridOwned(&c->g, rank, N, x, owner, &p));
  PetscCall(PeriHaloCreate(PETSC_COMM_WORLD, &p, r * (1 + 1e-10), &h));
  PetscCall(Links(c, &p, &h, r, &offset, &j, &live));
  PetscCall(PetscMalloc2(p.n, &label, N, &root));
  PetscCall(PeriComponentsLabel(PETSC_COMM_WORLD, &h, offset, j, all ? NULL : live, label, &rounds));
  PetscCall(Reference(c, N, x, number, r, root));
  PetscCall(CheckLabels(&p, number, root, label));
  /* the shortcuts keep the rounds logarithmic (label propagation alone took 35 and 125 on the snake) */
  PetscCheck(rounds <= 3 + 2 * (PetscInt)PetscCeilReal(PetscLog2Real((PetscReal)N)), PETSC_COMM_SELF, PETSC_ERR_PLIB, "%" PetscInt_FMT " rounds for %" PetscInt_FMT " particles", rounds, N);
  PetscCall(CheckTotals(&h, &p, N, number, root, label, &npieces));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s, %" PetscInt_FMT "D %s%s, %" PetscInt_FMT " particles on %d ranks: %" PetscInt_FMT " pieces as serial, %" PetscInt_FMT " rounds\n", name, c->g.dim, c->g.scattered ? "scattered" : "blocks", c->g.periodic[0] ? ", periodic x" : "", N, size, npieces, rounds));
  PetscCall(PetscFree2(label, root));
  PetscCall(PetscFree(offset));
  PetscCall(PetscFree2(j, live));
  PetscCall(PeriHaloDestroy(&h));
  PetscCall(PeriParticlesDestroy(&p));
  PetscCall(PetscFree3(x, owner, number));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const PeriTestGrid plate = {2, {24, 16, 1}, {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}, PETSC_FALSE}, ring = {2, {24, 17, 1}, {PETSC_TRUE, PETSC_FALSE, PETSC_FALSE}, PETSC_FALSE};
  const PeriTestGrid row   = {2, {3, 1, 1}, {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}, PETSC_FALSE}; /* 4 ranks: one owns nothing */
  const PeriTestGrid snake = {2, {16, 12, 1}, {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}, PETSC_FALSE}, cube = {3, {9, 8, 7}, {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}, PETSC_FALSE};
  const struct {
    const char *name;
    Case        c;
  } cases[] = {
      {"intact, every pair twice, live NULL", {plate, 0, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE, PETSC_TRUE}},
      {"intact, pairs once or twice", {plate, 0, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}},
      {"half the links killed", {plate, 0.5, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}},
      {"every link killed", {plate, 1, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}},
      {"cut in four equal quarters", {plate, 0, PETSC_TRUE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}},
      {"cut in quarters, isolated particles, 20 % killed", {plate, 0.2, PETSC_TRUE, PETSC_TRUE, PETSC_FALSE, PETSC_TRUE}},
      {"periodic ring, isolated particles, 30 % killed", {ring, 0.3, PETSC_FALSE, PETSC_TRUE, PETSC_FALSE, PETSC_FALSE}},
      {"three particles, pairs once or twice", {row, 0, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}},
      {"three particles, every link killed", {row, 1, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}},
      {"snake through the columns", {snake, 0, PETSC_FALSE, PETSC_FALSE, PETSC_TRUE, PETSC_FALSE}},
      {"cube cut in eighths, 40 % killed", {cube, 0.4, PETSC_TRUE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE}},
      {"cube, isolated particles, 60 % killed", {cube, 0.6, PETSC_FALSE, PETSC_TRUE, PETSC_FALSE, PETSC_TRUE}},
  };

  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++)
    for (PetscInt scattered = 0; scattered < 2; scattered++) {
      Case c        = cases[k].c;
      c.g.scattered = (PetscBool)scattered;
      PetscCall(RunCase(&c, cases[k].name));
    }
  PetscCall(PetscFinalize());
  return 0;
}
