/* analysis.type: setup. A dry run: the scene is read and the system set up (particles, partition,
 * bonds, calibration, regions, conditions, loads: every input check), and nothing is assembled or
 * solved. summary.json gives the sizes, the edge cut and the set-up cost, particles.vtu the
 * volumes, neighbour counts and ranks: a scene is checked, or a large run sized, before it is paid
 * for. Also the smallest example of an analysis (docs/design.md, "How to add an analysis"). */
#include "perilin/private/analysis.h"

static PetscErrorCode Report_Setup(PeriAnalysis an)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(an->comm, "perilin: set-up only, nothing solved: %" PetscInt_FMT " bonds between ranks; results in %s/\n", an->sys->run.log.edge_cut, an->output_dir));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* No schema: the dry run accepts every analysis' keys (src/problem.c), so that a modal or a
 * quasi-static scene can be checked with -analysis_type setup. No run: no solver is used, so
 * summary.json has no solver section and the report no solver line. Its memory estimate sizes a
 * static run with K assembled. */
const PeriAnalysisType PeriAnalysis_Setup = {
    .name  = "setup",
    .help  = "set up the system and stop: check a scene, size a run",
    .needs = {.static_solver = PETSC_TRUE, .dry_run = PETSC_TRUE},
    .ops   = {.report = Report_Setup},
};
