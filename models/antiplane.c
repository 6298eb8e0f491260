/* antiplane and antiplane_os: antiplane shear and torsion of a bar, modelled on its cross-section
 * with one unknown per particle, the out-of-plane displacement (warping) uz (Oterkus & Madenci,
 * ../shared/papers/oterkus-madenci-antiplane-torsion.md). Volumes include the bar length l (the
 * scene's thickness), so every per-unit-length result is independent of it.
 *
 * antiplane (bond-based, eqs. 37-41): the pair energy is c G_kj mu_b V_k V_j (u_j - u_k)^2 / (2 |xi|)
 * with c mu = 6 mu / (pi l delta^3) (eq. 40), G_kj the surface correction of eqs. 53, 57-58 when
 * corrections.surface is energy, and mu_b the bond's modulus across materials (eq. 60).
 *
 * antiplane_os (ordinary state-based, eqs. 22-30 and 55-56): particle k stores the energy
 * W_k V_k = mu_k |r_k|^2 V_k / 2 with the shear angles r_k = b g_k sum_j w_kj (u_j - u_k) n_kj V_j,
 * w = delta/|xi|, n the bond direction, b = 2/(pi l delta^3) and g_k = (g_xz, g_yz) of eq. 53.
 * The energy couples every pair of k's family, so the stiffness reaches 2 delta (docs/models/antiplane.md). */
#include <perilin/model.h>

static const char *const components[]       = {"uz"};
static const char *const measures[]         = {"shear_angle"};
static const char *const corrections_bond[] = {"none", "volume", "energy", NULL};
static const char *const corrections_os[]   = {"none", "energy", NULL};

/* what each measure is (the failure criteria find theirs by kind) */
static const PeriMeasureKind measure_kinds[] = {PERI_MEASURE_SHEAR_ANGLE};

typedef struct {
  PetscReal   c;             /* per unit shear modulus: 6/(pi l delta^3) (bond-based), 2/(pi l delta^3) (b, state-based) */
  PetscInt    n;             /* particles */
  PetscReal  *gx, *gy;       /* energy surface correction per particle (bond-based), or NULL */
  PetscReal  *mu;            /* shear modulus per particle (state-based), or NULL: the material's */
  PetscBool   energy;        /* state-based: the correction g_k of eq. 53, computed from the family */
  PetscReal   stabilization; /* state-based: weight of the misfit energy (model.stabilization) */
  PetscReal  *work;          /* state-based: workspace of the family kernel */
  PetscInt    nwork;
  PeriLattice lat; /* bond-based, model.calibration: lattice, else NULL */
} Antiplane;

/* The model.* keys of antiplane_os (SetFromSceneState); antiplane has none. */
static const PeriKey os_keys[] = {
    {"stabilization", PERI_KEY_REAL, "1", "[0, inf)", NULL, NULL, "weight of the misfit energy that removes zero-energy modes"},
    {NULL},
};
static const PeriSchema os_schema[] = {{"model", os_keys}, {NULL}};

static PetscErrorCode SetFromSceneState(PeriModel m, PeriScene scene, PeriNode node)
{
  Antiplane *ap = (Antiplane *)m->data;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetReal(scene, node, "stabilization", PETSC_FALSE, &ap->stabilization, NULL));
  if (ap->stabilization == 0) PetscSNPrintf(m->warning, sizeof(m->warning), "antiplane_os without stabilization has zero-energy modes (a checkerboard has no shear angle): the stiffness is singular");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Only the shear modulus matters: any Poisson ratio (E and nu, or material.mu) is admissible. */
static void NuRange(PeriModel m, PetscReal *lo, PetscReal *hi)
{
  (void)m;
  *lo = -1 + 1e-6;
  *hi = 0.5 - 1e-6;
}

/* The shear angle of the bond, r = (u_j - u_k)/|xi| (eq. 5): the measure of the failure criterion (eq. 70). */
static void BondMeasures(PeriModel m, const PeriBondGeometry *b, const PetscReal ui[], const PetscReal uj[], PetscReal r[])
{
  (void)m;
  r[0] = (uj[0] - ui[0]) / b->length;
}

/* eq. 78: breaking every bond across a unit crack area releases G_IIIc = (c mu/2) r_c^2 l delta^4 / 2
 * (eq. 77), so r_c = sqrt(2 pi G / (3 mu delta)); mu is the bond's modulus */
static PetscReal CriticalFromG(PeriModel m, const PeriBondGeometry *b, PetscReal G)
{
  PetscReal mu = b->mu > 0 ? b->mu : m->material.G;
  return PetscSqrtReal(2 * PETSC_PI * G / (3 * mu * m->delta));
}

static PetscInt RigidModes(PeriModel m, const PetscReal X[], PetscReal modes[][PERI_MAX_DOF])
{
  (void)m;
  (void)X;
  modes[0][0] = 1;
  return 1;
}

/* eq. 53 for the bond-based form: g = W_CCM / W_PD for u = x and u = y, W_PD = (c mu/4) sum_j alpha x^2/|xi| V_j
 * (eq. 49), summed over both ends of this rank's bonds and then over the ranks holding the particle. */
static PetscErrorCode EnergyCorrection(PeriModel m, const PeriCalibrationData *data)
{
  Antiplane           *ap = (Antiplane *)m->data;
  const PeriBonds     *b  = data->bonds;
  const PeriParticles *pt = data->particles;
  const PetscInt       n  = pt->n;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc2(n, &ap->gx, n, &ap->gy));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscInt  j = b->j[k];
      PetscReal a = b->alpha[k] / b->length[k];
      if (j == i) continue;
      ap->gx[i] += a * b->xi[3 * k] * b->xi[3 * k] * pt->volume[j];
      ap->gy[i] += a * b->xi[3 * k + 1] * b->xi[3 * k + 1] * pt->volume[j];
      ap->gx[j] += a * b->xi[3 * k] * b->xi[3 * k] * pt->volume[i];
      ap->gy[j] += a * b->xi[3 * k + 1] * b->xi[3 * k + 1] * pt->volume[i];
    }
  PetscCall(data->combine(data, MPIU_REAL, 1, MPI_SUM, ap->gx));
  PetscCall(data->combine(data, MPIU_REAL, 1, MPI_SUM, ap->gy));
  for (PetscInt i = 0; i < n; i++) {
    PetscCheck(ap->gx[i] > 0 && ap->gy[i] > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "antiplane: the particle at (%g, %g) has no bond along %s, so the energy surface correction is undefined (a section one particle thin?): use corrections.surface: none or volume", (double)pt->x[3 * i], (double)pt->x[3 * i + 1], ap->gx[i] > 0 ? "y" : "x");
    /* W_CCM / W_PD = (1/2) / ((c/4) S) */
    ap->gx[i] = 2 / (ap->c * ap->gx[i]);
    ap->gy[i] = 2 / (ap->c * ap->gy[i]);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CalibrateBond(PeriModel m, const PeriCalibrationData *data)
{
  Antiplane *ap = (Antiplane *)m->data;

  PetscFunctionBeginUser;
  ap->c = 6 / (PETSC_PI * m->material.thickness * PetscPowReal(m->delta, 3));
  ap->n = data->n;
  PetscCall(PetscFree2(ap->gx, ap->gy));
  if (data->surface == PERI_SURFACE_ENERGY) PetscCall(EnergyCorrection(m, data));
  /* the shear angle (u_j - u_k)/|xi| = e . grad u is linear in e: moments of degree 2 */
  PetscCall(PeriLatticeCreate(m, data, 2, PeriProfileLength, &ap->lat));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* eq. 58: the bond's factor from the mean correction of its ends along the bond direction */
static PetscReal BondCorrection(const Antiplane *ap, const PeriBondGeometry *b)
{
  PetscReal gx, gy, nx, ny;
  if (!ap->gx) return 1;
  gx = 0.5 * (ap->gx[b->i] + ap->gx[b->j]);
  gy = 0.5 * (ap->gy[b->i] + ap->gy[b->j]);
  nx = b->xi[0] / b->length;
  ny = b->xi[1] / b->length;
  return 1 / PetscSqrtReal(PetscSqr(nx / gx) + PetscSqr(ny / gy));
}

static void BondStiffness(PeriModel m, const PeriBondGeometry *b, PetscReal Ke[])
{
  const Antiplane *ap = (const Antiplane *)m->data;
  PetscReal        mu = b->mu > 0 ? b->mu : m->material.G;
  PetscReal        k  = ap->c * mu * BondCorrection(ap, b) * PeriLatticeFactor(ap->lat, b) * b->Vi * b->Vj * b->weight / b->length;
  Ke[0]               = k;
  Ke[1]               = -k;
  Ke[2]               = -k;
  Ke[3]               = k;
}

static PetscErrorCode CalibrateState(PeriModel m, const PeriCalibrationData *data)
{
  Antiplane *ap = (Antiplane *)m->data;

  PetscFunctionBeginUser;
  ap->c      = 2 / (PETSC_PI * m->material.thickness * PetscPowReal(m->delta, 3));
  ap->n      = data->n;
  ap->energy = data->surface == PERI_SURFACE_ENERGY ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscFree(ap->mu));
  if (data->mu) {
    PetscCall(PetscMalloc1(data->n, &ap->mu));
    PetscCall(PetscArraycpy(ap->mu, data->mu, data->n));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The best linear fit of the family, grad u = M^-1 sum_t w_t xi_t (u_t - u_k) with M = sum_t w_t xi_t xi_t^T
 * and w = alpha V_j / |xi|^2: G[2 a + d] is the coefficient of node a (0: particle k, t + 1: fam[t])
 * in component d. Exact for every linear field, at corners too. */
static void LinearFit(PetscInt n, const PeriBondGeometry fam[], PetscReal G[])
{
  PetscReal M[3] = {0, 0, 0}, det, Minv[2][2];
  for (PetscInt t = 0; t < n; t++) {
    PetscReal w = fam[t].weight * fam[t].Vj / PetscSqr(fam[t].length);
    M[0] += w * fam[t].xi[0] * fam[t].xi[0];
    M[1] += w * fam[t].xi[0] * fam[t].xi[1];
    M[2] += w * fam[t].xi[1] * fam[t].xi[1];
  }
  det = M[0] * M[2] - M[1] * M[1];
  if (det > 1e-12 * PetscSqr(M[0] + M[2])) {
    Minv[0][0] = M[2] / det;
    Minv[0][1] = Minv[1][0] = -M[1] / det;
    Minv[1][1]              = M[0] / det;
  } else { /* a row of particles: fit along it only */
    Minv[0][0] = M[0] > 0 ? 1 / M[0] : 0;
    Minv[1][1] = M[2] > 0 ? 1 / M[2] : 0;
    Minv[0][1] = Minv[1][0] = 0;
  }
  G[0] = G[1] = 0;
  for (PetscInt t = 0; t < n; t++) {
    PetscReal w = fam[t].weight * fam[t].Vj / PetscSqr(fam[t].length);
    for (PetscInt d = 0; d < 2; d++) {
      G[2 * (t + 1) + d] = w * (Minv[d][0] * fam[t].xi[0] + Minv[d][1] * fam[t].xi[1]);
      G[d] -= G[2 * (t + 1) + d];
    }
  }
}

/* K_k = mu_k V_k (bx bx^T + by by^T), b[2 a + d] the coefficient of node a in the shear angle r_k,d
 * (eq. 56), plus the stabilization s (c/4) mu_k sum_t alpha V_k V_t (u_t - u_k - xi_t . grad u)^2 / |xi_t|
 * with the family's linear fit grad u and c = 6/(pi l delta^3) the bond-based constant. Without it
 * the energy is blind to every pattern that is even about each particle (a checkerboard: all
 * shear angles vanish) and K is singular. The misfit d_t = E_t - G xi_t (E_t = e_{t+1} - e_0) gives
 * sum_t k_t d_t d_t^T = P - Q G^T - G Q^T + G S G^T with P = sum k_t E_t E_t^T, Q = sum k_t E_t xi_t^T,
 * S = sum k_t xi_t xi_t^T: O(n^2) work instead of O(n^3). */
static PetscErrorCode FamilyStiffness(PeriModel m, PetscInt n, const PeriBondGeometry fam[], PetscReal Ke[])
{
  Antiplane     *ap   = (Antiplane *)m->data;
  const PetscInt N    = n + 1;
  PetscReal      g[2] = {1, 1}, scale, mu, *b, *G, *Q, *k, S[3] = {0, 0, 0};

  PetscFunctionBeginUser;
  if (ap->nwork < 7 * N) {
    PetscCall(PetscFree(ap->work));
    ap->nwork = 7 * N;
    PetscCall(PetscMalloc1(ap->nwork, &ap->work));
  }
  b = ap->work;
  G = b + 2 * N;
  Q = G + 2 * N;
  k = Q + 2 * N;
  for (PetscInt a = 0; a < N * N; a++) Ke[a] = 0;
  if (!n) PetscFunctionReturn(PETSC_SUCCESS);
  b[0] = b[1] = 0;
  for (PetscInt t = 0; t < n; t++)
    for (PetscInt d = 0; d < 2; d++) {
      b[2 * (t + 1) + d] = ap->c * m->delta / fam[t].length * fam[t].weight * fam[t].Vj * fam[t].xi[d] / fam[t].length;
      b[d] -= b[2 * (t + 1) + d];
    }
  if (ap->energy)
    for (PetscInt d = 0; d < 2; d++) {
      /* eq. 53: r_k of u = x (u = y) must equal 1 */
      PetscReal r = 0;
      for (PetscInt t = 0; t < n; t++) r += b[2 * (t + 1) + d] * fam[t].xi[d];
      if (r > 0) g[d] = 1 / r;
    }
  mu    = ap->mu ? ap->mu[fam[0].i] : m->material.G;
  scale = mu * fam[0].Vi;
  for (PetscInt a = 0; a < N; a++)
    for (PetscInt c = 0; c < N; c++) Ke[a * N + c] = scale * (g[0] * g[0] * b[2 * a] * b[2 * c] + g[1] * g[1] * b[2 * a + 1] * b[2 * c + 1]);
  if (ap->stabilization <= 0) PetscFunctionReturn(PETSC_SUCCESS);
  LinearFit(n, fam, G);
  Q[0] = Q[1] = 0;
  for (PetscInt t = 0; t < n; t++) {
    k[t] = ap->stabilization * 0.75 * ap->c * mu * fam[t].weight * fam[t].Vi * fam[t].Vj / fam[t].length;
    /* P */
    Ke[0] += k[t];
    Ke[t + 1] -= k[t];
    Ke[(t + 1) * N] -= k[t];
    Ke[(t + 1) * N + t + 1] += k[t];
    for (PetscInt d = 0; d < 2; d++) {
      Q[2 * (t + 1) + d] = k[t] * fam[t].xi[d];
      Q[d] -= Q[2 * (t + 1) + d];
    }
    S[0] += k[t] * fam[t].xi[0] * fam[t].xi[0];
    S[1] += k[t] * fam[t].xi[0] * fam[t].xi[1];
    S[2] += k[t] * fam[t].xi[1] * fam[t].xi[1];
  }
  for (PetscInt a = 0; a < N; a++) {
    const PetscReal *Ga = &G[2 * a], *Qa = &Q[2 * a];
    PetscReal        GSa[2] = {S[0] * Ga[0] + S[1] * Ga[1], S[1] * Ga[0] + S[2] * Ga[1]};
    for (PetscInt c = 0; c < N; c++) {
      const PetscReal *Gc = &G[2 * c], *Qc = &Q[2 * c];
      Ke[a * N + c] += -(Qa[0] * Gc[0] + Qa[1] * Gc[1]) - (Ga[0] * Qc[0] + Ga[1] * Qc[1]) + GSa[0] * Gc[0] + GSa[1] * Gc[1];
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Destroy(PeriModel m)
{
  Antiplane *ap = (Antiplane *)m->data;

  PetscFunctionBeginUser;
  PetscCall(PetscFree2(ap->gx, ap->gy));
  PetscCall(PetscFree(ap->mu));
  PetscCall(PetscFree(ap->work));
  PetscCall(PeriLatticeDestroy(&ap->lat));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Create(PeriModel m)
{
  Antiplane *ap;

  PetscFunctionBeginUser;
  PetscCheck(m->dim == 2, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "model %s is a cross-section model (antiplane shear, torsion); use dim: 2", m->type);
  PetscCall(PetscNew(&ap));
  m->data                = ap;
  m->dofs                = 1;
  m->components          = components;
  m->axis[0]             = 2; /* uz, out of the cross-section's plane */
  m->nmeasures           = 1;
  m->measure_names       = measures;
  m->measure_kinds       = measure_kinds;
  m->ops.nu_range        = NuRange;
  m->ops.bond_measures   = BondMeasures;
  m->ops.rigid_modes     = RigidModes;
  m->ops.critical_from_G = CriticalFromG;
  m->ops.destroy         = Destroy;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PeriModelCreate_Antiplane(PeriModel m)
{
  PetscFunctionBeginUser;
  PetscCall(Create(m));
  m->surface_corrections = corrections_bond;
  m->ops.calibrate       = CalibrateBond;
  m->ops.bond_stiffness  = BondStiffness;
  m->takes_lattice       = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PeriModelCreate_AntiplaneOS(PeriModel m)
{
  PetscFunctionBeginUser;
  PetscCall(Create(m));
  m->surface_corrections  = corrections_os;
  m->ops.calibrate        = CalibrateState;
  m->ops.setfromscene     = SetFromSceneState;
  m->ops.family_stiffness = FamilyStiffness;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* the one rigid mode is the translation; the energy correction (eq. 53) makes every linear u_z
 * exact (without it 2 % and 6 % off at m = 3) */
const PeriModelType PeriModel_Antiplane   = {.name = "antiplane", .create = PeriModelCreate_Antiplane, .rotation_invariant = PETSC_TRUE, .exact_energy = PERI_EXACT_HOMOGENEOUS};
const PeriModelType PeriModel_AntiplaneOS = {.name = "antiplane_os", .schema = os_schema, .create = PeriModelCreate_AntiplaneOS, .rotation_invariant = PETSC_TRUE, .exact_energy = PERI_EXACT_HOMOGENEOUS};
