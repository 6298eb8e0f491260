/* Kernels shared by the bond models (include/perilin/model.h): central-force blocks, springs,
 * plane micromoduli, critical stretch, rigid modes. A model file may call these; nothing here
 * knows a model type. */
#include <perilin/model.h>

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

/* integral of |xi|^p over the continuous horizon of radius d (per unit thickness times t in 2D) */
PetscReal PeriModelHorizonMomentAt(PeriModel m, PetscInt p, PetscReal d)
{
  if (m->dim == 3) return 4 * PETSC_PI * PetscPowReal(d, p + 3) / (p + 3);
  return 2 * PETSC_PI * m->material.thickness * PetscPowReal(d, p + 2) / (p + 2);
}

/* ... of the model's horizon */
PetscReal PeriModelHorizonMoment(PeriModel m, PetscInt p)
{
  return PeriModelHorizonMomentAt(m, p, m->delta);
}

/* The horizon a bond's constants refer to: the model's, or with per-particle horizons the mean of
 * its two ends' (the constants c_ij are the mean of the ends' c_i, Diehl & Schweitzer). */
PetscReal PeriModelBondHorizon(PeriModel m, const PeriBondGeometry *b)
{
  return m->horizon ? 0.5 * (m->horizon[b->i] + m->horizon[b->j]) : m->delta;
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
 * (plane stress pmb: sqrt(4 pi G / (9 E delta))) and sqrt(10 G/(pi c delta^5)) = sqrt(5G/(9K delta)),
 * delta the bond's (PeriModelBondHorizon). */
PetscReal PeriCriticalStretchSpring(PeriModel m, const PeriBondGeometry *b, PetscReal c, PetscReal G)
{
  const PetscReal d = PeriModelBondHorizon(m, b);
  if (m->dim == 3) return PetscSqrtReal(10 * G / (PETSC_PI * c * PetscPowRealInt(d, 5)));
  return PetscSqrtReal(4 * G / (c * m->material.thickness * PetscPowRealInt(d, 4)));
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

static const PeriMeasureKind central_kinds[] = {PERI_MEASURE_STRETCH};

/* The common part of central-force (bond-based) models: the dim displacements as DOFs, the
 * stretch as measure, the one bond-based Poisson ratio, translations and rotations as rigid modes. */
void PeriModelSetCentralForce(PeriModel m)
{
  static const char *const components2[] = {"ux", "uy"}, *const components3[] = {"ux", "uy", "uz"};
  static const char *const measures[] = {"stretch"};
  m->dofs                             = m->dim;
  m->components                       = m->dim == 2 ? components2 : components3;
  for (PetscInt d = 0; d < m->dim; d++) m->axis[d] = d;
  m->nmeasures         = 1;
  m->measure_names     = measures;
  m->measure_kinds     = central_kinds;
  m->ops.nu_range      = PeriBondBasedNuRange;
  m->ops.bond_measures = PeriBondStretch;
  m->ops.rigid_modes   = PeriTranslationalRigidModes;
  m->central_force     = PETSC_TRUE;
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

/* Length profiles of springs for the lattice calibration (PeriLatticeCreate): the factor of |xi|
 * in a spring's pair energy per unit V_i V_j (measure)^2 / 2. */
PetscReal PeriProfileLength(PeriModel m, PetscReal L)
{
  (void)m;
  return L;
}

PetscReal PeriProfileOne(PeriModel m, PetscReal L)
{
  (void)m;
  (void)L;
  return 1;
}
