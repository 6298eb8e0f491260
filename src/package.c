/* The perilin package: log events and stages, the registries, their finalizer. */
#include "perilin.h"
#include "perilin/private/sys.h"
#include "perilin/private/scene_file.h"
#include "perilin/private/model_registry.h"
#include "perilin/private/problem.h"
#include "perilin/private/system.h"
#include <slepcsys.h>
#include <stdlib.h>

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
  PetscCall(PetscLogEventRegister("PeriMechanisms", id, &PERI_EVENT_Mechanisms));
  PetscCall(PetscLogEventRegister("PeriMultigrid", id, &PERI_EVENT_Multigrid)); /* the geometric multigrid's levels */
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
/* A process started without mpiexec (no launcher's variables) is an MPI singleton: it talks to
 * no other process, so Open MPI's probing of fast networks (UCX: 0.2 s) and its helper daemon
 * (0.1 s) are pure start-up cost, most of a small run's 0.4 s. Open MPI's own switches, only where
 * the user set none; other MPIs ignore them. Under mpiexec nothing changes. */
static void SingletonMPIDefaults(void)
{
  static const char *const launched[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID", "MPI_LOCALNRANKS", NULL};

  for (int k = 0; launched[k]; k++)
    if (getenv(launched[k])) return;
  (void)setenv("OMPI_MCA_pml", "ob1", 0);
  (void)setenv("OMPI_MCA_osc", "pt2pt", 0);
  (void)setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
}

PetscErrorCode PeriInitialize(int *argc, char ***argv, const char help[])
{
  PetscFunctionBeginUser;
  SingletonMPIDefaults();
  /* under LeakSanitizer, what MPI allocates at start and end is MPI's (Open MPI keeps much of it to
   * the end): not counted, so that a leak reported is perilin's (tests/sanitize/run.sh) */
  PeriLeakCheckPause(PETSC_TRUE);
  PetscCall(SlepcInitialize(argc, argv, NULL, help));
  PeriLeakCheckPause(PETSC_FALSE);
  PetscCall(PeriMallocInitialize());
  PetscCall(PeriSignalsInstall());
  PetscCall(PeriBLASThreadsInitialize());
  PetscCall(PeriInitializePackage());
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriFinalize(void)
{
  PetscFunctionBeginUser;
  PeriLeakCheckPause(PETSC_TRUE);
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
    {"core", "contact", PeriContactSchema},
};

/* The problem's keys, read by src/problem.c: the root keys, in the order "allowed here" lists
 * them, and the core's keys of analysis and output (the analyses declare theirs). Declared here,
 * with the table of every owner, so that the package sits below the problem. */
static const PeriKey root_keys[] = {
    {"dim", PERI_KEY_INT, "required", "{2, 3}", NULL, NULL, "the space dimension"},
    {"model", PERI_KEY_MAP, "required", NULL, NULL, NULL, "the bond model and its constants"},
    {"material", PERI_KEY_MAP, "required", NULL, NULL, NULL, "the elastic constants and the density"},
    {"grid", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "particles on a regular grid filling a box (or particles)"},
    {"particles", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "particles read from a CSV file (or grid)"},
    {"horizon", PERI_KEY_MAP, "required", NULL, NULL, NULL, "the horizon radius"},
    {"corrections", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "partial-volume and surface corrections"},
    {"regions", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "named boxes and boundary layers"},
    {"bc", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "boundary conditions, applied in order"},
    {"loads", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "forces, tractions and body forces"},
    {"probes", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "named points reported after the solve"},
    {"analysis", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "what to compute"},
    {"output", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "where and what to write"},
    {"reference", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "an exact plane elasticity field to compare with"},
    {"boundary_layers", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "fictitious layers outside the faces (cross-section models)"},
    {"torsion", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "the twist of a bar (cross-section models)"},
    {"failure", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "bond failure criteria"},
    {"cracks", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "pre-existing cracks"},
    {"contact", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "contact between particles without a bond, in time ({} for the defaults; docs/contact.md)"},
    {"impactors", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "rigid bodies in penalty contact with the body, in time"},
    {"solver", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "checks of the linear solves"},
    {NULL},
};
static const PeriKey analysis_keys[] = {
    {"type", PERI_KEY_STRING, "static", NULL, NULL, NULL, "the analysis"},
    {NULL},
};
static const PeriKey output_keys[] = {
    {"dir", PERI_KEY_STRING, "<scene file name without directory and last extension>-out", NULL, NULL, NULL, "output directory"},
    {"vtk", PERI_KEY_BOOL, "true", NULL, NULL, NULL, "write particles.vtu"},
    {"plots", PERI_KEY_BOOL, "true", NULL, NULL, NULL, "draw the run's pictures into the output set (PNG, python3-matplotlib): quasistatic load_displacement.png, modal modes.png, anisotropy anisotropy_polar.png and anisotropy_envelope.png; when they cannot be drawn, a warning and summary.json plots.error, the run's results stay"},
    {"stress", PERI_KEY_BOOL, "false", NULL, NULL, NULL, "per-particle stress and strain (vector models): arrays stress, strain, elastic_stress in particles.vtu and sigma, epsilon, sigma_elastic in the probes (docs/stress.md); costs a pass over the bonds and 27 numbers per particle"},
    {NULL},
};
const PeriSchema PeriProblemSchema[] = {
    {"", root_keys},
    {"analysis", analysis_keys},
    {"output", output_keys},
    {NULL},
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

/* perilin's own options, those that are no scene key (every scene key is an option too): -help
 * lists them before the keys. Keep in step with the PetscOptionsGet* calls that read them. */
static const char *const own_options[][2] = {
    {"-help, -h, --help", "this help; -help petsc adds PETSc's and SLEPc's generic options after it"},
    {"-version, --version", "perilin's version (from the build), PETSc's and SLEPc's"},
    {"-quiet", "no status line and no per-step log"},
    {"-progress <bool>", "the status line on or off (default: on when stdout is a terminal, outside mpiexec)"},
    {"-output_dir DIR", "the output directory (the scene key output.dir; default SCENE-out)"},
    {"-restart DIR", "quasistatic: continue the run whose output directory is DIR from its checkpoint (DIR/checkpoint/state.bin), same scene and ranks"},
    {"-peri_checkpoint_every N", "quasistatic: write the checkpoint every N equilibria (default 1); dynamic: every N time steps (default: at the frames, about 25 over the run); 0 writes none"},
    {"-peri_stop_after_step K", "quasistatic: stop after equilibrium K, dynamic: after time step K, as a SIGINT would (to test restarts)"},
    {"-options_unused_ok", "options that nothing reads are warnings, not errors"},
    {"-peri_scene_sealed <bool>", "an error when any part reads the scene after the set-up (a test that settings are read once)"},
    {"-peri_partition TYPE", "how the particles are shared out on several ranks: geometric (default), metis, ptscotch"},
    {"-peri_memory_check <bool>", "refuse a scene that does not fit in the node's available memory; default true"},
    {"-peri_release_bond_geometry <bool>", "free the bonds' geometry while a static solve runs, and search without it where nothing needs it stored; default true"},
    {"-peri_operator_springs <bool>", "the matrix-free operator keeps one number per central spring and forms its vector from the coordinates (12 bytes a bond); false: the vector itself (28 bytes, a product up to 1.2x faster on thin bodies); default true"},
    {"-peri_failure_screen <bool>", "a time loop's every-step failure check skips, by its stretch alone, each bond well below a tension or G limit (the same bonds break); false: every live bond in full; default true"},
    {"-peri_read_chunk N", "particles per chunk rank 0 deals out from particles.file or .mesh; default 65536"},
    {"-peri_malloc_mmap_threshold N", "arrays of N bytes and more (N <= 32 MiB) are mapped on their own; default 32 MiB, 0: off"},
    {"-scene_doc_update FILE", "rewrite the key tables of FILE (docs/scene.md) from the declared keys"},
    {"-scene_doc_check FILE", "fail when the key tables of FILE are out of date"},
};

/* Whether the option name (with its '-') is one of perilin's own <bool> options. */
static PetscBool OwnBool(const char name[])
{
  size_t n = strlen(name);
  for (size_t k = 0; k < PETSC_STATIC_ARRAY_LENGTH(own_options); k++)
    if (!strncmp(own_options[k][0], name, n) && !strcmp(own_options[k][0] + n, " <bool>")) return PETSC_TRUE;
  return PETSC_FALSE;
}

/* PeriOptionsEachValue's check for perilin's own <bool> options */
static PetscErrorCode CheckOwnBool(const char name[], const char value[], void *ctx, char msg[], size_t len)
{
  PetscBool      b;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  (void)ctx;
  if (!OwnBool(name)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = PetscOptionsStringToBool(value, &b);
  PetscCall(PetscPopErrorHandler());
  if (ierr) PetscCall(PetscSNPrintf(msg, len, "option %s: '%s' is not a boolean (true or false; also yes, no, on, off, 1, 0)", name, value));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOptionsCheckOwnBools - refuses a value of perilin's own <bool> options (-progress,
  -peri_memory_check, ...) that is no boolean, naming the option, before anything reads it
  (PETSc's refusal names the value only). Marks no option as read. Collective: every rank has the
  same options.
@*/
PetscErrorCode PeriOptionsCheckOwnBools(MPI_Comm comm)
{
  char *all, msg[256];

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetAll(NULL, &all));
  PetscCall(PeriOptionsEachValue(all, CheckOwnBool, NULL, msg, sizeof(msg)));
  PetscCall(PetscFree(all));
  PetscCheck(!msg[0], comm, PETSC_ERR_USER_INPUT, "%s", msg);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriPrintHelp - perilin's usage, its own options, then every scene key with its meaning (perilin
  -help). PETSc's options are not listed: perilin -help petsc prints them after this. Collective.
@*/
PetscErrorCode PeriPrintHelp(MPI_Comm comm)
{
  PeriSchemaOwner owners[PERI_MAX_SCHEMA_OWNERS];
  PetscInt        n;

  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(comm, "perilin: implicit static and modal peridynamics.\n"
                              "Usage: perilin SCENE.yaml [-KEY VALUE ...] [perilin options] [PETSc options]\n"
                              "       perilin -help [petsc] | -version\n"
                              "The scene file comes first; every option follows it.\n"
                              "perilin options:\n"));
  for (size_t k = 0; k < PETSC_STATIC_ARRAY_LENGTH(own_options); k++) PetscCall(PetscPrintf(comm, "  %-36s %s\n", own_options[k][0], own_options[k][1]));
  PetscCall(PeriSchemaOwners(PERI_MAX_SCHEMA_OWNERS, owners, &n));
  PetscCall(PeriSceneHelp(comm, n, owners));
  PetscCall(PetscPrintf(comm, "PETSc and SLEPc options (-ksp_*, -pc_*, -eps_*, -st_*, -log_view, ...) follow the scene file too;\n"
                              "perilin -help petsc lists PETSc's generic ones after this help (docs/scene.md).\n"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriGetVersions - perilin's version as built (the CMake project version, plus `git describe
  --always --dirty` of the checkout it was built from: "0.1.0+a163e3b"), and the versions of the
  PETSc and SLEPc libraries it runs with ("3.18.5"), each at most len characters. Not collective.
@*/
PetscErrorCode PeriGetVersions(char perilin[], char petsc[], char slepc[], size_t len)
{
  PetscInt major, minor, sub;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(perilin, PeriBuildVersion(), len));
  PetscCall(PetscGetVersionNumber(&major, &minor, &sub, NULL));
  PetscCall(PetscSNPrintf(petsc, len, "%" PetscInt_FMT ".%" PetscInt_FMT ".%" PetscInt_FMT, major, minor, sub));
  PetscCall(SlepcGetVersionNumber(&major, &minor, &sub, NULL));
  PetscCall(PetscSNPrintf(slepc, len, "%" PetscInt_FMT ".%" PetscInt_FMT ".%" PetscInt_FMT, major, minor, sub));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriPrintVersion - "perilin V", "PETSc V", "SLEPc V", one a line (perilin -version). Collective.
@*/
PetscErrorCode PeriPrintVersion(MPI_Comm comm)
{
  char perilin[PERI_VERSION_LEN], petsc[PERI_VERSION_LEN], slepc[PERI_VERSION_LEN];

  PetscFunctionBeginUser;
  PetscCall(PeriGetVersions(perilin, petsc, slepc, PERI_VERSION_LEN));
  PetscCall(PetscPrintf(comm, "perilin %s\nPETSc %s\nSLEPc %s\n", perilin, petsc, slepc));
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

/* The first error's message since PeriErrorReset, as perilin states it: input and convergence
 * errors by their message alone, others with PETSc's code and place. */
static char first_error[4096];

/*@C
  PeriErrorCapture - a PETSc error handler (PetscPushErrorHandler) that keeps the first error's
  message for PeriErrorFirst and returns the error: the executable prints it once instead of
  PETSc's traceback, the Python module raises it as perilin.Error. Not collective.
@*/
PetscErrorCode PeriErrorCapture(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *ctx)
{
  (void)comm;
  (void)ctx;
  if (p == PETSC_ERROR_INITIAL && !first_error[0]) {
    if (n == PETSC_ERR_USER_INPUT || n == PETSC_ERR_NOT_CONVERGED)
      PetscSNPrintf(first_error, sizeof(first_error), "%s", mess ? mess : "invalid input");
    else
      PetscSNPrintf(first_error, sizeof(first_error), "%s (PETSc error %d in %s() at %s:%d)", mess ? mess : "error", (int)n, fun, file, line);
  }
  return n;
}

/* The message PeriErrorCapture kept ("" when none). */
const char *PeriErrorFirst(void)
{
  return first_error;
}

/* Forgets the kept message: the next error's is kept. */
void PeriErrorReset(void)
{
  first_error[0] = 0;
}
