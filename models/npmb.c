/* npmb: the normalized PMB of Ganzenmueller et al. (eqs. 12-17). Micropotential w = c_ij s^2 / 2
 * with c_i = 4 W0 / sum_j alpha_ij V_j from the particle's discrete family volume (W0 the elastic
 * energy density of u = X, 9K/2 in 3D: c_i = 18K / sum_j V_j, eq. 14) and c_ij = (c_i + c_j)/2
 * (eq. 15). The discrete energy density of any isotropic expansion is then exact wherever the
 * family is uniform, at surfaces too, and particle volumes may differ. */
#include "perilin.h"

typedef struct {
  PetscInt   n;
  PetscReal *c; /* per particle (global index) */
} NPMB;

static const char *const components2[] = {"ux", "uy"}, *const components3[] = {"ux", "uy", "uz"};
static const char *const measures[] = {"stretch"};

static PetscErrorCode Calibrate(PeriModel m, const PeriCalibrationData *data)
{
  NPMB     *np = (NPMB *)m->data;
  PetscReal W0 = PeriModelIsotropicEnergy(m);

  PetscFunctionBeginUser;
  PetscCall(PetscFree(np->c));
  PetscCall(PetscMalloc1(data->n, &np->c));
  np->n = data->n;
  for (PetscInt i = 0; i < data->n; i++) {
    PetscCheck(data->family_volume[i] > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "npmb: particle %" PetscInt_FMT " has no neighbours, its micromodulus is undefined (is the horizon smaller than the spacing?)", i);
    np->c[i] = 4 * W0 / data->family_volume[i];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* pair energy V_i V_j w = (c_ij V_i V_j / |xi|^2) (e . (u_j - u_i))^2 / 2 */
static void BondStiffness(PeriModel m, const PeriBondGeometry *b, PetscReal Ke[])
{
  const NPMB *np = (const NPMB *)m->data;
  PetscReal   c  = 0.5 * (np->c[b->i] + np->c[b->j]);
  PeriCentralBondBlock(m, b, c * b->Vi * b->Vj * b->weight / (b->length * b->length), Ke);
}

static PetscErrorCode Destroy(PeriModel m)
{
  NPMB *np = (NPMB *)m->data;

  PetscFunctionBeginUser;
  PetscCall(PetscFree(np->c));
  PetscCall(PetscFree(m->data));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriModelCreate_NPMB(PeriModel m)
{
  NPMB *np;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&np));
  m->data          = np;
  m->dofs          = m->dim;
  m->components    = m->dim == 2 ? components2 : components3;
  m->nmeasures     = 1;
  m->measure_names = measures;
  /* the per-particle normalization already corrects surfaces; the volume method would count twice */
  m->allows_surface_correction = PETSC_FALSE;
  m->ops.nu_range              = PeriBondBasedNuRange;
  m->ops.calibrate             = Calibrate;
  m->ops.bond_stiffness        = BondStiffness;
  m->ops.bond_measures         = PeriBondStretch;
  m->ops.rigid_modes           = PeriTranslationalRigidModes;
  m->ops.destroy               = Destroy;
  PetscFunctionReturn(PETSC_SUCCESS);
}
