/* The maximum sliding criterion (Diana & Casolo eq. 49): a bond breaks when its sliding |gamma|
 * passes gamma_0. docs/failure.md. */
#include "perilin/private/bondstate.h"

static PetscErrorCode SetFromScene(PeriCriterion *c, PeriScene s, PeriNode node, PeriModel m)
{
  PetscFunctionBeginUser;
  PeriInputCheck(c->measure[0] >= 0, s, node, "sliding", "model %s has no sliding measure (pds, mppd, gerstle have)", m->type);
  c->causes = 1 << PERI_CAUSE_SLIDING;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscReal Index(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  (void)m, (void)g;
  *cause = PERI_CAUSE_SLIDING;
  return PetscAbsReal(meas[c->measure[0]]) / c->value[0];
}

static PetscErrorCode View(const PeriCriterion *c, PeriModel m, MPI_Comm comm)
{
  PetscFunctionBeginUser;
  (void)m;
  PetscCall(PetscPrintf(comm, " |gamma| > %g", (double)c->value[0]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

const PeriCriterionType PeriCriterion_Sliding = {
    .name      = "sliding",
    .keys      = {{"sliding", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "pds/mppd/gerstle: critical sliding gamma_0"}},
    .measures  = {PERI_MEASURE_SLIDING},
    .nmeasures = 1,
    .ops       = {.setfromscene = SetFromScene, .index = Index, .view = View},
};
