/* Exact plane elasticity fields a scene may name as its reference (reference: in the scene), and
 * the accuracy measures against them: the interior strain by least squares, the effective moduli
 * it implies, and the displacement error after removing the best-fit rigid motion. */
#include "perilin/private/system.h"

const char *const PeriReferenceTypes[] = {"none", "uniaxial", "shear", "bending", NULL};

static PetscBool Interior(PeriSystem, PetscInt);

static const char *const axes[]           = {"x", "y", NULL};
static const PeriKey     reference_keys[] = {
        {"type", PERI_KEY_CHOICE, "required", NULL, NULL, PeriReferenceTypes + 1, "the exact plane field to compare with"},
        {"stress", PERI_KEY_REAL, "required", NULL, "[stress]", NULL, "its stress: sigma (uniaxial), tau (shear), the extreme fibre stress (bending)"},
        {"axis", PERI_KEY_CHOICE, "x", NULL, NULL, axes, "uniaxial: the loaded axis"},
        {"center", PERI_KEY_REALS, "the centre of the bounding box", NULL, "[length]", NULL, "2 numbers: the point where the reference field has no displacement, and the origin of the fits"},
        {"E", PERI_KEY_REAL, "material.E", "(0, inf)", "[stress]", NULL, "Young's modulus of the reference solution"},
        {"nu", PERI_KEY_REAL, "material.nu", "(-1, 1/2)", NULL, NULL, "Poisson ratio of the reference solution"},
        {NULL},
};
const PeriSchema PeriReferenceSchema[] = {{"reference", reference_keys}, {NULL}};

PetscErrorCode PeriReferenceSetUp(PeriSystem sys)
{
  PeriScene      s = sys->scene;
  PeriReference *r = &sys->reference;
  PeriNode       node;
  PetscInt       type = PERI_REFERENCE_NONE, n, ux, uy, ninterior = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "reference", PETSC_FALSE, &node));
  r->type = PERI_REFERENCE_NONE;
  if (!node) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneCheckSection(s, node, "reference"));
  PeriInputCheck(sys->disc.particles.dim == 2, s, node, NULL, "reference fields are plane elasticity solutions: dim must be 2");
  PetscCall(PeriModelComponentIndex(sys->model, "ux", &ux));
  PetscCall(PeriModelComponentIndex(sys->model, "uy", &uy));
  /* checked here, not only after the solve, so that a bad scene fails before any work */
  PeriInputCheck(ux >= 0 && uy >= 0, s, node, NULL, "reference fields need the in-plane displacements ux, uy; model %s has none", sys->model->type);
  PetscCall(PeriSceneGetChoice(s, node, "type", PeriReferenceTypes, &type, NULL));
  PeriInputCheck(type != PERI_REFERENCE_NONE, s, node, "type", "is required: uniaxial, shear or bending");
  r->type = (PeriReferenceType)type;
  PetscCall(PeriSceneGetReal(s, node, "stress", PETSC_TRUE, &r->stress, NULL));
  PeriInputCheck(r->stress != 0, s, node, "stress", "must not be 0: the reference field would vanish and there is nothing to compare with");
  for (PetscInt i = 0; i < sys->disc.particles.n; i++) ninterior += Interior(sys, i);
  PeriInputCheck(ninterior >= 3, s, node, NULL, "only %" PetscInt_FMT " particles lie farther than 2 delta = %g from the edges: too few to measure the interior strain (enlarge the body or reduce the horizon)", ninterior, (double)(2 * sys->disc.delta));
  r->axis = 0;
  PetscCall(PeriSceneGetChoice(s, node, "axis", axes, &r->axis, NULL));
  for (PetscInt d = 0; d < 3; d++) r->center[d] = 0.5 * (sys->disc.particles.lower[d] + sys->disc.particles.upper[d]);
  PetscCall(PeriSceneGetRealArray(s, node, "center", PETSC_FALSE, 2, 2, r->center, &n));
  r->E  = sys->model->material.E;
  r->nu = sys->model->material.nu;
  PetscCall(PeriSceneGetReal(s, node, "E", PETSC_FALSE, &r->E, NULL));
  PetscCall(PeriSceneGetReal(s, node, "nu", PETSC_FALSE, &r->nu, NULL));
  PeriInputCheck(r->E > 0, s, node, "E", "must be positive");
  PeriInputCheck(r->nu > -1 && r->nu < 0.5, s, node, "nu", "must lie in (-1, 1/2)");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Plane strain is plane stress with E' = E/(1-nu^2), nu' = nu/(1-nu). */
static void PlaneConstants(PeriSystem sys, PetscReal *E, PetscReal *nu)
{
  const PeriReference *r = &sys->reference;
  *E                     = sys->model->plane_strain ? r->E / (1 - r->nu * r->nu) : r->E;
  *nu                    = sys->model->plane_strain ? r->nu / (1 - r->nu) : r->nu;
}

/* The exact displacement at X (up to a rigid motion):
 *   uniaxial along a: e_aa = sigma/E, e_bb = -nu sigma/E;   shear: gamma_xy = tau/G, no rotation;
 *   bending by end moments on the x faces, fibre stress sigma at y' = +-h (h half the height):
 *   u_x = k x'y', u_y = -k (x'^2 + nu y'^2)/2, k = sigma/(E h). */
void PeriReferenceDisplacement(PeriSystem sys, const PetscReal X[], PetscReal u[])
{
  const PeriReference *r = &sys->reference;
  PetscReal            E, nu, x = X[0] - r->center[0], y = X[1] - r->center[1], e, k;
  PlaneConstants(sys, &E, &nu);
  switch (r->type) {
  case PERI_REFERENCE_UNIAXIAL:
    e    = r->stress / E;
    u[0] = (r->axis == 0 ? e : -nu * e) * x;
    u[1] = (r->axis == 1 ? e : -nu * e) * y;
    break;
  case PERI_REFERENCE_SHEAR:
    e    = r->stress * (1 + nu) / E; /* gamma / 2 = tau / (2 G) */
    u[0] = e * y;
    u[1] = e * x;
    break;
  case PERI_REFERENCE_BENDING:
    k    = r->stress / (E * 0.5 * (sys->disc.particles.upper[1] - sys->disc.particles.lower[1]));
    u[0] = k * x * y;
    u[1] = -0.5 * k * (x * x + nu * y * y);
    break;
  default:
    u[0] = u[1] = 0;
  }
}

/* Solves the n x n system A z = b (n <= 3) by Gaussian elimination with partial pivoting. */
static PetscErrorCode SmallSolve(PetscInt n, PetscReal A[3][3], PetscReal b[3])
{
  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < n; c++) {
    PetscInt piv = c;
    for (PetscInt r = c + 1; r < n; r++)
      if (PetscAbsReal(A[r][c]) > PetscAbsReal(A[piv][c])) piv = r;
    PetscCheck(A[piv][c] != 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "too few interior particles for the least-squares fit: enlarge the body or reduce the horizon");
    for (PetscInt k = 0; k < n; k++) {
      PetscReal t = A[c][k];
      A[c][k]     = A[piv][k];
      A[piv][k]   = t;
    }
    {
      PetscReal t = b[c];
      b[c]        = b[piv];
      b[piv]      = t;
    }
    for (PetscInt r = c + 1; r < n; r++) {
      PetscReal f = A[r][c] / A[c][c];
      for (PetscInt k = c; k < n; k++) A[r][k] -= f * A[c][k];
      b[r] -= f * b[c];
    }
  }
  for (PetscInt c = n - 1; c >= 0; c--) {
    for (PetscInt k = c + 1; k < n; k++) b[c] -= A[c][k] * b[k];
    b[c] /= A[c][c];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscBool Interior(PeriSystem sys, PetscInt i)
{
  for (PetscInt d = 0; d < sys->disc.particles.dim; d++) {
    PetscReal x = sys->disc.particles.x[3 * i + d];
    if (!sys->disc.particles.periodic[d] && (x - sys->disc.particles.lower[d] < 2 * sys->disc.delta || sys->disc.particles.upper[d] - x < 2 * sys->disc.delta)) return PETSC_FALSE;
  }
  return PETSC_TRUE;
}

/*@C
  PeriReferenceEvaluate - on rank 0, from sys->u_all: the interior strain (least-squares displacement
  gradient over the particles farther than 2 delta from every edge), the effective moduli it
  implies for the reference's stress state, and the interior displacement error against the
  reference after removing the best-fit rigid motion. Not collective.
@*/
PetscErrorCode PeriReferenceEvaluate(PeriSystem sys)
{
  const PetscInt   bs      = sys->model->dofs;
  const PetscReal *c       = sys->reference.center;
  PetscReal        A[3][3] = {{0}}, bx[3] = {0, 0, 0}, by[3] = {0, 0, 0}, R[3][3] = {{0}}, br[3] = {0, 0, 0};
  PetscReal        num = 0, den = 0, dmax = 0, umax = 0;
  PetscInt         n = 0, ux, uy;

  PetscFunctionBeginUser;
  sys->reference.evaluated = PETSC_FALSE;
  if (sys->rank || sys->reference.type == PERI_REFERENCE_NONE) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriModelComponentIndex(sys->model, "ux", &ux));
  PetscCall(PeriModelComponentIndex(sys->model, "uy", &uy));
  PetscCheck(ux >= 0 && uy >= 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "reference fields need the in-plane displacements ux, uy; model %s has none", sys->model->type);
  /* least squares u = a + H x' for each component, and the rigid fit of the error */
  for (PetscInt i = 0; i < sys->disc.particles.n; i++) {
    const PetscReal *X = &sys->disc.particles.x[3 * i], *u = &sys->u_all[i * bs];
    PetscReal        phi[3] = {1, X[0] - c[0], X[1] - c[1]}, ref[2], d[2], rig[3][2];
    if (!Interior(sys, i)) continue;
    n++;
    PeriReferenceDisplacement(sys, X, ref);
    d[0] = u[ux] - ref[0];
    d[1] = u[uy] - ref[1];
    /* rigid motion basis: (1,0), (0,1), (-y', x') */
    rig[0][0] = 1, rig[0][1] = 0, rig[1][0] = 0, rig[1][1] = 1, rig[2][0] = -phi[2], rig[2][1] = phi[1];
    for (PetscInt a = 0; a < 3; a++) {
      bx[a] += phi[a] * u[ux];
      by[a] += phi[a] * u[uy];
      br[a] += rig[a][0] * d[0] + rig[a][1] * d[1];
      for (PetscInt b = 0; b < 3; b++) {
        A[a][b] += phi[a] * phi[b];
        R[a][b] += rig[a][0] * rig[b][0] + rig[a][1] * rig[b][1];
      }
    }
  }
  PetscCheck(n >= 3, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: only %" PetscInt_FMT " particles lie farther than 2 delta from the edges: too few to measure the interior strain", sys->scene->file, n);
  {
    PetscReal A2[3][3];
    PetscCall(PetscArraycpy(&A2[0][0], &A[0][0], 9));
    PetscCall(SmallSolve(3, A, bx));
    PetscCall(SmallSolve(3, A2, by));
    PetscCall(SmallSolve(3, R, br));
  }
  sys->reference.interior_particles = n;
  sys->reference.interior_strain[0] = bx[1];
  sys->reference.interior_strain[1] = by[2];
  sys->reference.interior_strain[2] = bx[2] + by[1];
  for (PetscInt i = 0; i < sys->disc.particles.n; i++) {
    const PetscReal *X = &sys->disc.particles.x[3 * i], *u = &sys->u_all[i * bs];
    PetscReal        ref[2], e[2];
    if (!Interior(sys, i)) continue;
    PeriReferenceDisplacement(sys, X, ref);
    e[0] = u[ux] - ref[0] - (br[0] - br[2] * (X[1] - c[1]));
    e[1] = u[uy] - ref[1] - (br[1] + br[2] * (X[0] - c[0]));
    num += e[0] * e[0] + e[1] * e[1];
    den += ref[0] * ref[0] + ref[1] * ref[1];
    dmax = PetscMax(dmax, PetscSqrtReal(e[0] * e[0] + e[1] * e[1]));
    umax = PetscMax(umax, PetscSqrtReal(ref[0] * ref[0] + ref[1] * ref[1]));
  }
  PetscCheck(den > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: the reference field vanishes on the interior particles (reference.stress = 0?)", sys->scene->file);
  sys->reference.error_l2_rel  = PetscSqrtReal(num / den);
  sys->reference.error_max_rel = dmax / umax;
  sys->reference.effective_E = sys->reference.effective_nu = sys->reference.effective_G = 0;
  if (sys->reference.type == PERI_REFERENCE_UNIAXIAL) {
    PetscInt  a  = sys->reference.axis;
    PetscReal ea = sys->reference.interior_strain[a], eb = sys->reference.interior_strain[1 - a];
    sys->reference.effective_E  = sys->reference.stress / ea;
    sys->reference.effective_nu = -eb / ea;
  } else if (sys->reference.type == PERI_REFERENCE_SHEAR)
    sys->reference.effective_G = sys->reference.stress / sys->reference.interior_strain[2];
  sys->reference.evaluated = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Against reference.*: interior strain, effective moduli, errors. */
PetscErrorCode PeriReferenceSummary(PeriSystem sys, PeriJSON j)
{

  PetscFunctionBeginUser;
  if (!sys->reference.evaluated) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "reference"));
  PetscCall(PeriJSONString(j, "type", PeriReferenceTypes[sys->reference.type]));
  PetscCall(PeriJSONReal(j, "stress", sys->reference.stress));
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PeriJSONInt(j, "interior_particles", sys->reference.interior_particles));
  PetscCall(PeriJSONRealArray(j, "interior_strain", 3, sys->reference.interior_strain));
  PetscCall(PeriJSONBeginObject(j, "effective"));
  if (sys->reference.effective_E != 0) PetscCall(PeriJSONReal(j, "E", sys->reference.effective_E));
  if (sys->reference.effective_E != 0) PetscCall(PeriJSONReal(j, "nu", sys->reference.effective_nu));
  if (sys->reference.effective_G != 0) PetscCall(PeriJSONReal(j, "G", sys->reference.effective_G));
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PeriJSONBeginObject(j, "error"));
  PetscCall(PeriJSONReal(j, "l2_rel", sys->reference.error_l2_rel));
  PetscCall(PeriJSONReal(j, "max_rel", sys->reference.error_max_rel));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}
