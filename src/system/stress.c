/* Stress and strain per particle after a solve (vector models; the antiplane models have their
 * shear stresses in fields.c).
 *
 * Stress: the bond-force (virial) stress. An element of the energy (a bond, or a state-based
 * family) exerts the forces f = K_e u_e on its particles; each particle p that shares its energy
 * takes sigma_p += (1/(nshare V_p)) sum_t f_t (x) (X_t - X_p), symmetrized. For a homogeneous strain
 * this is dW_p/d(eps) of the particle's own energy density, so wherever the energy is exact (the
 * interior of a lattice-calibrated body, docs/models/lattice.md) it is the elastic stress exactly,
 * for every model; and summed over the body, sum_p V_p sigma_p = sum_elements sum_t f_t (x) X_t, the
 * virial of the applied and reaction forces. Near a free surface a particle misses half its bonds,
 * so its own stress is not the continuum's there (docs/stress.md).
 *
 * Strain: the symmetric part of the least-squares displacement gradient of the particle's live
 * bonds, H = (sum_j w (u_j - u_i) (x) xi) M^-1, M = sum_j w xi (x) xi, w = alpha V_j / |xi|^2: exact
 * for every linear field, at surfaces and corners too. The elastic stress C : eps of that strain
 * (the target elasticity: plane stress, plane strain or 3D) is therefore exact for every linear
 * field at a free surface too, where the bond-force stress is not. */
#include "perilin/private/system.h"

typedef struct {
  const PetscScalar *u;
  PetscReal         *S; /* 9 per particle */
} StressCtx;

static PetscErrorCode ElementStress(PeriSystem sys, const PeriElement *el, void *ctx)
{
  StressCtx       *sc = (StressCtx *)ctx;
  const PetscInt   bs = sys->model->dofs, N = el->n * bs, dim = sys->disc.particles.dim;
  const PetscReal *f = el->work + N;

  PetscFunctionBeginUser;
  PeriElementForces(sys, el, sc->u);
  for (PetscInt s = 0; s < el->nshare; s++) {
    const PetscInt  p = el->idx[s];
    PetscReal      *S = &sc->S[9 * p];
    const PetscReal w = 1 / (el->nshare * sys->disc.particles.volume[p]);
    /* positions relative to idx[0]: 0 for it, the bond vectors (minimum image) for the others */
    for (PetscInt t = 0; t < el->n; t++)
      for (PetscInt b = 0; b < dim; b++) {
        PetscReal r = (t ? el->g[t - 1].xi[b] : 0) - (s ? el->g[s - 1].xi[b] : 0);
        for (PetscInt a = 0; a < dim; a++) S[3 * a + b] += w * f[t * bs + a] * r;
      }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A += w v (x) r over dim x dim, stored 3 x 3 */
static void AddOuter(PetscReal A[9], PetscReal w, const PetscReal v[], const PetscReal r[], PetscInt dim)
{
  for (PetscInt a = 0; a < dim; a++)
    for (PetscInt b = 0; b < dim; b++) A[3 * a + b] += w * v[a] * r[b];
}

/* per particle: M = sum w xi xi^T and R = sum w (u_j - u_i) xi^T over both ends of the live bonds */
static PetscErrorCode GradientMoments(PeriSystem sys, const PetscScalar u[], PetscReal acc[])
{
  const PeriBonds     *b  = &sys->disc.bonds;
  const PeriParticles *pt = &sys->disc.particles;
  const PetscInt       bs = sys->model->dofs, dim = pt->dim;

  PetscFunctionBeginUser;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      const PetscInt j     = b->j[k];
      PetscReal      du[3] = {0, 0, 0}, xi[3], len, w;
      if (!b->live[k] || j == i) continue;
      PeriDiscBondGeometry(&sys->disc, i, k, xi, &len, &w);
      w /= len * len;
      for (PetscInt a = 0; a < dim; a++) du[a] = PetscRealPart(u[j * bs + a] - u[i * bs + a]);
      /* seen from j, xi and du both change sign: the same products */
      AddOuter(&acc[18 * i], w * pt->volume[j], xi, xi, dim);
      AddOuter(&acc[18 * i + 9], w * pt->volume[j], du, xi, dim);
      AddOuter(&acc[18 * j], w * pt->volume[i], xi, xi, dim);
      AddOuter(&acc[18 * j + 9], w * pt->volume[i], du, xi, dim);
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* eps = sym(R M^-1); a singular M (a row of particles) fits along the axes it spans only */
static void StrainFromMoments(const PetscReal M[9], const PetscReal R[9], PetscInt dim, PetscReal eps[9])
{
  PetscReal Mi[9] = {0}, H[9] = {0}, tr = 0, det;
  for (PetscInt a = 0; a < dim; a++) tr += M[4 * a];
  if (dim == 2) {
    det = M[0] * M[4] - M[1] * M[3];
    if (det > 1e-12 * tr * tr) {
      Mi[0] = M[4] / det, Mi[1] = -M[1] / det, Mi[3] = -M[3] / det, Mi[4] = M[0] / det;
    } else
      for (PetscInt a = 0; a < 2; a++) Mi[4 * a] = M[4 * a] > 0 ? 1 / M[4 * a] : 0;
  } else {
    det = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) + M[2] * (M[3] * M[7] - M[4] * M[6]);
    if (det > 1e-12 * tr * tr * tr) {
      for (PetscInt a = 0; a < 3; a++)
        for (PetscInt b = 0; b < 3; b++) {
          /* the cofactor of (b, a) */
          PetscInt r0 = (b + 1) % 3, r1 = (b + 2) % 3, c0 = (a + 1) % 3, c1 = (a + 2) % 3;
          Mi[3 * a + b] = (M[3 * r0 + c0] * M[3 * r1 + c1] - M[3 * r0 + c1] * M[3 * r1 + c0]) / det;
        }
    } else
      for (PetscInt a = 0; a < 3; a++) Mi[4 * a] = M[4 * a] > 0 ? 1 / M[4 * a] : 0;
  }
  for (PetscInt a = 0; a < dim; a++)
    for (PetscInt b = 0; b < dim; b++)
      for (PetscInt c = 0; c < dim; c++) H[3 * a + b] += R[3 * a + c] * Mi[3 * c + b];
  for (PetscInt a = 0; a < 3; a++)
    for (PetscInt b = 0; b < 3; b++) eps[3 * a + b] = 0.5 * (H[3 * a + b] + H[3 * b + a]);
}

/* sigma = C : eps of the scene's isotropic material (plane stress: sigma_zz = 0; plane strain:
 * sigma_zz = lambda tr eps) */
static void ElasticStress(PeriModel m, PetscInt dim, const PetscReal eps[9], PetscReal sig[9])
{
  const PetscReal E = m->material.E, nu = m->material.nu, G = E / (2 * (1 + nu));
  PetscReal       lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), tr = 0;
  if (dim == 2 && !m->plane_strain) lambda = E * nu / (1 - nu * nu);
  for (PetscInt a = 0; a < dim; a++) tr += eps[4 * a];
  for (PetscInt k = 0; k < 9; k++) sig[k] = 2 * G * eps[k];
  for (PetscInt a = 0; a < dim; a++) sig[4 * a] += lambda * tr;
  if (dim == 2 && m->plane_strain) sig[8] = lambda * tr;
}

/*@C
  PeriSystemEvaluateStress - sys->fields.stress, sys->fields.strain and sys->fields.elastic_stress of the owned
  particles (9 per particle, row-major 3 x 3, symmetric; the ghosts' shares reach their owners)
  from the local view's DOFs u (PeriSystemLocalDOFs), when output.stress
  asks for them. Nothing for the antiplane models. Collective.
@*/
PetscErrorCode PeriSystemEvaluateStress(PeriSystem sys, const PetscScalar u[])
{
  const PetscInt n = sys->disc.particles.n;
  PetscReal     *S, *acc;
  StressCtx      sc;

  PetscFunctionBeginUser;
  PetscCall(PetscFree3(sys->fields.stress, sys->fields.strain, sys->fields.elastic_stress));
  if (!sys->fields.stress_output || !PeriModelInPlane(sys->model)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscCalloc2(9 * n, &S, 18 * n, &acc));
  sc.u = u;
  sc.S = S;
  PetscCall(PeriElementsForEach(sys, ElementStress, &sc));
  PetscCall(GradientMoments(sys, u, acc));
  PetscCall(PeriDiscGhostsToOwners(&sys->disc, MPIU_REAL, 9, MPI_SUM, S));
  PetscCall(PeriDiscGhostsToOwners(&sys->disc, MPIU_REAL, 18, MPI_SUM, acc));
  {
    const PetscInt no = sys->disc.nowned;
    PetscCall(PetscMalloc3(9 * no, &sys->fields.stress, 9 * no, &sys->fields.strain, 9 * no, &sys->fields.elastic_stress));
    for (PetscInt i = 0; i < no; i++) {
      for (PetscInt a = 0; a < 3; a++)
        for (PetscInt b = 0; b < 3; b++) sys->fields.stress[9 * i + 3 * a + b] = 0.5 * (S[9 * i + 3 * a + b] + S[9 * i + 3 * b + a]);
      StrainFromMoments(&acc[18 * i], &acc[18 * i + 9], sys->disc.particles.dim, &sys->fields.strain[9 * i]);
      ElasticStress(sys->model, sys->disc.particles.dim, &sys->fields.strain[9 * i], &sys->fields.elastic_stress[9 * i]);
    }
  }
  PetscCall(PetscFree2(S, acc));
  PetscFunctionReturn(PETSC_SUCCESS);
}
