/* The system's sections of summary.json, one function each: the model and material, the boundary
 * layers, the cost, the solver, torsion, the fields, the reference comparison and the probes.
 * Each writes nothing when its feature is inactive. */
#include "perilin/private/system.h"

PetscErrorCode PeriSystemSummaryModel(PeriSystem sys, PeriJSON j)
{
  const PeriModel m = sys->model;

  PetscFunctionBeginUser;
  PetscCall(PeriJSONString(j, "model", m->type));
  PetscCall(PeriJSONInt(j, "dim", sys->particles.dim));
  if (sys->particles.dim == 2) PetscCall(PeriJSONString(j, "plane", m->plane_strain ? "strain" : "stress"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sizes and the discretization: particles, bonds, DOFs, ranks, horizon, corrections, material,
 * boundary layers. */
PetscErrorCode PeriSystemSummaryDiscretization(PeriSystem sys, PeriJSON j)
{
  const PeriResults *r = &sys->results;
  const PeriModel    m = sys->model;

  PetscFunctionBeginUser;
  PetscCall(PeriJSONInt(j, "particles", sys->particles.n));
  PetscCall(PeriJSONInt(j, "bonds", r->nbonds_total));
  PetscCall(PeriJSONInt(j, "dofs", sys->particles.n * m->dofs));
  PetscCall(PeriJSONInt(j, "ranks", sys->size));
  PetscCall(PeriJSONInt(j, "edge_cut", r->edge_cut));
  PetscCall(PeriJSONReal(j, "horizon", sys->delta));
  PetscCall(PeriJSONString(j, "partial_volume", PeriPartialVolumes[sys->partial_volume]));
  PetscCall(PeriJSONString(j, "surface_correction", PeriSurfaceCorrections[sys->surface]));
  PetscCall(PeriJSONBeginObject(j, "material"));
  PetscCall(PeriJSONReal(j, "E", m->material.E));
  PetscCall(PeriJSONReal(j, "nu", m->material.nu));
  PetscCall(PeriJSONReal(j, "K", m->material.K));
  PetscCall(PeriJSONReal(j, "G", m->material.G));
  PetscCall(PeriJSONEndObject(j));
  if (sys->layers.nfaces) {
    static const char *const faces[] = {"x-", "x+", "y-", "y+"};
    PetscCall(PeriJSONBeginObject(j, "boundary_layers"));
    PetscCall(PeriJSONInt(j, "fictitious_particles", sys->particles.nfictitious));
    for (PetscInt f = 0; f < 4; f++)
      if (sys->layers.kind[f]) PetscCall(PeriJSONString(j, faces[f], PeriLayerKinds[sys->layers.kind[f]]));
    PetscCall(PeriJSONEndObject(j));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What the run cost: time per phase and peak memory. */
PetscErrorCode PeriSystemSummaryCost(PeriSystem sys, PeriJSON j)
{
  const PeriResults *r = &sys->results;

  PetscFunctionBeginUser;
  PetscCall(PeriJSONBeginObject(j, "timing"));
  PetscCall(PeriJSONReal(j, "neighbors_s", r->neighbors_s));
  PetscCall(PeriJSONReal(j, "assembly_s", r->assembly_s));
  PetscCall(PeriJSONReal(j, "solve_s", r->solve_s));
  PetscCall(PeriJSONReal(j, "total_s", r->total_s));
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PeriJSONReal(j, "memory_mb", r->memory_mb));
  PetscCall(PeriJSONReal(j, "memory_mb_max_rank", r->memory_mb_max_rank));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The last solve: KSP and PC, iterations, the true residual and its tolerance. None when no
 * solver was used (analysis setup); an interrupted run always says whether it converged. */
PetscErrorCode PeriSystemSummarySolver(PeriSystem sys, PeriJSON j)
{
  const PeriResults *r = &sys->results;

  PetscFunctionBeginUser;
  if (!r->ksp_type[0] && !sys->interrupted) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "solver"));
  PetscCall(PeriJSONString(j, "ksp_type", r->ksp_type));
  PetscCall(PeriJSONString(j, "pc_type", r->pc_type));
  PetscCall(PeriJSONInt(j, "iterations", r->iterations));
  PetscCall(PeriJSONString(j, "converged_reason", r->converged_reason));
  PetscCall(PeriJSONReal(j, "residual_norm", r->residual_norm));
  if (r->residual_tol > 0) PetscCall(PeriJSONReal(j, "residual_tol", r->residual_tol));
  /* written results passed every check; an interrupted solve did not finish */
  PetscCall(PeriJSONBool(j, "converged", sys->interrupted && !sys->u_all ? PETSC_FALSE : PETSC_TRUE));
  PetscCall(PeriJSONString(j, "operator", r->symmetric ? "symmetric" : "unsymmetric"));
  if (r->free_modes) {
    PetscCall(PeriJSONInt(j, "free_rigid_motions", r->free_modes));
    PetscCall(PeriJSONReal(j, "load_share_removed", r->load_imbalance));
  }
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSystemSummaryTorsion(PeriSystem sys, PeriJSON j)
{
  const PeriTorsion *t = &sys->torsion;

  PetscFunctionBeginUser;
  if (!t->active || !sys->tau) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "torsion"));
  PetscCall(PeriJSONReal(j, "twist", t->twist));
  PetscCall(PeriJSONRealArray(j, "center", 2, t->center));
  PetscCall(PeriJSONReal(j, "torque", t->torque));
  PetscCall(PeriJSONReal(j, "J", t->J));
  PetscCall(PeriJSONReal(j, "J_rectangle_exact", t->J_rectangle));
  PetscCall(PeriJSONReal(j, "J_error_vs_rectangle", t->J / t->J_rectangle - 1));
  PetscCall(PeriJSONReal(j, "max_shear_stress", t->max_stress));
  PetscCall(PeriJSONRealArray(j, "max_shear_stress_at", 2, t->max_at));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Strain energy and the largest |u| per component, when there is a solution. */
PetscErrorCode PeriSystemSummaryFields(PeriSystem sys, PeriJSON j)
{
  const PeriResults *r = &sys->results;

  PetscFunctionBeginUser;
  if (!sys->u_all) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONReal(j, "strain_energy", r->strain_energy));
  PetscCall(PeriJSONBeginObject(j, "max_abs_u"));
  for (PetscInt c = 0; c < sys->model->dofs; c++) PetscCall(PeriJSONReal(j, sys->model->components[c], r->max_abs_u[c]));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Against reference.*: interior strain, effective moduli, errors. */
PetscErrorCode PeriSystemSummaryReference(PeriSystem sys, PeriJSON j)
{
  const PeriResults *r = &sys->results;

  PetscFunctionBeginUser;
  if (!r->has_reference) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "reference"));
  PetscCall(PeriJSONString(j, "type", PeriReferenceTypes[sys->reference.type]));
  PetscCall(PeriJSONReal(j, "stress", sys->reference.stress));
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PeriJSONInt(j, "interior_particles", r->interior_particles));
  PetscCall(PeriJSONRealArray(j, "interior_strain", 3, r->interior_strain));
  PetscCall(PeriJSONBeginObject(j, "effective"));
  if (r->effective_E != 0) PetscCall(PeriJSONReal(j, "E", r->effective_E));
  if (r->effective_E != 0) PetscCall(PeriJSONReal(j, "nu", r->effective_nu));
  if (r->effective_G != 0) PetscCall(PeriJSONReal(j, "G", r->effective_G));
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PeriJSONBeginObject(j, "error"));
  PetscCall(PeriJSONReal(j, "l2_rel", r->error_l2_rel));
  PetscCall(PeriJSONReal(j, "max_rel", r->error_max_rel));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* probes: the values at the nearest particle of each point, when there is a solution. */
PetscErrorCode PeriSystemSummaryProbes(PeriSystem sys, PeriJSON j)
{
  PetscFunctionBeginUser;
  PetscCall(PeriJSONBeginObject(j, "probes"));
  for (PetscInt k = 0; sys->u_all && k < sys->nprobes; k++) {
    const PeriProbe *pr = &sys->probes[k];
    PetscCall(PeriJSONBeginObject(j, pr->name));
    PetscCall(PeriJSONRealArray(j, "x", sys->particles.dim, pr->x));
    PetscCall(PeriJSONRealArray(j, "particle_x", sys->particles.dim, &sys->particles.x[3 * pr->particle]));
    PetscCall(PeriJSONString(j, "sampling", "nearest particle"));
    PetscCall(PeriJSONRealArray(j, "u", sys->model->dofs, pr->u));
    PetscCall(PeriJSONReal(j, "W", pr->W));
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}
