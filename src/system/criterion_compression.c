/* The compression criterion: a bond breaks when its stretch s falls below -s_cc; with
 * ultimate_compressive_stretch S_uc it softens instead (Diana & Casolo eq. 46), keeping
 * (S_uc + s)/(S_uc - s_cc) of its stiffness, and breaks at -S_uc. docs/failure.md. */
#include "perilin/private/bondstate.h"

enum {
  CRITICAL,
  ULTIMATE
};

static PetscErrorCode SetFromScene(PeriCriterion *c, PeriScene s, PeriNode node, PeriModel m)
{
  PetscFunctionBeginUser;
  PeriInputCheck(!c->given[CRITICAL] || c->measure[0] >= 0, s, node, "compressive_stretch", "model %s has no stretch measure", m->type);
  PeriInputCheck(!c->given[ULTIMATE] || (c->given[CRITICAL] && c->value[ULTIMATE] > c->value[CRITICAL]), s, node, "ultimate_compressive_stretch", "softening needs compressive_stretch below ultimate_compressive_stretch");
  c->causes  = 1 << PERI_CAUSE_COMPRESSION;
  c->softens = c->given[ULTIMATE];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* -s/s_cc for s < 0 (to the ultimate stretch with softening) */
static PetscReal Index(const PeriCriterion *c, PeriModel m, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  (void)m, (void)g;
  const PetscReal s = meas[c->measure[0]], scc = c->softens ? c->value[ULTIMATE] : c->value[CRITICAL];

  *cause = PERI_CAUSE_COMPRESSION;
  return s < 0 ? -s / scc : 0;
}

static PetscReal Softening(const PeriCriterion *c, const PetscReal meas[])
{
  const PetscReal s = meas[c->measure[0]], s0 = c->value[CRITICAL], su = c->value[ULTIMATE];

  return -s > s0 ? PetscMax(0, (su + s) / (su - s0)) : 1;
}

static PetscErrorCode View(const PeriCriterion *c, PeriModel m, MPI_Comm comm)
{
  PetscFunctionBeginUser;
  (void)m;
  PetscCall(PetscPrintf(comm, " -s > %g", (double)c->value[CRITICAL]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

const PeriCriterionType PeriCriterion_Compression = {
    .name           = "compression",
    .keys           = {{"compressive_stretch", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "critical compressive stretch: a bond breaks when s < -value"}},
    .softening_keys = {{"ultimate_compressive_stretch", PERI_KEY_REAL, NULL, "(compressive_stretch, inf)", NULL, NULL, "softening in compression (eq. 46)"}},
    .measures       = {PERI_MEASURE_STRETCH},
    .nmeasures      = 1,
    .ops            = {.setfromscene = SetFromScene, .index = Index, .softening = Softening, .view = View},
};
