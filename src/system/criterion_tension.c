/* The tension criterion (Diana & Casolo eq. 44): a bond breaks when its stretch s passes the
 * critical stretch s_c; with ultimate_stretch S_u it softens instead (eq. 45), keeping
 * (S_u - s)/(S_u - s_c) of its stiffness, and breaks at S_u. docs/failure.md. */
#include "perilin/private/bondstate.h"

enum {
  CRITICAL,
  ULTIMATE
};

static PetscErrorCode SetFromScene(PeriCriterion *c, PeriScene s, PeriNode node, PeriModel m)
{
  PetscFunctionBeginUser;
  PeriInputCheck(!c->given[CRITICAL] || c->measure[0] >= 0, s, node, "critical_stretch", "model %s has no stretch measure", m->type);
  PeriInputCheck(!c->given[ULTIMATE] || (c->given[CRITICAL] && c->value[ULTIMATE] > c->value[CRITICAL]), s, node, "ultimate_stretch", "softening needs critical_stretch (where it starts) below ultimate_stretch (where the bond is gone)");
  c->causes  = 1 << PERI_CAUSE_TENSION;
  c->softens = c->given[ULTIMATE];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* s/s_c for s > 0; with softening the bond is gone at the ultimate stretch (before, Softening
   weakens it) */
static PetscReal Index(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  (void)m, (void)g;
  const PetscReal s = meas[c->measure[0]], sc = c->softens ? c->value[ULTIMATE] : c->value[CRITICAL];

  *cause = PERI_CAUSE_TENSION;
  return s > 0 ? s / sc : 0;
}

/* s_c itself; a softening bond is not a bound on s alone (its stiffness falls before it breaks) */
static PetscReal StretchLimit(const PeriCriterion *c, PeriModel m, PetscInt k)
{
  (void)m, (void)k;
  return c->softens || c->measure[0] != 0 ? -1 : c->value[CRITICAL];
}

static PetscReal Softening(const PeriCriterion *c, const PetscReal meas[])
{
  const PetscReal s = meas[c->measure[0]], s0 = c->value[CRITICAL], su = c->value[ULTIMATE];

  return s > s0 ? PetscMax(0, (su - s) / (su - s0)) : 1;
}

static PetscErrorCode View(const PeriCriterion *c, PeriModel m, MPI_Comm comm)
{
  PetscFunctionBeginUser;
  (void)m;
  PetscCall(PetscPrintf(comm, " s > s_c = %g%s", (double)c->value[CRITICAL], c->softens ? " (softening to the ultimate stretch, eq. 45)" : ""));
  PetscFunctionReturn(PETSC_SUCCESS);
}

const PeriCriterionType PeriCriterion_Tension = {
    .name           = "tension",
    .keys           = {{"critical_stretch", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "critical tensile stretch s_c (models with a stretch: pmb, npmb, cpmb, pds, mppd, gerstle); not with G"}},
    .softening_keys = {{"ultimate_stretch", PERI_KEY_REAL, NULL, "(critical_stretch, inf)", NULL, NULL, "softening (eq. 45): the stiffness falls linearly from critical_stretch to 0 here"}},
    .measures       = {PERI_MEASURE_STRETCH},
    .nmeasures      = 1,
    .ops            = {.setfromscene = SetFromScene, .index = Index, .stretch_limit = StretchLimit, .softening = Softening, .view = View},
};
