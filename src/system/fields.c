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
    {"<name>", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "a point [x, y(, z)] inside the body: the displacement and energy density of the nearest particle"},
    {NULL},
};
const PeriSchema PeriProbesSchema[] = {{"probes", probe_keys}, {NULL}};

PetscErrorCode PeriReadProbes(PeriSystem sys)
{
  PeriScene            s = sys->scene;
  PeriNode             map;
  const PeriParticles *pt = &sys->disc.particles;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "probes", PETSC_FALSE, &map));
  if (!map) PetscFunctionReturn(PETSC_SUCCESS);
  sys->nprobes = map->n;
  PetscCall(PetscCalloc1(map->n, &sys->probes));
  for (PetscInt k = 0; k < map->n; k++) {
    PeriProbe *pr   = &sys->probes[k];
    PetscReal  best = PETSC_MAX_REAL;
    PetscInt   n;
    PetscCall(PetscStrncpy(pr->name, map->child[k]->key, sizeof(pr->name)));
    PetscCall(PeriSceneGetRealArray(s, map, map->child[k]->key, PETSC_TRUE, pt->dim, pt->dim, pr->x, &n));
    for (PetscInt i = 0; i < pt->n; i++) {
      PetscReal d2 = 0;
      if (PeriParticleIsFictitious(pt, i)) continue;
      for (PetscInt d = 0; d < pt->dim; d++) d2 += PetscSqr(pt->x[3 * i + d] - pr->x[d]);
      /* ties go to the lexicographically smallest position, whatever the numbering (ranks) */
      if (d2 < best || (d2 == best && LexLess(&pt->x[3 * i], &pt->x[3 * pr->particle]))) {
        best         = d2;
        pr->particle = i;
      }
    }
    /* inside the body: within the nearest particle's cell (its circumscribed ball) */
    PeriInputCheck(PetscSqrtReal(best) <= 0.5 * PetscSqrtReal((PetscReal)pt->dim) * pt->spacing[pr->particle] * (1 + 1e-9), s, map, map->child[k]->key, "the point lies outside the body (nearest particle at distance %g)", (double)PetscSqrtReal(best));
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
  for (PetscInt a = 0; a < N; a++)
    for (PetscInt c = 0; c < N; c++) e += 0.5 * ue[a] * el->K[a * N + c] * ue[c];
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
 * the full 2x2 moment, so also at corners), and tau = mu (grad uz + twist terms). Every rank gets
 * tau_xz, tau_yz and |tau| of every particle: rank 0 for the torsion results, each rank its own
 * particles' for its piece of the output (the whole array until the per-rank data of issue 17
 * item 3 replaces it). */
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
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, acc, (PetscMPIInt)(5 * n), MPIU_REAL, MPI_SUM, sys->comm));
  PetscCall(PetscFree(sys->tau));
  {
    PetscCall(PetscMalloc1(3 * n, &sys->tau));
    for (PetscInt i = 0; i < n; i++) {
      const PetscReal *A   = &acc[5 * i];
      PetscReal        det = A[0] * A[2] - A[1] * A[1], gx = 0, gy = 0, mu = sys->mu ? sys->mu[i] : sys->model->material.G;
      if (det > 1e-12 * PetscSqr(A[0] + A[2])) {
        gx = (A[2] * A[3] - A[1] * A[4]) / det;
        gy = (A[0] * A[4] - A[1] * A[3]) / det;
      } else if (A[0] + A[2] > 0) { /* a one-dimensional family (a row of particles): along it only */
        gx = A[0] > 0 ? A[3] / A[0] : 0;
        gy = A[2] > 0 ? A[4] / A[2] : 0;
      }
      if (sys->torsion.active) {
        gx -= sys->torsion.twist * (pt->x[3 * i + 1] - sys->torsion.center[1]);
        gy += sys->torsion.twist * (pt->x[3 * i] - sys->torsion.center[0]);
      }
      sys->tau[3 * i]     = mu * gx;
      sys->tau[3 * i + 1] = mu * gy;
      sys->tau[3 * i + 2] = mu * PetscSqrtReal(gx * gx + gy * gy);
    }
  }
  PetscCall(PetscFree(acc));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* sys->u_owned: this rank's particles' DOFs, from the distributed sys->u (no gather), so that its
 * piece of the output shows the state the other results describe. */
static PetscErrorCode KeepOwnedSolution(PeriSystem sys)
{
  const PetscScalar *u;
  PetscInt           nl;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(sys->u, &nl));
  PetscCheck(nl == (sys->disc.bonds.rend - sys->disc.bonds.rstart) * sys->model->dofs, PETSC_COMM_SELF, PETSC_ERR_PLIB, "The solution's local size %" PetscInt_FMT " is not the owned particles' DOFs", nl);
  PetscCall(PetscFree(sys->u_owned));
  PetscCall(PetscMalloc1(nl, &sys->u_owned));
  PetscCall(VecGetArrayRead(sys->u, &u));
  for (PetscInt k = 0; k < nl; k++) sys->u_owned[k] = PetscRealPart(u[k]);
  PetscCall(VecRestoreArrayRead(sys->u, &u));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemEvaluateEnergy - from the solution sys->u: the strain energy of the body, the energy
  density W_i = (1/2) sum_j (pair energy) / V_i of every particle (every rank, all particles: the
  accumulation spans them until issue 17 item 3), the displacements of all particles (rank 0,
  u_all) and of the owned ones (every rank, u_owned), the probes, the largest displacement per component, and for antiplane
  models the shear stresses and the torsion results. Collective.
@*/
PetscErrorCode PeriSystemEvaluateEnergy(PeriSystem sys)
{
  VecScatter           scatter;
  Vec                  all;
  const PetscScalar   *u;
  PeriModel            m  = sys->model;
  const PeriParticles *pt = &sys->disc.particles;
  const PetscInt       n = pt->n, bs = m->dofs;
  PetscReal            umax[PERI_MAX_DOF] = {0, 0, 0}, *W;
  EnergyCtx            E;

  PetscFunctionBeginUser;
  PetscCall(VecScatterCreateToAll(sys->u, &scatter, &all));
  PetscCall(VecScatterBegin(scatter, sys->u, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(scatter, sys->u, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGetArrayRead(all, &u));
  PetscCall(PetscCalloc1(n, &W));
  E.u      = u;
  E.W      = W;
  E.energy = 0;
  PetscCall(PeriElementsForEach(sys, ElementEnergy, &E));
  for (PetscInt i = sys->disc.bonds.rstart; i < sys->disc.bonds.rend; i++)
    for (PetscInt c = 0; c < bs && !PeriParticleIsFictitious(pt, i); c++) umax[c] = PetscMax(umax[c], PetscAbsReal(PetscRealPart(u[i * bs + c])));
  PetscCallMPI(MPI_Allreduce(umax, sys->max_abs_u, (PetscMPIInt)bs, MPIU_REAL, MPI_MAX, sys->comm));
  PetscCallMPI(MPI_Allreduce(&E.energy, &sys->strain_energy, 1, MPIU_REAL, MPI_SUM, sys->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, W, (PetscMPIInt)n, MPIU_REAL, MPI_SUM, sys->comm));
  if (m->antiplane) PetscCall(ShearStresses(sys, u));
  PetscCall(PeriSystemEvaluateStress(sys, u));
  PetscCall(PetscFree(sys->W));
  PetscCall(PetscFree(sys->u_all));
  PetscCall(KeepOwnedSolution(sys));
  sys->W = W;
  if (sys->rank == 0) {
    PetscCall(PetscMalloc1(n * bs, &sys->u_all));
    for (PetscInt k = 0; k < n * bs; k++) sys->u_all[k] = PetscRealPart(u[k]);
    for (PetscInt k = 0; k < sys->nprobes; k++) {
      PeriProbe *pr = &sys->probes[k];
      for (PetscInt c = 0; c < bs; c++) pr->u[c] = sys->u_all[pr->particle * bs + c];
      pr->W = W[pr->particle];
    }
    PetscCall(PeriTorsionEvaluate(sys));
  }
  if (sys->torsion.active) PetscCallMPI(MPI_Bcast(&sys->torsion.torque, 6, MPIU_REAL, 0, sys->comm));
  PetscCall(VecRestoreArrayRead(all, &u));
  PetscCall(VecDestroy(&all));
  PetscCall(VecScatterDestroy(&scatter));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSystemFindProbe(PeriSystem sys, const char name[], PeriProbe **probe)
{
  PetscFunctionBeginUser;
  *probe = NULL;
  for (PetscInt k = 0; k < sys->nprobes; k++)
    if (!strcmp(sys->probes[k].name, name)) *probe = &sys->probes[k];
  PetscCheck(*probe, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "no probe named %s", name);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemAddFields - the system's per-particle fields besides the solution, over this rank's
  particles (a list of PeriSystemFieldListCreate): volume, neighbours, rank, and where they exist
  strain energy density and antiplane shear stresses; then the features' own (damage:
  PeriFailureAddFields; mirror images: PeriLayersAddFields). Every rank: the arrays hold all
  particles today (issue 17 item 1), each rank's piece is its owned range of them.
@*/
PetscErrorCode PeriSystemAddFields(PeriSystem sys, PeriFieldList fl)
{
  const PetscInt r0 = sys->disc.bonds.rstart;

  PetscFunctionBeginUser;
  PetscCall(PeriFieldListAddReal(fl, "volume", 1, sys->disc.particles.volume + r0, 1, NULL));
  PetscCall(PeriFieldListAddInt(fl, "neighbors", sys->disc.neighbor_count + r0));
  PetscCall(PeriFieldListAddInt(fl, "rank", sys->disc.owner + r0));
  if (sys->W) PetscCall(PeriFieldListAddReal(fl, "strain_energy_density", 1, sys->W + r0, 1, NULL));
  if (sys->tau) {
    const PetscInt tmap[3] = {0, 1, -1}, nmap = 2;
    PetscCall(PeriFieldListAddReal(fl, "shear_stress", 3, sys->tau + 3 * r0, 3, tmap)); /* tau_xz, tau_yz, 0 */
    PetscCall(PeriFieldListAddReal(fl, "shear_stress_norm", 1, sys->tau + 3 * r0, 3, &nmap));
  }
  if (sys->stress) {
    PetscCall(PeriFieldListAddReal(fl, "stress", 9, sys->stress + 9 * r0, 9, NULL));
    PetscCall(PeriFieldListAddReal(fl, "strain", 9, sys->strain + 9 * r0, 9, NULL));
    PetscCall(PeriFieldListAddReal(fl, "elastic_stress", 9, sys->elastic_stress + 9 * r0, 9, NULL));
  }
  PetscCall(PeriFailureAddFields(sys, fl));
  PetscCall(PeriLayersAddFields(sys, fl));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* An empty field list over this rank's particles: its piece of the output (no gather). */
PetscErrorCode PeriSystemFieldListCreate(PeriSystem sys, PeriFieldList *fl)
{
  const PeriBonds *b = &sys->disc.bonds;

  PetscFunctionBeginUser;
  /* the coordinates of all particles are on every rank today (issue 17 item 1): the owned range */
  PetscCall(PeriFieldListCreate(b->rend - b->rstart, sys->disc.particles.x + 3 * b->rstart, fl));
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
  if (u) PetscCall(PeriFieldListAddSolution(fl, "", sys->model->dofs, sys->model->components, u));
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
  for (PetscInt k = 0; sys->u_all && k < sys->nprobes; k++) {
    const PeriProbe *pr = &sys->probes[k];
    PetscCall(PeriJSONBeginObject(j, pr->name));
    PetscCall(PeriJSONRealArray(j, "x", sys->disc.particles.dim, pr->x));
    PetscCall(PeriJSONRealArray(j, "particle_x", sys->disc.particles.dim, &sys->disc.particles.x[3 * pr->particle]));
    PetscCall(PeriJSONString(j, "sampling", "nearest particle"));
    PetscCall(PeriJSONRealArray(j, "u", sys->model->dofs, pr->u));
    PetscCall(PeriJSONReal(j, "W", pr->W));
    if (sys->stress) {
      PetscCall(ProbeTensor(j, "sigma", sys->disc.particles.dim, &sys->stress[9 * pr->particle]));
      PetscCall(ProbeTensor(j, "epsilon", sys->disc.particles.dim, &sys->strain[9 * pr->particle]));
      PetscCall(ProbeTensor(j, "sigma_elastic", sys->disc.particles.dim, &sys->elastic_stress[9 * pr->particle]));
    }
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}
