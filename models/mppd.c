/* mppd and gerstle: 2D micropolar bonds (Diana & Casolo sec. 2.2), 3 DOFs per particle
 * (ux, uy, theta). Deformation measures of a bond (eqs. 26-28, kappa = 0):
 *   s     = e.(u_j - u_i) / |xi|                       stretch
 *   gamma = t.(u_j - u_i) / |xi| - (theta_i + theta_j)/2  sliding (chord rotation minus the
 *                                                        particles' mean rotation)
 *   vartheta = theta_j - theta_i                         relative rotation
 * with e = xi/|xi|, t = e rotated by +90 degrees, theta counter-clockwise. The pair energy is
 * alpha lambda V_i V_j (k_n s^2 |xi| + k_t gamma^2 |xi| + k_theta vartheta^2) / 2 (eq. 32); a rigid
 * rotation u = w x X, theta = w leaves every measure zero. Eqs. (30) and (33) print the theta
 * terms of the sliding with the opposite sign, which is the clockwise convention; with it a rigid
 * rotation would slide the bonds (docs/models/mppd.md).
 *   mppd:    k_n = c, k_t = g (eqs. 7, 21), k_theta = f c delta^2 / (36 |xi|), f = model.k_theta_factor
 *            (default 1: Gerstle's rotational spring at nu = 0), or k_theta = model.k_theta.
 *   gerstle: k_n = c, k_t = 12 d / |xi|^2, k_theta = d / |xi| (eqs. 42-43), d = g delta^2 / 36. */
#include <perilin/model.h>

typedef struct {
  PetscBool   gerstle;
  PetscReal   c, g, d;
  PetscReal   k_theta, k_theta_factor; /* mppd: absolute value when >= 0, else the factor applies */
  PeriLattice normal, shear;           /* model.calibration: lattice, else NULL; gerstle's shear springs have their own */
} MPPD;

static const char *const components[] = {"ux", "uy", "theta"};
static const char *const measures[]   = {"stretch", "sliding", "relative_rotation"};

/* what each measure is (the failure criteria find theirs by kind) */
static const PeriMeasureKind measure_kinds[] = {PERI_MEASURE_STRETCH, PERI_MEASURE_SLIDING, PERI_MEASURE_RELATIVE_ROTATION};

static PetscErrorCode SetFromScene(PeriModel m, PeriScene scene, PeriNode node)
{
  MPPD     *mp = (MPPD *)m->data;
  PetscBool has_k;

  PetscFunctionBeginUser;
  mp->k_theta = -1;
  PetscCall(PeriSceneGetReal(scene, node, "k_theta", PETSC_FALSE, &mp->k_theta, &has_k));
  if (has_k)
    PetscCall(PeriSceneCheckAbsent(scene, node, "k_theta_factor", "give model.k_theta or model.k_theta_factor, not both"));
  else
    PetscCall(PeriSceneGetReal(scene, node, "k_theta_factor", PETSC_FALSE, &mp->k_theta_factor, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* gerstle's shear spring k_t |xi| = 12 d / |xi| */
static PetscReal ProfileGerstleShear(PeriModel m, PetscReal L)
{
  (void)m;
  return 1 / L;
}

static PetscErrorCode Calibrate(PeriModel m, const PeriCalibrationData *data)
{
  MPPD *mp = (MPPD *)m->data;

  PetscFunctionBeginUser;
  PeriPlaneMicromoduli(m, &mp->c, &mp->g);
  mp->d = mp->g * m->delta * m->delta / 36;
  PetscCall(PeriLatticeCreate(m, data, 4, PeriProfileLength, &mp->normal));
  if (mp->gerstle) PetscCall(PeriLatticeCreate(m, data, 4, ProfileGerstleShear, &mp->shear));
  /* at the bond-based Poisson ratio the shear springs vanish and theta no longer acts on the
   * displacements: it is held at 0 rather than left singular. Within 1e-6 of it (nu = 0.3333333333
   * typed for 1/3) the springs are 1e-10 of the normal ones: a nearly singular theta whose spurious
   * modes of a few Hz a modal run would report; that is the same model, so it is treated the same. */
  if (PetscAbsReal(mp->g) <= 1e-6 * mp->c) mp->g = mp->d = 0;
  m->inactive[2] = (PetscBool)(mp->g == 0);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The lattice factors: mppd's three springs all weigh |xi| in a homogeneous strain (k_theta in the
 * curvature state theta = kappa . X), so one family's factor scales them; gerstle's shear and
 * rotational springs keep their beam ratio k_t = 12 k_theta / |xi| and take the shear family's. */
static void Springs(const MPPD *mp, PetscReal delta, const PeriBondGeometry *b, PetscReal *kn, PetscReal *kt, PetscReal *kth)
{
  const PetscReal L = b->length, fn = PeriLatticeFactor(mp->normal, b);
  *kn = mp->c * fn;
  if (mp->gerstle) {
    const PetscReal ft = PeriLatticeFactor(mp->shear, b);
    *kt                = 12 * mp->d * ft / (L * L);
    *kth               = mp->d * ft / L;
  } else {
    *kt  = mp->g * fn;
    *kth = fn * (mp->k_theta >= 0 ? mp->k_theta : mp->k_theta_factor * mp->c * delta * delta / (36 * L));
  }
}

/* measure vectors over (ux_i, uy_i, theta_i, ux_j, uy_j, theta_j) */
static void Vectors(const PeriBondGeometry *b, PetscReal bs[6], PetscReal bg[6], PetscReal bt[6])
{
  const PetscReal L = b->length, ex = b->xi[0] / L, ey = b->xi[1] / L;
  const PetscReal s[6] = {-ex / L, -ey / L, 0, ex / L, ey / L, 0};
  const PetscReal g[6] = {ey / L, -ex / L, -0.5, -ey / L, ex / L, -0.5};
  const PetscReal t[6] = {0, 0, -1, 0, 0, 1};
  for (PetscInt a = 0; a < 6; a++) {
    bs[a] = s[a];
    bg[a] = g[a];
    bt[a] = t[a];
  }
}

static void BondStiffness(PeriModel m, const PeriBondGeometry *b, PetscReal Ke[])
{
  const MPPD *mp = (const MPPD *)m->data;
  PetscReal   bs[6], bg[6], bt[6], kn, kt, kth, w = b->Vi * b->Vj * b->weight;
  Vectors(b, bs, bg, bt);
  Springs(mp, m->delta, b, &kn, &kt, &kth);
  for (PetscInt a = 0; a < 36; a++) Ke[a] = 0;
  PeriAddSpring(6, bs, w * kn * b->length, Ke);
  PeriAddSpring(6, bg, w * kt * b->length, Ke);
  PeriAddSpring(6, bt, w * kth, Ke);
}

/* the normal springs' critical stretch (the shear and rotational springs are left out of the energy balance) */
static PetscReal CriticalFromG(PeriModel m, const PeriBondGeometry *b, PetscReal G)
{
  const MPPD *mp = (const MPPD *)m->data;
  return PeriCriticalStretchSpring(m, b, mp->c * PeriLatticeFactor(mp->normal, b), G);
}

static PetscErrorCode Destroy(PeriModel m)
{
  MPPD *mp = (MPPD *)m->data;

  PetscFunctionBeginUser;
  PetscCall(PeriLatticeDestroy(&mp->normal));
  PetscCall(PeriLatticeDestroy(&mp->shear));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static void BondMeasures(PeriModel m, const PeriBondGeometry *b, const PetscReal ui[], const PetscReal uj[], PetscReal h[])
{
  PetscReal bs[6], bg[6], bt[6], u[6] = {ui[0], ui[1], ui[2], uj[0], uj[1], uj[2]};
  (void)m;
  Vectors(b, bs, bg, bt);
  h[0] = h[1] = h[2] = 0;
  for (PetscInt a = 0; a < 6; a++) {
    h[0] += bs[a] * u[a];
    h[1] += bg[a] * u[a];
    h[2] += bt[a] * u[a];
  }
}

/* translations, and the rigid rotation u = w x X with theta = w */
static PetscInt RigidModes(PeriModel m, const PetscReal X[], PetscReal modes[][PERI_MAX_DOF])
{
  (void)m;
  for (PetscInt k = 0; k < PERI_MAX_MODES; k++)
    for (PetscInt c = 0; c < PERI_MAX_DOF; c++) modes[k][c] = 0;
  modes[0][0] = 1;
  modes[1][1] = 1;
  modes[2][0] = -X[1];
  modes[2][1] = X[0];
  modes[2][2] = 1;
  return 3;
}

static PetscErrorCode Create(PeriModel m, PetscBool gerstle)
{
  MPPD *mp;

  PetscFunctionBeginUser;
  PetscCheck(m->dim == 2, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "model %s is two-dimensional (plane stress or plane strain); use dim: 2", m->type);
  PetscCall(PetscNew(&mp));
  mp->gerstle            = gerstle;
  mp->k_theta            = -1;
  mp->k_theta_factor     = 1;
  m->data                = mp;
  m->dofs                = 3;
  m->components          = components;
  m->nmeasures           = 3;
  m->measure_names       = measures;
  m->measure_kinds       = measure_kinds;
  m->rotational[2]       = PETSC_TRUE; /* theta, about z */
  m->axis[0]             = 0;
  m->axis[1]             = 1;
  m->ops.setfromscene    = gerstle ? NULL : SetFromScene;
  m->ops.nu_range        = PeriShearBondNuRange;
  m->ops.calibrate       = Calibrate;
  m->ops.bond_stiffness  = BondStiffness;
  m->ops.bond_measures   = BondMeasures;
  m->ops.critical_from_G = CriticalFromG;
  m->ops.rigid_modes     = RigidModes;
  m->ops.destroy         = Destroy;
  m->takes_lattice       = PETSC_TRUE;
  m->calibration         = PERI_CALIBRATION_LATTICE; /* the default: it wins on every lamina benchmark (docs/models/lattice.md) */
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PeriModelCreate_MPPD(PeriModel m)
{
  PetscFunctionBeginUser;
  PetscCall(Create(m, PETSC_FALSE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PeriModelCreate_Gerstle(PeriModel m)
{
  PetscFunctionBeginUser;
  PetscCall(Create(m, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The model.* keys SetFromScene reads (mppd only: gerstle's rotational spring is fixed). */
static const PeriKey mppd_keys[] = {
    {"k_theta", PERI_KEY_REAL, NULL, "[0, inf)", "[energy/volume^2]", NULL, "rotational spring k_theta, instead of the factor"},
    {"k_theta_factor", PERI_KEY_REAL, "1", "[0, inf)", NULL, NULL, "k_theta = f c delta^2 / (36 |xi|); not with k_theta"},
    {NULL},
};
static const PeriSchema mppd_schema[] = {{"model", mppd_keys}, {NULL}};

/* the micromoduli come from the continuous horizon, so no energy is exact on a grid: at m = 3 mppd
 * is 1 % off, as pds (theta is idle in a homogeneous strain), gerstle 16 % (its shear springs
 * weigh 1/|xi|, so the nearest bonds dominate) */
const PeriModelType PeriModel_MPPD    = {.name = "mppd", .schema = mppd_schema, .create = PeriModelCreate_MPPD, .rotation_invariant = PETSC_TRUE, .exact_energy = PERI_EXACT_NONE};
const PeriModelType PeriModel_Gerstle = {.name = "gerstle", .create = PeriModelCreate_Gerstle, .rotation_invariant = PETSC_TRUE, .exact_energy = PERI_EXACT_NONE};
