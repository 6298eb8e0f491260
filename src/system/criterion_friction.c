/* The frictional sliding criterion (Diana & Casolo eq. 58): a bond breaks when its sliding
 * |gamma| passes gamma_l = a - s tan(beta), the cohesion a raised by compression (s < 0); a bond
 * in tension past a/tan(beta) has no sliding strength left and breaks at any sliding.
 * docs/failure.md. */
#include "perilin/private/bondstate.h"

enum {
  ANGLE,
  COHESION
};

static PetscErrorCode SetFromScene(PeriCriterion *c, PeriScene s, PeriNode node, PeriModel m)
{
  PetscFunctionBeginUser;
  PeriInputCheck(!c->given[COHESION] || c->value[COHESION] >= 0, s, node, "cohesion", "must not be negative, got %g", (double)c->value[COHESION]);
  PeriInputCheck(c->measure[0] >= 0, s, node, "friction_angle", "model %s has no sliding measure (pds, mppd, gerstle have)", m->type);
  PeriInputCheck(c->given[ANGLE] == c->given[COHESION], s, node, c->given[ANGLE] ? "cohesion" : "friction_angle", "frictional sliding needs both friction_angle (degrees) and cohesion");
  PeriInputCheck(c->value[ANGLE] < 90, s, node, "friction_angle", "must lie in (0, 90) degrees, got %g", (double)c->value[ANGLE]);
  c->causes = 1 << PERI_CAUSE_SLIDING;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* |gamma|/(a - s tan(beta)); the stretch is 0 for a model without one */
static PetscReal Index(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  (void)m, (void)g;
  const PetscReal gam = PetscAbsReal(meas[c->measure[0]]), s = c->measure[1] >= 0 ? meas[c->measure[1]] : 0;
  const PetscReal lim = c->value[COHESION] - s * PetscTanReal(c->value[ANGLE] * PETSC_PI / 180);

  *cause = PERI_CAUSE_SLIDING;
  return lim > 0 ? gam / lim : (gam > 0 ? PETSC_MAX_REAL : 0);
}

static PetscErrorCode View(const PeriCriterion *c, PeriModel m, MPI_Comm comm)
{
  PetscFunctionBeginUser;
  (void)m;
  PetscCall(PetscPrintf(comm, " |gamma| > %g - s tan(%g deg)", (double)c->value[COHESION], (double)c->value[ANGLE]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

const PeriCriterionType PeriCriterion_Frictional = {
    .name      = "frictional",
    .given_as  = "friction_angle with cohesion",
    .keys      = {{"friction_angle", PERI_KEY_REAL, NULL, "(0, 90)", "[degrees]", NULL, "pds/mppd/gerstle: frictional sliding gamma_l = cohesion - s tan(angle); with cohesion"},
                  {"cohesion", PERI_KEY_REAL, NULL, NULL, NULL, NULL, "pds/mppd/gerstle: the sliding limit without stretch; with friction_angle"}},
    .measures  = {PERI_MEASURE_SLIDING, PERI_MEASURE_STRETCH},
    .nmeasures = 2,
    .ops       = {.setfromscene = SetFromScene, .index = Index, .view = View},
};
