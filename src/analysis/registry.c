/* The analysis registry: analysis.type to its run function. PeriInitializePackage registers the
 * built-in analyses of src/analysis/list.h; PeriProblemRun finds the scene's. */
#include "perilin.h"

#define PERI_ANALYSIS(id) extern const PeriAnalysisType PeriAnalysis_##id;
#include "list.h"
#undef PERI_ANALYSIS

static const PeriAnalysisType *const builtin[] = {
#define PERI_ANALYSIS(id) &PeriAnalysis_##id,
#include "list.h"
#undef PERI_ANALYSIS
};

static PetscFunctionList PeriAnalysisList              = NULL;
static PetscBool         PeriAnalysisRegisterAllCalled = PETSC_FALSE;

/* Run by PetscFinalize: frees the list and forgets it was filled, as PETSc's own packages do. */
static PetscErrorCode PeriAnalysisFinalizePackage(void)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListDestroy(&PeriAnalysisList));
  PeriAnalysisRegisterAllCalled = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriAnalysisRegister(const char name[], PetscErrorCode (*run)(PeriProblem))
{
  PetscFunctionBeginUser;
  if (!PeriAnalysisList) PetscCall(PetscRegisterFinalize(PeriAnalysisFinalizePackage));
  PetscCall(PetscFunctionListAdd(&PeriAnalysisList, name, run));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriAnalysisRegisterAll(void)
{
  PetscFunctionBeginUser;
  if (PeriAnalysisRegisterAllCalled) PetscFunctionReturn(PETSC_SUCCESS);
  PeriAnalysisRegisterAllCalled = PETSC_TRUE;
  for (size_t k = 0; k < PETSC_STATIC_ARRAY_LENGTH(builtin); k++) PetscCall(PeriAnalysisRegister(builtin[k]->name, builtin[k]->run));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* run is NULL when no analysis of that name is registered */
PetscErrorCode PeriAnalysisFind(const char name[], PetscErrorCode (**run)(PeriProblem))
{
  PetscFunctionBeginUser;
  *run = NULL;
  PetscCall(PetscFunctionListFind(PeriAnalysisList, name, run));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* the registered names, comma-separated, in the order of registration */
PetscErrorCode PeriAnalysisListTypes(char buf[], size_t len)
{
  PetscFunctionBeginUser;
  PetscCall(PeriFunctionListNames(PeriAnalysisList, buf, len));
  PetscFunctionReturn(PETSC_SUCCESS);
}
