/* perilin's log events and stages (-log_view), registered by PeriInitializePackage. Defined here,
 * at the bottom, so that every layer may time itself. */
#include "perilin/private/sys.h"
#include <sys/resource.h>
#if defined(__GLIBC__)
#  include <malloc.h>
#endif
#if defined(PERI_ASAN)
#  include <sanitizer/lsan_interface.h>
#endif

PetscLogEvent PERI_EVENT_Neighbors, PERI_EVENT_Partition, PERI_EVENT_Assembly, PERI_EVENT_Solve, PERI_EVENT_MatMultFree, PERI_EVENT_Mechanisms, PERI_EVENT_Multigrid;
PetscLogStage PERI_STAGE_Setup, PERI_STAGE_Assembly, PERI_STAGE_Solve, PERI_STAGE_Output;

/* This process's peak resident memory so far (MB): the operating system's count, which sees
 * what PETSc's allocator does not (MPI, BLAS, MUMPS). Not collective. */
PetscReal PeriPeakMemoryMB(void)
{
  struct rusage ru;
  if (getrusage(RUSAGE_SELF, &ru)) return 0;
  return (PetscReal)ru.ru_maxrss / 1024.0; /* kilobytes on Linux */
}

/* The heap this process has in use now (MB): glibc's count of allocated bytes, which unlike the
 * resident memory falls when arrays are freed (the libraries keep freed memory resident, see
 * PeriMallocInitialize), so that the memory of one computation among several can be told. Elsewhere
 * PETSc's resident-memory count. Not collective. */
PetscReal PeriHeapInUseMB(void)
{
#if defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 33)
  struct mallinfo2 mi = mallinfo2();
  return (PetscReal)(mi.uordblks + mi.hblkhd) / 1048576.0;
#else
  PetscLogDouble mem = 0;
  if (PetscMemoryGetCurrentUsage(&mem)) return 0;
  return (PetscReal)mem / 1048576.0;
#endif
}

/* Bytes this node can still give: MemAvailable, or the cgroup's limit when lower; 0 if unknown.
 * Here, at the bottom, so that the readers of every layer can check an estimate before they
 * allocate (the system's of a grid scene, the mesh reader's of particles.refine). Not collective. */
PetscReal PeriMemoryAvailable(void)
{
  PetscReal have = 0;
  char      line[256];
  FILE     *fp = fopen("/proc/meminfo", "r");
  if (fp) {
    while (fgets(line, sizeof(line), fp))
      if (!strncmp(line, "MemAvailable:", 13)) have = 1024.0 * strtod(line + 13, NULL);
    fclose(fp);
  }
  if ((fp = fopen("/sys/fs/cgroup/memory.max", "r"))) {
    double limit = 0, used = 0;
    FILE  *fu = fopen("/sys/fs/cgroup/memory.current", "r");
    if (fscanf(fp, "%lf", &limit) == 1 && fu && fscanf(fu, "%lf", &used) == 1 && limit - used < have) have = limit - used;
    if (fu) fclose(fu);
    fclose(fp);
  }
  return have;
}

/*@C
  PeriMallocInitialize - gives freed arrays back to the system. Constructors of the libraries
  PETSc loads turn off glibc's mmap and heap trimming (M_MMAP_MAX 0 from Debian's libsuperlu_dist,
  M_TRIM_THRESHOLD -1): every array then comes from the heap and none goes back, so a run's peak
  was the heap's high-water mark (issue 14, item 4). With -peri_malloc_mmap_threshold N (bytes, at
  most 32 MiB; default 32 MiB), arrays of N bytes and more are mapped and unmapped on their own, so
  the bonds' geometry, released for the solve and restored after it, does not leave a hole that
  the solver's smaller arrays split: 787 -> 718 MB on the 641,601-particle plate with the
  multigrid, for 4 % more wall time (page faults of the remapped arrays); arrays below 32 MiB
  (runs below about 10^5 particles) are not affected. 0 keeps the libraries' setting
  (docs/performance.md, issue 29 item 3). Under AddressSanitizer (-DPERILIN_SANITIZE=ON), whose
  allocator ignores mallopt, nothing is set: a note when the option is given. Not collective.
@*/
PetscErrorCode PeriMallocInitialize(void)
{
  PetscInt  threshold = 32 << 20;
  PetscBool set       = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-peri_malloc_mmap_threshold", &threshold, &set));
#if defined(PERI_ASAN)
  /* AddressSanitizer's allocator replaces glibc's and refuses every mallopt: nothing to set */
  if (set && threshold > 0)
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "perilin: note: -peri_malloc_mmap_threshold %" PetscInt_FMT " has no effect: this build runs under AddressSanitizer, whose allocator ignores mallopt\n", threshold));
  else
    PetscCall(PetscInfo(NULL, "AddressSanitizer build: the allocator settings (-peri_malloc_mmap_threshold) are not applied\n"));
#elif defined(__GLIBC__)
  if (threshold > 0) {
    PetscCheck(mallopt(M_MMAP_MAX, 65536) && mallopt(M_MMAP_THRESHOLD, (int)threshold) && mallopt(M_TRIM_THRESHOLD, 2 * (int)threshold), PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "-peri_malloc_mmap_threshold %" PetscInt_FMT ": glibc takes at most 32 MiB", threshold);
  }
#endif
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Allocations of this thread between PeriLeakCheckPause(PETSC_TRUE) and PeriLeakCheckPause(PETSC_FALSE)
 * are not leaks to LeakSanitizer (MPI's start and end keep memory to the process's end); without
 * AddressSanitizer nothing. Not collective. */
void PeriLeakCheckPause(PetscBool pause)
{
#if defined(PERI_ASAN)
  if (pause)
    __lsan_disable();
  else
    __lsan_enable();
#else
  (void)pause;
#endif
}
