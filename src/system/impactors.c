/* Rigid impactors in penalty contact with the body (include/perilin/private/contact.h;
 * docs/contact.md): impactors.<k> read, each particle's depth inside one, the forces both ways,
 * and the impactor's motion by velocity Verlet with the body's step. */
#include "perilin/private/system.h"
#include "perilin/private/contact.h"

const char *const PeriImpactorShapes[] = {"sphere", "cylinder", "punch", NULL};

static PetscReal Dot(const PetscReal a[3], const PetscReal b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* A direction key (cylinder axis, punch normal) as a unit vector; a zero vector is refused. */
static PetscErrorCode ReadDirection(PeriScene s, PeriNode item, const char key[], PetscInt dim, PetscReal a[3])
{
  PetscInt  n;
  PetscReal norm;

  PetscFunctionBeginUser;
  a[0] = a[1] = a[2] = 0;
  PetscCall(PeriSceneGetRealArray(s, item, key, PETSC_TRUE, dim, dim, a, &n));
  norm = PetscSqrtReal(Dot(a, a));
  PeriInputCheck(norm > 0, s, item, key, "a direction cannot be the zero vector");
  for (PetscInt d = 0; d < 3; d++) a[d] /= norm;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The shape's own keys: a cylinder's axis and length (3D; in 2D a cylinder is a disc, as a
 * sphere), a punch's normal. */
static PetscErrorCode ReadShape(PeriSystem sys, PeriNode item, PeriImpactor *imp)
{
  PeriScene      s   = sys->scene;
  const PetscInt dim = sys->disc.particles.dim;
  char           shape[16];
  PetscBool      found;
  PetscInt       k;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetString(s, item, "shape", PETSC_TRUE, shape, sizeof(shape), NULL));
  PetscCall(PetscEListFind(3, PeriImpactorShapes, shape, &k, &found));
  PeriInputCheck(found, s, item, "shape", "'%s' is no impactor shape: sphere, cylinder or punch", shape);
  imp->shape = (PeriImpactorShape)k;
  if (imp->shape == PERI_IMPACTOR_CYLINDER && dim == 3) {
    PetscCall(ReadDirection(s, item, "axis", dim, imp->axis));
    PetscCall(PeriSceneGetReal(s, item, "length", PETSC_TRUE, &imp->length, NULL));
  } else {
    PeriNode extra;
    PetscCall(PeriSceneGetNode(item, "axis", &extra));
    PeriInputCheck(!extra, s, item, "axis", "only a cylinder in 3D has an axis (in 2D a cylinder is a disc)");
    PetscCall(PeriSceneGetNode(item, "length", &extra));
    PeriInputCheck(!extra, s, item, "length", "only a cylinder in 3D has a length");
  }
  if (imp->shape == PERI_IMPACTOR_PUNCH)
    PetscCall(ReadDirection(s, item, "normal", dim, imp->axis));
  else {
    PeriNode extra;
    PetscCall(PeriSceneGetNode(item, "normal", &extra));
    PeriInputCheck(!extra, s, item, "normal", "only a punch has a normal");
  }
  PetscCall(PetscStrcmp(shape, "cylinder", &found));
  if (found && dim == 2) imp->shape = PERI_IMPACTOR_SPHERE; /* a disc */
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ReadImpactor(PeriSystem sys, PeriNode item, PeriImpactor *imp)
{
  PeriScene      s   = sys->scene;
  const PetscInt dim = sys->disc.particles.dim;
  PetscInt       n;

  PetscFunctionBeginUser;
  PeriInputCheck(item->kind == PERI_NODE_MAP, s, item, NULL, "an impactor is a map {shape, center, radius, mass, velocity, ...}");
  PetscCall(PeriSceneCheckSection(s, item, "impactors.<k>"));
  PetscCall(PetscMemzero(imp, sizeof(*imp)));
  PetscCall(ReadShape(sys, item, imp));
  PetscCall(PeriSceneGetRealArray(s, item, "center", PETSC_TRUE, dim, dim, imp->x0, &n));
  PetscCall(PeriSceneGetRealArray(s, item, "velocity", PETSC_TRUE, dim, dim, imp->v0, &n));
  PetscCall(PeriSceneGetReal(s, item, "radius", PETSC_TRUE, &imp->radius, NULL));
  PetscCall(PeriSceneGetReal(s, item, "mass", PETSC_TRUE, &imp->mass, NULL));
  imp->k = sys->contact.k;
  PetscCall(PeriSceneGetReal(s, item, "stiffness", PETSC_FALSE, &imp->k, NULL));
  PetscCall(PetscArraycpy(imp->x, imp->x0, 3));
  PetscCall(PetscArraycpy(imp->v, imp->v0, 3));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The depth p of a point inside a solid and the normal n of the nearest face, given the depths
 * below each face (p_k > 0 inside) and the faces' normals: the smallest depth wins, so that p falls
 * continuously to 0 at every face and a particle is pushed out through the nearest one. */
static PetscReal Nearest(PetscInt nf, const PetscReal depth[], const PetscReal normal[][3], PetscReal n[3])
{
  PetscInt best = 0;

  for (PetscInt k = 0; k < nf; k++) {
    if (depth[k] <= 0) return 0;
    if (depth[k] < depth[best]) best = k;
  }
  for (PetscInt d = 0; d < 3; d++) n[d] = normal[best][d];
  return depth[best];
}

/* How deep the point y lies inside imp (centre x), and the normal of the face it is pushed out
 * through (from the impactor into the body); 0 outside. A punch is a solid cylinder (a rectangle
 * in 2D) of the face's radius behind the face, one radius deep; a cylinder has its end caps. */
static PetscReal Depth(const PeriImpactor *imp, const PetscReal x[3], const PetscReal y[3], PetscReal n[3])
{
  PetscReal w[3], s = 0, r, depth[3], normal[3][3];
  PetscInt  nf = 1;

  for (PetscInt d = 0; d < 3; d++) w[d] = y[d] - x[d];
  if (imp->shape != PERI_IMPACTOR_SPHERE) {
    s = Dot(w, imp->axis);
    for (PetscInt d = 0; d < 3; d++) w[d] -= s * imp->axis[d];
  }
  r        = PetscSqrtReal(Dot(w, w));
  depth[0] = imp->radius - r; /* the round face (sphere, cylinder) or the side (punch) */
  for (PetscInt d = 0; d < 3; d++) normal[0][d] = r > 0 ? w[d] / r : 0;
  if (imp->shape == PERI_IMPACTOR_PUNCH) { /* its face at s = 0, its back one radius behind */
    depth[nf] = -s, depth[nf + 1] = imp->radius + s;
    for (PetscInt d = 0; d < 3; d++) normal[nf][d] = imp->axis[d], normal[nf + 1][d] = -imp->axis[d];
    nf += 2;
  } else if (imp->shape == PERI_IMPACTOR_CYLINDER) { /* its end caps */
    depth[nf] = 0.5 * imp->length - PetscAbsReal(s);
    for (PetscInt d = 0; d < 3; d++) normal[nf][d] = s >= 0 ? imp->axis[d] : -imp->axis[d];
    nf++;
  }
  if (r == 0 && depth[0] < PetscMin(depth[nf - 1], nf > 1 ? depth[1] : PETSC_MAX_REAL)) return 0; /* on the axis: no direction */
  return Nearest(nf, depth, (const PetscReal(*)[3])normal, n);
}

/* The impactor's centre at time t >= imp->t: it drifts with its velocity until the step's kick. */
static void PositionAt(const PeriImpactor *imp, PetscReal t, PetscReal x[3])
{
  for (PetscInt d = 0; d < 3; d++) x[d] = imp->x[d] + (t - imp->t) * imp->v[d];
}

/* Refuses an impactor that holds a particle at t = 0 (its penalty would fling it out). */
static PetscErrorCode CheckClear(PeriSystem sys, PeriNode item, const PeriImpactor *imp)
{
  PetscInt  inside = 0;
  PetscReal n[3];

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->disc.nowned; i++) inside += Depth(imp, imp->x0, &sys->disc.particles.x[3 * i], n) > 0;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &inside, 1, MPIU_INT, MPI_SUM, sys->comm));
  PeriInputCheck(!inside, sys->scene, item, "center", "the impactor overlaps the body at t = 0 (%" PetscInt_FMT " particles inside it): place it clear of the body", inside);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriImpactorsSetUp - reads impactors (a list, at most 4) and checks each clear of the body.
  Collective.
@*/
PetscErrorCode PeriImpactorsSetUp(PeriSystem sys)
{
  PeriContact *C = &sys->contact;
  PeriScene    s = sys->scene;
  PeriNode     list;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "impactors", &list));
  PeriInputCheck(list->kind == PERI_NODE_SEQ && list->n > 0, s, list, NULL, "must be a list of impactors, each {shape, center, radius, mass, velocity, ...}");
  PeriInputCheck(list->n <= 4, s, list, NULL, "at most 4 impactors, got %" PetscInt_FMT, list->n);
  for (PetscInt k = 0; k < list->n; k++) {
    PetscCall(ReadImpactor(sys, list->child[k], &C->impactors[k]));
    PetscCall(CheckClear(sys, list->child[k], &C->impactors[k]));
  }
  C->nimpactors = list->n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Over this rank's owned particles at the local DOFs ul: each impactor's penalty at time
 * contact.t, its internal force into fa (may be NULL), the force on the impactors into F (3 per
 * impactor, this rank's share) and the penalty energy into E. Not collective. */
void PeriImpactorsAddForce(PeriSystem sys, const PetscScalar ul[], PetscScalar fa[], PetscReal F[], PetscReal *E)
{
  PeriContact   *C  = &sys->contact;
  const PetscInt bs = sys->model->dofs, dim = sys->disc.particles.dim;

  *E = 0;
  for (PetscInt k = 0; k < C->nimpactors; k++) {
    const PeriImpactor *imp = &C->impactors[k];
    PetscReal           x[3];
    PositionAt(imp, C->t, x);
    for (PetscInt d = 0; d < 3; d++) F[3 * k + d] = 0;
    for (PetscInt i = 0; i < sys->disc.nowned; i++) {
      PetscReal y[3], n[3], p, kp;
      for (PetscInt d = 0; d < 3; d++) {
        const PetscInt c = d < dim ? PeriModelTranslation(sys->model, d) : -1;
        y[d]             = sys->disc.particles.x[3 * i + d] + (c >= 0 ? PetscRealPart(ul[i * bs + c]) : 0);
      }
      p = Depth(imp, x, y, n);
      if (p <= 0) continue;
      kp = imp->k * PetscSqr(sys->disc.particles.volume[i]) / C->delta;
      *E += 0.5 * kp * p * p;
      for (PetscInt d = 0; d < dim; d++) {
        const PetscInt c = PeriModelTranslation(sys->model, d);
        if (fa && c >= 0) fa[i * bs + c] -= kp * p * n[d]; /* internal: the particle is pushed along n */
        F[3 * k + d] -= kp * p * n[d];
      }
    }
  }
}

/*@C
  PeriImpactorsAdvance - after a step of the body to time t: each impactor kicked by the force of
  the step's evaluation (half a step in, PeriContactSetTime) and drifted to t, as PETSc's velocity
  Verlet moves the particles. Collective.
@*/
PetscErrorCode PeriImpactorsAdvance(PeriSystem sys, PetscReal t)
{
  PeriContact *C = &sys->contact;
  PetscReal    F[12];

  PetscFunctionBeginUser;
  if (!C->nimpactors) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCallMPI(MPI_Allreduce(C->fstep, F, (PetscMPIInt)(3 * C->nimpactors), MPIU_REAL, MPI_SUM, sys->comm));
  for (PetscInt k = 0; k < C->nimpactors; k++) {
    PeriImpactor   *imp = &C->impactors[k];
    const PetscReal h   = t - imp->t;
    for (PetscInt d = 0; d < 3; d++) {
      const PetscReal v = imp->v[d] + h * F[3 * k + d] / imp->mass;
      imp->x[d] += 0.5 * h * (imp->v[d] + v);
      imp->v[d]     = v;
      imp->force[d] = F[3 * k + d];
    }
    imp->t = t;
  }
  PetscCall(PetscArrayzero(C->fstep, 12));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The impactors' kinetic energy. */
PetscReal PeriImpactorsKinetic(PeriSystem sys)
{
  PetscReal T = 0;

  for (PetscInt k = 0; k < sys->contact.nimpactors; k++) T += 0.5 * sys->contact.impactors[k].mass * Dot(sys->contact.impactors[k].v, sys->contact.impactors[k].v);
  return T;
}

/* Gershgorin's bound: the penalty's stiffness k V_i^2/delta on every translation of every owned
 * particle (any may come into contact). */
void PeriImpactorsAddRowSums(PeriSystem sys, PetscScalar ra[])
{
  const PetscInt bs = sys->model->dofs;
  PetscReal      k  = 0;

  for (PetscInt m = 0; m < sys->contact.nimpactors; m++) k = PetscMax(k, sys->contact.impactors[m].k);
  for (PetscInt i = 0; k > 0 && i < sys->disc.nowned; i++)
    for (PetscInt c = 0; c < bs; c++) ra[i * bs + c] += k * PetscSqr(sys->disc.particles.volume[i]) / sys->contact.delta;
}
