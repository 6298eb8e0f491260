/* Particles their bonds cannot hold (issue 27): a particle without bonds, or one whose bonds leave
 * it a motion of its own without energy (central springs all along one line in 2D, or in one
 * plane in 3D), makes K singular, and the solve then stops on a NaN or a breakdown that names no
 * particle. Both are refused before the solve with the count, the first particle's place and
 * region, and what to change. */
#include "perilin/private/system.h"

/* A pivot of a particle's own block, scaled to a unit diagonal, below this is a motion of the
 * particle that its bonds do not resist: central bonds in 2D within about 1e-5 rad of one line. */
#define PERI_HOLD_PIVOT 1e-10

/* PeriPointBefore - whether point a comes before b (x, then y, then z): the first particle is the
 * same on any ranks. */
PetscBool PeriPointBefore(const PetscReal a[], const PetscReal b[])
{
  for (PetscInt d = 0; d < 3; d++)
    if (a[d] != b[d]) return (PetscBool)(a[d] < b[d]);
  return PETSC_FALSE;
}

/* PeriRegionOf - the smallest region of the scene (besides all) that holds local particle i, or "". */
const char *PeriRegionOf(PeriSystem sys, PetscInt i)
{
  const PeriDisc *d    = &sys->disc;
  const char     *name = "";
  PetscInt        best = PETSC_MAX_INT;

  for (PetscInt g = 1; g < d->nregions; g++)
    if (d->regions[g].count < best && PeriRegionContains(&d->regions[g], &d->particles.x[3 * i])) {
      best = d->regions[g].count;
      name = d->regions[g].name;
    }
  return name;
}

/* Refuses the scene when an owned particle is flagged in bad: the count, and the place, region,
 * bonds and spacing of the first (by position), the same message on every rank. Collective. */
static PetscErrorCode Refuse(PeriSystem sys, const PetscBool bad[], const char what[], const char advice[])
{
  const PeriParticles *p     = &sys->disc.particles;
  PetscInt             count = 0, first = -1;
  PetscMPIInt          rank, size, root = -1;
  PetscReal            mine[4]    = {0, 0, 0, 0}, *all;
  char                 where[256] = "";

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->disc.nowned; i++)
    if (bad[i]) {
      count++;
      if (first < 0 || PeriPointBefore(&p->x[3 * i], &p->x[3 * first])) first = i;
    }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPIU_INT, MPI_SUM, sys->comm));
  if (!count) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCallMPI(MPI_Comm_rank(sys->comm, &rank));
  PetscCallMPI(MPI_Comm_size(sys->comm, &size));
  PetscCall(PetscMalloc1(4 * size, &all));
  if (first >= 0) {
    mine[0] = 1;
    for (PetscInt d = 0; d < 3; d++) mine[1 + d] = p->x[3 * first + d];
  }
  PetscCallMPI(MPI_Allgather(mine, 4, MPIU_REAL, all, 4, MPIU_REAL, sys->comm));
  for (PetscMPIInt r = 0; r < size; r++)
    if (all[4 * r] > 0 && (root < 0 || PeriPointBefore(&all[4 * r + 1], &all[4 * root + 1]))) root = r;
  PetscCall(PetscFree(all));
  if (rank == root) {
    const char *region = PeriRegionOf(sys, first);
    PetscCall(PetscSNPrintf(where, sizeof(where), "(%g, %g, %g)%s%s%s, with %" PetscInt_FMT " bond%s, spacing %g", (double)p->x[3 * first], (double)p->x[3 * first + 1], (double)p->x[3 * first + 2], region[0] ? " in region '" : "", region, region[0] ? "'" : "", sys->disc.neighbor_count[first], sys->disc.neighbor_count[first] == 1 ? "" : "s", (double)p->spacing[first]));
  }
  PetscCallMPI(MPI_Bcast(where, sizeof(where), MPI_CHAR, root, sys->comm));
  SETERRQ(sys->comm, PETSC_ERR_USER_INPUT, "%s: %" PetscInt_FMT " particle%s %s: the first at %s (horizon %g): %s", sys->scene->file, count, count == 1 ? "" : "s", what, where, (double)sys->disc.delta, advice);
}

static const char advice[] = "give a larger horizon.m or horizon.delta, or space the particles more evenly (a mesh graded more smoothly)";

/*@C
  PeriCheckBonded - refuses a scene where a particle has no live bond: it would move freely.
  Before the calibration, which divides by the family volumes. Collective.
@*/
PetscErrorCode PeriCheckBonded(PeriSystem sys)
{
  PetscBool     *bad;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(sys->disc.nowned, &bad));
  for (PetscInt i = 0; i < sys->disc.nowned; i++) bad[i] = (PetscBool)(sys->disc.neighbor_count[i] == 0 && !PeriParticleIsFictitious(&sys->disc.particles, i));
  ierr = Refuse(sys, bad, "without bonds would move freely", advice);
  PetscCall(PetscFree(bad)); /* a refused scene too: the Python module lives on after it */
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* PeriBlockHolds - whether the block A (bs x bs) is nonsingular on the DOFs free[]: LDL^T of A scaled to a unit
 * diagonal (so that the test does not depend on units, a rotation's stiffness beside a
 * displacement's), a pivot near 0 being a motion without energy. A negative pivot is no such
 * motion: the negative shear springs of nu > 1/3 make the block indefinite, and the solver, not
 * this check, answers for that (docs/models: CG stops with a reason, a direct solver solves). */
PetscBool PeriBlockHolds(PetscInt bs, const PetscReal A[], const PetscBool free[])
{
  PetscInt  f[PERI_MAX_DOF], n = 0;
  PetscReal L[PERI_MAX_DOF][PERI_MAX_DOF], d[PERI_MAX_DOF], sc[PERI_MAX_DOF];

  for (PetscInt a = 0; a < bs; a++)
    if (free[a]) {
      if (!(PetscAbsReal(A[a * bs + a]) > 0)) return PETSC_FALSE;
      sc[n]  = 1 / PetscSqrtReal(PetscAbsReal(A[a * bs + a]));
      f[n++] = a;
    }
  for (PetscInt k = 0; k < n; k++) {
    d[k] = A[f[k] * bs + f[k]] * sc[k] * sc[k];
    for (PetscInt l = 0; l < k; l++) d[k] -= L[k][l] * L[k][l] * d[l];
    if (PetscAbsReal(d[k]) <= PERI_HOLD_PIVOT) return PETSC_FALSE;
    for (PetscInt r = k + 1; r < n; r++) {
      PetscReal v = A[f[r] * bs + f[k]] * sc[r] * sc[k];
      for (PetscInt l = 0; l < k; l++) v -= L[r][l] * L[k][l] * d[l];
      L[r][k] = v / d[k];
    }
  }
  return PETSC_TRUE;
}

/* Each particle's own block K_ii of the local view: the sum of the ii blocks of its live bonds
 * (one pass over the bonds, the ghosts' shares sent to their owners). Collective. */
static PetscErrorCode OwnBlocks(PeriSystem sys, PetscReal A[])
{
  const PeriBonds *b  = &sys->disc.bonds;
  const PetscInt   bs = sys->model->dofs, nb = 2 * bs;
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF];
  PeriBondGeometry g;

  PetscFunctionBeginUser;
  PetscCall(PetscArrayzero(A, sys->disc.particles.n * bs * bs));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      if (!b->live[k] || b->j[k] == i) continue; /* a self-image moves with the particle */
      PetscCall(PeriBondStiffness(sys, i, k, 1, &g, Ke));
      for (PetscInt a = 0; a < bs; a++)
        for (PetscInt c = 0; c < bs; c++) {
          A[(i * bs + a) * bs + c] += Ke[a * nb + c];
          A[(b->j[k] * bs + a) * bs + c] += Ke[(bs + a) * nb + bs + c];
        }
    }
  PetscCall(PeriDiscGhostsToOwners(&sys->disc, MPIU_REAL, bs * bs, MPI_SUM, A));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Unflags the particles of the unloaded pieces cut off by cracks: the solve holds those in place
 * (PeriPieces). Collective. */
static PetscErrorCode ExemptHeldPieces(PeriSystem sys, PetscBool bad[])
{
  PetscInt   nhold, npieces, loc;
  PetscInt  *hold;
  PetscReal *held;
  PetscBool  lost;

  PetscFunctionBeginUser;
  PetscCall(PeriPieces(sys, &nhold, &hold, &held, &npieces, &lost));
  for (PetscInt i = 0; i < sys->disc.nowned; i++) {
    if (!bad[i]) continue;
    PetscCall(PetscFindInt((sys->disc.rstart + i) * sys->model->dofs, nhold, hold, &loc));
    if (loc >= 0) bad[i] = PETSC_FALSE;
  }
  PetscCall(PetscFree2(hold, held));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCheckHeld - refuses a scene where a particle's bonds leave it a motion of its own without
  energy on its free DOFs (neither held by a bc nor inactive): its own block K_ii is singular
  there, and so is K. For central-force bonds that is bonds all along one line in 2D, or in one
  plane in 3D; shear or micropolar bonds hold with fewer directions, which the block shows. The
  unloaded pieces cut off by cracks are exempt (the solve holds them); state-based models are not
  checked (a particle's energy couples its whole family). After the boundary conditions. Collective.
@*/
PetscErrorCode PeriCheckHeld(PeriSystem sys)
{
  const PetscInt bs = sys->model->dofs, no = sys->disc.nowned;
  PetscReal     *A;
  PetscBool     *bad, free[PERI_MAX_DOF];
  PetscInt       nbad = 0, loc;
  char           what[256];
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  if (sys->model->ops.family_stiffness) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc1(sys->disc.particles.n * bs * bs, &A));
  PetscCall(PetscMalloc1(no, &bad));
  PetscCall(OwnBlocks(sys, A));
  for (PetscInt i = 0; i < no; i++) {
    for (PetscInt c = 0; c < bs; c++) {
      PetscCall(PetscFindInt((sys->disc.rstart + i) * bs + c, sys->conditions.nconstrained, sys->conditions.constrained, &loc));
      free[c] = (PetscBool)(!sys->model->inactive[c] && loc < 0);
    }
    bad[i] = (PetscBool)(!PeriParticleIsFictitious(&sys->disc.particles, i) && !PeriBlockHolds(bs, &A[i * bs * bs], free));
    nbad += bad[i];
  }
  PetscCall(PetscFree(A));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &nbad, 1, MPIU_INT, MPI_SUM, sys->comm));
  if (nbad) PetscCall(ExemptHeldPieces(sys, bad));
  PetscCall(PetscSNPrintf(what, sizeof(what), "cannot be held by their bonds (model %s: each has a motion without energy%s)", sys->model->type, sys->model->central_force ? (sys->model->dim == 2 ? ", its central bonds all along one line" : ", its central bonds all in one plane") : ""));
  ierr = Refuse(sys, bad, what, advice);
  PetscCall(PetscFree(bad)); /* a refused scene too: the Python module lives on after it */
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}
