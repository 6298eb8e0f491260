#include "testing.h"

/* Loads, sets up and runs the scene's analysis on comm; no output files. */
PetscErrorCode PeriTestRunScene(MPI_Comm comm, const char file[], PeriProblem *p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriProblemCreate(comm, p));
  PetscCall(PeriProblemLoad(*p, file));
  PetscCall(PeriProblemSetUp(*p));
  PetscCall(PeriProblemRun(*p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sets (value) or clears (NULL) an option for the next scene. */
PetscErrorCode PeriTestSetOption(const char name[], const char value[])
{
  PetscFunctionBeginUser;
  if (value)
    PetscCall(PetscOptionsSetValue(NULL, name, value));
  else
    PetscCall(PetscOptionsClearValue(NULL, name));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The whole grid on every rank: positions (3 per cell), each cell's owner on size ranks and its
 * global number (owners in rank order, each owner's cells in grid order); free with PetscFree3. */
PetscErrorCode PeriTestGridCreate(const PeriTestGrid *c, PetscMPIInt size, PetscInt *N, PetscReal **x, PetscMPIInt **owner, PetscInt **number)
{
  PetscInt *fill;

  PetscFunctionBeginUser;
  *N = c->cells[0] * c->cells[1] * c->cells[2];
  PetscCall(PetscMalloc3(3 * *N, x, *N, owner, *N, number));
  PetscCall(PetscCalloc1(size + 1, &fill));
  for (PetscInt k = 0; k < *N; k++) {
    PetscInt i[3] = {k % c->cells[0], (k / c->cells[0]) % c->cells[1], k / (c->cells[0] * c->cells[1])};
    for (PetscInt d = 0; d < 3; d++) (*x)[3 * k + d] = d < c->dim ? (i[d] + 0.5) * 0.1 : 0;
    (*owner)[k] = (PetscMPIInt)(c->scattered ? k % size : k * size / *N);
    fill[(*owner)[k] + 1]++;
  }
  for (PetscMPIInt r = 0; r < size; r++) fill[r + 1] += fill[r];
  for (PetscInt k = 0; k < *N; k++) (*number)[k] = fill[(*owner)[k]]++;
  PetscCall(PetscFree(fill));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Distance between two points of the grid's box, minimum image on its periodic axes. */
PetscReal PeriTestGridDistance(const PeriTestGrid *c, const PetscReal a[], const PetscReal b[])
{
  PetscReal s = 0;
  for (PetscInt d = 0; d < c->dim; d++) {
    PetscReal L = 0.1 * c->cells[d], g = PetscAbsReal(a[d] - b[d]);
    if (c->periodic[d]) g = PetscMin(g, L - g);
    s += g * g;
  }
  return PetscSqrtReal(s);
}

/* The particles owner[] gives to rank, in the order of their global numbers: volume 1 + cell
 * index, spacing 0.1, source_line the cell index (how a test finds a particle in the whole grid). */
PetscErrorCode PeriTestGridOwned(const PeriTestGrid *c, PetscMPIInt rank, PetscInt N, const PetscReal x[], const PetscMPIInt owner[], PeriParticles *p)
{
  PetscInt n = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(p, sizeof(*p)));
  p->dim = c->dim;
  for (PetscInt d = 0; d < 3; d++) {
    p->lower[d]    = 0;
    p->upper[d]    = d < c->dim ? 0.1 * c->cells[d] : 0;
    p->periodic[d] = c->periodic[d];
  }
  for (PetscInt k = 0; k < N; k++) n += owner[k] == rank;
  PetscCall(PetscMalloc1(3 * n, &p->x));
  PetscCall(PetscMalloc3(n, &p->volume, n, &p->spacing, n, &p->source_line));
  for (PetscInt k = 0; k < N; k++)
    if (owner[k] == rank) {
      PetscCall(PetscArraycpy(&p->x[3 * p->n], &x[3 * k], 3));
      p->volume[p->n]      = 1 + k;
      p->spacing[p->n]     = 0.1;
      p->source_line[p->n] = k;
      p->n++;
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The least-squares slope of v against s over the n points where mask holds (NULL: all) of every
 * rank of comm: each rank's sums, then theirs. */
PetscErrorCode PeriTestSlope(MPI_Comm comm, PetscInt n, const PetscReal s[], PetscInt sstride, const PetscReal v[], PetscInt vstride, const PetscBool mask[], PetscReal *slope)
{
  PetscReal m[5] = {0, 0, 0, 0, 0}; /* count, sum s, sum v, sum s^2, sum s v */

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < n; k++) {
    const PetscReal x = s[k * sstride], y = v[k * vstride];
    if (mask && !mask[k]) continue;
    m[0] += 1;
    m[1] += x;
    m[2] += y;
    m[3] += x * x;
    m[4] += x * y;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, m, 5, MPIU_REAL, MPI_SUM, comm));
  *slope = (m[0] * m[4] - m[1] * m[2]) / (m[0] * m[3] - m[1] * m[1]);
  PetscFunctionReturn(PETSC_SUCCESS);
}
