/* The system's general sections of summary.json: the model, the discretization, the cost, the
 * solver, the fields. Features contribute theirs from their own files (PeriTorsionSummary in
 * layers.c, PeriReferenceSummary in reference.c, PeriProbesSummary in fields.c). Each writes
 * nothing when its feature is inactive. */
#include "perilin/private/system.h"

PetscErrorCode PeriSystemSummaryModel(PeriSystem sys, PeriJSON j)
{
  const PeriModel m = sys->model;

  PetscFunctionBeginUser;
  PetscCall(PeriJSONString(j, "model", m->type));
  PetscCall(PeriJSONInt(j, "dim", sys->disc.particles.dim));
  if (sys->disc.particles.dim == 2) PetscCall(PeriJSONString(j, "plane", m->plane_strain ? "strain" : "stress"));
  PetscCall(PeriJSONString(j, "calibration", PeriCalibrationKinds[m->calibration]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sizes and the discretization: particles, bonds, DOFs, ranks, horizon, corrections, material. */
PetscErrorCode PeriSystemSummaryDiscretization(PeriSystem sys, PeriJSON j)
{
  const PeriModel m = sys->model;

  PetscFunctionBeginUser;
  PetscCall(PeriJSONInt(j, "particles", sys->disc.N));
  PetscCall(PeriJSONInt(j, "bonds", sys->run.log.nbonds_total));
  if (sys->bond_state.failure.ncracks) PetscCall(PeriJSONInt(j, "precracked_bonds", sys->bond_state.failure.precracked_bonds)); /* cracks: */
  PetscCall(PeriJSONInt(j, "dofs", sys->disc.N * m->dofs));
  PetscCall(PeriJSONInt(j, "ranks", sys->size));
  PetscCall(PeriJSONInt(j, "edge_cut", sys->run.log.edge_cut));
  PetscCall(PeriJSONReal(j, "horizon", sys->disc.delta));
  if (sys->disc.horizon) PetscCall(PeriJSONReal(j, "horizon_min", sys->disc.horizon_min)); /* horizon.spacing: own: "horizon" is the largest */
  PetscCall(PeriJSONString(j, "partial_volume", PeriPartialVolumes[sys->disc.partial_volume]));
  PetscCall(PeriJSONString(j, "surface_correction", PeriSurfaceCorrections[sys->disc.surface]));
  PetscCall(PeriJSONBeginObject(j, "material"));
  PetscCall(PeriJSONReal(j, "E", m->material.E));
  PetscCall(PeriJSONReal(j, "nu", m->material.nu));
  PetscCall(PeriJSONReal(j, "K", m->material.K));
  PetscCall(PeriJSONReal(j, "G", m->material.G));
  if (m->material.rho > 0) PetscCall(PeriJSONReal(j, "rho", m->material.rho)); /* given: the mass of a transient or modal run */
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What the run cost: time per phase and peak memory. */
PetscErrorCode PeriSystemSummaryCost(PeriSystem sys, PeriJSON j)
{

  PetscFunctionBeginUser;
  PetscCall(PeriJSONBeginObject(j, "timing"));
  PetscCall(PeriJSONReal(j, "neighbors_s", sys->run.log.neighbors_s));
  PetscCall(PeriJSONReal(j, "assembly_s", sys->run.log.assembly_s));
  PetscCall(PeriJSONReal(j, "solve_s", sys->run.log.solve_s));
  PetscCall(PeriJSONReal(j, "total_s", sys->run.log.total_s));
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PeriJSONReal(j, "memory_mb", sys->run.log.memory_mb));
  PetscCall(PeriJSONReal(j, "memory_mb_max_rank", sys->run.log.memory_mb_max_rank));
  /* where the peak was reached (issue 14, item 4): the largest rank's peak at the end of each
     phase, and K's own bytes for comparison */
  PetscCall(PeriJSONBeginObject(j, "memory_phases_mb"));
  PetscCall(PeriJSONReal(j, "setup", sys->run.log.memory_phase_mb[0]));
  if (sys->run.log.memory_phase_mb[1] > 0) PetscCall(PeriJSONReal(j, "assembly", sys->run.log.memory_phase_mb[1]));
  PetscCall(PeriJSONReal(j, "run", sys->run.log.memory_phase_mb[2]));
  PetscCall(PeriJSONEndObject(j));
  if (sys->run.log.matrix_mb > 0) PetscCall(PeriJSONReal(j, "matrix_mb", sys->run.log.matrix_mb));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The last solve: KSP and PC, iterations, the true residual and its tolerance. None when no
 * solver was used (analysis setup); an interrupted run always says whether it converged. */
PetscErrorCode PeriSystemSummarySolver(PeriSystem sys, PeriJSON j)
{

  PetscFunctionBeginUser;
  if (!sys->fields.solve.ksp_type[0] && !sys->run.interrupted) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "solver"));
  PetscCall(PeriJSONString(j, "ksp_type", sys->fields.solve.ksp_type));
  PetscCall(PeriJSONString(j, "pc_type", sys->fields.solve.pc_type));
  PetscCall(PeriJSONInt(j, "iterations", sys->fields.solve.iterations));
  PetscCall(PeriJSONString(j, "converged_reason", sys->fields.solve.converged_reason));
  PetscCall(PeriJSONReal(j, "residual_norm", sys->fields.solve.residual_norm));
  if (sys->fields.solve.residual_tol > 0) PetscCall(PeriJSONReal(j, "residual_tol", sys->fields.solve.residual_tol));
  /* written results passed every check; an interrupted solve did not finish */
  PetscCall(PeriJSONBool(j, "converged", sys->run.interrupted && !sys->fields.has_solution ? PETSC_FALSE : PETSC_TRUE));
  PetscCall(PeriJSONString(j, "operator", sys->fields.solve.symmetric ? "symmetric" : "unsymmetric"));
  PetscCall(PeriJSONString(j, "stiffness", sys->stiffness.op ? "matrix_free" : "assembled"));
  if (sys->fields.solve.free_modes) {
    PetscCall(PeriJSONInt(j, "free_rigid_motions", sys->fields.solve.free_modes));
    PetscCall(PeriJSONReal(j, "load_share_removed", sys->fields.solve.load_imbalance));
  }
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Strain energy and the largest |u| per component, when there is a solution. */
PetscErrorCode PeriSystemSummaryFields(PeriSystem sys, PeriJSON j)
{

  PetscFunctionBeginUser;
  if (!sys->fields.has_solution) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONReal(j, "strain_energy", sys->fields.strain_energy));
  PetscCall(PeriJSONBeginObject(j, "max_abs_u"));
  for (PetscInt c = 0; c < sys->model->dofs; c++) PetscCall(PeriJSONReal(j, sys->model->components[c], sys->fields.max_abs_u[c]));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}
