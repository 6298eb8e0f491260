/* perilin's log events and stages (-log_view), registered by PeriInitializePackage. Defined here,
 * at the bottom, so that every layer may time itself. */
#include "perilin/private/sys.h"

PetscLogEvent PERI_EVENT_Neighbors, PERI_EVENT_Partition, PERI_EVENT_Assembly, PERI_EVENT_Solve;
PetscLogStage PERI_STAGE_Setup, PERI_STAGE_Assembly, PERI_STAGE_Solve, PERI_STAGE_Output;
