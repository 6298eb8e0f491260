/* summary.json: what the run was, what it cost, and its results (docs/summary.md lists the keys). */
#include "perilin.h"
#include <signal.h>

static PetscErrorCode WriteSummary(PeriProblem p, PeriJSON j)
{
  PeriResults   *r  = &p->results;
  const PetscInt bs = p->model->dofs;

  PetscFunctionBeginUser;
  PetscCall(PeriJSONString(j, "scene", p->scene->file));
  PetscCall(PeriJSONString(j, "model", p->model->type));
  PetscCall(PeriJSONInt(j, "dim", p->particles.dim));
  if (p->particles.dim == 2) PetscCall(PeriJSONString(j, "plane", p->model->plane_strain ? "strain" : "stress"));
  PetscCall(PeriJSONString(j, "analysis", p->analysis));
  /* false only for a run stopped by a signal: then the fields below describe the last complete
     state (quasistatic), or there are none */
  PetscCall(PeriJSONBool(j, "complete", p->interrupted ? PETSC_FALSE : PETSC_TRUE));
  if (p->interrupted) PetscCall(PeriJSONString(j, "interrupted_by", p->interrupted == SIGTERM ? "SIGTERM" : "SIGINT"));
  PetscCall(PeriJSONInt(j, "particles", p->particles.n));
  PetscCall(PeriJSONInt(j, "bonds", r->nbonds_total));
  PetscCall(PeriJSONInt(j, "dofs", p->particles.n * bs));
  PetscCall(PeriJSONInt(j, "ranks", p->size));
  PetscCall(PeriJSONInt(j, "edge_cut", r->edge_cut));
  PetscCall(PeriJSONReal(j, "horizon", p->delta));
  PetscCall(PeriJSONString(j, "partial_volume", PeriPartialVolumes[p->partial_volume]));
  PetscCall(PeriJSONString(j, "surface_correction", PeriSurfaceCorrections[p->surface]));
  PetscCall(PeriJSONBeginObject(j, "material"));
  PetscCall(PeriJSONReal(j, "E", p->model->material.E));
  PetscCall(PeriJSONReal(j, "nu", p->model->material.nu));
  PetscCall(PeriJSONReal(j, "K", p->model->material.K));
  PetscCall(PeriJSONReal(j, "G", p->model->material.G));
  PetscCall(PeriJSONEndObject(j));
  if (p->layers.nfaces) {
    static const char *const faces[] = {"x-", "x+", "y-", "y+"};
    PetscCall(PeriJSONBeginObject(j, "boundary_layers"));
    PetscCall(PeriJSONInt(j, "fictitious_particles", p->particles.nfictitious));
    for (PetscInt f = 0; f < 4; f++)
      if (p->layers.kind[f]) PetscCall(PeriJSONString(j, faces[f], PeriLayerKinds[p->layers.kind[f]]));
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONBeginObject(j, "timing"));
  PetscCall(PeriJSONReal(j, "neighbors_s", r->neighbors_s));
  PetscCall(PeriJSONReal(j, "assembly_s", r->assembly_s));
  PetscCall(PeriJSONReal(j, "solve_s", r->solve_s));
  PetscCall(PeriJSONReal(j, "total_s", r->total_s));
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PeriJSONReal(j, "memory_mb", r->memory_mb));
  PetscCall(PeriJSONReal(j, "memory_mb_max_rank", r->memory_mb_max_rank));
  PetscCall(PeriJSONBeginObject(j, "solver"));
  PetscCall(PeriJSONString(j, "ksp_type", r->ksp_type));
  PetscCall(PeriJSONString(j, "pc_type", r->pc_type));
  PetscCall(PeriJSONInt(j, "iterations", r->iterations));
  PetscCall(PeriJSONString(j, "converged_reason", r->converged_reason));
  PetscCall(PeriJSONReal(j, "residual_norm", r->residual_norm));
  if (r->residual_tol > 0) PetscCall(PeriJSONReal(j, "residual_tol", r->residual_tol));
  /* written results passed every check; an interrupted solve did not finish */
  PetscCall(PeriJSONBool(j, "converged", p->interrupted && !p->u_all ? PETSC_FALSE : PETSC_TRUE));
  PetscCall(PeriJSONString(j, "operator", r->symmetric ? "symmetric" : "unsymmetric"));
  if (r->free_modes) {
    PetscCall(PeriJSONInt(j, "free_rigid_motions", r->free_modes));
    PetscCall(PeriJSONReal(j, "load_share_removed", r->load_imbalance));
  }
  PetscCall(PeriJSONEndObject(j));
  if (p->quasistatic) {
    const PeriQuasistatic *q = p->quasistatic;
    PetscCall(PeriJSONBeginObject(j, "quasistatic"));
    PetscCall(PeriJSONInt(j, "steps", q->nsteps));
    PetscCall(PeriJSONString(j, "state", "last equilibrium"));
    PetscCall(PeriJSONReal(j, "peak_load_factor", q->peak_load_factor));
    if (q->failed) {
      PetscCall(PeriJSONReal(j, "critical_load_factor", q->critical_load_factor));
      PetscCall(PeriJSONInt(j, "failure_step", q->failure_step));
      PetscCall(PeriJSONInt(j, "failed_trial_broken_bonds", q->failed_trial_broken));
    }
    PetscCall(PeriJSONInt(j, "broken_bonds", q->broken_bonds));
    PetscCall(PeriJSONInt(j, "precracked_bonds", r->precracked_bonds));
    PetscCall(PeriJSONBool(j, "failed", q->failed));
    PetscCall(PeriJSONBool(j, "complete", q->complete));
    PetscCall(PeriJSONString(j, "ending", q->ending));
    PetscCall(PeriJSONInt(j, "solves", q->solves));
    PetscCall(PeriJSONInt(j, "preconditioner_setups", q->pc_setups));
    if (q->control[0]) PetscCall(PeriJSONString(j, "control_probe", q->control));
    PetscCall(PeriJSONEndObject(j));
  }
  if (p->torsion.active && p->tau) {
    const PeriTorsion *t = &p->torsion;
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
  }
  if (p->u_all) {
    PetscCall(PeriJSONReal(j, "strain_energy", r->strain_energy));
    PetscCall(PeriJSONBeginObject(j, "max_abs_u"));
    for (PetscInt c = 0; c < bs; c++) PetscCall(PeriJSONReal(j, p->model->components[c], r->max_abs_u[c]));
    PetscCall(PeriJSONEndObject(j));
  }
  if (r->has_reference) {
    PetscCall(PeriJSONBeginObject(j, "reference"));
    PetscCall(PeriJSONString(j, "type", PeriReferenceTypes[p->reference.type]));
    PetscCall(PeriJSONReal(j, "stress", p->reference.stress));
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
  }
  if (p->modal) {
    const PeriModal *md = p->modal;
    PetscReal        f[256];
    PetscCall(PeriJSONBeginObject(j, "modal"));
    for (PetscInt k = 0; k < PetscMin(md->nmodes, 256); k++) f[k] = md->modes[k].f_hz;
    PetscCall(PeriJSONRealArray(j, "frequencies_hz", PetscMin(md->nmodes, 256), f));
    PetscCall(PeriJSONInt(j, "rigid_modes", md->nrigid));
    PetscCall(PeriJSONInt(j, "free_dofs", md->nfree_dofs));
    PetscCall(PeriJSONReal(j, "total_mass", md->total_mass));
    PetscCall(PeriJSONString(j, "axis", (const char *[]){"x", "y", "z"}[md->axis]));
    PetscCall(PeriJSONReal(j, "factorization_s", md->factor_s));
    PetscCall(PeriJSONReal(j, "eigensolve_s", md->solve_s));
    if (md->longitudinal_speed > 0) PetscCall(PeriJSONReal(j, "longitudinal_speed", md->longitudinal_speed));
    if (md->theory_speed > 0) PetscCall(PeriJSONReal(j, "theory_speed", md->theory_speed));
    PetscCall(PeriJSONBeginArray(j, "modes"));
    for (PetscInt k = 0; k < md->nmodes; k++) {
      const PeriMode *m = &md->modes[k];
      PetscCall(PeriJSONBeginObject(j, NULL));
      PetscCall(PeriJSONReal(j, "f_hz", m->f_hz));
      PetscCall(PeriJSONReal(j, "residual", m->residual));
      PetscCall(PeriJSONString(j, "kind", m->kind));
      PetscCall(PeriJSONBeginObject(j, "energy_share"));
      for (PetscInt c = 0; c < bs; c++) PetscCall(PeriJSONReal(j, p->model->components[c], m->energy_share[c]));
      PetscCall(PeriJSONEndObject(j));
      PetscCall(PeriJSONRealArray(j, "effective_mass", p->particles.dim, m->effective_mass));
      PetscCall(PeriJSONEndObject(j));
    }
    PetscCall(PeriJSONEndArray(j));
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONBeginObject(j, "probes"));
  for (PetscInt k = 0; p->u_all && k < p->nprobes; k++) {
    PeriProbe *pr = &p->probes[k];
    PetscCall(PeriJSONBeginObject(j, pr->name));
    PetscCall(PeriJSONRealArray(j, "x", p->particles.dim, pr->x));
    PetscCall(PeriJSONRealArray(j, "particle_x", p->particles.dim, &p->particles.x[3 * pr->particle]));
    PetscCall(PeriJSONString(j, "sampling", "nearest particle"));
    PetscCall(PeriJSONRealArray(j, "u", bs, pr->u));
    PetscCall(PeriJSONReal(j, "W", pr->W));
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONEndObject(j));
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
