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
  ux = PeriModelTranslation(sys->model, 0);
  uy = PeriModelTranslation(sys->model, 1);
  /* checked here, not only after the solve, so that a bad scene fails before any work */
  PeriInputCheck(ux >= 0 && uy >= 0, s, node, NULL, "reference fields need the in-plane displacements ux, uy; model %s has none", sys->model->type);
  PetscCall(PeriSceneGetChoice(s, node, "type", PeriReferenceTypes, &type, NULL));
  PeriInputCheck(type != PERI_REFERENCE_NONE, s, node, "type", "is required: uniaxial, shear or bending");
  r->type = (PeriReferenceType)type;
  PetscCall(PeriSceneGetReal(s, node, "stress", PETSC_TRUE, &r->stress, NULL));
  PeriInputCheck(r->stress != 0, s, node, "stress", "must not be 0: the reference field would vanish and there is nothing to compare with");
  for (PetscInt i = 0; i < sys->disc.nowned; i++) ninterior += Interior(sys, i);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &ninterior, 1, MPIU_INT, MPI_SUM, sys->comm));
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

/* The least-squares sums over the owned interior particles, then over the ranks: u = a + H x' for
 * each component (A, bx, by) and the rigid fit of the error (R, br). Collective. */
typedef struct {
  PetscReal A[3][3], bx[3], by[3], R[3][3], br[3], n;
} FitSums;

static PetscErrorCode InteriorFit(PeriSystem sys, PetscInt ux, PetscInt uy, FitSums *F)
{
  const PetscInt   bs = sys->model->dofs;
  const PetscReal *c  = sys->reference.center;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(F, sizeof(*F)));
  for (PetscInt i = 0; i < sys->disc.nowned; i++) {
    const PetscReal *X = &sys->disc.particles.x[3 * i], *u = &sys->fields.u_owned[i * bs];
    PetscReal        phi[3] = {1, X[0] - c[0], X[1] - c[1]}, ref[2], d[2], rig[3][2];
    if (!Interior(sys, i)) continue;
    F->n++;
    PeriReferenceDisplacement(sys, X, ref);
    d[0] = u[ux] - ref[0];
    d[1] = u[uy] - ref[1];
    /* rigid motion basis: (1,0), (0,1), (-y', x') */
    rig[0][0] = 1, rig[0][1] = 0, rig[1][0] = 0, rig[1][1] = 1, rig[2][0] = -phi[2], rig[2][1] = phi[1];
    for (PetscInt a = 0; a < 3; a++) {
      F->bx[a] += phi[a] * u[ux];
      F->by[a] += phi[a] * u[uy];
      F->br[a] += rig[a][0] * d[0] + rig[a][1] * d[1];
      for (PetscInt b = 0; b < 3; b++) {
        F->A[a][b] += phi[a] * phi[b];
        F->R[a][b] += rig[a][0] * rig[b][0] + rig[a][1] * rig[b][1];
      }
    }
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, F, (PetscMPIInt)(sizeof(*F) / sizeof(PetscReal)), MPIU_REAL, MPI_SUM, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The interior displacement error after the rigid fit br: sums of |e|^2 and |ref|^2 and the largest
 * |e| and |ref|, over the ranks. Collective. */
static PetscErrorCode InteriorError(PeriSystem sys, PetscInt ux, PetscInt uy, const PetscReal br[], PetscReal err[4])
{
  const PetscInt   bs = sys->model->dofs;
  const PetscReal *c  = sys->reference.center;

  PetscFunctionBeginUser;
  err[0] = err[1] = err[2] = err[3] = 0;
  for (PetscInt i = 0; i < sys->disc.nowned; i++) {
    const PetscReal *X = &sys->disc.particles.x[3 * i], *u = &sys->fields.u_owned[i * bs];
    PetscReal        ref[2], e[2];
    if (!Interior(sys, i)) continue;
    PeriReferenceDisplacement(sys, X, ref);
    e[0] = u[ux] - ref[0] - (br[0] - br[2] * (X[1] - c[1]));
    e[1] = u[uy] - ref[1] - (br[1] + br[2] * (X[0] - c[0]));
    err[0] += e[0] * e[0] + e[1] * e[1];
    err[1] += ref[0] * ref[0] + ref[1] * ref[1];
    err[2] = PetscMax(err[2], PetscSqrtReal(e[0] * e[0] + e[1] * e[1]));
    err[3] = PetscMax(err[3], PetscSqrtReal(ref[0] * ref[0] + ref[1] * ref[1]));
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, err, 2, MPIU_REAL, MPI_SUM, sys->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, err + 2, 2, MPIU_REAL, MPI_MAX, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriReferenceEvaluate - from the owned particles' DOFs (u_owned) of every rank: the interior
  strain (least-squares displacement gradient over the particles farther than 2 delta from every
  edge), the effective moduli it implies for the reference's stress state, and the interior
  displacement error against the reference after removing the best-fit rigid motion. Collective.
@*/
PetscErrorCode PeriReferenceEvaluate(PeriSystem sys)
{
  PeriReference *r = &sys->reference;
  FitSums        F;
  PetscReal      err[4];
  PetscInt       ux, uy;

  PetscFunctionBeginUser;
  r->evaluated = PETSC_FALSE;
  if (r->type == PERI_REFERENCE_NONE) PetscFunctionReturn(PETSC_SUCCESS);
  ux = PeriModelTranslation(sys->model, 0);
  uy = PeriModelTranslation(sys->model, 1);
  PetscCheck(ux >= 0 && uy >= 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "reference fields need the in-plane displacements ux, uy; model %s has none", sys->model->type);
  PetscCall(InteriorFit(sys, ux, uy, &F));
  PetscCheck(F.n >= 3, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: only %" PetscInt_FMT " particles lie farther than 2 delta from the edges: too few to measure the interior strain", sys->scene->file, (PetscInt)F.n);
  {
    PetscReal A2[3][3];
    PetscCall(PetscArraycpy(&A2[0][0], &F.A[0][0], 9));
    PetscCall(SmallSolve(3, F.A, F.bx));
    PetscCall(SmallSolve(3, A2, F.by));
    PetscCall(SmallSolve(3, F.R, F.br));
  }
  r->interior_particles = (PetscInt)F.n;
  r->interior_strain[0] = F.bx[1];
  r->interior_strain[1] = F.by[2];
  r->interior_strain[2] = F.bx[2] + F.by[1];
  PetscCall(InteriorError(sys, ux, uy, F.br, err));
  PetscCheck(err[1] > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: the reference field vanishes on the interior particles (reference.stress = 0?)", sys->scene->file);
  r->error_l2_rel  = PetscSqrtReal(err[0] / err[1]);
  r->error_max_rel = err[2] / err[3];
  r->effective_E = r->effective_nu = r->effective_G = 0;
  if (r->type == PERI_REFERENCE_UNIAXIAL) {
    PetscInt  a  = r->axis;
    PetscReal ea = r->interior_strain[a], eb = r->interior_strain[1 - a];
    r->effective_E  = r->stress / ea;
    r->effective_nu = -eb / ea;
  } else if (r->type == PERI_REFERENCE_SHEAR)
    r->effective_G = r->stress / r->interior_strain[2];
  r->evaluated = PETSC_TRUE;
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
