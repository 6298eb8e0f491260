/* The system's layout and bond geometry (bottom of src/system/): vectors with one block of DOFs per
 * owned particle, a bond's or a family's geometry for the model's kernels, and the local DOFs of a
 * state (owned and ghosts). Every other file of the system builds on these. */
#include "perilin/private/system.h"

/* A vector with one block of DOFs per owned particle. */
PetscErrorCode PeriSystemCreateVec(PeriSystem sys, Vec *v)
{
  PetscFunctionBeginUser;
  PetscCall(VecCreate(sys->comm, v));
  PetscCall(VecSetSizes(*v, (sys->disc.bonds.rend - sys->disc.bonds.rstart) * sys->model->dofs, PETSC_DETERMINE));
  PetscCall(VecSetBlockSize(*v, sys->model->dofs));
  PetscCall(VecSetFromOptions(*v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The kernel's view of bond k of owned particle i in the list b, its vector and length already in
 * g, with the partial-volume factor alpha (bond_mu: per bond, or NULL). */
static inline void FillGeometry(const PeriParticles *pt, const PeriBonds *b, const PetscReal bond_mu[], PetscInt i, PetscInt k, PetscReal alpha, PeriBondGeometry *g)
{
  g->i      = i;
  g->j      = b->j[k];
  g->Vi     = pt->volume[i];
  g->Vj     = pt->volume[g->j];
  g->weight = alpha * (b->lambda ? b->lambda[k] : 1) * (b->intact ? b->intact[k] : 1);
  g->mu     = bond_mu ? bond_mu[k] : 0;
  g->bond   = 0;
}

/* The kernel's view of local bond k of owned particle i (its geometry stored or recomputed:
 * PeriDiscBondGeometry). */
PetscErrorCode PeriSystemBondGeometry(PeriSystem sys, PetscInt i, PetscInt k, PeriBondGeometry *g)
{
  PetscReal alpha;

  PetscFunctionBeginUser;
  PeriDiscBondGeometry(&sys->disc, i, k, g->xi, &g->length, &alpha);
  FillGeometry(&sys->disc.particles, &sys->disc.bonds, sys->materials.bond_mu, i, k, alpha, g);
  g->bond = k + 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemBondVectorsFromCoordinates - whether every live bond of this rank to another particle
  has the vector X_j - X_i to the bit, so that a loop over the bonds may form it from the
  coordinates instead of reading it (the operator's spring form, the failure screen). A periodic
  image's is not; a list without stored vectors has them so. Not collective.
@*/
PetscBool PeriSystemBondVectorsFromCoordinates(PeriSystem sys)
{
  const PeriBonds *b = &sys->disc.bonds;
  const PetscReal *x = sys->disc.particles.x;

  if (!b->xi) return PETSC_TRUE;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++)
      for (PetscInt d = 0; d < 3 && b->live[k] && b->j[k] != i; d++)
        if (b->xi[3 * k + d] != x[3 * b->j[k] + d] - x[3 * i + d]) return PETSC_FALSE;
  return PETSC_TRUE;
}

/* Gathers the family of owned particle i from sys->disc.family (state-based models). */
PetscErrorCode PeriSystemFamilyGeometry(PeriSystem sys, PetscInt i, PetscInt *n, PeriBondGeometry fam[])
{
  const PeriBonds     *b  = &sys->disc.family;
  const PeriParticles *pt = &sys->disc.particles;

  PetscFunctionBeginUser;
  *n = 0;
  for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++)
    if (b->live[k]) {
      PeriBondGeometry *g = &fam[(*n)++];
      for (PetscInt d = 0; d < 3; d++) g->xi[d] = b->xi[3 * k + d];
      g->length = b->length[k];
      FillGeometry(pt, b, NULL, i, k, b->alpha[k], g);
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Largest family in sys->disc.family, for workspace. */
PetscInt PeriSystemMaxFamily(PeriSystem sys)
{
  PetscInt nmax = 0;
  for (PetscInt i = sys->disc.family.rstart; i < sys->disc.family.rend; i++) nmax = PetscMax(nmax, sys->disc.family.offset[i - sys->disc.family.rstart + 1] - sys->disc.family.offset[i - sys->disc.family.rstart]);
  return nmax;
}

/*@C
  PeriSystemLocalDOFs - the DOFs of the local view from the distributed u: the owned particles'
  from u, the ghosts' from their owners. *ul (particles.n x dofs) is freed with PetscFree.
  Collective.
@*/
PetscErrorCode PeriSystemLocalDOFs(PeriSystem sys, Vec u, PetscScalar **ul)
{
  const PetscInt     bs = sys->model->dofs;
  const PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(sys->disc.particles.n * bs, ul));
  PetscCall(VecGetArrayRead(u, &a));
  PetscCall(PetscArraycpy(*ul, a, sys->disc.nowned * bs));
  PetscCall(VecRestoreArrayRead(u, &a));
  PetscCall(PeriDiscOwnersToGhosts(&sys->disc, MPIU_SCALAR, bs, *ul));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* horizon.spacing's choices: one horizon for the body (mean), or one per particle (own); read by
 * the set-up (system.c) and the memory estimate (memory.c) */
const char *const PeriHorizonSpacings[] = {"mean", "own", NULL};

/*@C
  PeriSystemBondsLean - whether the bonds are searched without their geometry (PeriBonds.no_geometry),
  from what a scene and its model say: the set-up applies it (system.c, BondsWithoutGeometry),
  the memory estimate (memory.c) predicts with it. own: the
  particles have their own horizons; periodic: the body has a periodic axis; layers: fictitious
  boundary layers. Not collective.
@*/
PetscErrorCode PeriSystemBondsLean(PeriScene s, PeriModel m, PetscBool own, PetscBool periodic, PetscBool layers, PetscBool *lean)
{
  PetscBool release = PETSC_TRUE;
  PeriNode  failure, cracks;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_release_bond_geometry", &release, NULL));
  PetscCall(PeriSceneGetNode(s->root, "failure", &failure));
  PetscCall(PeriSceneGetNode(s->root, "cracks", &cracks));
  *lean = (PetscBool)(release && m->central_force && !PeriModelHasFamilies(m) && m->calibration == PERI_CALIBRATION_CONTINUUM && !own && !periodic && !layers && !failure && !cracks);
  PetscFunctionReturn(PETSC_SUCCESS);
}
