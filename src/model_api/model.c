/* The model interface: registry by name (PetscFunctionList), material constants from the scene,
 * and the pieces several bond models share. Assembly and analyses call models only through
 * PeriModelOps. */
#include "perilin/private/model_registry.h"

static PetscFunctionList PeriModelList = NULL;

const char *const PeriCalibrationKinds[] = {"continuum", "lattice", "patch", NULL};

/* Run by PetscFinalize: frees the list, as PETSc's own packages do (src/model_api/model_registry.c forgets on
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
  for (PetscInt c = 0; c < PERI_MAX_DOF; c++) m->axis[c] = -1; /* the model declares its translations */
  /* a model may refuse the setting (pds in 3D): an input error, after which nothing may leak */
  ierr = (*create)(m);
  if (ierr) PetscCall(PeriModelDestroy(&m));
  PetscCall(ierr);
  *model = m;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* material.*: rho_by_region is read by the modal analysis, but declared here to keep the order of
 * "allowed here". */
static const PeriKey material_keys[] = {
    {"E", PERI_KEY_REAL, NULL, "(0, inf)", "[stress]", NULL, "Young's modulus; give exactly one of E, K and mu"},
    {"nu", PERI_KEY_REAL, "the model's fixed value", NULL, NULL, NULL, "Poisson ratio: pmb/npmb only 1/3 (plane stress) or 1/4 (plane strain, 3D); pds/mppd/gerstle (2D) and lps (2D, 3D) in (-1, 1/2)"},
    {"K", PERI_KEY_REAL, NULL, "(0, inf)", "[stress]", NULL, "3D bulk modulus, instead of E: E = 3 K (1 - 2 nu)"},
    {"mu", PERI_KEY_REAL, NULL, "(0, inf)", "[stress]", NULL, "shear modulus, instead of E: E = 2 mu (1 + nu) (the cross-section models need only mu)"},
    {"rho", PERI_KEY_REAL, "0", "[0, inf)", "[mass/volume]", NULL, "density; the modal analysis requires > 0"},
    {"rho_by_region", PERI_KEY_MAP, NULL, NULL, "[mass/volume]", NULL, "modal only: map region -> density (> 0), replacing rho there (later entries win)"},
    {"mu_by_region", PERI_KEY_MAP, NULL, NULL, "[stress]", NULL, "antiplane models: map region -> shear modulus (> 0) there (later entries win; interfaces: eq. 60)"},
    {"thickness", PERI_KEY_REAL, "1", "(0, inf)", "[length]", NULL, "2D thickness (ignored in 3D); for antiplane models the bar length"},
    {NULL},
};
const PeriSchema PeriMaterialSchema[] = {{"material", material_keys}, {NULL}};

/*@C
  PeriModelSetFromScene - reads material.* (E and nu, or K and nu; nu defaults to the model's only
  admissible value when it has one), the model's own keys, and the horizon delta. Not collective.
@*/
PetscErrorCode PeriModelSetFromScene(PeriModel m, PeriScene scene, PetscReal delta)
{
  PeriNode  mat, node;
  PetscReal lo, hi, E = 0, nu = 0, K = 0, mu = 0;
  PetscBool hasE, hasnu, hasK, hasmu;

  PetscFunctionBeginUser;
  m->delta = delta;
  PetscCall(PeriSceneGetMap(scene, scene->root, "material", PETSC_TRUE, &mat));
  PetscCall(PeriSceneCheckSection(scene, mat, "material"));
  PetscCall(PeriSceneGetReal(scene, mat, "E", PETSC_FALSE, &E, &hasE));
  PetscCall(PeriSceneGetReal(scene, mat, "nu", PETSC_FALSE, &nu, &hasnu));
  PetscCall(PeriSceneGetReal(scene, mat, "K", PETSC_FALSE, &K, &hasK));
  PetscCall(PeriSceneGetReal(scene, mat, "mu", PETSC_FALSE, &mu, &hasmu));
  PeriInputCheck(hasE || hasK || hasmu, scene, mat, "E", "is required (or give the bulk modulus K or the shear modulus mu)");
  PeriInputCheck((hasE ? 1 : 0) + (hasK ? 1 : 0) + (hasmu ? 1 : 0) == 1, scene, mat, hasE ? (hasK ? "K" : "mu") : "mu", "give one of E, K and mu");
  m->ops.nu_range(m, &lo, &hi);
  if (!hasnu) {
    /* an out-of-plane field needs only the shear modulus: nu is then irrelevant and taken as 0 */
    PeriInputCheck(lo == hi || PeriModelOutOfPlane(m), scene, mat, "nu", "is required by model %s (admissible range %g to %g)", m->type, (double)lo, (double)hi);
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
  m->material.E  = E;
  m->material.nu = nu;
  m->material.K  = E / (3 * (1 - 2 * nu));
  m->material.G  = E / (2 * (1 + nu));
  PetscCall(PeriSceneGetReal(scene, mat, "rho", PETSC_FALSE, &m->material.rho, NULL));
  PetscCall(PeriSceneGetReal(scene, mat, "thickness", PETSC_FALSE, &m->material.thickness, NULL));
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

/* The component that translates along axis d (0, 1, 2), or -1 when the model has none. */
PetscInt PeriModelTranslation(PeriModel m, PetscInt d)
{
  for (PetscInt c = 0; c < m->dofs; c++)
    if (m->axis[c] == d) return c;
  return -1;
}

/* Whether the model's field is the displacement normal to a 2D body, as its DOFs declare it (one
 * translation, along z): antiplane shear and the torsion of a cross-section. Such a field needs
 * the shear modulus only, takes fictitious layers and a twist, and its stress is the shear vector
 * (tau_xz, tau_yz). */
PetscBool PeriModelOutOfPlane(PeriModel m)
{
  return (PetscBool)(m->dim == 2 && m->dofs == 1 && m->axis[0] == 2);
}

/* Whether the model translates along every axis of the body: a stress tensor is then defined. */
PetscBool PeriModelInPlane(PeriModel m)
{
  for (PetscInt d = 0; d < m->dim; d++)
    if (PeriModelTranslation(m, d) < 0) return PETSC_FALSE;
  return PETSC_TRUE;
}

/*@C
  PeriModelMeasureIndex - the index of the model's bond measure of the given kind (its place in
  what ops.bond_measures writes), or -1 when the model has none. Not collective.
@*/
PetscInt PeriModelMeasureIndex(PeriModel m, PeriMeasureKind kind)
{
  for (PetscInt k = 0; k < m->nmeasures; k++)
    if (m->measure_kinds && m->measure_kinds[k] == kind) return k;
  return -1;
}
