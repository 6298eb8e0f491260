/* The neighbour search for per-particle horizons (src/disc/levels.c) against brute force: on
 * graded, jittered clouds whose spacing grows 100-fold along x in 2D and 10-fold in 3D, each
 * particle's horizon m times its own spacing, every pair within the larger of its two horizons
 * (with the partial-volume ramp of each kind) must be bonded exactly once, with its brute-force
 * partial-volume factor, in the row of its smaller index (half) and in both rows (full). Then the
 * same clouds periodic across the columns (y, and z in 3D), with coarse horizons beyond the
 * period: every image of every pair (a particle's own images included) as brute force finds them. */
#include "testing.h"

/* A deterministic generator, so that the cloud is the same on every machine. */
static PetscReal Uniform(unsigned long long *s)
{
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (PetscReal)(*s >> 11) / 9007199254740992.0;
}

/* Columns across x whose spacing grows by 10 % from h0 to ratio h0; each column a jittered grid
 * of its spacing over the height (and depth) of 4 coarse spacings. */
static PetscErrorCode GradedCloud(PetscInt dim, PetscReal ratio, PeriParticles *p)
{
  const PetscReal    h0 = 0.01, H = 4 * ratio * h0;
  PetscInt           n = 0, cap = 0;
  unsigned long long seed = 12345;

  PetscFunctionBeginUser;
  for (PetscInt pass = 0; pass < 2; pass++) {
    PetscReal x = 0;
    if (pass) PetscCall(PeriParticlesAllocate(p, cap));
    n = 0;
    for (PetscReal h = h0; h <= ratio * h0 * (1 + 1e-12); h *= 1.1, x += h) {
      PetscInt m = (PetscInt)(H / h), mz = dim == 3 ? m : 1;
      for (PetscInt a = 0; a < m; a++)
        for (PetscInt c = 0; c < mz; c++, n++) {
          if (!pass) continue;
          p->x[3 * n]       = x + 0.3 * h * (2 * Uniform(&seed) - 1);
          p->x[3 * n + 1]   = (a + 0.5) * h + 0.3 * h * (2 * Uniform(&seed) - 1);
          p->x[3 * n + 2]   = dim == 3 ? (c + 0.5) * h + 0.3 * h * (2 * Uniform(&seed) - 1) : 0;
          p->spacing[n]     = h;
          p->volume[n]      = PetscPowRealInt(h, dim);
          p->source_line[n] = 0;
        }
    }
    cap = n;
  }
  p->dim       = dim;
  p->thickness = 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Bond i-j of b (row i) with bond vector x, or -1. */
static PetscInt FindBond(const PeriBonds *b, PetscInt i, PetscInt j, const PetscReal x[])
{
  for (PetscInt k = b->offset[i]; k < b->offset[i + 1]; k++)
    if (b->j[k] == j && PetscAbsReal(b->xi[3 * k] - x[0]) + PetscAbsReal(b->xi[3 * k + 1] - x[1]) + PetscAbsReal(b->xi[3 * k + 2] - x[2]) < 1e-12) return k;
  return -1;
}

/* Wraps the cloud into 0 .. H across the columns: periodic in y (and z in 3D). */
static void MakePeriodic(PeriParticles *p, PetscReal H)
{
  for (PetscInt d = 1; d < p->dim; d++) {
    p->periodic[d] = PETSC_TRUE;
    p->lower[d]    = 0;
    p->upper[d]    = H;
    for (PetscInt k = 0; k < p->n; k++) p->x[3 * k + d] -= H * PetscFloorReal(p->x[3 * k + d] / H);
  }
}

/* Is image w of the pair (i, j) due in i's row? Self-images once (w positive) in half lists,
 * never in full ones. */
static PetscBool Due(PetscInt i, PetscInt j, const PetscInt w[], PetscBool half)
{
  if (j != i) return (PetscBool)(!half || j > i);
  if (!half || (!w[0] && !w[1] && !w[2])) return PETSC_FALSE;
  for (PetscInt d = 0; d < 3; d++)
    if (w[d]) return (PetscBool)(w[d] > 0);
  return PETSC_FALSE;
}

static PetscErrorCode Check(const PeriParticles *p, const PetscReal horizon[], PeriPartialVolume pv, PetscBool half)
{
  PeriBonds b;
  PetscInt  expected = 0;
  PetscInt  lo[3], hi[3], w[3];
  PetscReal R = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriNeighborSearchLevels(p, horizon, pv, 0, p->n, half, &b));
  for (PetscInt k = 0; k < p->n; k++) R = PetscMax(R, 2 * horizon[k]); /* beyond any ramp */
  for (PetscInt i = 0; i < p->n; i++)
    for (PetscInt j = 0; j < p->n; j++) {
      for (PetscInt d = 0; d < 3; d++) { /* the images within R along each axis */
        PetscReal L = p->upper[d] - p->lower[d], dx = p->x[3 * j + d] - p->x[3 * i + d];
        lo[d] = p->periodic[d] ? (PetscInt)PetscCeilReal((-R - dx) / L) : 0;
        hi[d] = p->periodic[d] ? (PetscInt)PetscFloorReal((R - dx) / L) : 0;
      }
      for (w[2] = lo[2]; w[2] <= hi[2]; w[2]++)
        for (w[1] = lo[1]; w[1] <= hi[1]; w[1]++)
          for (w[0] = lo[0]; w[0] <= hi[0]; w[0]++) {
            PetscReal x[3], alpha;
            PetscInt  k;
            if (!Due(i, j, w, half)) continue;
            for (PetscInt d = 0; d < 3; d++) x[d] = p->x[3 * j + d] - p->x[3 * i + d] + (w[d] ? w[d] * (p->upper[d] - p->lower[d]) : 0);
            alpha = PeriPartialVolumeFactor(pv, PetscSqrtReal(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), PetscMax(horizon[i], horizon[j]), 0.5 * (p->spacing[i] + p->spacing[j]));
            if (alpha <= 0) continue; /* a bond where none is due shows in the count below */
            k = FindBond(&b, i, j, x);
            PetscCheck(k >= 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "dim %" PetscInt_FMT ", partial volume %s: pair %" PetscInt_FMT "-%" PetscInt_FMT " image (%" PetscInt_FMT ",%" PetscInt_FMT ",%" PetscInt_FMT ") (horizons %g, %g) missing", p->dim, PeriPartialVolumes[pv], i, j, w[0], w[1], w[2], (double)horizon[i], (double)horizon[j]);
            PetscCheck(b.alpha[k] == alpha, PETSC_COMM_SELF, PETSC_ERR_PLIB, "pair %" PetscInt_FMT "-%" PetscInt_FMT ": alpha %g, expected %g", i, j, (double)b.alpha[k], (double)alpha);
            expected++;
          }
    }
  PetscCheck(b.nbonds == expected, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%" PetscInt_FMT " bonds, expected %" PetscInt_FMT " (a pair listed twice?)", b.nbonds, expected);
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "ok: %" PetscInt_FMT "D%s, %" PetscInt_FMT " particles, partial volume %s, %s: %" PetscInt_FMT " bonds as brute force\n", p->dim, p->periodic[1] ? " periodic" : "", p->n, PeriPartialVolumes[pv], half ? "half" : "full", b.nbonds));
  PetscCall(PeriBondsDestroy(&b));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  for (PetscInt dim = 2; dim <= 3; dim++) {
    PeriParticles p;
    PetscReal    *horizon, m = dim == 2 ? 3 : 2;
    PetscCall(PetscMemzero(&p, sizeof(p)));
    PetscCall(GradedCloud(dim, dim == 2 ? 100 : 10, &p));
    PetscCall(PetscMalloc1(p.n, &horizon));
    for (PetscInt k = 0; k < p.n; k++) horizon[k] = m * p.spacing[k];
    for (PetscInt pv = 0; pv < 3; pv++) PetscCall(Check(&p, horizon, (PeriPartialVolume)pv, PETSC_TRUE));
    PetscCall(Check(&p, horizon, PERI_PARTIAL_VOLUME_LINEAR_CONTINUED, PETSC_FALSE));
    MakePeriodic(&p, 4 * (dim == 2 ? 100 : 10) * 0.01);
    for (PetscInt k = 0; k < p.n; k++) horizon[k] *= dim == 2 ? 1.6 : 2.2; /* coarse horizons beyond the period: self-images */
    PetscCall(Check(&p, horizon, PERI_PARTIAL_VOLUME_LINEAR_CONTINUED, PETSC_TRUE));
    PetscCall(Check(&p, horizon, PERI_PARTIAL_VOLUME_NONE, PETSC_FALSE));
    PetscCall(PetscFree(horizon));
    PetscCall(PeriParticlesDestroy(&p));
  }
  PetscCall(PetscFinalize());
  return 0;
}
