/* The analysis registry: analysis.type to its PeriAnalysisType. The built-in analyses of
 * src/analysis/analysis_list.h live in a static table, so the registry needs no heap and no finalizer;
 * PeriProblemRun finds the scene's. */
#include "perilin/private/analysis.h"

#define PERI_ANALYSIS(id) extern const PeriAnalysisType PeriAnalysis_##id;
#include "analysis_list.h"
#undef PERI_ANALYSIS

static const PeriAnalysisType *const builtin[] = {
#define PERI_ANALYSIS(id) &PeriAnalysis_##id,
#include "analysis_list.h"
#undef PERI_ANALYSIS
};

/* Kept for the package's life cycle (PeriInitializePackage): the table is static, nothing to do. */
PetscErrorCode PeriAnalysisRegisterAll(void)
{
  PetscFunctionBeginUser;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* *type is NULL when no analysis of that name exists. */
PetscErrorCode PeriAnalysisFind(const char name[], const PeriAnalysisType **type)
{
  PetscFunctionBeginUser;
  *type = NULL;
  for (size_t k = 0; k < PETSC_STATIC_ARRAY_LENGTH(builtin); k++)
    if (!strcmp(builtin[k]->name, name)) *type = builtin[k];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The built-in types, in the order of src/analysis/analysis_list.h: their schemas for validation and -help. */
PetscErrorCode PeriAnalysisGetTypes(PetscInt *n, const PeriAnalysisType *const **types)
{
  PetscFunctionBeginUser;
  *n     = (PetscInt)PETSC_STATIC_ARRAY_LENGTH(builtin);
  *types = builtin;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The names, comma-separated, in the order of src/analysis/analysis_list.h. */
PetscErrorCode PeriAnalysisListTypes(char buf[], size_t len)
{
  PetscFunctionBeginUser;
  if (len) buf[0] = 0;
  for (size_t k = 0; k < PETSC_STATIC_ARRAY_LENGTH(builtin); k++) PeriListAppend(buf, len, builtin[k]->name);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisCreate - an analysis of the given type, before the system exists. The caller sets
  what the output asks (vtk, every, output_dir) and the snapshot callback before PeriAnalysisRun.
  Not collective.
@*/
PetscErrorCode PeriAnalysisCreate(MPI_Comm comm, const PeriAnalysisType *type, PeriAnalysis *analysis)
{
  PeriAnalysis an;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&an));
  an->type  = type;
  an->needs = type->needs;
  an->comm  = comm;
  PetscCallMPI(MPI_Comm_rank(comm, &an->rank));
  *analysis = an;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisSetFromScene - reads and checks the analysis' keys (ops.setfromscene) from the
  scene's analysis section, before any particle is created. Collective.
@*/
PetscErrorCode PeriAnalysisSetFromScene(PeriAnalysis an, PeriScene s)
{
  PeriNode a;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_FALSE, &a));
  if (an->type->ops.setfromscene) PetscCall(an->type->ops.setfromscene(an, s, a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisSetUp - binds the analysis to the set-up system (borrowed) and runs its checks that
  need the system (ops.setup). Collective.
@*/
PetscErrorCode PeriAnalysisSetUp(PeriAnalysis an, PeriSystem sys)
{
  PetscFunctionBeginUser;
  an->sys = sys;
  if (an->type->ops.setup) PetscCall(an->type->ops.setup(an));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisRun - runs the analysis (ops.run) on its system. Collective.
@*/
PetscErrorCode PeriAnalysisRun(PeriAnalysis an)
{
  PetscFunctionBeginUser;
  PetscCheck(an->sys, an->comm, PETSC_ERR_ORDER, "PeriAnalysisSetUp must come before PeriAnalysisRun");
  if (an->type->ops.run) PetscCall(an->type->ops.run(an));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriAnalysisDestroy(PeriAnalysis *analysis)
{
  PeriAnalysis an = *analysis;

  PetscFunctionBeginUser;
  if (!an) PetscFunctionReturn(PETSC_SUCCESS);
  if (an->data && an->type->ops.destroy) PetscCall(an->type->ops.destroy(an));
  PetscCall(PetscFree(an->data));
  PetscCall(PetscFree(an));
  *analysis = NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}
