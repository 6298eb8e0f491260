/* perilin's log events and stages (-log_view), registered by PeriInitializePackage. Defined here,
 * at the bottom, so that every layer may time itself. */
#include "perilin/private/sys.h"
#include <sys/resource.h>

PetscLogEvent PERI_EVENT_Neighbors, PERI_EVENT_Partition, PERI_EVENT_Assembly, PERI_EVENT_Solve, PERI_EVENT_MatMultFree;
PetscLogStage PERI_STAGE_Setup, PERI_STAGE_Assembly, PERI_STAGE_Solve, PERI_STAGE_Output;

/* This process's peak resident memory so far (MB): the operating system's count, which sees
 * what PETSc's allocator does not (MPI, BLAS, MUMPS). Not collective. */
PetscReal PeriPeakMemoryMB(void)
{
  struct rusage ru;
  if (getrusage(RUSAGE_SELF, &ru)) return 0;
  return (PetscReal)ru.ru_maxrss / 1024.0; /* kilobytes on Linux */
}
