/* pmb: Silling's prototype micro-brittle bond model with the analytic micromodulus.
 * Micropotential w = c s^2 |xi| / 2; c from equating the energy density of u = s X over the
 * continuous horizon with the elastic one: c = 18K/(pi delta^4) in 3D, 9E/(pi t delta^3) in plane
 * stress, 48E/(5 pi t delta^3) in plane strain (docs/models/pmb.md). */
#include "perilin.h"

typedef struct {
  PetscReal c;
} PMB;

static const char *const components2[] = {"ux", "uy"}, *const components3[] = {"ux", "uy", "uz"};
static const char *const measures[] = {"stretch"};

static PetscErrorCode Calibrate(PeriModel m, const PeriCalibrationData *data)
{
  PMB *pmb = (PMB *)m->data;

  PetscFunctionBeginUser;
  (void)data;
  pmb->c = 4 * PeriModelIsotropicEnergy(m) / PeriModelHorizonMoment(m, 1);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* pair energy V_i V_j w = (c V_i V_j / |xi|) (e . (u_j - u_i))^2 / 2 */
static void BondStiffness(PeriModel m, const PeriBondGeometry *b, PetscReal Ke[])
{
  const PMB *pmb = (const PMB *)m->data;
  PeriCentralBondBlock(m, b, pmb->c * b->Vi * b->Vj * b->weight / b->length, Ke);
}

static PetscErrorCode Destroy(PeriModel m)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(m->data));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriModelCreate_PMB(PeriModel m)
{
  PMB *pmb;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&pmb));
  m->data               = pmb;
  m->dofs               = m->dim;
  m->components         = m->dim == 2 ? components2 : components3;
  m->nmeasures          = 1;
  m->measure_names      = measures;
  m->ops.nu_range       = PeriBondBasedNuRange;
  m->ops.calibrate      = Calibrate;
  m->ops.bond_stiffness = BondStiffness;
  m->ops.bond_measures  = PeriBondStretch;
  m->ops.rigid_modes    = PeriTranslationalRigidModes;
  m->ops.destroy        = Destroy;
  PetscFunctionReturn(PETSC_SUCCESS);
}
