/* cpmb: PMB with the conical influence function omega = 1 - |xi|/delta (Seleson & Parks, "On the
 * role of the influence function in the peridynamic theory", 2011): micropotential
 * w = c omega s^2 |xi| / 2, so that distant bonds, which a grid resolves worst, weigh least.
 * c from the energy density of u = s X over the continuous horizon, as pmb's:
 * c = 4 W0 / (M1 - M2/delta), M_p the horizon moment of |xi|^p (docs/models/cpmb.md).
 * Also the worked example of docs/design.md, "How to add a model": this file and one line in
 * models/model_list.h are all it took. */
#include <perilin/model.h>

typedef struct {
  PetscReal   c;
  PeriLattice lat; /* model.calibration: lattice, else NULL */
} CPMB;

/* the spring's |xi| profile omega |xi| for the lattice calibration */
static PetscReal Profile(PeriModel m, PetscReal L)
{
  return PetscMax(1 - L / m->delta, 0) * L;
}

static PetscErrorCode Calibrate(PeriModel m, const PeriCalibrationData *data)
{
  CPMB *cp = (CPMB *)m->data;

  PetscFunctionBeginUser;
  cp->c = 4 * PeriModelIsotropicEnergy(m) / (PeriModelHorizonMoment(m, 1) - PeriModelHorizonMoment(m, 2) / m->delta);
  PetscCall(PeriLatticeCreate(m, data, 4, Profile, &cp->lat));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* pair energy V_i V_j w = (c omega V_i V_j / |xi|) (e . (u_j - u_i))^2 / 2 */
static void BondStiffness(PeriModel m, const PeriBondGeometry *b, PetscReal Ke[])
{
  const CPMB     *cp    = (const CPMB *)m->data;
  const PetscReal omega = PetscMax(1 - b->length / m->delta, 0);
  PeriCentralBondBlock(m, b, cp->c * PeriLatticeFactor(cp->lat, b) * omega * b->Vi * b->Vj * b->weight / b->length, Ke);
}

static PetscErrorCode Destroy(PeriModel m)
{
  PetscFunctionBeginUser;
  PetscCall(PeriLatticeDestroy(&((CPMB *)m->data)->lat));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PeriModelCreate_CPMB(PeriModel m)
{
  CPMB *cp;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&cp));
  m->data = cp;
  PeriModelSetCentralForce(m);
  m->ops.calibrate      = Calibrate;
  m->ops.bond_stiffness = BondStiffness;
  m->ops.destroy        = Destroy;
  m->takes_lattice      = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* c comes from the continuous horizon, as pmb's: no energy is exact on a grid */
const PeriModelType PeriModel_CPMB = {.name = "cpmb", .create = PeriModelCreate_CPMB, .rotation_invariant = PETSC_TRUE, .exact_energy = PERI_EXACT_NONE};
