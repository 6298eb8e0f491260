/* summary.json: what the run was, what it cost, and its results (docs/summary.md lists the keys).
 * One call per contributor: the system's sections, then the analysis' own (ops.summary). */
#include "perilin/private/problem.h"

/* What made the run, to repeat it: "build" (perilin's version as built, PETSc's and SLEPc's) and
 * "command_line" (the arguments PETSc was started with, the program first). */
static PetscErrorCode WriteProvenance(PeriJSON j)
{
  char   perilin[PERI_VERSION_LEN], petsc[PERI_VERSION_LEN], slepc[PERI_VERSION_LEN];
  int    argc = 0;
  char **args = NULL;

  PetscFunctionBeginUser;
  PetscCall(PeriGetVersions(perilin, petsc, slepc, PERI_VERSION_LEN));
  PetscCall(PeriJSONBeginObject(j, "build"));
  PetscCall(PeriJSONString(j, "perilin", perilin));
  PetscCall(PeriJSONString(j, "petsc", petsc));
  PetscCall(PeriJSONString(j, "slepc", slepc));
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PetscGetArgs(&argc, &args));
  PetscCall(PeriJSONBeginArray(j, "command_line"));
  for (int k = 0; k < argc; k++) PetscCall(PeriJSONString(j, NULL, args[k]));
  PetscCall(PeriJSONEndArray(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode WriteSummary(PeriProblem p, PeriJSON j)
{
  PeriSystem sys = p->sys;

  PetscFunctionBeginUser;
  PetscCall(PeriJSONString(j, "scene", p->scene->file));
  PetscCall(WriteProvenance(j));
  PetscCall(PeriSystemSummaryModel(sys, j));
  PetscCall(PeriJSONString(j, "analysis", p->analysis_type));
  /* false only for a run stopped by a signal: then the fields below describe the last complete
     state (quasistatic), or there are none */
  PetscCall(PeriJSONBool(j, "complete", sys->run.interrupted ? PETSC_FALSE : PETSC_TRUE));
  if (sys->run.interrupted) PetscCall(PeriJSONString(j, "interrupted_by", PeriSignalName(sys->run.interrupted)));
  PetscCall(PeriSystemSummaryDiscretization(sys, j));
  PetscCall(PeriLayersSummary(sys, j));
  PetscCall(PeriSystemSummaryCost(sys, j));
  PetscCall(PeriSystemSummarySolver(sys, j));
  if (p->analysis && p->analysis->type->ops.summary) PetscCall(p->analysis->type->ops.summary(p->analysis, j));
  if (p->analysis) PetscCall(PeriPlotsSummary(&p->analysis->plots, j));
  PetscCall(PeriTorsionSummary(sys, j));
  PetscCall(PeriSystemSummaryFields(sys, j));
  PetscCall(PeriReactionsSummary(sys, j));
  PetscCall(PeriReferenceSummary(sys, j));
  PetscCall(PeriProbesSummary(sys, j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWriteSummary - writes summary.json on rank 0 (temporary name, then rename). Collective.
@*/
PetscErrorCode PeriWriteSummary(PeriProblem p, const char path[])
{
  PeriJSON       j = NULL;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  if (p->rank) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONOpen(path, &j));
  ierr = WriteSummary(p, j);
  PetscCall(PeriJSONClose(&j, ierr ? PETSC_FALSE : PETSC_TRUE));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The command line as a shell would take it back: arguments with other characters than these
 * single-quoted. */
static PetscErrorCode CommandLine(char buf[], size_t len)
{
  int    argc = 0;
  char **args = NULL;

  PetscFunctionBeginUser;
  buf[0] = 0;
  PetscCall(PetscGetArgs(&argc, &args));
  for (int k = 0; k < argc; k++) {
    PetscBool plain = (PetscBool)(args[k][0] && strspn(args[k], "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_./=:,+-@%") == strlen(args[k]));
    size_t    used  = strlen(buf);
    PetscCall(PetscSNPrintf(buf + used, len - used, "%s%s%s%s", k ? " " : "", plain ? "" : "'", args[k], plain ? "" : "'"));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWriteScene - writes scene.yaml on rank 0 (temporary name, then rename): the resolved scene
  (src/scene/resolved.c) after a header saying what made it. Collective.
@*/
PetscErrorCode PeriWriteScene(PeriProblem p, const char path[])
{
  char           perilin[PERI_VERSION_LEN], petsc[PERI_VERSION_LEN], slepc[PERI_VERSION_LEN], cmd[4096], header[8192], tmp[PETSC_MAX_PATH_LEN + 8];
  FILE          *fp;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  if (p->rank) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriGetVersions(perilin, petsc, slepc, PERI_VERSION_LEN));
  PetscCall(CommandLine(cmd, sizeof(cmd)));
  PetscCall(PetscSNPrintf(header, sizeof(header),
                          "The resolved scene of a perilin %s run (docs/summary.md): every key the run read, with the value it used.\n"
                          "command line: %s\n"
                          "Given back to perilin, this reproduces the run: perilin scene.yaml [-output_dir DIR]\n"
                          "(without -output_dir it writes into output.dir again; PETSc options are no scene keys: give them again)\n",
                          perilin, cmd));
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  ierr = PeriSceneWriteResolved(p->scene, header, fp);
  PetscCall(PeriFileCloseCommit(fp, tmp, path, ierr != 0));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}
