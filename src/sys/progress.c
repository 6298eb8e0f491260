/* The one-line status of a long run on a terminal (issue 16, item 6): what the run is doing, at
 * most once a second, overwritten in place with '\r'. stdout stays exactly as without it when it
 * is not a terminal, so logs, pipes and the golden tests see nothing of it.
 *
 * The line is made of slots, left to right: the analysis (quasi-static step and load factor), the
 * phase (setup, assembly, solve, eigensolve, output) and the solver (KSP iteration and residual,
 * converged eigenpairs). Setting a slot clears those after it: a new phase has no solver state
 * yet. While the line is on the terminal, every line PETSc prints (PetscPrintf, PetscFPrintf, the
 * error messages) first erases it, through PETSc's PetscVFPrintf hook, so messages never get glued
 * to a stale status. There is one terminal per process: one progress object at a time draws. */
#include "perilin/private/sys.h"
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

#define PERI_PROGRESS_LEN 160

struct _p_PeriProgress {
  PetscBool      active;                                       /* this rank draws (rank 0, a terminal, not -quiet) */
  char           slot[PERI_PROGRESS_SLOTS][PERI_PROGRESS_LEN]; /* the texts, "" when empty */
  PetscLogDouble start, last;                                  /* creation, last drawing */
  size_t         shown;                                        /* characters of the line now on the terminal */
};

/* the object whose line may be on the terminal, and PETSc's printer it stands in front of */
static PeriProgress drawer                                             = NULL;
static PetscErrorCode (*petsc_vfprintf)(FILE *, const char[], va_list) = NULL;

/* Writes blanks over the line and returns to its start. Not PETSc's printer: this is its hook. */
static void Erase(PeriProgress p)
{
  if (!p->shown) return;
  fputc('\r', stdout);
  for (size_t k = 0; k < p->shown; k++) fputc(' ', stdout);
  fputc('\r', stdout);
  fflush(stdout);
  p->shown = 0;
}

/* PetscVFPrintf while a line is drawn: stdout and stderr share the terminal, so both erase it. */
static PetscErrorCode EraseThenPrint(FILE *fd, const char format[], va_list ap)
{
  if (drawer && (fd == stdout || fd == stderr)) Erase(drawer);
  return (*petsc_vfprintf)(fd, format, ap);
}

/* Whether stdout is the user's terminal. Open MPI's mpiexec gives every rank a pseudo-terminal as
 * its stdout even when mpiexec itself writes into a pipe or a file, so under it isatty() cannot
 * tell: the line is then off unless -progress asks for it. mpiexec sets OMPI_COMM_WORLD_SIZE
 * before the ranks start (PMIX_RANK is no sign: a singleton's MPI_Init sets it too). */
static PetscBool Terminal(void)
{
  if (!isatty(STDOUT_FILENO)) return PETSC_FALSE;
  return getenv("OMPI_COMM_WORLD_SIZE") ? PETSC_FALSE : PETSC_TRUE;
}

/*@C
  PeriProgressCreate - the status line of a run on comm. It draws on rank 0 when stdout is a
  terminal (not under an MPI launcher, see Terminal()) and -quiet is not given; -progress
  true|false forces it on or off. Collective (reads options only).
@*/
PetscErrorCode PeriProgressCreate(MPI_Comm comm, PeriProgress *progress)
{
  PeriProgress p;
  PetscMPIInt  rank;
  PetscBool    quiet = PETSC_FALSE, on, set;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&p));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-quiet", &quiet, NULL));
  on = Terminal();
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-progress", &on, &set));
  p->active = (PetscBool)(rank == 0 && on && !(quiet && !set) && !drawer);
  PetscCall(PetscTime(&p->start));
  p->last = p->start; /* the first drawing after a second: short runs show nothing */
  if (p->active) {
    drawer         = p;
    petsc_vfprintf = PetscVFPrintf;
    PetscVFPrintf  = EraseThenPrint;
  }
  *progress = p;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The terminal's width, to keep the line on one row ('\r' goes back to the start of a row only). */
static size_t Width(void)
{
  struct winsize w;
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 1) return (size_t)w.ws_col - 1;
  return 79;
}

static void Draw(PeriProgress p, PetscLogDouble now)
{
  char   line[PERI_PROGRESS_SLOTS * (PERI_PROGRESS_LEN + 3) + 32];
  size_t n;

  n = (size_t)snprintf(line, sizeof(line), "perilin: %.0f s", (double)(now - p->start));
  for (int s = 0; s < PERI_PROGRESS_SLOTS; s++)
    if (p->slot[s][0] && n < sizeof(line)) n += (size_t)snprintf(line + n, sizeof(line) - n, " | %s", p->slot[s]);
  n       = PetscMin(strlen(line), Width());
  line[n] = 0;
  /* blanks over the rest of a longer line before, then the new line again to leave the cursor
     at its end */
  fputc('\r', stdout);
  fputs(line, stdout);
  if (p->shown > n) {
    for (size_t k = n; k < p->shown; k++) fputc(' ', stdout);
    fputc('\r', stdout);
    fputs(line, stdout);
  }
  fflush(stdout);
  p->shown = n;
  p->last  = now;
}

/*@C
  PeriProgressUpdate - sets the text of a slot (printf format; NULL: empty) and clears the slots
  after it; redraws the line when a second has passed since it was last drawn. A NULL or inactive
  progress does nothing, so the callers need no test. Not collective: cheap enough for every KSP
  iteration.
@*/
PetscErrorCode PeriProgressUpdate(PeriProgress p, PeriProgressSlot slot, const char format[], ...)
{
  PetscLogDouble now;

  PetscFunctionBeginUser;
  if (!p || !p->active) PetscFunctionReturn(PETSC_SUCCESS);
  for (int s = slot; s < PERI_PROGRESS_SLOTS; s++) p->slot[s][0] = 0;
  if (format) {
    va_list ap;
    va_start(ap, format);
    vsnprintf(p->slot[slot], PERI_PROGRESS_LEN, format, ap);
    va_end(ap);
  }
  PetscCall(PetscTime(&now));
  if (now - p->last >= 1.0) Draw(p, now);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether this rank draws a status line: stdout is the user's terminal and not -quiet. */
PetscBool PeriProgressActive(PeriProgress p)
{
  return (PetscBool)(p && p->active);
}

/*@C
  PeriProgressDestroy - erases the line and gives PETSc its printer back. Not collective.
@*/
PetscErrorCode PeriProgressDestroy(PeriProgress *progress)
{
  PeriProgress p = *progress;

  PetscFunctionBeginUser;
  if (!p) PetscFunctionReturn(PETSC_SUCCESS);
  if (p->active && drawer == p) {
    Erase(p);
    PetscVFPrintf = petsc_vfprintf;
    drawer        = NULL;
  }
  PetscCall(PetscFree(p));
  *progress = NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}
