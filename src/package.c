/* The perilin package: log events and stages, the registries, their finalizer. */
#include "perilin.h"
#include "perilin/private/sys.h"
#include "perilin/private/scene.h"
#include "perilin/private/model.h"
#include "perilin/private/problem.h"
#include "perilin/private/system.h"
#include <slepcsys.h>

static PetscBool PeriPackageInitialized = PETSC_FALSE;

/* PetscFinalize drops the log events and stages: a second PetscInitialize must register them again. */
static PetscErrorCode PeriFinalizePackage(void)
{
  PetscFunctionBeginUser;
  PeriPackageInitialized = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriInitializePackage(void)
{
  PetscClassId id;

  PetscFunctionBeginUser;
  if (PeriPackageInitialized) PetscFunctionReturn(PETSC_SUCCESS);
  PeriPackageInitialized = PETSC_TRUE;
  PetscCall(PetscRegisterFinalize(PeriFinalizePackage));
  PetscCall(PetscClassIdRegister("perilin", &id));
  PetscCall(PetscLogEventRegister("PeriPartition", id, &PERI_EVENT_Partition));
  PetscCall(PetscLogEventRegister("PeriNeighbors", id, &PERI_EVENT_Neighbors));
  PetscCall(PetscLogEventRegister("PeriAssembly", id, &PERI_EVENT_Assembly));
  PetscCall(PetscLogEventRegister("PeriSolve", id, &PERI_EVENT_Solve));
  PetscCall(PetscLogEventRegister("PeriMatMultFree", id, &PERI_EVENT_MatMultFree));
  PetscCall(PetscLogStageRegister("Peri setup", &PERI_STAGE_Setup));
  PetscCall(PetscLogStageRegister("Peri assembly", &PERI_STAGE_Assembly));
  PetscCall(PetscLogStageRegister("Peri solve", &PERI_STAGE_Solve));
  PetscCall(PetscLogStageRegister("Peri output", &PERI_STAGE_Output));
  /* the registries are filled here, once, so that neither calls back into the package */
  PetscCall(PeriModelRegisterAll());
  PetscCall(PeriAnalysisRegisterAll());
  {
    /* the output sets learn the analyses' files from the analyses themselves */
    PetscInt                       na;
    const PeriAnalysisType *const *types;
    PetscCall(PeriAnalysisGetTypes(&na, &types));
    for (PetscInt k = 0; k < na; k++) PetscCall(PeriOutputSetAddNames(types[k]->files));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriInitialize - starts SLEPc (and with it PETSc) once for the process, installs the signal
  handlers (SIGINT, SIGTERM end a run early with its last complete state) and fills the registries.
@*/
PetscErrorCode PeriInitialize(int *argc, char ***argv, const char help[])
{
  PetscFunctionBeginUser;
  PetscCall(SlepcInitialize(argc, argv, NULL, help));
  PetscCall(PeriMallocInitialize());
  PetscCall(PeriSignalsInstall());
  PetscCall(PeriBLASThreadsInitialize());
  PetscCall(PeriInitializePackage());
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriFinalize(void)
{
  PetscFunctionBeginUser;
  PetscCall(SlepcFinalize());
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The core modules' schemas, each next to the code that reads its sections; the root keys
 * (problem) first. */
static const PeriSchemaOwner core_owners[] = {
    {"core", "problem", PeriProblemSchema},
    {"core", "system", PeriSystemSchema},
    {"core", "material", PeriMaterialSchema},
    {"core", "particles", PeriParticlesSchema},
    {"core", "regions", PeriRegionsSchema},
    {"core", "boundary", PeriBoundarySchema},
    {"core", "probes", PeriProbesSchema},
    {"core", "reference", PeriReferenceSchema},
    {"core", "layers", PeriLayersSchema},
    {"core", "failure", PeriFailureSchema},
};

/*@C
  PeriSchemaOwners - the core's schemas, then every built-in model's and analysis' schema, for the
  scene layer, which cannot ask the modules and registries itself: it validates, documents and
  adds from options the keys they declare. At most max; not collective.
@*/
PetscErrorCode PeriSchemaOwners(PetscInt max, PeriSchemaOwner owners[], PetscInt *n)
{
  const PeriModelType *const    *models;
  const PeriAnalysisType *const *analyses;
  const PetscInt                 nc = (PetscInt)PETSC_STATIC_ARRAY_LENGTH(core_owners);
  PetscInt                       nm, na;

  PetscFunctionBeginUser;
  PetscCall(PeriModelGetTypes(&nm, &models));
  PetscCall(PeriAnalysisGetTypes(&na, &analyses));
  PetscCheck(nc + nm + na <= max, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%" PetscInt_FMT " schema owners, more than %" PetscInt_FMT, nc + nm + na, max);
  for (PetscInt k = 0; k < nc; k++) owners[k] = core_owners[k];
  for (PetscInt k = 0; k < nm; k++) owners[nc + k] = (PeriSchemaOwner){"model", models[k]->name, models[k]->schema};
  for (PetscInt k = 0; k < na; k++) owners[nc + nm + k] = (PeriSchemaOwner){"analysis", analyses[k]->name, analyses[k]->schema};
  *n = nc + nm + na;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriPrintHelp(MPI_Comm comm)
{
  PeriSchemaOwner owners[PERI_MAX_SCHEMA_OWNERS];
  PetscInt        n;

  PetscFunctionBeginUser;
  PetscCall(PeriSchemaOwners(PERI_MAX_SCHEMA_OWNERS, owners, &n));
  PetscCall(PeriSceneHelp(comm, n, owners));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneDoc - rewrites the key tables of file (docs/scene.md) from the schemas, or with check
  only compares them: an out-of-date table is a PETSC_ERR_USER_INPUT. Collective.
@*/
PetscErrorCode PeriSceneDoc(MPI_Comm comm, const char file[], PetscBool check)
{
  PeriSchemaOwner owners[PERI_MAX_SCHEMA_OWNERS];
  PetscInt        n;

  PetscFunctionBeginUser;
  PetscCall(PeriSchemaOwners(PERI_MAX_SCHEMA_OWNERS, owners, &n));
  PetscCall(PeriSceneDocUpdate(comm, file, check, n, owners));
  PetscFunctionReturn(PETSC_SUCCESS);
}
