/* The critical shear angle of antiplane models (Oterkus & Madenci eq. 70): a bond breaks when
 * |r|, r = (u_j - u_i)/|xi|, passes r_c. docs/failure.md. The ops are the shared ones of a bound
 * on a magnitude. */
#include "perilin/private/bondstate.h"

const PeriCriterionType PeriCriterion_ShearAngle = {
    .name      = "shear_angle",
    .keys      = {{"shear_angle", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "antiplane: critical shear angle r_c; not with G"}},
    .measures  = {PERI_MEASURE_SHEAR_ANGLE},
    .nmeasures = 1,
    .cause     = PERI_CAUSE_SHEAR_ANGLE,
    .holders   = "antiplane models",
    .symbol    = "|r|",
    .ops       = {.setfromscene = PeriCriterionMagnitudeSetFromScene, .index = PeriCriterionMagnitudeIndex, .view = PeriCriterionMagnitudeView},
};
