/* SIGINT and SIGTERM end a run early but cleanly: the handler only records the signal; the
 * analyses poll PeriSignalReceived() at points where every rank is (between solves, and in the
 * KSP convergence test), stop, and write what they have marked "complete": false. mpiexec
 * forwards both signals to every rank as SIGTERM, then kills the ranks after a grace period
 * (Open MPI: odls_base_sigkill_timeout, 1 s by default), so the work after the signal is small. */
#include "perilin/private/sys.h"
#include <signal.h>
#include <time.h>

static volatile sig_atomic_t peri_signal = 0;
static volatile time_t       peri_signal_time;

static void OnSignal(int sig)
{
  time_t now = time(NULL); /* async-signal-safe */

  /* A signal again, some seconds after the first, means "now": the default action ends the
     process. Copies of one signal arrive together (timeout(1) and a terminal signal the process
     group as well as the process; mpiexec forwards what the ranks already got) and are ignored. */
  if (peri_signal) {
    if (now - peri_signal_time >= 3) {
      signal(sig, SIG_DFL);
      raise(sig);
    }
    return;
  }
  peri_signal_time = now;
  peri_signal      = sig;
}

/*@C
  PeriSignalsInstall - from now on SIGINT, SIGTERM and SIGHUP (a closed terminal or ssh session)
  are recorded instead of ending the process (this replaces PETSc's own SIGTERM handler, which
  aborts). Not collective.
@*/
PetscErrorCode PeriSignalsInstall(void)
{
  struct sigaction sa;

  PetscFunctionBeginUser;
  memset(&sa, 0, sizeof(sa));
  sa.sa_handler = OnSignal;
  sigemptyset(&sa.sa_mask);
  PetscCheck(sigaction(SIGINT, &sa, NULL) == 0 && sigaction(SIGTERM, &sa, NULL) == 0 && sigaction(SIGHUP, &sa, NULL) == 0, PETSC_COMM_SELF, PETSC_ERR_SYS, "cannot install the SIGINT/SIGTERM/SIGHUP handlers");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The name of a signal perilin records, for messages and summary.json. */
const char *PeriSignalName(int sig)
{
  return sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP"
                                  : sig == SIGINT   ? "SIGINT"
                                                    : "a signal";
}

/*@C
  PeriSignalReceived - the signal any rank of comm has received (0: none), so that every rank
  takes the same branch. Collective.
@*/
PetscErrorCode PeriSignalReceived(MPI_Comm comm, int *sig)
{
  int mine = (int)peri_signal;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&mine, sig, 1, MPI_INT, MPI_MAX, comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The signal this process received, without communication (for the exit status). */
int PeriSignalPending(void)
{
  return (int)peri_signal;
}

/*@C
  PeriSignalSimulate - records sig as if it had arrived (-peri_stop_after_step: a run stopped at a
  chosen point takes the very path of an interrupted one). Not collective: every rank that should
  stop calls it.
@*/
void PeriSignalSimulate(int sig)
{
  if (!peri_signal) peri_signal = sig;
}
