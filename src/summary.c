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
