/* The critical shear angle of antiplane models (Oterkus & Madenci eq. 70): a bond breaks when
 * |r|, r = (u_j - u_i)/|xi|, passes r_c. docs/failure.md. */
#include "perilin/private/bondstate.h"

static PetscErrorCode SetFromScene(PeriCriterion *c, PeriScene s, PeriNode node, PeriModel m)
{
  PetscFunctionBeginUser;
  PeriInputCheck(c->measure[0] >= 0, s, node, "shear_angle", "model %s has no shear angle (antiplane models have)", m->type);
  c->causes = 1 << PERI_CAUSE_SHEAR_ANGLE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscReal Index(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  (void)m, (void)g;
  *cause = PERI_CAUSE_SHEAR_ANGLE;
  return PetscAbsReal(meas[c->measure[0]]) / c->value[0];
}

static PetscErrorCode View(const PeriCriterion *c, PeriModel m, MPI_Comm comm)
{
  PetscFunctionBeginUser;
  (void)m;
  PetscCall(PetscPrintf(comm, " |r| > r_c = %g", (double)c->value[0]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

const PeriCriterionType PeriCriterion_ShearAngle = {
    .name      = "shear_angle",
    .keys      = {{"shear_angle", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "antiplane: critical shear angle r_c; not with G"}},
    .measures  = {PERI_MEASURE_SHEAR_ANGLE},
    .nmeasures = 1,
    .ops       = {.setfromscene = SetFromScene, .index = Index, .view = View},
};
