/* The run's pictures (output.plots): PNG files drawn from the output set's own files by
 * src/output/draw_plots.py (matplotlib, Agg backend: no display) in a child process.
 *
 * Why a child process: a picture is a view of results already written, so nothing that goes wrong
 * in it (no python3, no matplotlib, a crash, a hang) may touch the run. The child draws into a
 * scratch directory inside the staging set; only when it exits 0 within PERI_PLOTS_TIMEOUT are its
 * PNGs renamed into the set, all of them or none, and the scratch directory is removed either way.
 * A picture that could not be drawn is a warning on stdout and summary.json's plots.error, never a
 * failed run: the physics outputs stay as they are (docs/build.md, "Pictures"). Rank 0 draws. */
#define _GNU_SOURCE
#include "perilin/private/output.h"
#include "perilin/private/sys.h"

#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PERI_PLOTS_TIMEOUT 60 /* seconds: matplotlib draws any of them in about one */
#ifndef PERI_PLOTS_PYTHON
#  define PERI_PLOTS_PYTHON "python3"
#endif
#ifndef PERI_PLOTS_SCRIPT
#  define PERI_PLOTS_SCRIPT ""
#endif
#ifndef PERI_PLOTS_SCRIPT_INSTALLED
#  define PERI_PLOTS_SCRIPT_INSTALLED ""
#endif

/* Moves every PNG of scratch into dir, in name order, and lists them in pl->files. */
static PetscErrorCode CommitPictures(const char scratch[], const char dir[], PeriPlots *pl)
{
  struct dirent **names;
  int             n = scandir(scratch, &names, NULL, alphasort);
  char            from[PETSC_MAX_PATH_LEN], to[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCheck(n >= 0, PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "cannot list %s: %s", scratch, strerror(errno));
  for (int k = 0; k < n; k++) {
    size_t l = strlen(names[k]->d_name);
    if (l > 4 && !strcmp(names[k]->d_name + l - 4, ".png")) {
      PetscCall(PetscSNPrintf(from, sizeof(from), "%s/%s", scratch, names[k]->d_name));
      PetscCall(PetscSNPrintf(to, sizeof(to), "%s/%s", dir, names[k]->d_name));
      PetscCall(PeriFileCommit(from, to));
      if (strlen(pl->files) + l + 2 < sizeof(pl->files)) {
        if (pl->files[0]) strcat(pl->files, " ");
        strcat(pl->files, names[k]->d_name);
      }
    }
    free(names[k]);
  }
  free(names);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rank 0's part of PeriPlotsDraw. */
static PetscErrorCode Draw(const char dir[], const char kind[], const char *const args[], PeriPlots *pl)
{
  char        scratch[PETSC_MAX_PATH_LEN], log[PETSC_MAX_PATH_LEN + 8];
  char       *argv[32];
  PetscInt    n      = 0;
  const char *script = PeriChildScript("PERILIN_PLOTS_SCRIPT", PERI_PLOTS_SCRIPT, PERI_PLOTS_SCRIPT_INSTALLED);

  PetscFunctionBeginUser;
  if (!script) {
    PetscCall(PetscSNPrintf(pl->error, sizeof(pl->error), "draw_plots.py is neither at %s nor at %s (set PERILIN_PLOTS_SCRIPT)", PERI_PLOTS_SCRIPT, PERI_PLOTS_SCRIPT_INSTALLED));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscSNPrintf(scratch, sizeof(scratch), "%s/plots.tmp", dir));
  PetscCheck(mkdir(scratch, 0755) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot create %s: %s", scratch, strerror(errno));
  PetscCall(PetscSNPrintf(log, sizeof(log), "%s/log", scratch));
  argv[n++] = (char *)PeriChildPython(PERI_PLOTS_PYTHON);
  argv[n++] = (char *)script;
  argv[n++] = (char *)kind;
  argv[n++] = (char *)dir;
  argv[n++] = scratch;
  for (PetscInt k = 0; args && args[k] && n < 31; k++) argv[n++] = (char *)args[k];
  argv[n] = NULL;
  if (!PeriChildRun(argv, log, PERI_PLOTS_TIMEOUT, pl->error, sizeof(pl->error))) PetscCall(CommitPictures(scratch, dir, pl));
  (void)PeriOutputRemoveTree(scratch);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriPlotsDraw - draws the pictures of kind (quasistatic, modal, anisotropy) from the files of the
  output set in dir, into dir, when pl->enabled (output.plots). args: "key=value" facts that are
  not in the set's files yet (summary.json is written last), NULL-terminated. pl->files lists the
  pictures written; pl->error says why none was (the run goes on: a warning); an error set before
  the call is the caller's reason not to draw. Not collective: rank 0 of comm draws and warns, the
  others return.
@*/
PetscErrorCode PeriPlotsDraw(MPI_Comm comm, const char dir[], const char kind[], const char *const args[], PeriPlots *pl)
{
  PetscMPIInt rank;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(pl->kind, kind, sizeof(pl->kind)));
  pl->files[0] = 0;
  if (!pl->enabled || pl->error[0]) PetscFunctionReturn(PETSC_SUCCESS); /* off, or the caller's reason not to draw */
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) PetscCall(Draw(dir, kind, args, pl));
  if (pl->error[0]) PetscCall(PetscPrintf(comm, "perilin: warning: no pictures drawn (output.plots): %s; the run's results are complete\n", pl->error));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriPlotsSummary - summary.json's "plots" object when the analysis draws pictures: enabled, the
  files written, the error when none was. Not collective (the summary's rank).
@*/
PetscErrorCode PeriPlotsSummary(const PeriPlots *pl, PeriJSON j)
{
  char list[sizeof(pl->files)], *tok, *save = NULL;

  PetscFunctionBeginUser;
  if (!pl->kind[0]) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "plots"));
  PetscCall(PeriJSONBool(j, "enabled", pl->enabled));
  PetscCall(PeriJSONBeginArray(j, "files"));
  PetscCall(PetscStrncpy(list, pl->files, sizeof(list)));
  for (tok = strtok_r(list, " ", &save); tok; tok = strtok_r(NULL, " ", &save)) PetscCall(PeriJSONString(j, NULL, tok));
  PetscCall(PeriJSONEndArray(j));
  if (pl->error[0]) PetscCall(PeriJSONString(j, "error", pl->error));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}
