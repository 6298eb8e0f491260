/* pds: bond-based peridynamics with shear bonds (Zhu & Ni; Diana & Casolo sec. 2.1), 2D.
 * Pair energy alpha lambda V_i V_j (c s^2 + g gamma^2) |xi| / 2 with the stretch s = e.(u_j-u_i)/|xi|
 * and the sliding gamma = t.(u_j-u_i)/|xi| (t = e rotated by +90 degrees); c and g from eqs. 7 and
 * 21, so any Poisson ratio in (-1, 1/2) is reached; g = 0 at nu = 1/3 (plane stress) or 1/4
 * (plane strain), where pds is pmb. The sliding does not subtract the rotation of the bond, so a
 * rigid rotation stores energy when g != 0: the defect Diana & Casolo demonstrate (docs/models/pds.md). */
#include <perilin/model.h>

typedef struct {
  PetscReal   c, g;
  PeriLattice lat; /* model.calibration: lattice, else NULL */
} PDS;

static const char *const components[] = {"ux", "uy"};
static const char *const measures[]   = {"stretch", "sliding"};

/* what each measure is (the failure criteria find theirs by kind) */
static const PeriMeasureKind measure_kinds[] = {PERI_MEASURE_STRETCH, PERI_MEASURE_SLIDING};

static PetscErrorCode Calibrate(PeriModel m, const PeriCalibrationData *data)
{
  PDS *pds = (PDS *)m->data;

  PetscFunctionBeginUser;
  PeriPlaneMicromoduli(m, &pds->c, &pds->g);
  /* both springs weigh |xi|: one family */
  PetscCall(PeriLatticeCreate(m, data, 4, PeriProfileLength, &pds->lat));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* b_s . u_e = s and b_g . u_e = gamma over (ux_i, uy_i, ux_j, uy_j) */
static void Vectors(const PeriBondGeometry *b, PetscReal bs[4], PetscReal bg[4])
{
  const PetscReal L = b->length, ex = b->xi[0] / L, ey = b->xi[1] / L;
  bs[0] = -ex / L;
  bs[1] = -ey / L;
  bs[2] = ex / L;
  bs[3] = ey / L;
  bg[0] = ey / L;
  bg[1] = -ex / L;
  bg[2] = -ey / L;
  bg[3] = ex / L;
}

static void BondStiffness(PeriModel m, const PeriBondGeometry *b, PetscReal Ke[])
{
  const PDS *pds = (const PDS *)m->data;
  PetscReal  bs[4], bg[4], w = b->Vi * b->Vj * b->weight * b->length * PeriLatticeFactor(pds->lat, b);
  Vectors(b, bs, bg);
  for (PetscInt a = 0; a < 16; a++) Ke[a] = 0;
  PeriAddSpring(4, bs, w * pds->c, Ke);
  PeriAddSpring(4, bg, w * pds->g, Ke);
}

/* the normal springs' critical stretch (the shear springs are left out of the energy balance) */
static PetscReal CriticalFromG(PeriModel m, const PeriBondGeometry *b, PetscReal G)
{
  const PDS *pds = (const PDS *)m->data;
  return PeriCriticalStretchSpring(m, b, pds->c * PeriLatticeFactor(pds->lat, b), G);
}

static PetscErrorCode Destroy(PeriModel m)
{
  PetscFunctionBeginUser;
  PetscCall(PeriLatticeDestroy(&((PDS *)m->data)->lat));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static void BondMeasures(PeriModel m, const PeriBondGeometry *b, const PetscReal ui[], const PetscReal uj[], PetscReal h[])
{
  PetscReal bs[4], bg[4], u[4] = {ui[0], ui[1], uj[0], uj[1]};
  (void)m;
  Vectors(b, bs, bg);
  h[0] = h[1] = 0;
  for (PetscInt a = 0; a < 4; a++) {
    h[0] += bs[a] * u[a];
    h[1] += bg[a] * u[a];
  }
}

static PetscErrorCode PeriModelCreate_PDS(PeriModel m)
{
  PDS *pds;

  PetscFunctionBeginUser;
  PetscCheck(m->dim == 2, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "model pds is two-dimensional (plane stress or plane strain); use dim: 2");
  PetscCall(PetscNew(&pds));
  m->data                = pds;
  m->dofs                = 2;
  m->components          = components;
  m->axis[0]             = 0;
  m->axis[1]             = 1;
  m->nmeasures           = 2;
  m->measure_names       = measures;
  m->measure_kinds       = measure_kinds;
  m->ops.nu_range        = PeriShearBondNuRange;
  m->ops.calibrate       = Calibrate;
  m->ops.bond_stiffness  = BondStiffness;
  m->ops.bond_measures   = BondMeasures;
  m->ops.critical_from_G = CriticalFromG;
  m->ops.destroy         = Destroy;
  m->takes_lattice       = PETSC_TRUE;
  m->calibration         = PERI_CALIBRATION_LATTICE; /* the default: it wins on every lamina benchmark (docs/models/lattice.md) */
  /* the rotation is not a zero-energy mode for g != 0, but it is the near-null space AMG wants */
  m->ops.rigid_modes = PeriTranslationalRigidModes;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* not rotation invariant (the defect described at the top; the rotation in rigid_modes is only
 * AMG's near-null space); c and g come from the continuous horizon, so no energy is exact (1 % at m = 3) */
const PeriModelType PeriModel_PDS = {.name = "pds", .create = PeriModelCreate_PDS, .rotation_invariant = PETSC_FALSE, .exact_energy = PERI_EXACT_NONE};
