/* The energy release rate G as a criterion: each bond's critical value of the model's first
 * measure (a stretch: tension; a shear angle) from its model, ops.critical_from_G (breaking every
 * bond across a unit crack area releases G: Silling & Askari, Ha & Bobaru, Diehl & Schweitzer,
 * Oterkus & Madenci eq. 78). It replaces critical_stretch or shear_angle. docs/failure.md. */
#include "perilin/private/bondstate.h"

static PetscErrorCode SetFromScene(PeriCriterion *c, PeriScene s, PeriNode node, PeriModel m)
{
  PeriNode        other;
  PeriMeasureKind first;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(node, "critical_stretch", &other));
  PeriInputCheck(!other, s, node, "G", "give critical_stretch or G, not both");
  PetscCall(PeriSceneGetNode(node, "shear_angle", &other));
  PeriInputCheck(!other, s, node, "G", "give shear_angle or G, not both");
  PeriInputCheck(m->ops.critical_from_G, s, node, "G", "model %s cannot convert an energy release rate into a critical measure; give it directly", m->type);
  first = m->nmeasures > 0 && m->measure_kinds ? m->measure_kinds[0] : PERI_MEASURE_RELATIVE_ROTATION;
  PeriInputCheck(first == PERI_MEASURE_STRETCH || first == PERI_MEASURE_SHEAR_ANGLE, s, node, "G", "model %s's first measure is no stretch or shear angle: G gives it no critical value", m->type);
  c->causes = 1 << (first == PERI_MEASURE_STRETCH ? PERI_CAUSE_TENSION : PERI_CAUSE_SHEAR_ANGLE);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bond's critical value from G, kept per listed bond once computed (a time loop asks every
 * step; the square root and a lattice calibration's factor cost as much as the force). */
static PetscReal Critical(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g)
{
  PetscReal *v;

  if (g->bond <= 0 || g->bond > c->ncritical) return m->ops.critical_from_G(m, g, c->value[0]);
  v = &c->critical[g->bond - 1];
  if (*v < 0) *v = m->ops.critical_from_G(m, g, c->value[0]);
  return *v;
}

/* s/s_c(G) for s > 0 (tension), or |r|/r_c(G) */
static PetscReal Index(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  const PetscReal crit = Critical(c, m, g);

  if (m->measure_kinds[0] == PERI_MEASURE_SHEAR_ANGLE) {
    *cause = PERI_CAUSE_SHEAR_ANGLE;
    return PetscAbsReal(meas[0]) / crit;
  }
  *cause = PERI_CAUSE_TENSION;
  return meas[0] > 0 ? meas[0] / crit : 0;
}

/* the bond's s_c(G) once Critical has computed it; a shear angle is no stretch */
static PetscReal StretchLimit(const PeriCriterion *c, PeriModel m, PetscInt k)
{
  if (m->measure_kinds[0] != PERI_MEASURE_STRETCH || k >= c->ncritical) return -1;
  return c->critical[k];
}

static PetscErrorCode View(const PeriCriterion *c, PeriModel m, MPI_Comm comm)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(comm, " %s critical value of each bond from G = %g by model %s", m->measure_kinds[0] == PERI_MEASURE_SHEAR_ANGLE ? "shear-angle" : "stretch", (double)c->value[0], m->type));
  PetscFunctionReturn(PETSC_SUCCESS);
}

const PeriCriterionType PeriCriterion_Energy = {
    .name     = "energy",
    .per_bond = PETSC_TRUE,
    .keys     = {{"G", PERI_KEY_REAL, NULL, "(0, inf)", "[energy/length^2]", NULL, "energy release rate: each bond's critical stretch or shear angle from its model"}},
    .ops      = {.setfromscene = SetFromScene, .index = Index, .stretch_limit = StretchLimit, .view = View},
};
