/* The failure criteria, one line each: PERI_CRITERION(id) names the descriptor PeriCriterion_<id>
 * that src/system/criterion_<name>.c defines. The order is the order in which failure.c asks them
 * (the first to give the largest index names the cause), lists their keys (-help, docs/scene.md)
 * and prints them in the run log. Included by src/system/failure.c with PERI_CRITERION defined;
 * no include guard. */
PERI_CRITERION(Tension)
PERI_CRITERION(Energy)
PERI_CRITERION(Compression)
PERI_CRITERION(Sliding)
PERI_CRITERION(Frictional)
PERI_CRITERION(ShearAngle)
