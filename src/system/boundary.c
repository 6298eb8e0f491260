/* Boundary conditions (prescribed DOFs), loads, and the check that the constraints leave no
 * rigid-body motion free. */
#include "perilin/private/system.h"

/* Translational component of axis a, or -1 when the model has none. */
static PetscErrorCode AxisComponent(PeriModel m, PetscInt a, PetscInt *c)
{
  PetscFunctionBeginUser;
  *c = PeriModelTranslation(m, a);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ComponentList(PeriModel m, char buf[], size_t len)
{
  PetscFunctionBeginUser;
  buf[0] = 0;
  for (PetscInt c = 0; c < m->dofs; c++) {
    PeriListAppend(buf, len, m->components[c]);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* optional: true skips a component of other models, never a name no model has (a misspelling). */
static PetscErrorCode CheckOptional(PeriSystem sys, PeriNode node, const char name[])
{
  PetscBool known;

  PetscFunctionBeginUser;
  PetscCall(PeriModelAnyComponent(name, &known));
  PeriInputCheck(known, sys->scene, node, NULL, "'%s' is a component of no model: optional: true skips only the components of other models (ux, uy, uz, theta, ...)", name);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ComponentFromNode(PeriSystem sys, PeriNode node, const char name[], PetscInt *c)
{
  char list[128];

  PetscFunctionBeginUser;
  PetscCall(PeriModelComponentIndex(sys->model, name, c));
  PetscCall(ComponentList(sys->model, list, sizeof(list)));
  PeriInputCheck(*c >= 0, sys->scene, node, NULL, "'%s' is not a component of model %s; its components are: %s", name, sys->model->type, list);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* bc.<k>, loads.<k> and their fields A X + b. */
static const PeriKey bc_keys[] = {
    {"region", PERI_KEY_STRING, "required", NULL, NULL, NULL, "the region the condition applies to (all: every particle)"},
    {"fix", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "components held at zero, e.g. [ux, uy]"},
    {"value", PERI_KEY_MAP, NULL, NULL, "[length] (theta: radians)", NULL, "map component -> prescribed value, e.g. {ux: 0.001}"},
    {"affine", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "the prescribed field u = A X + b at the reference positions X: {A: [[..],..], b: [..]}; every translational component, never theta"},
    {"velocity", PERI_KEY_REALS, NULL, NULL, "[length/time]", NULL, "a dynamic analysis (explicit or implicit): the translations move at this velocity, u = v t (v a(t) under amplitude, u its integral); one number per dimension"},
    {"amplitude", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "with velocity: its amplitude in time a(t) (default a step: v from t = 0; a ramp starts from rest)"},
    {"optional", PERI_KEY_BOOL, "false", NULL, NULL, NULL, "skip the components of fix and value the model lacks (one scene for several models)"},
    {"override", PERI_KEY_BOOL, "false", NULL, NULL, NULL, "this item wins where an earlier item holds the same component of the same particle with another value (else that is an input error; equal values are always fine)"},
    {NULL},
};
static const PeriKey affine_keys[] = {
    {"A", PERI_KEY_LIST, "required", NULL, NULL, NULL, "dim rows of dim numbers"},
    {"b", PERI_KEY_REALS, "0", NULL, NULL, NULL, "dim numbers"},
    {NULL},
};
static const PeriKey load_keys[] = {
    {"region", PERI_KEY_STRING, "required", NULL, NULL, NULL, "the region the load applies to"},
    {"force", PERI_KEY_REALS, NULL, NULL, "[force]", NULL, "total force, spread over the region's particles by volume"},
    {"traction", PERI_KEY_REALS, NULL, NULL, "[stress]", NULL, "traction on the face of a layer region: force = traction x face area, spread by volume"},
    {"body_force", PERI_KEY_REALS, NULL, NULL, "[force/volume]", NULL, "force per unit volume"},
    {"traction_field", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "traction varying over a layer region, t = A X + b at the particles: {A: [[..],..], b: [..]}"},
    {"amplitude", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "a transient analysis: this load's amplitude in time, instead of analysis.amplitude"},
    {NULL},
};
const PeriSchema PeriBoundarySchema[] = {
    {"bc.<k>", bc_keys},
    {"bc.<k>.affine", affine_keys},
    {"bc.<k>.amplitude", PeriAmplitudeKeys},
    {"loads.<k>", load_keys},
    {"loads.<k>.traction_field", affine_keys},
    {"loads.<k>.amplitude", PeriAmplitudeKeys},
    {NULL},
};

/* {A: [[..], ..], b: [..]}, the mapping of section: a field A X + b with dim rows (b optional). */
PetscErrorCode PeriBoundaryParseAffine(PeriSystem sys, PeriNode node, const char section[], PetscReal A[3][3], PetscReal b[3])
{
  PeriScene      s   = sys->scene;
  const PetscInt dim = sys->disc.particles.dim;
  PeriNode       Anode;
  PetscInt       n;

  PetscFunctionBeginUser;
  PeriInputCheck(node->kind == PERI_NODE_MAP, s, node, NULL, "must be {A: [[..], ..], b: [..]}");
  PetscCall(PeriSceneCheckSection(s, node, section));
  PetscCall(PeriSceneGetNode(node, "A", &Anode));
  PeriInputCheck(Anode && Anode->kind == PERI_NODE_SEQ && Anode->n == dim, s, Anode ? Anode : node, Anode ? NULL : "A", "must be a list of %" PetscInt_FMT " rows of %" PetscInt_FMT " numbers (A X + b)", dim, dim);
  for (PetscInt a = 0; a < dim; a++) PetscCall(PeriSceneParseRealArray(s, Anode->child[a], dim, dim, A[a], &n));
  PetscCall(PeriSceneGetRealArray(s, node, "b", PETSC_FALSE, dim, dim, b, &n));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The owned DOFs' prescribed values as the bc items build them, item by item. */
typedef struct {
  PetscReal *value, *velocity; /* u = value + velocity t */
  PetscBool *set;
  PetscInt  *region; /* the condition's region, for its reaction (-1: none) */
  PetscInt  *item;   /* the bc item that set the value (-1: none) */
} Prescribed;

/* Where bc item k first gave a component of a particle another value than an earlier item j. */
typedef struct {
  PetscInt  j, c;
  PetscReal was, now, X[3];
} Conflict;

static PetscBool SameValue(PetscReal a, PetscReal b)
{
  return (PetscBool)(PetscAbsReal(a - b) <= 1e-12 * PetscMax(PetscAbsReal(a), PetscAbsReal(b)));
}

/* A contradiction found on some rank (x->j >= 0) is the input error of every rank: the lowest rank
 * with one tells the others which. Collective. */
static PetscErrorCode ReportConflict(PeriSystem sys, PeriNode bc, PetscInt k, const Conflict *x)
{
  PetscMPIInt rank, size, first;
  PetscReal   buf[7] = {(PetscReal)x->j, (PetscReal)x->c, x->was, x->now, x->X[0], x->X[1], x->X[2]};
  PeriNode    earlier;
  char        at[96];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(sys->comm, &rank));
  PetscCallMPI(MPI_Comm_size(sys->comm, &size));
  first = x->j >= 0 ? rank : size;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, sys->comm));
  if (first == size) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCallMPI(MPI_Bcast(buf, 7, MPIU_REAL, first, sys->comm));
  earlier = bc->child[(PetscInt)buf[0]];
  if (sys->disc.particles.dim == 2)
    PetscCall(PetscSNPrintf(at, sizeof(at), "(%g, %g)", (double)buf[4], (double)buf[5]));
  else
    PetscCall(PetscSNPrintf(at, sizeof(at), "(%g, %g, %g)", (double)buf[4], (double)buf[5], (double)buf[6]));
  PeriInputCheck(PETSC_FALSE, sys->scene, bc->child[k], NULL, "contradicts %s (line %d): at the particle at %s it prescribes %s = %g, %s prescribes %g; give each component of a particle one value (regions that do not overlap), or override: true on this item to let it win", earlier->path, earlier->line, at, sys->model->components[(PetscInt)buf[1]], (double)buf[3], earlier->path, (double)buf[2]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* bc.<k>.velocity: every translation held at 0 and moving at its velocity w under the item's
 * amplitude, into bc_amp[k] (a dynamic analysis). */
static PetscErrorCode ReadVelocity(PeriSystem sys, PeriNode item, PetscInt k, PetscBool use[], PetscReal v[], PetscReal w[])
{
  PeriScene      s   = sys->scene;
  const PetscInt dim = sys->disc.particles.dim;
  PeriNode       amp;
  PetscReal      vel[3];
  PetscInt       n;

  PetscFunctionBeginUser;
  PeriInputCheck(sys->stiffness.needs.transient || sys->stiffness.needs.dry_run, s, item, "velocity", "a boundary moves in time in a dynamic analysis; a quasi-static one scales value by its load factor instead");
  PetscCall(PeriSceneGetRealArray(s, item, "velocity", PETSC_TRUE, dim, dim, vel, &n));
  PetscCall(PeriSceneGetNode(item, "amplitude", &amp));
  PetscCall(PeriAmplitudeFromScene(s, amp, &sys->conditions.bc_amp[k]));
  for (PetscInt a = 0; a < dim; a++) {
    PetscInt c;
    PetscCall(AxisComponent(sys->model, a, &c));
    PeriInputCheck(c >= 0, s, item, "velocity", "model %s has no displacement along axis %c", sys->model->type, (char)('x' + a));
    use[c] = PETSC_TRUE;
    v[c]   = 0;
    w[c]   = vel[a];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* bc.<k>.fix: the components held at 0 (optional: those of other models skipped). */
static PetscErrorCode ReadFix(PeriSystem sys, PeriNode fix, PetscBool optional, PetscBool use[], PetscReal v[])
{
  PeriScene s = sys->scene;

  PetscFunctionBeginUser;
  PeriInputCheck(fix->kind == PERI_NODE_SEQ && fix->n > 0, s, fix, NULL, "must be a list of components, e.g. [ux, uy]");
  for (PetscInt k = 0; k < fix->n; k++) {
    PetscInt c;
    PeriInputCheck(fix->child[k]->kind == PERI_NODE_SCALAR, s, fix->child[k], NULL, "must be a component name");
    PetscCall(PeriModelComponentIndex(sys->model, fix->child[k]->value, &c));
    if (c < 0 && optional) {
      PetscCall(CheckOptional(sys, fix->child[k], fix->child[k]->value));
      continue;
    }
    PetscCall(ComponentFromNode(sys, fix->child[k], fix->child[k]->value, &c));
    use[c] = PETSC_TRUE;
    v[c]   = 0;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* bc.<k>.value: component -> prescribed value (optional: those of other models skipped). */
static PetscErrorCode ReadValue(PeriSystem sys, PeriNode val, PetscBool optional, PetscBool use[], PetscReal v[])
{
  PeriScene s = sys->scene;

  PetscFunctionBeginUser;
  PeriInputCheck(val->kind == PERI_NODE_MAP && val->n > 0, s, val, NULL, "must map components to values, e.g. {ux: 0.001}");
  for (PetscInt k = 0; k < val->n; k++) {
    PetscInt c;
    PetscCall(PeriModelComponentIndex(sys->model, val->child[k]->key, &c));
    if (c < 0 && optional) {
      PetscCall(CheckOptional(sys, val->child[k], val->child[k]->key));
      continue;
    }
    PetscCall(ComponentFromNode(sys, val->child[k], val->child[k]->key, &c));
    PetscCall(PeriSceneGetReal(s, val, val->child[k]->key, PETSC_TRUE, &v[c], NULL));
    use[c] = PETSC_TRUE;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* bc item k into P over the owned DOFs. Where an earlier item holds a component of a particle,
 * a different value is an input error unless this item says override: true (then it wins).
 * Collective. */
static PetscErrorCode ApplyCondition(PeriSystem sys, PeriNode bc, PetscInt k, Prescribed *P)
{
  PeriNode       item = bc->child[k];
  Conflict       x    = {-1, -1, 0, 0, {0, 0, 0}};
  PetscBool      over = PETSC_FALSE;
  PeriScene      s    = sys->scene;
  PeriModel      m    = sys->model;
  const PetscInt bs = m->dofs, dim = sys->disc.particles.dim;
  PeriRegion    *r;
  PeriNode       fix, val, aff, vel, amp;
  PetscReal      v[PERI_MAX_DOF], A[3][3] = {{0}}, b0[3] = {0, 0, 0}, w[PERI_MAX_DOF] = {0};
  PetscBool      use[PERI_MAX_DOF] = {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE};
  PetscInt       axis_comp[3]      = {-1, -1, -1};
  PetscBool      optional          = PETSC_FALSE;

  PetscFunctionBeginUser;
  PeriInputCheck(item->kind == PERI_NODE_MAP, s, item, NULL, "a boundary condition is a mapping {region: name, fix: [..] | value: {..} | affine: {..}}");
  PetscCall(PeriSceneCheckSection(s, item, "bc.<k>"));
  PetscCall(PeriRegionFind(s, item, "region", sys->disc.nregions, sys->disc.regions, &r));
  PetscCall(PeriSceneGetBool(s, item, "optional", &optional, NULL));
  PetscCall(PeriSceneGetBool(s, item, "override", &over, NULL));
  PetscCall(PeriSceneGetNode(item, "fix", &fix));
  PetscCall(PeriSceneGetNode(item, "value", &val));
  PetscCall(PeriSceneGetNode(item, "affine", &aff));
  PetscCall(PeriSceneGetNode(item, "velocity", &vel));
  PetscCall(PeriSceneGetNode(item, "amplitude", &amp));
  PeriInputCheck((fix ? 1 : 0) + (val ? 1 : 0) + (aff ? 1 : 0) + (vel ? 1 : 0) == 1, s, item, NULL, "give exactly one of fix, value, affine, velocity");
  if (vel) PetscCall(ReadVelocity(sys, item, k, use, v, w));
  PeriInputCheck(vel || !amp, s, item, "amplitude", "moves a bc velocity in time; a held value has none");
  if (fix)
    PetscCall(ReadFix(sys, fix, optional, use, v));
  else if (val)
    PetscCall(ReadValue(sys, val, optional, use, v));
  else if (aff) {
    PetscCall(PeriBoundaryParseAffine(sys, aff, "bc.<k>.affine", A, b0));
    for (PetscInt a = 0; a < dim; a++) {
      PetscCall(AxisComponent(m, a, &axis_comp[a]));
      PeriInputCheck(axis_comp[a] >= 0, s, aff, NULL, "model %s has no displacement along axis %c", m->type, (char)('x' + a));
      use[axis_comp[a]] = PETSC_TRUE;
    }
  }
  for (PetscInt i = sys->disc.bonds.rstart; i < sys->disc.bonds.rend; i++) {
    const PetscReal *X = &sys->disc.particles.x[3 * i];
    if (!PeriRegionContains(r, X)) continue;
    if (aff)
      for (PetscInt a = 0; a < dim; a++) {
        v[axis_comp[a]] = b0[a];
        for (PetscInt d = 0; d < dim; d++) v[axis_comp[a]] += A[a][d] * X[d];
      }
    for (PetscInt c = 0; c < bs; c++) {
      const PetscInt d = (i - sys->disc.bonds.rstart) * bs + c;
      if (!use[c]) continue;
      if (P->set[d] && !over && x.j < 0 && (!SameValue(P->value[d], v[c]) || !SameValue(P->velocity[d], w[c]))) {
        x = (Conflict){P->item[d], c, P->value[d] + P->velocity[d], v[c] + w[c], {X[0], X[1], X[2]}};
      }
      P->value[d]    = v[c];
      P->velocity[d] = w[c];
      P->set[d]      = PETSC_TRUE;
      P->region[d]   = (PetscInt)(r - sys->disc.regions);
      P->item[d]     = k;
    }
  }
  PetscCall(ReportConflict(sys, bc, k, &x));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The velocity of the k-th constrained DOF and the bc item whose amplitude moves it, in
 * conditions.constrained_velocity and constrained_amp (made on the first). */
static PetscErrorCode KeepVelocity(PeriSystem sys, PetscInt k, PetscReal w, PetscInt item)
{
  PeriConditions *C = &sys->conditions;

  PetscFunctionBeginUser;
  if (!C->constrained_velocity) PetscCall(PetscCalloc2(C->nconstrained, &C->constrained_velocity, C->nconstrained, &C->constrained_amp));
  C->constrained_velocity[k] = w;
  C->constrained_amp[k]      = item;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriConditionsMotion - the k-th constrained DOF's motion beyond its value at time t: displacement
  w I(t), velocity w a(t) and acceleration w a'(t) (a the amplitude of its bc item, I its
  integral from 0); all 0 for a DOF that does not move. Not collective.
@*/
void PeriConditionsMotion(const PeriConditions *C, PetscInt k, PetscReal t, PetscReal *u, PetscReal *v, PetscReal *a)
{
  const PetscReal      w   = C->constrained_velocity ? C->constrained_velocity[k] : 0;
  const PeriAmplitude *amp = w != 0 ? &C->bc_amp[C->constrained_amp[k]] : NULL;

  if (u) *u = amp ? w * PeriAmplitudeIntegral(amp, t) : 0;
  if (v) *v = amp ? w * PeriAmplitudeValue(amp, t) : 0;
  if (a) *a = amp ? w * PeriAmplitudeRate(amp, t) : 0;
}

/*@C
  PeriBoundarySetUp - reads bc: the owned constrained DOFs (global rows) and their values. Collective.
@*/
PetscErrorCode PeriBoundarySetUp(PeriSystem sys)
{
  PeriScene      s  = sys->scene;
  const PetscInt bs = sys->model->dofs, nloc = (sys->disc.bonds.rend - sys->disc.bonds.rstart) * bs;
  PeriNode       bc;
  Prescribed     P;
  PetscReal     *value;
  PetscBool     *set;
  PetscInt       n    = 0, *region;
  PetscErrorCode ierr = PETSC_SUCCESS;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "bc", &bc));
  PeriInputCheck(!bc || bc->kind == PERI_NODE_SEQ, s, bc, NULL, "must be a list of conditions, each {region: .., fix: [..]}");
  PetscCall(PetscCalloc5(nloc, &P.value, nloc, &P.velocity, nloc, &P.set, nloc, &P.region, nloc, &P.item));
  sys->conditions.nbc_amp = bc ? bc->n : 0;
  PetscCall(PetscCalloc1(sys->conditions.nbc_amp + 1, &sys->conditions.bc_amp)); /* step amplitudes (zeroed) */
  value = P.value, set = P.set, region = P.region;
  for (PetscInt k = 0; k < nloc; k++) region[k] = P.item[k] = -1; /* held by no bc item (an inactive component) */
  /* a bad condition is an input error, not an exit: free the work arrays before passing it on */
  for (PetscInt k = 0; bc && k < bc->n && !ierr; k++) ierr = ApplyCondition(sys, bc, k, &P);
  if (ierr) PetscCall(PetscFree5(P.value, P.velocity, P.set, P.region, P.item));
  PetscCall(ierr);
  for (PetscInt c = 0; c < bs; c++) {
    if (!sys->model->inactive[c]) continue;
    PetscCall(PetscPrintf(sys->comm, "perilin: note: in model %s at nu = %g the shear springs vanish and %s no longer acts on the displacements: it is held at 0\n", sys->model->type, (double)sys->model->material.nu, sys->model->components[c]));
    for (PetscInt i = 0; i < nloc / bs; i++) {
      value[i * bs + c] = 0;
      set[i * bs + c]   = PETSC_TRUE;
    }
  }
  for (PetscInt k = 0; k < nloc; k++) n += set[k] ? 1 : 0;
  sys->conditions.nconstrained = n;
  PetscCall(PetscMalloc1(n, &sys->conditions.constrained));
  PetscCall(PetscMalloc1(n, &sys->conditions.constrained_value));
  PetscCall(PetscMalloc1(n, &sys->conditions.constrained_region));
  n = 0;
  for (PetscInt k = 0; k < nloc; k++)
    if (set[k]) {
      sys->conditions.constrained[n]        = sys->disc.rstart * bs + k;
      sys->conditions.constrained_value[n]  = value[k];
      sys->conditions.constrained_region[n] = region[k];
      if (P.velocity[k] != 0) PetscCall(KeepVelocity(sys, n, P.velocity[k], P.item[k]));
      n++;
    }
  PetscCall(PetscFree5(P.value, P.velocity, P.set, P.region, P.item));
  sys->conditions.moving = (PetscBool)(sys->conditions.constrained_velocity != NULL);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &sys->conditions.moving, 1, MPIU_BOOL, MPI_LOR, sys->comm));
  PetscCall(PeriReactionsSetUp(sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Adds load item (loads.<k>) to the owned entries a of the load vector. Collective. */
static PetscErrorCode AddLoad(PeriSystem sys, PeriNode item, PetscScalar *a)
{
  PeriScene      s  = sys->scene;
  PeriModel      m  = sys->model;
  const PetscInt bs = m->dofs, dim = sys->disc.particles.dim, uz = PeriModelTranslation(m, 2);
  const PetscInt ncomp = dim == 2 && uz >= 0 ? 3 : dim; /* a 2D cross-section model's loads act along z: [0, 0, F] */
  PetscReal      largest, A[3][3] = {{0}}, F[3] = {0, 0, 0}, scale;
  PeriNode       force, traction, body, field, amp;
  PeriRegion    *r;
  PetscInt       n, comp[3] = {-1, -1, -1};

  PetscFunctionBeginUser;
  PeriInputCheck(item->kind == PERI_NODE_MAP, s, item, NULL, "a load is a mapping {region: name, force | traction | body_force | traction_field: ..}");
  PetscCall(PeriSceneCheckSection(s, item, "loads.<k>"));
  PetscCall(PeriRegionFind(s, item, "region", sys->disc.nregions, sys->disc.regions, &r));
  PetscCall(PeriSceneGetNode(item, "force", &force));
  PetscCall(PeriSceneGetNode(item, "traction", &traction));
  PetscCall(PeriSceneGetNode(item, "body_force", &body));
  PetscCall(PeriSceneGetNode(item, "traction_field", &field));
  PetscCall(PeriSceneGetNode(item, "amplitude", &amp));
  PeriInputCheck(!amp || sys->stiffness.needs.transient || sys->stiffness.needs.dry_run, s, item, "amplitude", "only a transient analysis (analysis.type: dynamic) has time");
  PeriInputCheck((force ? 1 : 0) + (traction ? 1 : 0) + (body ? 1 : 0) + (field ? 1 : 0) == 1, s, item, NULL, "give exactly one of force, traction, body_force, traction_field");
  if (field)
    PetscCall(PeriBoundaryParseAffine(sys, field, "loads.<k>.traction_field", A, F));
  else
    PetscCall(PeriSceneGetRealArray(s, item, force ? "force" : traction ? "traction"
                                                                        : "body_force",
                                    PETSC_TRUE, dim, ncomp, F, &n));
  PeriInputCheck(!(traction || field) || r->face_area > 0, s, item, traction ? "traction" : "traction_field", "needs a layer region (side: ..), whose face area converts traction to force, or a mesh's boundary group; region '%s' is not one", r->name);
  /* particle i receives (A X_i + F) scale V_i */
  scale = body ? 1.0 : (traction || field ? r->face_area : 1.0) / r->volume;
  for (PetscInt d = 0; d < ncomp; d++) {
    PetscCall(AxisComponent(m, d, &comp[d]));
    PeriInputCheck(comp[d] >= 0 || (F[d] == 0 && A[d][0] == 0 && A[d][1] == 0 && A[d][2] == 0), s, item, NULL, "model %s has no displacement along axis %c", m->type, (char)('x' + d));
  }
  largest = 0;
  for (PetscInt i = sys->disc.bonds.rstart; i < sys->disc.bonds.rend; i++) {
    const PetscReal *X = &sys->disc.particles.x[3 * i];
    if (!PeriRegionContains(r, X)) continue;
    for (PetscInt d = 0; d < ncomp; d++) {
      PetscReal v = F[d];
      for (PetscInt e = 0; e < dim; e++) v += A[d][e] * X[e];
      if (comp[d] < 0) continue;
      v *= scale * sys->disc.particles.volume[i];
      a[(i - sys->disc.bonds.rstart) * bs + comp[d]] += v;
      /* NaN must fail the check below, so it counts as infinitely large */
      largest = PetscIsInfOrNanReal(v) ? PETSC_INFINITY : PetscMax(largest, PetscAbsReal(v));
    }
  }
  /* Finite but huge values (1e308) overflow the solver's inner products, which then stops with
     a NaN residual that blames the operator; say here that the load is at fault. */
  PetscCallMPI(MPIU_Allreduce(MPI_IN_PLACE, &largest, 1, MPIU_REAL, MPIU_MAX, sys->comm));
  PeriInputCheck(!PetscIsInfOrNanReal(largest * largest * (PetscReal)(sys->disc.N * bs)), s, item, field ? "traction_field" : force  ? "force"
                                                                                                                          : traction ? "traction"
                                                                                                                                     : "body_force",
                 "the load is too large for double precision: a particle force of %g overflows the solver's inner products (keep particle forces below about 1e150)", (double)largest);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriLoadsAssemble - the load vector from loads: total forces and tractions spread over a
  region's particles in proportion to their volume, and body forces. Collective.
@*/
PetscErrorCode PeriLoadsAssemble(PeriSystem sys, Vec f)
{
  PeriScene    s = sys->scene;
  PeriNode     loads;
  PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(VecSet(f, 0));
  PetscCall(PeriTorsionLoads(sys, f));
  PetscCall(PeriSceneGetNode(s->root, "loads", &loads));
  if (!loads) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(loads->kind == PERI_NODE_SEQ, s, loads, NULL, "must be a list of loads, each {region: .., force: [..]}");
  PetscCall(VecGetArray(f, &a));
  for (PetscInt k = 0; k < loads->n; k++) PetscCall(AddLoad(sys, loads->child[k], a));
  PetscCall(VecRestoreArray(f, &a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriLoadAssemble - the load vector of loads.<k> alone (a transient analysis gives each load with
  an amplitude of its own a vector). Collective.
@*/
PetscErrorCode PeriLoadAssemble(PeriSystem sys, PetscInt k, Vec f)
{
  PeriNode     loads;
  PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(VecSet(f, 0));
  PetscCall(PeriSceneGetNode(sys->scene->root, "loads", &loads));
  PetscCheck(loads && k >= 0 && k < loads->n, sys->comm, PETSC_ERR_ARG_OUTOFRANGE, "No load %" PetscInt_FMT, k);
  PetscCall(VecGetArray(f, &a));
  PetscCall(AddLoad(sys, loads->child[k], a));
  PetscCall(VecRestoreArray(f, &a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Eigen-decomposition of a small symmetric matrix by cyclic Jacobi rotations. */
static void SymmetricEigen(PetscInt n, PetscReal A[PERI_MAX_MODES][PERI_MAX_MODES], PetscReal w[], PetscReal V[PERI_MAX_MODES][PERI_MAX_MODES])
{
  for (PetscInt a = 0; a < n; a++)
    for (PetscInt b = 0; b < n; b++) V[a][b] = a == b;
  for (PetscInt sweep = 0; sweep < 100; sweep++) {
    PetscReal off = 0;
    for (PetscInt a = 0; a < n; a++)
      for (PetscInt b = a + 1; b < n; b++) off += A[a][b] * A[a][b];
    if (off < 1e-30) break;
    for (PetscInt a = 0; a < n; a++)
      for (PetscInt b = a + 1; b < n; b++) {
        PetscReal theta, t, c, s;
        if (PetscAbsReal(A[a][b]) < 1e-300) continue;
        theta = (A[b][b] - A[a][a]) / (2 * A[a][b]);
        t     = (theta >= 0 ? 1 : -1) / (PetscAbsReal(theta) + PetscSqrtReal(theta * theta + 1));
        c     = 1 / PetscSqrtReal(t * t + 1);
        s     = t * c;
        for (PetscInt k = 0; k < n; k++) {
          PetscReal akp = A[k][a], akq = A[k][b];
          A[k][a] = c * akp - s * akq;
          A[k][b] = s * akp + c * akq;
        }
        for (PetscInt k = 0; k < n; k++) {
          PetscReal apk = A[a][k], aqk = A[b][k];
          A[a][k] = c * apk - s * aqk;
          A[b][k] = s * apk + c * aqk;
        }
        for (PetscInt k = 0; k < n; k++) {
          PetscReal vkp = V[k][a], vkq = V[k][b];
          V[k][a] = c * vkp - s * vkq;
          V[k][b] = s * vkp + c * vkq;
        }
      }
  }
  for (PetscInt a = 0; a < n; a++) w[a] = A[a][a];
}

/* Adds to G the Gram matrix of the rigid modes restricted to this rank's constrained DOFs. */
static PetscErrorCode RigidGramConstrained(PeriSystem sys, PetscInt nm, Vec modes[], PetscReal G[PERI_MAX_MODES][PERI_MAX_MODES])
{
  const PetscScalar *a[PERI_MAX_MODES];
  PetscInt           rstart;

  PetscFunctionBeginUser;
  PetscCall(VecGetOwnershipRange(modes[0], &rstart, NULL));
  for (PetscInt k = 0; k < nm; k++) PetscCall(VecGetArrayRead(modes[k], &a[k]));
  for (PetscInt c = 0; c < sys->conditions.nconstrained; c++) {
    PetscInt row = sys->conditions.constrained[c] - rstart;
    for (PetscInt k = 0; k < nm; k++)
      for (PetscInt l = 0; l < nm; l++) G[k][l] += PetscRealPart(a[k][row] * a[l][row]);
  }
  for (PetscInt k = 0; k < nm; k++) PetscCall(VecRestoreArrayRead(modes[k], &a[k]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Adds to G what this rank's fictitious particles hold of the (unit) rigid modes: a relation
 * u_f = s u_m + o holds a mode v unless v_f = s v_m. */
static PetscErrorCode RigidGramLayers(PeriSystem sys, PetscInt nm, const PetscReal norm[], PetscReal G[PERI_MAX_MODES][PERI_MAX_MODES])
{
  const PeriParticles *pt = &sys->disc.particles;
  PeriModel            m  = sys->model;
  PetscReal            centre[3], X[3], vf[PERI_MAX_MODES][PERI_MAX_DOF], vm[PERI_MAX_MODES][PERI_MAX_DOF];

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) centre[d] = 0.5 * (pt->lower[d] + pt->upper[d]);
  for (PetscInt i = sys->disc.bonds.rstart; i < sys->disc.bonds.rend; i++) {
    PetscInt           mi = pt->image ? pt->image[i] : -1, ncols;
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscReal          sign;
    if (mi < 0) continue;
    mi = PeriDiscLocal(&sys->disc, mi); /* the image is a ghost at worst (SetLocalView) */
    PetscCall(MatGetRow(sys->conditions.layers.T, pt->global[i], &ncols, &cols, &vals));
    sign = PetscRealPart(vals[0]);
    PetscCall(MatRestoreRow(sys->conditions.layers.T, pt->global[i], &ncols, &cols, &vals));
    for (PetscInt d = 0; d < 3; d++) X[d] = pt->x[3 * i + d] - centre[d];
    m->ops.rigid_modes(m, X, vf);
    for (PetscInt d = 0; d < 3; d++) X[d] = pt->x[3 * mi + d] - centre[d];
    m->ops.rigid_modes(m, X, vm);
    for (PetscInt c = 0; c < m->dofs; c++)
      for (PetscInt k = 0; k < nm; k++)
        for (PetscInt l = 0; l < nm; l++) G[k][l] += (vf[k][c] - sign * vm[k][c]) * (vf[l][c] - sign * vm[l][c]) / (norm[k] * norm[l]);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Creates free[nfree], the free combination V[.][k] of the modes, orthonormalised against free[0..nfree-1]. */
static PetscErrorCode RigidFreeVector(PetscInt nm, Vec modes[], PetscReal V[PERI_MAX_MODES][PERI_MAX_MODES], PetscInt k, PetscInt nfree, Vec free[])
{
  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(modes[0], &free[nfree]));
  PetscCall(VecZeroEntries(free[nfree]));
  for (PetscInt l = 0; l < nm; l++) PetscCall(VecAXPY(free[nfree], V[l][k], modes[l]));
  for (PetscInt q = 0; q < nfree; q++) {
    PetscScalar dot;
    PetscCall(VecDot(free[nfree], free[q], &dot));
    PetscCall(VecAXPY(free[nfree], -dot, free[q]));
  }
  PetscCall(VecNormalize(free[nfree], NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Names the free combination V[.][k] of the modes in what: a rotation by its axis, else its largest mode. */
static PetscErrorCode RigidMotionName(PeriSystem sys, PetscInt nm, const PetscReal norm[], PetscReal V[PERI_MAX_MODES][PERI_MAX_MODES], PetscInt k, char what[], size_t len)
{
  static const char *const names1[] = {"translation along z"};
  static const char *const names2[] = {"translation along x", "translation along y", "rotation about z"};
  static const char *const names3[] = {"translation along x", "translation along y", "translation along z", "rotation about x", "rotation about y", "rotation about z"};
  const PeriParticles     *pt       = &sys->disc.particles;
  PetscInt                 best     = 0;

  PetscFunctionBeginUser;
  for (PetscInt l = 0; l < nm; l++)
    if (PetscAbsReal(V[l][k]) > PetscAbsReal(V[best][k])) best = l;
  if (nm == 3 && PetscAbsReal(V[2][k]) > 0.05) {
    /* A rotation about a held point (a pin) is, about the box centre the modes use, a rotation
       plus a translation that may be the larger part; naming the translation would point at
       DOFs that are in fact held, so name the centre of rotation: u = w (-(y - Py), x - Px). */
    PetscReal wz = V[2][k] / norm[2], P[2];
    P[0]         = 0.5 * (pt->lower[0] + pt->upper[0]) - V[1][k] / norm[1] / wz;
    P[1]         = 0.5 * (pt->lower[1] + pt->upper[1]) + V[0][k] / norm[0] / wz;
    PetscCall(PetscSNPrintf(what, len, "rotation about z around (%g, %g)", (double)P[0], (double)P[1]));
  } else if (nm == 6 && PetscSqrtReal(V[3][k] * V[3][k] + V[4][k] * V[4][k] + V[5][k] * V[5][k]) > 0.05) {
    /* the same in 3D: u = t + w x (X - c) is a rotation about the axis along w through
       P = c + (w x t) / |w|^2 (plus a slide along w, if any) */
    PetscReal t[3], w[3], w2, P[3];
    for (PetscInt d = 0; d < 3; d++) {
      t[d] = V[d][k] / norm[d];
      w[d] = V[3 + d][k] / norm[3 + d];
    }
    w2   = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    P[0] = 0.5 * (pt->lower[0] + pt->upper[0]) + (w[1] * t[2] - w[2] * t[1]) / w2;
    P[1] = 0.5 * (pt->lower[1] + pt->upper[1]) + (w[2] * t[0] - w[0] * t[2]) / w2;
    P[2] = 0.5 * (pt->lower[2] + pt->upper[2]) + (w[0] * t[1] - w[1] * t[0]) / w2;
    w2   = PetscSqrtReal(w2);
    for (PetscInt d = 0; d < 3; d++) w[d] = PetscAbsReal(w[d]) < 1e-8 * w2 ? 0 : w[d]; /* no -1e-16 in the message */
    PetscCall(PetscSNPrintf(what, len, "rotation about the axis along (%.3g, %.3g, %.3g) through (%g, %g, %g)", (double)(w[0] / w2), (double)(w[1] / w2), (double)(w[2] / w2), (double)P[0], (double)P[1], (double)P[2]));
  } else if (nm == 1 || nm == 3 || nm == 6)
    PetscCall(PetscSNPrintf(what, len, "%s", (nm == 1 ? names1 : nm == 3 ? names2
                                                                         : names3)[best]));
  else
    PetscCall(PetscSNPrintf(what, len, "rigid mode %" PetscInt_FMT, best));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriRigidMotionFree - how many combinations of the rigid-body modes the constrained DOFs and the
  fictitious layers leave free (K is singular when any is), the main motion of the first, named,
  and (when free is not NULL) those combinations as orthonormal vectors, created here. Collective.
@*/
PetscErrorCode PeriRigidMotionFree(PeriSystem sys, PetscInt *nfree, char what[], size_t len, Vec free[])
{
  Vec       modes[PERI_MAX_MODES];
  PetscInt  nm;
  PetscReal G[PERI_MAX_MODES][PERI_MAX_MODES] = {{0}}, V[PERI_MAX_MODES][PERI_MAX_MODES], w[PERI_MAX_MODES], norm[PERI_MAX_MODES];

  PetscFunctionBeginUser;
  PetscCall(PeriRigidModes(sys, &nm, modes, norm));
  PetscCall(RigidGramConstrained(sys, nm, modes, G));
  if (sys->conditions.layers.T) PetscCall(RigidGramLayers(sys, nm, norm, G));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, G, PERI_MAX_MODES * PERI_MAX_MODES, MPIU_REAL, MPI_SUM, sys->comm));
  /* G holds sums of squares of unit vectors' entries: a free motion gives an eigenvalue of about
   * round-off; one constrained particle already gives ~1/N */
  SymmetricEigen(nm, G, w, V);
  *nfree = 0;
  if (what) what[0] = 0;
  for (PetscInt k = 0; k < nm; k++) {
    if (w[k] > 1e-12 / sys->disc.N) continue;
    if (free) PetscCall(RigidFreeVector(nm, modes, V, k, *nfree, free));
    if ((*nfree)++ || !what) continue;
    PetscCall(RigidMotionName(sys, nm, norm, V, k, what, len));
  }
  for (PetscInt k = 0; k < nm; k++) PetscCall(VecDestroy(&modes[k]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Frees what the conditions hold. */
PetscErrorCode PeriConditionsDestroy(PeriConditions *C)
{
  PetscFunctionBeginUser;
  PetscCall(PeriLayersDestroy(&C->layers));
  PetscCall(PetscFree(C->constrained));
  PetscCall(PetscFree(C->constrained_value));
  PetscCall(PetscFree(C->constrained_region));
  PetscCall(PetscFree2(C->constrained_velocity, C->constrained_amp));
  for (PetscInt k = 0; k < C->nbc_amp; k++) PetscCall(PeriAmplitudeDestroy(&C->bc_amp[k]));
  PetscCall(PetscFree(C->bc_amp));
  PetscCall(PeriReactionsDestroy(&C->reactions));
  PetscCall(PeriConditionFieldsDestroy(&C->fields));
  PetscFunctionReturn(PETSC_SUCCESS);
}
