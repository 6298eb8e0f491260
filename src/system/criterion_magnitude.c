/* The shared ops of the criteria that bound one measure's magnitude, |measure| <= limit
 * (criterion_sliding.c, criterion_shear_angle.c): the descriptor names the cause, the models that
 * have the measure and the run log's symbol. A file of ops, not a criterion: it is in no list. */
#include "perilin/private/bondstate.h"

/* The model must have the measure; the criterion gives its cause. */
PetscErrorCode PeriCriterionMagnitudeSetFromScene(PeriCriterion *c, PeriScene s, PeriNode node, PeriModel m)
{
  PetscFunctionBeginUser;
  PeriInputCheck(c->measure[0] >= 0, s, node, c->type->keys[0].name, "model %s has no %s measure (%s have)", m->type, c->type->name, c->type->holders);
  c->causes = 1 << c->type->cause;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* |measure| / limit. */
PetscReal PeriCriterionMagnitudeIndex(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  (void)m, (void)g;
  *cause = c->type->cause;
  return PetscAbsReal(meas[c->measure[0]]) / c->value[0];
}

/* " |gamma| > 0.01" */
PetscErrorCode PeriCriterionMagnitudeView(const PeriCriterion *c, PeriModel m, MPI_Comm comm)
{
  PetscFunctionBeginUser;
  (void)m;
  PetscCall(PetscPrintf(comm, " %s > %g", c->type->symbol, (double)c->value[0]));
  PetscFunctionReturn(PETSC_SUCCESS);
}
