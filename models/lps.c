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
 * energy on a live bond is then Peridigm's LPS force state, and the energy stays >= 0. */
#include <perilin/model.h>

static const char *const influences[]  = {"constant", "inverse", "gaussian", NULL};
static const char *const corrections[] = {"none", NULL};

typedef enum {
  INFLUENCE_CONSTANT,
  INFLUENCE_INVERSE,
  INFLUENCE_GAUSSIAN
} Influence;

typedef struct {
  Influence  influence;
  PetscReal  kappa, b; /* the dimension's bulk modulus; d (d + 2) G */
  PetscInt   n;
  PetscReal *m; /* weighted volume per particle of the local view */
  PetscReal *V; /* the particles' volumes (borrowed from the calibration data) */
} LPS;

static const PeriKey lps_keys[] = {
    {"influence", PERI_KEY_CHOICE, "constant", NULL, NULL, influences, "influence function omega(|xi|): constant 1, inverse delta/|xi|, gaussian exp(-|xi|^2/delta^2)"},
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
  for (PetscInt i = bd->rstart; i < bd->rend; i++)
    for (PetscInt k = bd->offset[i - bd->rstart]; k < bd->offset[i - bd->rstart + 1]; k++) {
      PeriBondGeometry g = {.i = i, .j = bd->j[k], .length = bd->length[k]};
      const PetscReal  w = Omega(m, &g) * PetscSqr(bd->length[k]) * bd->alpha[k];
      lps->m[i] += w * lps->V[g.j];
      lps->m[g.j] += w * lps->V[i];
    }
  PetscCall(data->combine(data, MPIU_REAL, 1, MPI_SUM, lps->m));
  for (PetscInt i = 0; i < data->nowned; i++) PetscCheck(lps->m[i] > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "lps: particle %" PetscInt_FMT " has no neighbours, its weighted volume is 0 (is the horizon smaller than the spacing?)", i);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* the pair springs: b omega alpha V_i V_j (1/m_i + 1/m_j) along the bond */
static void BondStiffness(PeriModel m, const PeriBondGeometry *b, PetscReal Ke[])
{
  const LPS *lps = (const LPS *)m->data;
  PeriCentralBondBlock(m, b, lps->b * Omega(m, b) * b->weight * b->Vi * b->Vj * (1 / lps->m[b->i] + 1 / lps->m[b->j]), Ke);
}

/* theta_i += (d omega |xi| alpha V_j / m_i) n . (u_j - u_i), and theta_j alike with V_i / m_j */
static void BondState(PeriModel m, const PeriBondGeometry *b, PetscReal gi[], PetscReal gj[])
{
  const LPS      *lps = (const LPS *)m->data;
  const PetscReal c   = m->dim * Omega(m, b) * b->length * b->weight;
  for (PetscInt a = 0; a < m->dofs; a++) {
    const PetscReal n = a < m->dim ? b->xi[a] / b->length : 0;
    gi[a]             = c * b->Vj / lps->m[b->i] * n;
    gj[a]             = c * b->Vi / lps->m[b->j] * n;
  }
}

static PetscReal StateModulus(PeriModel m, PetscInt i)
{
  const LPS *lps = (const LPS *)m->data;
  return lps->V[i] * (lps->kappa - lps->b / (m->dim * m->dim));
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
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* theta = tr(eps) exactly wherever the family is point-symmetric with isotropic second moments
 * (every grid family), so an isotropic expansion stores exactly kappa theta^2 / 2; a shear's energy
 * needs isotropic fourth moments, which a cubic grid family lacks */
const PeriModelType PeriModel_LPS = {.name = "lps", .schema = lps_schema, .create = PeriModelCreate_LPS, .rotation_invariant = PETSC_TRUE, .exact_energy = PERI_EXACT_EXPANSION};
