/* BLAS threads. Debian's OpenBLAS (the pthread build) keeps worker threads that spin in
 * sched_yield between BLAS calls: on one rank they burn a second core for nothing (a static run's
 * CPU time was 2x its wall time, 43 % of it in the kernel). perilin's BLAS work outside
 * factorizations is small (GAMG's dense kernels), so it runs one thread, and gives the threads
 * back around factorizations (MUMPS), where they help. The functions are looked up at run time:
 * with another BLAS nothing changes; an explicit OPENBLAS_NUM_THREADS or OMP_NUM_THREADS wins. */
#include "perilin/private/sys.h"
#include <dlfcn.h>
#include <stdlib.h>

static void (*set_threads)(int) = NULL;
static int default_threads      = 1;

/* One BLAS thread from now on, unless the environment says otherwise. */
PetscErrorCode PeriBLASThreadsInitialize(void)
{
  int (*procs)(void);

  PetscFunctionBeginUser;
  if (getenv("OPENBLAS_NUM_THREADS") || getenv("OMP_NUM_THREADS")) PetscFunctionReturn(PETSC_SUCCESS);
  *(void **)&set_threads = dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
  *(void **)&procs       = dlsym(RTLD_DEFAULT, "openblas_get_num_procs");
  if (!set_threads || !procs) {
    set_threads = NULL;
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  default_threads = procs();
  set_threads(1);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* many: the library's own number of threads (around a factorization), else one. */
PetscErrorCode PeriBLASThreads(PetscBool many)
{
  PetscFunctionBeginUser;
  if (set_threads) set_threads(many ? default_threads : 1);
  PetscFunctionReturn(PETSC_SUCCESS);
}
