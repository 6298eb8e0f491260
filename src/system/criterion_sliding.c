/* The maximum sliding criterion (Diana & Casolo eq. 49): a bond breaks when its sliding |gamma|
 * passes gamma_0. docs/failure.md. The ops are the shared ones of a bound on a magnitude. */
#include "perilin/private/bondstate.h"

const PeriCriterionType PeriCriterion_Sliding = {
    .name      = "sliding",
    .keys      = {{"sliding", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "pds/mppd/gerstle: critical sliding gamma_0"}},
    .measures  = {PERI_MEASURE_SLIDING},
    .nmeasures = 1,
    .cause     = PERI_CAUSE_SLIDING,
    .holders   = "pds, mppd, gerstle",
    .symbol    = "|gamma|",
    .ops       = {.setfromscene = PeriCriterionMagnitudeSetFromScene, .index = PeriCriterionMagnitudeIndex, .view = PeriCriterionMagnitudeView},
};
