/* lps: the linear peridynamic solid (Silling, Epton, Weckner, Lehoucq & Askari, J. Elasticity 88,
 * 2007, sec. 15), linearized, any Poisson ratio in (-1, 1/2), in 3D and in 2D plane strain and
 * plane stress (docs/models/lps.md). With d the dimension, omega the influence function, e the
 * extension n . (u_j - u_i) of a bond (n its unit vector) and alpha its partial volume:
 *   m_i     = sum_j omega |xi|^2 alpha V_j                     (weighted volume, the actual family)
 *   theta_i = (d / m_i) sum_j omega |xi| e alpha V_j           (dilatation)
 *   W_i     = (kappa/2) theta_i^2 + (b / 2 m_i) sum_j omega (e - theta_i |xi| / d)^2 alpha V_j
 * with b = d (d + 2) G (15 G in 3D, 8 G in 2D: Le, Bobaru et al., IJNME 98, 2014) and kappa the
 * bulk modulus of the dimension (3D: K; plane strain: K + G/3; plane stress: E / (2 (1 - nu))).
 * Since sum_j omega e |xi| alpha V_j = theta_i m_i / d, W_i = (kappa - b/d^2) theta_i^2 / 2 +
 * (b / 2 m_i) sum_j omega e^2 alpha V_j: central springs k_ij = b omega alpha V_i V_j (1/m_i + 1/m_j)
 * plus one state per particle, theta_i, with modulus A_i = V_i (kappa - b/d^2) (ops.bond_state).
 * m_i stays that of the reference family when bonds break, as in Peridigm: the force of this
 * energy on a live bond is then Peridigm's LPS force state, and the energy stays >= 0.
 * model.dilatation: affine replaces theta_i in the (kappa/2) theta_i^2 term (only there) by
 *   theta_i = sum_j omega alpha V_j (S_i^-1 xi) . (u_j - u_i),  S_i = sum_j omega alpha V_j xi xi^T
 * the trace of the family's least-squares deformation gradient, exact for every affine field at
 * every particle, surfaces included (the standard theta is exact only where S_i is isotropic). The
 * energy is then the springs plus two states, the standard one with modulus -V_i b/d^2 and this
 * one with V_i kappa: W_i = (kappa/2) theta_i^2 + (b / 2 m_i) sum_j omega (e - phi_i |xi| / d)^2
 * alpha V_j, phi_i the standard dilatation; >= 0 by the same Cauchy-Schwarz bound.
 * model.calibration: lattice weighs every bond in particle i's family by i's lattice multiplier
 * f_i(e) (models/lattice.c, profile omega |xi|^2), in m_i, theta_i and the springs alike: the
 * family's moments of degree 0, 2 and 4 are then the continuum's, so theta_i = tr(eps) and the
 * springs give the isotropic deviatoric energy for every homogeneous strain at every particle,
 * surfaces and corners included (where the family is not too lopsided, models/lattice.c), and
 * W_i >= 0 by the same bound, the springs and theta_i having the same weights. */
#include <perilin/model.h>

static const char *const influences[]  = {"constant", "inverse", "gaussian", NULL};
static const char *const corrections[] = {"none", NULL};
static const char *const dilatations[] = {"standard", "affine", NULL};

typedef enum {
  INFLUENCE_CONSTANT,
  INFLUENCE_INVERSE,
  INFLUENCE_GAUSSIAN
} Influence;

typedef struct {
  Influence   influence;
  PetscReal   kappa, b; /* the dimension's bulk modulus; d (d + 2) G */
  PetscInt    n;
  PetscReal  *m; /* weighted volume per particle of the local view */
  PetscReal  *V; /* the particles' volumes (borrowed from the calibration data) */
  PetscBool   affine;
  PetscReal  *Sinv; /* model.dilatation: affine: the inverse shape tensor per particle, dim x dim */
  PeriLattice lat;  /* model.calibration: lattice, else NULL (multipliers 1) */
} LPS;

static const PeriKey lps_keys[] = {
    {"influence", PERI_KEY_CHOICE, "constant", NULL, NULL, influences, "influence function omega(|xi|): constant 1, inverse delta/|xi|, gaussian exp(-|xi|^2/delta^2)"},
    {"dilatation", PERI_KEY_CHOICE, "standard", NULL, NULL, dilatations, "the dilatation of the bulk term: standard (d/m_i) sum omega |xi| e V (Silling et al.), affine the trace of the family's fitted deformation gradient (exact for affine fields at surfaces; matrix-free or assembled, docs/models/lps.md)"},
    {NULL},
};
static const PeriSchema lps_schema[] = {{"model", lps_keys}, {NULL}};

static PetscErrorCode SetFromScene(PeriModel m, PeriScene scene, PeriNode node)
{
  LPS     *lps = (LPS *)m->data;
  PetscInt k   = INFLUENCE_CONSTANT;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetChoice(scene, node, "influence", influences, &k, NULL));
  lps->influence = (Influence)k;
  k              = 0;
  PetscCall(PeriSceneGetChoice(scene, node, "dilatation", dilatations, &k, NULL));
  lps->affine = (PetscBool)(k == 1);
  PeriInputCheck(!lps->affine || m->calibration == PERI_CALIBRATION_CONTINUUM, scene, node, "dilatation", "affine with model.calibration: lattice: the lattice calibration already makes the standard dilatation exact for every homogeneous strain; use dilatation: standard, or calibration: continuum");
  m->nstates            = lps->affine ? 2 : 1;
  m->states_along_bonds = 1; /* the standard dilatation (state 0 of either); the affine one is off the bond */
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Any isotropic elasticity that is positive definite: -1 < nu < 1/2 (the material reader refuses
 * the bounds themselves, naming the key). */
static void NuRange(PeriModel m, PetscReal *lo, PetscReal *hi)
{
  (void)m;
  *lo = -1;
  *hi = 0.5;
}

/* omega of a bond, dimensionless; delta the bond's horizon */
static PetscReal Omega(PeriModel m, const PeriBondGeometry *b)
{
  const LPS      *lps = (const LPS *)m->data;
  const PetscReal d   = PeriModelBondHorizon(m, b);
  if (lps->influence == INFLUENCE_INVERSE) return d / b->length;
  if (lps->influence == INFLUENCE_GAUSSIAN) return PetscExpReal(-PetscSqr(b->length / d));
  return 1;
}

/* the lattice calibration's length profile: the weight omega |xi|^2 of m_i */
static PetscReal Profile(PeriModel m, PetscReal L)
{
  PeriBondGeometry g = {.length = L};
  return Omega(m, &g) * L * L;
}

/* Inverts the symmetric d x d matrix S in place (d = 2, 3) by its adjugate; false when it is
 * singular relative to its size (a family whose bonds do not span the dimension). */
static PetscBool InvertShape(PetscInt d, PetscReal S[])
{
  PetscReal a[9], det;
  if (d == 2) {
    det = S[0] * S[3] - S[1] * S[2];
    if (!(PetscAbsReal(det) > 1e-12 * PetscSqr(S[0] + S[3]))) return PETSC_FALSE;
    a[0] = S[3], a[1] = -S[1], a[2] = -S[2], a[3] = S[0];
  } else {
    a[0] = S[4] * S[8] - S[5] * S[7], a[1] = S[2] * S[7] - S[1] * S[8], a[2] = S[1] * S[5] - S[2] * S[4];
    a[3] = S[5] * S[6] - S[3] * S[8], a[4] = S[0] * S[8] - S[2] * S[6], a[5] = S[2] * S[3] - S[0] * S[5];
    a[6] = S[3] * S[7] - S[4] * S[6], a[7] = S[1] * S[6] - S[0] * S[7], a[8] = S[0] * S[4] - S[1] * S[3];
    det = S[0] * a[0] + S[1] * a[3] + S[2] * a[6];
    if (!(PetscAbsReal(det) > 1e-12 * PetscPowRealInt(S[0] + S[4] + S[8], 3))) return PETSC_FALSE;
  }
  for (PetscInt k = 0; k < d * d; k++) S[k] = a[k] / det;
  return PETSC_TRUE;
}

/* model.dilatation: affine: S_i = sum_j omega alpha V_j xi xi^T over the actual family (a periodic
 * self-image bond adds both of its images, +xi and -xi, through its two ends), then inverted. */
static PetscErrorCode ShapeTensors(PeriModel m, const PeriCalibrationData *data)
{
  LPS             *lps = (LPS *)m->data;
  const PeriBonds *bd  = data->bonds;
  const PetscInt   d = m->dim, dd = d * d;

  PetscFunctionBeginUser;
  PetscCall(PetscFree(lps->Sinv));
  PetscCall(PetscCalloc1(data->n * dd, &lps->Sinv));
  for (PetscInt i = bd->rstart; i < bd->rend; i++)
    for (PetscInt k = bd->offset[i - bd->rstart]; k < bd->offset[i - bd->rstart + 1]; k++) {
      PeriBondGeometry g  = {.i = i, .j = bd->j[k], .length = bd->length[k]};
      const PetscReal *xi = bd->xi + 3 * k, w = Omega(m, &g) * bd->alpha[k];
      for (PetscInt a = 0; a < d; a++)
        for (PetscInt c = 0; c < d; c++) {
          lps->Sinv[i * dd + a * d + c] += w * lps->V[g.j] * xi[a] * xi[c];
          lps->Sinv[g.j * dd + a * d + c] += w * lps->V[i] * xi[a] * xi[c];
        }
    }
  PetscCall(data->combine(data, MPIU_REAL, dd, MPI_SUM, lps->Sinv));
  for (PetscInt i = 0; i < data->n; i++)
    PetscCheck(InvertShape(d, lps->Sinv + i * dd) || i >= data->nowned, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "lps with model.dilatation: affine: the family of particle %" PetscInt_FMT " does not span the dimension (its bonds lie on a line or plane); use model.dilatation: standard or a larger horizon", i);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* m_i over the rank's bonds, then summed over the ranks that hold each particle. A periodic
 * self-image bond stands for the particle's two images, at +xi and -xi. */
static PetscErrorCode Calibrate(PeriModel m, const PeriCalibrationData *data)
{
  LPS             *lps = (LPS *)m->data;
  const PeriBonds *bd  = data->bonds;
  const PetscReal  d   = m->dim;
  PeriMaterial    *mt  = &m->material;

  PetscFunctionBeginUser;
  lps->b     = d * (d + 2) * mt->G;
  lps->kappa = m->dim == 3 ? mt->K : m->plane_strain ? mt->K + mt->G / 3
                                                     : mt->E / (2 * (1 - mt->nu));
  lps->V     = data->particles->volume;
  lps->n     = data->n;
  PetscCall(PetscFree(lps->m));
  PetscCall(PetscCalloc1(data->n, &lps->m));
  if (m->calibration != PERI_CALIBRATION_CONTINUUM) {
    PetscCheck(!m->horizon, data->comm, PETSC_ERR_PLIB, "lps: the lattice calibration with per-particle horizons (the scene check refuses it)");
    PetscCall(PeriLatticeCreate(m, data, 4, Profile, &lps->lat));
  }
  for (PetscInt i = bd->rstart; i < bd->rend; i++)
    for (PetscInt k = bd->offset[i - bd->rstart]; k < bd->offset[i - bd->rstart + 1]; k++) {
      PeriBondGeometry g = {.i = i, .j = bd->j[k], .length = bd->length[k]};
      PetscReal        w, fi, fj;
      for (PetscInt a = 0; a < 3; a++) g.xi[a] = bd->xi[3 * k + a];
      w = Omega(m, &g) * PetscSqr(bd->length[k]) * bd->alpha[k];
      PeriLatticeMultipliers(lps->lat, &g, &fi, &fj);
      lps->m[i] += w * fi * lps->V[g.j];
      lps->m[g.j] += w * fj * lps->V[i];
    }
  PetscCall(data->combine(data, MPIU_REAL, 1, MPI_SUM, lps->m));
  for (PetscInt i = 0; i < data->nowned; i++) PetscCheck(lps->m[i] > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "lps: particle %" PetscInt_FMT " has no neighbours, its weighted volume is 0 (is the horizon smaller than the spacing?)", i);
  if (lps->affine) PetscCall(ShapeTensors(m, data));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* the pair springs: b omega alpha V_i V_j (f_i/m_i + f_j/m_j) along the bond (f = 1 but with the
 * lattice calibration) */
static void BondStiffness(PeriModel m, const PeriBondGeometry *b, PetscReal Ke[])
{
  const LPS *lps = (const LPS *)m->data;
  PetscReal  fi, fj;
  PeriLatticeMultipliers(lps->lat, b, &fi, &fj);
  PeriCentralBondBlock(m, b, lps->b * Omega(m, b) * b->weight * b->Vi * b->Vj * (fi / lps->m[b->i] + fj / lps->m[b->j]), Ke);
}

/* State 0, the standard dilatation: theta_i += (d omega |xi| alpha V_j / m_i) n . (u_j - u_i), and
 * theta_j alike with V_i / m_j. State 1 (affine): omega alpha V_j S_i^-1 xi, and V_i S_j^-1 xi. */
static void BondState(PeriModel m, const PeriBondGeometry *b, PetscInt s, PetscReal gi[], PetscReal gj[])
{
  const LPS      *lps = (const LPS *)m->data;
  const PetscInt  d = m->dim, dd = d * d;
  const PetscReal w = Omega(m, b) * b->weight, c = d * w * b->length;
  PetscReal       fi, fj;
  PeriLatticeMultipliers(lps->lat, b, &fi, &fj);
  for (PetscInt a = 0; a < m->dofs; a++) {
    gi[a] = gj[a] = 0;
    for (PetscInt e = 0; e < d && a < d; e++) {
      if (s == 0 && e == a) {
        gi[a] = c * fi * b->Vj / lps->m[b->i] * b->xi[a] / b->length;
        gj[a] = c * fj * b->Vi / lps->m[b->j] * b->xi[a] / b->length;
      }
      if (s == 1) {
        gi[a] += w * b->Vj * lps->Sinv[b->i * dd + a * d + e] * b->xi[e];
        gj[a] += w * b->Vi * lps->Sinv[b->j * dd + a * d + e] * b->xi[e];
      }
    }
  }
}

/* standard: V_i (kappa - b/d^2) on theta; affine: -V_i b/d^2 on the standard theta, V_i kappa on
 * the affine one */
static PetscReal StateModulus(PeriModel m, PetscInt i, PetscInt s)
{
  const LPS      *lps = (const LPS *)m->data;
  const PetscReal dev = lps->b / (m->dim * m->dim);
  if (!lps->affine) return lps->V[i] * (lps->kappa - dev);
  return s == 0 ? -lps->V[i] * dev : lps->V[i] * lps->kappa;
}

/* The critical stretch for the energy release rate G of the LPS with a constant influence
 * function (Madenci & Oterkus, Peridynamic Theory and Its Applications, Springer 2014, secs. 4.5
 * and 4.6): s_c = sqrt(G / ((3 mu + (3/4)^4 (kappa - 5 mu / 3)) delta)) in 3D and
 * sqrt(G / ((6 mu / pi + 16 (kappa - 2 mu) / (9 pi^2)) delta)) in 2D, delta the bond's horizon. */
static PetscReal CriticalFromG(PeriModel m, const PeriBondGeometry *b, PetscReal G)
{
  const LPS      *lps = (const LPS *)m->data;
  const PetscReal mu = m->material.G, d = PeriModelBondHorizon(m, b);
  if (m->dim == 3) return PetscSqrtReal(G / ((3 * mu + PetscPowRealInt(0.75, 4) * (lps->kappa - 5 * mu / 3)) * d));
  return PetscSqrtReal(G / ((6 * mu / PETSC_PI + 16 * (lps->kappa - 2 * mu) / (9 * PETSC_PI * PETSC_PI)) * d));
}

static PetscErrorCode Destroy(PeriModel m)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(((LPS *)m->data)->m));
  PetscCall(PetscFree(((LPS *)m->data)->Sinv));
  PetscCall(PeriLatticeDestroy(&((LPS *)m->data)->lat));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PeriModelCreate_LPS(PeriModel m)
{
  LPS *lps;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&lps));
  m->data = lps;
  PeriModelSetCentralForce(m); /* the springs are central; the DOFs, stretch and rigid modes too */
  m->ops.nu_range        = NuRange;
  m->ops.setfromscene    = SetFromScene;
  m->ops.calibrate       = Calibrate;
  m->ops.bond_stiffness  = BondStiffness;
  m->ops.bond_state      = BondState;
  m->ops.state_modulus   = StateModulus;
  m->ops.critical_from_G = CriticalFromG;
  m->ops.destroy         = Destroy;
  m->surface_corrections = corrections; /* m_i from the actual family is the model's own */
  m->takes_own_horizon   = PETSC_TRUE;
  m->takes_lattice       = PETSC_TRUE;
  m->nstates             = 1;
  m->states_along_bonds  = 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* theta = tr(eps) exactly wherever the family is point-symmetric with isotropic second moments
 * (every grid family), so an isotropic expansion stores exactly kappa theta^2 / 2; a shear's energy
 * needs isotropic fourth moments, which a cubic grid family lacks */
const PeriModelType PeriModel_LPS = {.name = "lps", .schema = lps_schema, .create = PeriModelCreate_LPS, .rotation_invariant = PETSC_TRUE, .exact_energy = PERI_EXACT_EXPANSION};
