/* The conditions as particle arrays of particles.vtu, in every analysis and in a setup run above
 * all: which components each particle has fixed and to what value, the force the loads put on it,
 * and the regions it lies in, so that a scene's boundary conditions can be checked in ParaView
 * before anything is solved (docs/summary.md lists the arrays). */
#include "perilin/private/system.h"

PetscErrorCode PeriConditionFieldsDestroy(PeriConditionFields *F)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree3(F->fixed, F->prescribed, F->force));
  PetscCall(PetscFree(F->in_region));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* fixed and prescribed from the constrained DOFs (this rank's, global rows), force from the loads
 * vector (at load factor 1: what a static solve takes as its right-hand side). */
static PetscErrorCode FillDOFs(PeriSystem sys, PeriConditionFields *F, PetscInt ndof)
{
  const PeriConditions *C  = &sys->conditions;
  const PetscInt        r0 = sys->disc.rstart * sys->model->dofs;
  const PetscScalar    *f;
  PetscInt              nf;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < C->nconstrained; k++) {
    const PetscInt j = C->constrained[k] - r0;
    PetscCheck(j >= 0 && j < ndof, PETSC_COMM_SELF, PETSC_ERR_PLIB, "constrained row %" PetscInt_FMT " is not an owned DOF", C->constrained[k]);
    F->fixed[j]      = 1;
    F->prescribed[j] = C->constrained_value[k];
  }
  if (!sys->fields.f) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecGetLocalSize(sys->fields.f, &nf));
  PetscCheck(nf == ndof, PETSC_COMM_SELF, PETSC_ERR_PLIB, "the loads' local size %" PetscInt_FMT " is not the owned particles' DOFs %" PetscInt_FMT, nf, ndof);
  PetscCall(VecGetArrayRead(sys->fields.f, &f));
  for (PetscInt j = 0; j < ndof; j++) F->force[j] = PetscRealPart(f[j]);
  PetscCall(VecRestoreArrayRead(sys->fields.f, &f));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* region_<name>: 1 for the owned particles inside each region (a particle may lie in several);
 * not the built-in region all, which holds every particle. */
static PetscErrorCode AddRegions(PeriSystem sys, PeriFieldList fl, PeriConditionFields *F, PetscInt n)
{
  const PeriDisc *disc = &sys->disc;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(PetscMax(disc->nregions * n, 1), &F->in_region));
  for (PetscInt r = 0; r < disc->nregions; r++) {
    char name[PERI_NAME_LEN + 8];
    if (disc->regions[r].kind == PERI_REGION_ALL) continue;
    for (PetscInt i = 0; i < n; i++) F->in_region[r * n + i] = PeriRegionContains(&disc->regions[r], &disc->particles.x[3 * (disc->bonds.rstart + i)]) ? 1 : 0;
    PetscCall(PetscSNPrintf(name, sizeof(name), "region_%s", disc->regions[r].name));
    PetscCall(PeriFieldListAddFlags(fl, name, 1, &F->in_region[r * n], NULL));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriConditionsAddFields - the conditions' arrays of the owned particles: fixed (UInt8, one
  component per DOF, named as the model's: ux, uy, theta), prescribed_displacement and
  applied_force (as a displacement: a vector along x, y, z, other components on their own, e.g.
  applied_force_theta), region_<name> (UInt8) per region. The arrays live in sys until the next
  call. Not collective: every rank its piece, the same arrays on every rank.
@*/
PetscErrorCode PeriConditionsAddFields(PeriSystem sys, PeriFieldList fl)
{
  PeriConditionFields *F  = &sys->conditions.fields;
  const PeriModel      m  = sys->model;
  const PetscInt       n  = sys->disc.bonds.rend - sys->disc.bonds.rstart;
  const PetscInt       nd = PetscMax(n * m->dofs, 1);

  PetscFunctionBeginUser;
  PetscCall(PeriConditionFieldsDestroy(F));
  PetscCall(PetscCalloc3(nd, &F->fixed, nd, &F->prescribed, nd, &F->force));
  PetscCall(FillDOFs(sys, F, n * m->dofs));
  PetscCall(PeriFieldListAddFlags(fl, "fixed", m->dofs, F->fixed, m->components));
  PetscCall(PeriFieldListAddSolution(fl, "prescribed_displacement", m->dofs, m->components, m->axis, F->prescribed));
  PetscCall(PeriFieldListAddSolution(fl, "applied_force", m->dofs, m->components, m->axis, F->force));
  PetscCall(AddRegions(sys, fl, F, n));
  PetscFunctionReturn(PETSC_SUCCESS);
}
