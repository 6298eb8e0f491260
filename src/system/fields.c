/* Fields after a solve: strain energy density, antiplane shear stresses, probes. */
#include "perilin/private/system.h"

static PetscBool LexLess(const PetscReal a[], const PetscReal b[])
{
  for (PetscInt d = 0; d < 3; d++)
    if (a[d] != b[d]) return a[d] < b[d] ? PETSC_TRUE : PETSC_FALSE;
  return PETSC_FALSE;
}

/* probes: any names, each a point. */
static const PeriKey probe_keys[] = {
    {"<name>", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "a point [x, y(, z)] inside the body: the displacement and energy density of the nearest particle (beyond its cell but within the horizon: taken there with a note; farther: an error)"},
    {NULL},
};
const PeriSchema PeriProbesSchema[] = {{"probes", probe_keys}, {NULL}};

/* The nearest owned particle of the body to the point y: its local index (-1: none) and squared
 * distance; ties go to the lexicographically smallest position, whatever the numbering (ranks). */
static PetscInt NearestOwned(PeriSystem sys, const PetscReal y[], PetscReal *best)
{
  const PeriParticles *pt = &sys->disc.particles;
  PetscInt             p  = -1;

  *best = PETSC_MAX_REAL;
  for (PetscInt i = 0; i < sys->disc.nowned; i++) {
    PetscReal d2 = 0;
    if (PeriParticleIsFictitious(pt, i)) continue;
    for (PetscInt d = 0; d < pt->dim; d++) d2 += PetscSqr(pt->x[3 * i + d] - y[d]);
    if (d2 < *best || (d2 == *best && LexLess(&pt->x[3 * i], &pt->x[3 * p]))) {
      *best = d2;
      p     = i;
    }
  }
  return p;
}

/* The probe's nearest particle over all ranks: each rank offers its nearest owned one (squared
 * distance, position, spacing, horizon), the best offer wins. Collective. */
static PetscErrorCode ProbeLocate(PeriSystem sys, PeriProbe *pr, PetscReal *dist, PetscReal *spacing, PetscReal *delta)
{
  const PeriParticles *pt = &sys->disc.particles;
  PetscReal            mine[6], *all;
  PetscInt             p = NearestOwned(sys, pr->x, &mine[0]);

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) mine[1 + d] = p >= 0 ? pt->x[3 * p + d] : 0;
  mine[4] = p >= 0 ? pt->spacing[p] : 0;
  mine[5] = p >= 0 && sys->disc.horizon ? sys->disc.horizon[p] : sys->disc.delta;
  PetscCall(PetscMalloc1(6 * sys->size, &all));
  PetscCallMPI(MPI_Allgather(mine, 6, MPIU_REAL, all, 6, MPIU_REAL, sys->comm));
  pr->rank = 0;
  for (PetscMPIInt r = 1; r < sys->size; r++) {
    const PetscReal *o = &all[6 * r], *b = &all[6 * pr->rank];
    if (o[0] < b[0] || (o[0] == b[0] && o[0] < PETSC_MAX_REAL && LexLess(&o[1], &b[1]))) pr->rank = r;
  }
  pr->particle = pr->rank == sys->rank ? p : -1;
  for (PetscInt d = 0; d < 3; d++) pr->particle_x[d] = all[6 * pr->rank + 1 + d];
  *dist    = PetscSqrtReal(all[6 * pr->rank]);
  *spacing = all[6 * pr->rank + 4];
  *delta   = all[6 * pr->rank + 5];
  PetscCall(PetscFree(all));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* "(x, y)" or "(x, y, z)", for messages. */
static PetscErrorCode PointString(PetscInt dim, const PetscReal x[], char s[], size_t len)
{
  PetscFunctionBeginUser;
  if (dim == 3)
    (void)snprintf(s, len, "(%g, %g, %g)", (double)x[0], (double)x[1], (double)x[2]);
  else
    (void)snprintf(s, len, "(%g, %g)", (double)x[0], (double)x[1]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A point within the nearest particle's cell (its circumscribed ball, radius sqrt(dim) h / 2) is
 * that particle's. A mesh's cells are not balls: a point inside the body near an element's corner,
 * or in an element beside a hole whose centroid is farther, can lie beyond it. Such a point, still
 * within the particle's horizon, is taken at the nearest particle with a note (summary.json:
 * snapped, distance); only a point farther than the horizon from every particle is outside. */
static PetscErrorCode ProbeCheckInside(PeriSystem sys, PeriNode map, PeriProbe *pr, PetscReal dist, PetscReal h, PetscReal delta)
{
  const PetscInt dim = sys->disc.particles.dim;
  char           at[96], used[96];

  PetscFunctionBeginUser;
  PetscCall(PointString(dim, pr->x, at, sizeof(at)));
  PetscCall(PointString(dim, pr->particle_x, used, sizeof(used)));
  PeriInputCheck(dist <= delta * (1 + 1e-9), sys->scene, map, pr->name, "the point lies outside the body: the nearest particle to %s, at %s, is %g away, farther than the horizon %g (a point within the horizon of a particle is taken at the nearest one, with a note)", at, used, (double)dist, (double)delta);
  pr->snapped  = dist > 0.5 * PetscSqrtReal((PetscReal)dim) * h * (1 + 1e-9) ? PETSC_TRUE : PETSC_FALSE;
  pr->distance = dist;
  if (pr->snapped)
    PetscCall(PetscPrintf(sys->comm, "perilin: note: probe '%s' %s lies %g from the nearest particle, outside its cell (spacing %g) but within the horizon %g: it samples the particle at %s\n", pr->name, at, (double)dist, (double)h, (double)delta, used));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriReadProbes(PeriSystem sys)
{
  PeriScene s = sys->scene;
  PeriNode  map;
  PetscInt  dim = sys->disc.particles.dim;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "probes", PETSC_FALSE, &map));
  if (!map) PetscFunctionReturn(PETSC_SUCCESS);
  sys->fields.nprobes = map->n;
  PetscCall(PetscCalloc1(map->n, &sys->fields.probes));
  for (PetscInt k = 0; k < map->n; k++) {
    PeriProbe *pr   = &sys->fields.probes[k];
    PetscReal  dist = 0, h = 0, delta = 0;
    PetscInt   n;
    PetscCall(PetscStrncpy(pr->name, map->child[k]->key, sizeof(pr->name)));
    PetscCall(PeriSceneGetRealArray(s, map, map->child[k]->key, PETSC_TRUE, dim, dim, pr->x, &n));
    PetscCall(ProbeLocate(sys, pr, &dist, &h, &delta));
    PetscCall(ProbeCheckInside(sys, map, pr, dist, h, delta));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The probes' values from their owners' particles, on every rank. Collective. */
static PetscErrorCode ProbesEvaluate(PeriSystem sys, const PetscScalar u[])
{
  const PetscInt bs = sys->model->dofs;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < sys->fields.nprobes; k++) {
    PeriProbe     *pr = &sys->fields.probes[k];
    const PetscInt p  = pr->particle;
    if (p >= 0) {
      for (PetscInt c = 0; c < bs; c++) pr->u[c] = PetscRealPart(u[p * bs + c]);
      pr->W = sys->fields.W[p];
      if (sys->fields.stress) {
        PetscCall(PetscArraycpy(pr->sigma, &sys->fields.stress[9 * p], 9));
        PetscCall(PetscArraycpy(pr->epsilon, &sys->fields.strain[9 * p], 9));
        PetscCall(PetscArraycpy(pr->sigma_elastic, &sys->fields.elastic_stress[9 * p], 9));
      }
    }
    /* u, W and the three tensors are contiguous: PERI_MAX_DOF + 28 reals */
    PetscCallMPI(MPI_Bcast(pr->u, PERI_MAX_DOF + 28, MPIU_REAL, pr->rank, sys->comm));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What the energy evaluation accumulates: all particles' DOFs, W per particle, the body's energy. */
typedef struct {
  const PetscScalar *u;
  PetscReal         *W, energy;
} EnergyCtx;

/* An element's energy e = u_e^T K_e u_e / 2, shared equally by the particles that own it (a bond's
 * two ends, a family's particle): their W gets share / V, the body's energy the shares of its own
 * particles (fictitious ones are not part of the body). */
static PetscErrorCode ElementEnergy(PeriSystem sys, const PeriElement *el, void *ctx)
{
  EnergyCtx     *E  = (EnergyCtx *)ctx;
  const PetscInt bs = sys->model->dofs, N = el->n * bs;
  PetscReal     *ue = el->work, e = 0, share;

  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < bs; c++)
    for (PetscInt t = 0; t < el->n; t++) ue[t * bs + c] = PetscRealPart(E->u[el->idx[t] * bs + c]);
  e     = PeriElementEnergy(el, N, ue);
  share = e / el->nshare;
  for (PetscInt t = 0; t < el->nshare; t++) {
    PetscInt p = el->idx[t];
    if (!PeriParticleIsFictitious(&sys->disc.particles, p)) E->energy += share;
    E->W[p] += share / sys->disc.particles.volume[p];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Antiplane models: the corrected shear angles grad uz = M^-1 R with M = sum w alpha xi xi^T V_j
 * and R = sum w alpha (u_j - u_i) xi V_j (w = 1/|xi|^2), exact for every linear field (eq. 53 with
 * the full 2x2 moment, so also at corners), and tau = mu (grad uz + twist terms): tau_xz, tau_yz
 * and |tau| of the owned particles (u: the local view's DOFs). */
static PetscErrorCode ShearStresses(PeriSystem sys, const PetscScalar u[])
{
  const PeriBonds     *b  = &sys->disc.bonds;
  const PeriParticles *pt = &sys->disc.particles;
  const PetscInt       n  = pt->n;
  PetscReal           *acc; /* per particle: M00 M01 M11 R0 R1 */

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(5 * n, &acc));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscInt         j  = b->j[k];
      const PetscReal *xi = &b->xi[3 * k];
      PetscReal        w = b->alpha[k] / (b->length[k] * b->length[k]), e = PetscRealPart(u[j] - u[i]);
      if (!b->live[k] || j == i) continue;
      for (PetscInt end = 0; end < 2; end++) {
        PetscReal *A = &acc[5 * (end ? j : i)], V = pt->volume[end ? i : j];
        A[0] += w * xi[0] * xi[0] * V;
        A[1] += w * xi[0] * xi[1] * V;
        A[2] += w * xi[1] * xi[1] * V;
        A[3] += w * e * xi[0] * V;
        A[4] += w * e * xi[1] * V;
      }
    }
  PetscCall(PeriDiscGhostsToOwners(&sys->disc, MPIU_REAL, 5, MPI_SUM, acc));
  PetscCall(PetscFree(sys->fields.tau));
  {
    PetscCall(PetscMalloc1(3 * sys->disc.nowned, &sys->fields.tau));
    for (PetscInt i = 0; i < sys->disc.nowned; i++) {
      const PetscReal *A   = &acc[5 * i];
      PetscReal        det = A[0] * A[2] - A[1] * A[1], gx = 0, gy = 0, mu = sys->materials.mu ? sys->materials.mu[i] : sys->model->material.G;
      if (det > 1e-12 * PetscSqr(A[0] + A[2])) {
        gx = (A[2] * A[3] - A[1] * A[4]) / det;
        gy = (A[0] * A[4] - A[1] * A[3]) / det;
      } else if (A[0] + A[2] > 0) { /* a one-dimensional family (a row of particles): along it only */
        gx = A[0] > 0 ? A[3] / A[0] : 0;
        gy = A[2] > 0 ? A[4] / A[2] : 0;
      }
      if (sys->conditions.torsion.active) {
        gx -= sys->conditions.torsion.twist * (pt->x[3 * i + 1] - sys->conditions.torsion.center[1]);
        gy += sys->conditions.torsion.twist * (pt->x[3 * i] - sys->conditions.torsion.center[0]);
      }
      sys->fields.tau[3 * i]     = mu * gx;
      sys->fields.tau[3 * i + 1] = mu * gy;
      sys->fields.tau[3 * i + 2] = mu * PetscSqrtReal(gx * gx + gy * gy);
    }
  }
  PetscCall(PetscFree(acc));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* *owned: this rank's particles' DOFs of the distributed v (no gather), so that its piece of the
 * output shows the state the other results describe. */
static PetscErrorCode KeepOwned(PeriSystem sys, Vec v, PetscReal **owned)
{
  const PetscScalar *a;
  PetscInt           nl;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(v, &nl));
  PetscCheck(nl == (sys->disc.bonds.rend - sys->disc.bonds.rstart) * sys->model->dofs, PETSC_COMM_SELF, PETSC_ERR_PLIB, "The state's local size %" PetscInt_FMT " is not the owned particles' DOFs", nl);
  PetscCall(PetscFree(*owned));
  PetscCall(PetscMalloc1(nl, owned));
  PetscCall(VecGetArrayRead(v, &a));
  for (PetscInt k = 0; k < nl; k++) (*owned)[k] = PetscRealPart(a[k]);
  PetscCall(VecRestoreArrayRead(v, &a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemKeepVelocity - the velocities v (the layout of sys->fields.u) of the state the output
  describes: particles.vtu's "velocity" (translations) and "velocity_<component>" (the others).
  Not collective.
@*/
PetscErrorCode PeriSystemKeepVelocity(PeriSystem sys, Vec v)
{
  PetscFunctionBeginUser;
  PetscCall(KeepOwned(sys, v, &sys->fields.v_owned));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The largest |u| per component over the body's particles (fictitious ones excluded). */
static PetscErrorCode MaxDisplacement(PeriSystem sys, const PetscScalar u[])
{
  const PetscInt bs                 = sys->model->dofs;
  PetscReal      umax[PERI_MAX_DOF] = {0, 0, 0};

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->disc.nowned; i++)
    for (PetscInt c = 0; c < bs && !PeriParticleIsFictitious(&sys->disc.particles, i); c++) umax[c] = PetscMax(umax[c], PetscAbsReal(PetscRealPart(u[i * bs + c])));
  PetscCallMPI(MPI_Allreduce(umax, sys->fields.max_abs_u, (PetscMPIInt)bs, MPIU_REAL, MPI_MAX, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemEvaluateEnergy - from the solution sys->fields.u: the strain energy of the body, the energy
  density W_i = (1/2) sum_j (pair energy) / V_i of the owned particles (the ghosts' shares reach
  their owners), the owned particles' DOFs (u_owned), the probes, the largest displacement per
  component, and for antiplane models the shear stresses and the torsion results. Collective.
@*/
PetscErrorCode PeriSystemEvaluateEnergy(PeriSystem sys)
{
  PetscScalar *u;
  EnergyCtx    E;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemLocalDOFs(sys, sys->fields.u, &u));
  PetscCall(PetscFree(sys->fields.W));
  PetscCall(PetscCalloc1(sys->disc.particles.n, &sys->fields.W));
  E.u      = u;
  E.W      = sys->fields.W;
  E.energy = 0;
  PetscCall(PeriElementsForEach(sys, ElementEnergy, &E));
  PetscCall(PeriDiscGhostsToOwners(&sys->disc, MPIU_REAL, 1, MPI_SUM, sys->fields.W));
  PetscCall(MaxDisplacement(sys, u));
  PetscCallMPI(MPI_Allreduce(&E.energy, &sys->fields.strain_energy, 1, MPIU_REAL, MPI_SUM, sys->comm));
  if (PeriModelOutOfPlane(sys->model)) PetscCall(ShearStresses(sys, u));
  PetscCall(PeriSystemEvaluateStress(sys, u));
  PetscCall(KeepOwned(sys, sys->fields.u, &sys->fields.u_owned));
  PetscCall(ProbesEvaluate(sys, u));
  PetscCall(PeriTorsionEvaluate(sys));
  sys->fields.has_solution = PETSC_TRUE;
  PetscCall(PetscFree(u));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSystemFindProbe(PeriSystem sys, const char name[], PeriProbe **probe)
{
  PetscFunctionBeginUser;
  *probe = NULL;
  for (PetscInt k = 0; k < sys->fields.nprobes; k++)
    if (!strcmp(sys->fields.probes[k].name, name)) *probe = &sys->fields.probes[k];
  PetscCheck(*probe, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "no probe named %s", name);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemAddFields - the system's per-particle fields besides the solution, over this rank's
  particles (a list of PeriSystemFieldListCreate): volume, neighbours, each particle's horizon
  (per-particle horizons), rank, and where they exist
  strain energy density and antiplane shear stresses; then the features' own (damage:
  PeriFailureAddFields; mirror images: PeriLayersAddFields; the conditions: fixed components,
  prescribed values, applied forces, regions: PeriConditionsAddFields). Each rank's piece: its owned particles, local 0..nowned-1.
@*/
PetscErrorCode PeriSystemAddFields(PeriSystem sys, PeriFieldList fl)
{
  PetscFunctionBeginUser;
  PetscCall(PeriFieldListAddReal(fl, "volume", 1, sys->disc.particles.volume, 1, NULL));
  PetscCall(PeriFieldListAddInt(fl, "neighbors", sys->disc.neighbor_count));
  if (sys->disc.horizon) PetscCall(PeriFieldListAddReal(fl, "horizon", 1, sys->disc.horizon, 1, NULL)); /* per-particle horizons */
  PetscCall(PeriFieldListAddIntConstant(fl, "rank", sys->rank));
  if (sys->fields.v_owned) PetscCall(PeriFieldListAddSolution(fl, "velocity", sys->model->dofs, sys->model->components, sys->model->axis, sys->fields.v_owned));
  if (sys->fields.W) PetscCall(PeriFieldListAddReal(fl, "strain_energy_density", 1, sys->fields.W, 1, NULL));
  if (sys->fields.tau) {
    const PetscInt tmap[3] = {0, 1, -1}, nmap = 2;
    PetscCall(PeriFieldListAddReal(fl, "shear_stress", 3, sys->fields.tau, 3, tmap)); /* tau_xz, tau_yz, 0 */
    PetscCall(PeriFieldListAddReal(fl, "shear_stress_norm", 1, sys->fields.tau, 3, &nmap));
  }
  if (sys->fields.stress) {
    PetscCall(PeriFieldListAddReal(fl, "stress", 9, sys->fields.stress, 9, NULL));
    PetscCall(PeriFieldListAddReal(fl, "strain", 9, sys->fields.strain, 9, NULL));
    PetscCall(PeriFieldListAddReal(fl, "elastic_stress", 9, sys->fields.elastic_stress, 9, NULL));
  }
  PetscCall(PeriFailureAddFields(sys, fl));
  PetscCall(PeriLayersAddFields(sys, fl));
  PetscCall(PeriConditionsAddFields(sys, fl));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* An empty field list over this rank's particles: its piece of the output (no gather). */
PetscErrorCode PeriSystemFieldListCreate(PeriSystem sys, PeriFieldList *fl)
{
  const PeriBonds *b = &sys->disc.bonds;

  PetscFunctionBeginUser;
  PetscCall(PeriFieldListCreate(b->rend - b->rstart, sys->disc.particles.x, fl));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemWriteParticles - dir/base.vtu (one rank) or dir/base.pvtu and its pieces (several)
  with u (the owned particles' DOFs, or NULL: no solution) and the system's fields. Collective;
  every rank writes its own particles.
@*/
PetscErrorCode PeriSystemWriteParticles(PeriSystem sys, const PetscReal *u, const char dir[], const char base[])
{
  PeriFieldList fl;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemFieldListCreate(sys, &fl));
  if (u) PetscCall(PeriFieldListAddSolution(fl, "", sys->model->dofs, sys->model->components, sys->model->axis, u));
  PetscCall(PeriSystemAddFields(sys, fl));
  PetscCall(PeriWriteParticles(sys->comm, fl, dir, base));
  PetscCall(PeriFieldListDestroy(&fl));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* a symmetric tensor by its components: xx, yy, xy in 2D; xx, yy, zz, yz, xz, xy in 3D */
static PetscErrorCode ProbeTensor(PeriJSON j, const char name[], PetscInt dim, const PetscReal T[9])
{
  static const char *const names[] = {"xx", "yy", "zz", "yz", "xz", "xy"};
  static const PetscInt    idx[]   = {0, 4, 8, 5, 2, 1};

  PetscFunctionBeginUser;
  PetscCall(PeriJSONBeginObject(j, name));
  for (PetscInt k = 0; k < 6; k++)
    if (dim == 3 || k == 0 || k == 1 || k == 5) PetscCall(PeriJSONReal(j, names[k], T[idx[k]]));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* probes: the values at the nearest particle of each point, when there is a solution. */
PetscErrorCode PeriProbesSummary(PeriSystem sys, PeriJSON j)
{
  PetscFunctionBeginUser;
  PetscCall(PeriJSONBeginObject(j, "probes"));
  for (PetscInt k = 0; sys->fields.has_solution && k < sys->fields.nprobes; k++) {
    const PeriProbe *pr = &sys->fields.probes[k];
    PetscCall(PeriJSONBeginObject(j, pr->name));
    PetscCall(PeriJSONRealArray(j, "x", sys->disc.particles.dim, pr->x));
    PetscCall(PeriJSONRealArray(j, "particle_x", sys->disc.particles.dim, pr->particle_x));
    PetscCall(PeriJSONString(j, "sampling", "nearest particle"));
    if (pr->snapped) {
      PetscCall(PeriJSONBool(j, "snapped", PETSC_TRUE));
      PetscCall(PeriJSONReal(j, "distance", pr->distance));
    }
    PetscCall(PeriJSONRealArray(j, "u", sys->model->dofs, pr->u));
    PetscCall(PeriJSONReal(j, "W", pr->W));
    if (sys->fields.stress) {
      PetscCall(ProbeTensor(j, "sigma", sys->disc.particles.dim, pr->sigma));
      PetscCall(ProbeTensor(j, "epsilon", sys->disc.particles.dim, pr->epsilon));
      PetscCall(ProbeTensor(j, "sigma_elastic", sys->disc.particles.dim, pr->sigma_elastic));
    }
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Frees what the fields hold. */
PetscErrorCode PeriFieldsDestroy(PeriFields *F)
{
  PetscFunctionBeginUser;
  PetscCall(VecDestroy(&F->u));
  PetscCall(VecDestroy(&F->f));
  PetscCall(PetscFree(F->tau));
  PetscCall(PetscFree3(F->stress, F->strain, F->elastic_stress));
  PetscCall(PetscFree(F->probes));
  PetscCall(PetscFree(F->W));
  PetscCall(PetscFree(F->u_owned));
  PetscCall(PetscFree(F->v_owned));
  PetscFunctionReturn(PETSC_SUCCESS);
}
