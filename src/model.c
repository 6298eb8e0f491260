/* The model interface: registry by name (PetscFunctionList), material constants from the scene,
 * and the pieces several bond models share. Assembly and analyses call models only through
 * PeriModelOps. */
#include "perilin.h"

static PetscFunctionList PeriModelList = NULL;

/* Run by PetscFinalize: frees the list, as PETSc's own packages do (models/registry.c forgets on
 * its own that it filled it). */
static PetscErrorCode PeriModelFinalizePackage(void)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListDestroy(&PeriModelList));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriModelRegister(const char name[], PetscErrorCode (*create)(PeriModel))
{
  PetscFunctionBeginUser;
  /* whoever registers first (PeriModelRegisterAll or a user's model) arranges the cleanup */
  if (!PeriModelList) PetscCall(PetscRegisterFinalize(PeriModelFinalizePackage));
  PetscCall(PetscFunctionListAdd(&PeriModelList, name, create));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The list is filled by PeriInitializePackage (PeriModelRegisterAll), never from here: the
 * registry calls this file, not the other way round. An empty list means the package was not
 * initialized, which the "unknown model" message would hide. */
static PetscErrorCode ModelFind(const char type[], PetscErrorCode (**create)(PeriModel))
{
  PetscFunctionBeginUser;
  PetscCheck(PeriModelList, PETSC_COMM_SELF, PETSC_ERR_ORDER, "no model is registered: call PeriInitializePackage() first");
  *create = NULL;
  PetscCall(PetscFunctionListFind(PeriModelList, type, create));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriModelTypeRegistered(const char type[], PetscBool *found)
{
  PetscErrorCode (*create)(PeriModel) = NULL;

  PetscFunctionBeginUser;
  PetscCall(ModelFind(type, &create));
  *found = create ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriModelListTypes(char buf[], size_t len)
{
  PetscFunctionBeginUser;
  PetscCall(PeriFunctionListNames(PeriModelList, buf, len));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriModelCreate - creates the model registered as type for dim (2, 3) and plane kind. Not
  collective. Errors name the registered types when type is unknown. PeriInitializePackage must
  have run (PeriProblemCreate runs it).
@*/
PetscErrorCode PeriModelCreate(const char type[], PetscInt dim, PetscBool plane_strain, PeriModel *model)
{
  PetscErrorCode (*create)(PeriModel) = NULL;
  PeriModel      m;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(ModelFind(type, &create));
  if (!create) {
    char list[256];
    PetscCall(PeriModelListTypes(list, sizeof(list)));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "unknown model type '%s'; registered: %s", type, list);
  }
  PetscCall(PetscNew(&m));
  PetscCall(PetscStrncpy(m->type, type, sizeof(m->type)));
  m->dim                       = dim;
  m->plane_strain              = plane_strain;
  m->allows_surface_correction = PETSC_TRUE;
  /* a model may refuse the setting (pds in 3D): an input error, after which nothing may leak */
  ierr = (*create)(m);
  if (ierr) PetscCall(PeriModelDestroy(&m));
  PetscCall(ierr);
  *model = m;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriModelSetFromScene - reads material.* (E and nu, or K and nu; nu defaults to the model's only
  admissible value when it has one), the model's own keys, and the horizon delta. Not collective.
@*/
PetscErrorCode PeriModelSetFromScene(PeriModel m, PeriScene scene, PetscReal delta)
{
  static const char *const keys[] = {"E", "nu", "K", "mu", "rho", "rho_by_region", "mu_by_region", "thickness", NULL};
  PeriNode                 mat, node;
  PetscReal                lo, hi, E = 0, nu = 0, K = 0, mu = 0;
  PetscBool                hasE, hasnu, hasK, hasmu;

  PetscFunctionBeginUser;
  m->delta = delta;
  PetscCall(PeriSceneGetMap(scene, scene->root, "material", PETSC_TRUE, &mat));
  PetscCall(PeriSceneCheckKeys(scene, mat, keys));
  PetscCall(PeriSceneGetReal(scene, mat, "E", PETSC_FALSE, &E, &hasE));
  PetscCall(PeriSceneGetReal(scene, mat, "nu", PETSC_FALSE, &nu, &hasnu));
  PetscCall(PeriSceneGetReal(scene, mat, "K", PETSC_FALSE, &K, &hasK));
  PetscCall(PeriSceneGetReal(scene, mat, "mu", PETSC_FALSE, &mu, &hasmu));
  PeriInputCheck(hasE || hasK || hasmu, scene, mat, "E", "is required (or give the bulk modulus K or the shear modulus mu)");
  PeriInputCheck((hasE ? 1 : 0) + (hasK ? 1 : 0) + (hasmu ? 1 : 0) == 1, scene, mat, hasE ? (hasK ? "K" : "mu") : "mu", "give one of E, K and mu");
  PeriInputCheck(!hasE || E > 0, scene, mat, "E", "must be positive, got %g", (double)E);
  PeriInputCheck(!hasK || K > 0, scene, mat, "K", "must be positive, got %g", (double)K);
  PeriInputCheck(!hasmu || mu > 0, scene, mat, "mu", "must be positive, got %g", (double)mu);
  m->ops.nu_range(m, &lo, &hi);
  if (!hasnu) {
    /* antiplane models need only the shear modulus: nu is then irrelevant and taken as 0 */
    PeriInputCheck(lo == hi || m->antiplane, scene, mat, "nu", "is required by model %s (admissible range %g to %g)", m->type, (double)lo, (double)hi);
    nu = lo == hi ? lo : 0;
  } else if (lo == hi) {
    /* 0.333 means 1/3: bond-based models have one Poisson ratio, accept it to 3 digits */
    PeriInputCheck(PetscAbsReal(nu - lo) < 1e-3, scene, mat, "nu", "model %s in this setting has the fixed Poisson ratio %g; got %g (use a model with shear bonds for other values)", m->type, (double)lo, (double)nu);
    nu = lo;
  } else
    PeriInputCheck(nu >= lo && nu <= hi, scene, mat, "nu", "must lie in [%g, %g] for model %s, got %g", (double)lo, (double)hi, m->type, (double)nu);
  PeriInputCheck(nu > -1 && nu < 0.5, scene, mat, "nu", "must lie in (-1, 1/2), got %g", (double)nu);
  if (hasK) E = 3 * K * (1 - 2 * nu);
  if (hasmu) E = 2 * mu * (1 + nu);
  m->material.E   = E;
  m->material.nu  = nu;
  m->material.K   = E / (3 * (1 - 2 * nu));
  m->material.G   = E / (2 * (1 + nu));
  m->material.rho = 0;
  PetscCall(PeriSceneGetReal(scene, mat, "rho", PETSC_FALSE, &m->material.rho, NULL));
  PeriInputCheck(m->material.rho >= 0, scene, mat, "rho", "must not be negative");
  m->material.thickness = 1;
  PetscCall(PeriSceneGetReal(scene, mat, "thickness", PETSC_FALSE, &m->material.thickness, NULL));
  PeriInputCheck(m->material.thickness > 0, scene, mat, "thickness", "must be positive");
  PetscCall(PeriSceneGetNode(scene->root, "model", &node));
  if (m->ops.setfromscene) PetscCall(m->ops.setfromscene(m, scene, node));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriModelDestroy(PeriModel *m)
{
  PetscFunctionBeginUser;
  if (!*m) PetscFunctionReturn(PETSC_SUCCESS);
  if ((*m)->ops.destroy) PetscCall((*m)->ops.destroy(*m));
  PetscCall(PetscFree((*m)->data));
  PetscCall(PetscFree(*m));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriModelComponentIndex(PeriModel m, const char name[], PetscInt *c)
{
  PetscFunctionBeginUser;
  *c = -1;
  for (PetscInt k = 0; k < m->dofs; k++)
    if (!strcmp(m->components[k], name)) *c = k;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Strain energy density of the isotropic expansion u = s X, divided by s^2: 9K/2 in 3D,
 * E/(1-nu) in plane stress, E/((1+nu)(1-2nu)) in plane strain. Calibrations equate the
 * peridynamic energy density of that field with it. */
PetscReal PeriModelIsotropicEnergy(PeriModel m)
{
  const PeriMaterial *mt = &m->material;
  if (m->dim == 3) return 4.5 * mt->K;
  if (m->plane_strain) return mt->E / ((1 + mt->nu) * (1 - 2 * mt->nu));
  return mt->E / (1 - mt->nu);
}

/* integral of |xi|^p over the continuous horizon (per unit thickness times t in 2D) */
PetscReal PeriModelHorizonMoment(PeriModel m, PetscInt p)
{
  PetscReal d = m->delta;
  if (m->dim == 3) return 4 * PETSC_PI * PetscPowReal(d, p + 3) / (p + 3);
  return 2 * PETSC_PI * m->material.thickness * PetscPowReal(d, p + 2) / (p + 2);
}

/* k [e e^T, -e e^T; -e e^T, e e^T] on the translational DOFs (the first dim of the dofs),
 * e the bond's unit vector. */
void PeriCentralBondBlock(PeriModel m, const PeriBondGeometry *b, PetscReal k, PetscReal Ke[])
{
  const PetscInt dofs = m->dofs, n = 2 * dofs;
  for (PetscInt a = 0; a < n * n; a++) Ke[a] = 0;
  for (PetscInt a = 0; a < m->dim; a++)
    for (PetscInt c = 0; c < m->dim; c++) {
      PetscReal v                   = k * b->xi[a] * b->xi[c] / (b->length * b->length);
      Ke[a * n + c]                 = v;
      Ke[(a + dofs) * n + c + dofs] = v;
      Ke[a * n + c + dofs]          = -v;
      Ke[(a + dofs) * n + c]        = -v;
    }
}

/* K += k b b^T for a deformation measure h = b . u_e over the bond's 2 dofs DOFs. */
void PeriAddSpring(PetscInt n, const PetscReal b[], PetscReal k, PetscReal Ke[])
{
  for (PetscInt a = 0; a < n; a++)
    for (PetscInt c = 0; c < n; c++) Ke[a * n + c] += k * b[a] * b[c];
}

/* The 2D micromoduli of a bond with normal and shear springs, calibrated on an isotropic
 * expansion and a pure shear (Diana & Casolo eqs. 7 and 21): c = k_n, g = k_t. g = 0 at the
 * bond-based Poisson ratio, g < 0 above it. */
void PeriPlaneMicromoduli(PeriModel m, PetscReal *c, PetscReal *g)
{
  const PetscReal E = m->material.E, nu = m->material.nu, d3 = PetscPowReal(m->delta, 3), t = m->material.thickness;
  if (m->plane_strain) {
    *c = 6 * E / (PETSC_PI * t * d3 * (1 - 2 * nu) * (1 + nu));
    *g = 6 * E * (1 - 4 * nu) / (PETSC_PI * t * d3 * (1 - 2 * nu) * (1 + nu));
  } else {
    *c = 6 * E / (PETSC_PI * t * d3 * (1 - nu));
    *g = 6 * E * (1 - 3 * nu) / (PETSC_PI * t * d3 * (1 - nu * nu));
  }
  if (*g < 0) PetscSNPrintf(m->warning, sizeof(m->warning), "nu = %g is above the bond-based value %s: the shear springs are negative and the stiffness may be indefinite; if CG fails use -ksp_type preonly -pc_type lu", (double)nu, m->plane_strain ? "1/4" : "1/3");
}

/* Admissible Poisson ratios of 2D shear-bond models: where the plane elasticity they calibrate to
 * is positive definite. */
void PeriShearBondNuRange(PeriModel m, PetscReal *lo, PetscReal *hi)
{
  (void)m;
  *lo = -1 + 1e-6;
  *hi = 0.5 - 1e-6;
}

/* Critical stretch of a spring with pair energy c s^2 |xi| V_i V_j / 2 for the energy release rate G:
 * the energy of all bonds across a unit crack area at stretch s is G = c s^2 t delta^4 / 4 in 2D
 * and pi c s^2 delta^5 / 10 in 3D (Silling & Askari; Ha & Bobaru), so s_c = sqrt(4G/(c t delta^4))
 * (plane stress pmb: sqrt(4 pi G / (9 E delta))) and sqrt(10 G/(pi c delta^5)) = sqrt(5G/(9K delta)). */
PetscReal PeriCriticalStretchSpring(PeriModel m, PetscReal c, PetscReal G)
{
  if (m->dim == 3) return PetscSqrtReal(10 * G / (PETSC_PI * c * PetscPowReal(m->delta, 5)));
  return PetscSqrtReal(4 * G / (c * m->material.thickness * PetscPowReal(m->delta, 4)));
}

/* Linearized stretch s = e . (u_j - u_i) / |xi|. */
void PeriBondStretch(PeriModel m, const PeriBondGeometry *b, const PetscReal ui[], const PetscReal uj[], PetscReal s[])
{
  PetscReal t = 0;
  for (PetscInt d = 0; d < m->dim; d++) t += b->xi[d] * (uj[d] - ui[d]);
  s[0] = t / (b->length * b->length);
}

/* Central-force bond models have one Poisson ratio: 1/4 in 3D and plane strain, 1/3 in plane stress. */
void PeriBondBasedNuRange(PeriModel m, PetscReal *lo, PetscReal *hi)
{
  *lo = *hi = (m->dim == 2 && !m->plane_strain) ? 1.0 / 3.0 : 0.25;
}

/* The common part of central-force (bond-based) models: the dim displacements as DOFs, the
 * stretch as measure, the one bond-based Poisson ratio, translations and rotations as rigid modes. */
void PeriModelSetCentralForce(PeriModel m)
{
  static const char *const components2[] = {"ux", "uy"}, *const components3[] = {"ux", "uy", "uz"};
  static const char *const measures[] = {"stretch"};
  m->dofs                             = m->dim;
  m->components                       = m->dim == 2 ? components2 : components3;
  m->nmeasures                        = 1;
  m->measure_names                    = measures;
  m->ops.nu_range                     = PeriBondBasedNuRange;
  m->ops.bond_measures                = PeriBondStretch;
  m->ops.rigid_modes                  = PeriTranslationalRigidModes;
}

/* Translations, and rotations u = w x X, of models whose DOFs are the dim displacements. */
PetscInt PeriTranslationalRigidModes(PeriModel m, const PetscReal X[], PetscReal modes[][PERI_MAX_DOF])
{
  for (PetscInt k = 0; k < PERI_MAX_MODES; k++)
    for (PetscInt c = 0; c < PERI_MAX_DOF; c++) modes[k][c] = 0;
  for (PetscInt d = 0; d < m->dim; d++) modes[d][d] = 1;
  if (m->dim == 2) {
    modes[2][0] = -X[1];
    modes[2][1] = X[0];
    return 3;
  }
  /* rotations about x, y, z */
  modes[3][1] = -X[2];
  modes[3][2] = X[1];
  modes[4][0] = X[2];
  modes[4][2] = -X[0];
  modes[5][0] = -X[1];
  modes[5][1] = X[0];
  return 6;
}
