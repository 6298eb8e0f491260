/* Bond failure: the scene's criteria (failure:), pre-existing cracks (cracks:), the damage per
 * particle and the connected pieces of the body. Sources: Ganzenmueller sec. 3.2 and Diehl &
 * Schweitzer (critical stretch from G), Diana & Casolo eqs. 44-58 (tension, compression, sliding,
 * friction), Oterkus & Madenci eqs. 70, 78-79 (critical shear angle, damage). docs/failure.md. */
#include "perilin/private/system.h"
#include "perilin/private/crack_surfaces.h"

const char *const PeriFailureCauses[] = {"crack", "tension", "compression", "sliding", "shear_angle", NULL};

/* The criteria of criterion_list.h: each defines its failure.* keys, its checks and its index. */
#define PERI_CRITERION(id) extern const PeriCriterionType PeriCriterion_##id;
#include "criterion_list.h"
#undef PERI_CRITERION
static const PeriCriterionType *const criteria[] = {
#define PERI_CRITERION(id) &PeriCriterion_##id,
#include "criterion_list.h"
#undef PERI_CRITERION
};

/* failure: is the union of the criteria's keys, in the order of the list, their softening keys
 * last; then cracks.<k>. */
const PeriSchema PeriFailureSchema[] = {
#define PERI_CRITERION(id) {"failure", PeriCriterion_##id.keys},
#include "criterion_list.h"
#undef PERI_CRITERION
#define PERI_CRITERION(id) {"failure", PeriCriterion_##id.softening_keys},
#include "criterion_list.h"
#undef PERI_CRITERION
    {"cracks.<k>", PeriCrackKeys},
    {"cracks.<k>.disc", PeriCrackDiscKeys},
    {NULL},
};

/* The k-th key of a criterion: its keys, then its softening keys; NULL past the last. */
static const PeriKey *CriterionKey(const PeriCriterionType *t, PetscInt k)
{
  PetscInt n = 0;

  while (n < PERI_CRITERION_MAX_KEYS && t->keys[n].name) n++;
  if (k < 0) return NULL;
  if (k < n) return &t->keys[k];
  if (k == n && t->softening_keys[0].name) return &t->softening_keys[0];
  return NULL;
}

/* Reads every criterion's keys into its values (those with a declared range must be positive) and
 * checks that the scene switches on at least one criterion. */
static PetscErrorCode ReadKeys(PeriScene s, PeriNode node, PeriFailure *F)
{
  char      list[256] = "";
  PetscBool any       = PETSC_FALSE;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < F->ncriteria; i++) {
    PeriCriterion *c = &F->criterion[i];
    for (PetscInt k = 0; CriterionKey(c->type, k); k++) {
      const PeriKey *key = CriterionKey(c->type, k);
      PetscCall(PeriSceneGetReal(s, node, key->name, PETSC_FALSE, &c->value[k], &c->given[k]));
      PeriInputCheck(!c->given[k] || !key->range || c->value[k] > 0, s, node, key->name, "must be positive, got %g", (double)c->value[k]);
    }
    any = (PetscBool)(any || c->given[0]);
    PeriListAppend(list, sizeof(list), c->type->given_as ? c->type->given_as : c->type->keys[0].name);
  }
  PeriInputCheck(any, s, node, NULL, "give at least one criterion: %s", list);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFailureSetUp - reads failure: and has each criterion the scene gives keys of check them
  against the model's measures (found by kind); the scene's first key of a criterion switches it
  on. Not collective.
@*/
PetscErrorCode PeriFailureSetUp(PeriSystem sys)
{
  PeriScene    s = sys->scene;
  PeriFailure *F = &sys->bond_state.failure;
  PeriModel    m = sys->model;
  PeriNode     node;

  PetscFunctionBeginUser;
  F->ncriteria = (PetscInt)PETSC_STATIC_ARRAY_LENGTH(criteria);
  for (PetscInt i = 0; i < F->ncriteria; i++) {
    PeriCriterion *c = &F->criterion[i];
    PetscCall(PetscMemzero(c, sizeof(*c)));
    c->type       = criteria[i];
    c->measure[0] = c->measure[1] = -1;
    for (PetscInt k = 0; k < c->type->nmeasures; k++) c->measure[k] = PeriModelMeasureIndex(m, c->type->measures[k]);
  }
  PetscCall(PeriSceneGetMap(s, s->root, "failure", PETSC_FALSE, &node));
  if (!node) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneCheckSection(s, node, "failure"));
  PetscCall(ReadKeys(s, node, F));
  for (PetscInt i = 0; i < F->ncriteria; i++) {
    PeriCriterion *c   = &F->criterion[i];
    PetscBool      any = PETSC_FALSE;
    for (PetscInt k = 0; CriterionKey(c->type, k); k++) any = (PetscBool)(any || c->given[k]);
    if (!any) continue;
    PetscCall(c->type->ops.setfromscene(c, s, node, m));
    c->active    = c->given[0];
    F->softening = (PetscBool)(F->softening || c->softens);
  }
  PetscCall(PetscCalloc1(sys->disc.bonds.nbonds, &sys->disc.bonds.cause));
  if (F->softening) {
    PetscCall(PetscMalloc1(sys->disc.bonds.nbonds, &sys->disc.bonds.intact));
    for (PetscInt k = 0; k < sys->disc.bonds.nbonds; k++) sys->disc.bonds.intact[k] = 1;
  }
  F->screen    = PETSC_TRUE;
  F->screen_xi = -1;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_failure_screen", &F->screen, NULL));
  F->active = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The criterion that declares key, and the key's place in its values; NULL when none does. */
static PeriCriterion *FindKey(const PeriFailure *F, const char key[], PetscInt *k)
{
  for (PetscInt i = 0; i < F->ncriteria; i++)
    for (*k = 0; CriterionKey(F->criterion[i].type, *k); (*k)++)
      if (!strcmp(CriterionKey(F->criterion[i].type, *k)->name, key)) return (PeriCriterion *)&F->criterion[i];
  return NULL;
}

/*@C
  PeriFailureValue - the value of the failure key (failure.<key>), 0 when the scene does not give
  it. Not collective.
@*/
PetscReal PeriFailureValue(const PeriFailure *F, const char key[])
{
  PetscInt             k;
  const PeriCriterion *c = FindKey(F, key, &k);

  return c ? c->value[k] : 0;
}

/*@C
  PeriFailureSetValue - for white-box tests: as if the scene gave failure.<key>: value (0: not
  given), without the checks of PeriFailureSetUp; the criterion's first key switches it on or
  off. Not collective.
@*/
PetscErrorCode PeriFailureSetValue(PeriFailure *F, const char key[], PetscReal value)
{
  PetscInt       k;
  PeriCriterion *c = FindKey(F, key, &k);

  PetscFunctionBeginUser;
  PetscCheck(c, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "no failure criterion declares the key '%s'", key);
  c->value[k] = value;
  c->given[k] = (PetscBool)(value != 0);
  c->active   = c->given[0];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFailureSelect - keeps only the named criteria (NULL-ended list) of those the scene switched
  on; with softening false the bonds break at the critical values and do not soften. The anisotropy
  analysis studies one criterion at a time this way. Not collective.
@*/
PetscErrorCode PeriFailureSelect(PeriFailure *F, const char *const names[], PetscBool softening)
{
  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < F->ncriteria; i++) {
    PeriCriterion *c     = &F->criterion[i];
    PetscBool      named = PETSC_FALSE;
    for (PetscInt k = 0; names[k]; k++) named = (PetscBool)(named || !strcmp(names[k], c->type->name));
    c->active = (PetscBool)(named && c->given[0]);
    if (!softening) c->softens = PETSC_FALSE;
  }
  if (!softening) F->softening = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFailureIsActive - whether the criterion of that name is active. Not collective.
@*/
PetscBool PeriFailureIsActive(const PeriFailure *F, const char name[])
{
  for (PetscInt i = 0; i < F->ncriteria; i++)
    if (!strcmp(F->criterion[i].type->name, name)) return F->criterion[i].active;
  return PETSC_FALSE;
}

/*@C
  PeriFailureView - each active criterion's description (its formula and limits), in the order of
  the list, on one line without its end. Collective on comm.
@*/
PetscErrorCode PeriFailureView(const PeriFailure *F, PeriModel m, MPI_Comm comm)
{
  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < F->ncriteria; i++)
    if (F->criterion[i].active) PetscCall(F->criterion[i].type->ops.view(&F->criterion[i], m, comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every crack item must cut a bond somewhere (hits: per item, over all ranks): one that cuts none
   is almost always a mistake of units or coordinates, or a crack along a row of particles. */
static PetscErrorCode CheckHits(PeriSystem sys, PeriNode list, const PetscInt hits[])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < list->n; k++) PeriInputCheck(hits[k] > 0, sys->scene, list->child[k], NULL, "the crack cuts no bond (it is smaller than the bonds' spacing, or lies on a face of the body)");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCracksApply - reads cracks: (2D segments {from: [x, y], to: [x, y]}; 3D polygons, discs and
  surface files: src/system/cracks.c) and removes every bond that crosses one, before the family
  volumes and the calibration see the body. Each crack must cut a bond. Collective.
@*/
PetscErrorCode PeriCracksApply(PeriSystem sys)
{
  PeriScene      s   = sys->scene;
  PeriCrackSet   set = {0};
  PeriNode       list;
  PetscInt       cut, *hits;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "cracks", &list));
  if (!list) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(list->kind == PERI_NODE_SEQ, s, list, NULL, "must be a list of segments, each {from: [x, y], to: [x, y]} (2D), or of polygon, disc and surface items (3D)");
  PetscCall(PeriCracksRead(sys, list, &set));
  PetscCall(PetscCalloc1(list->n, &hits));
  cut = PeriCracksCut(&sys->disc.particles, &sys->disc.bonds, &set, hits);
  if (sys->disc.family.offset) PeriCracksCut(&sys->disc.particles, &sys->disc.family, &set, NULL);
  PetscCall(PeriCrackSetDestroy(&set));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &cut, 1, MPIU_INT, MPI_SUM, sys->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, hits, (PetscMPIInt)list->n, MPIU_INT, MPI_SUM, sys->comm));
  ierr = CheckHits(sys, list, hits);
  PetscCall(PetscFree(hits)); /* before an input error is passed on (LeakSanitizer) */
  PetscCall(ierr);
  sys->bond_state.failure.precracked_bonds = cut;
  sys->bond_state.failure.ncracks          = list->n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFailureCacheBonds - room for the per-bond critical values of the active criteria that keep
  them (type->per_bond), sized to the bond list, to be filled on first use. Not collective.
@*/
PetscErrorCode PeriFailureCacheBonds(PeriSystem sys)
{
  PeriFailure   *F = &sys->bond_state.failure;
  const PetscInt n = sys->disc.bonds.nbonds;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < F->ncriteria; i++) {
    PeriCriterion *c = &F->criterion[i];
    if (!c->active || !c->type->per_bond || c->ncritical == n) continue;
    PetscCall(PetscFree(c->critical));
    PetscCall(PetscMalloc1(n, &c->critical));
    for (PetscInt k = 0; k < n; k++) c->critical[k] = -1;
    c->ncritical = n;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriBondFailureIndex - how far the bond is past the scene's criteria: the largest of the active
  criteria's indices (s/s_c, -s/s_cc, |gamma|/gamma_0, |gamma|/(a - s tan beta), |r|/r_c: each
  criterion's file); the bond breaks when it reaches 1. meas[] are the model's measures; cause (may
  be NULL) gets the cause of the first criterion that gave the index. Not collective.
@*/
PetscReal PeriBondFailureIndex(PeriSystem sys, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  const PeriFailure *F   = &sys->bond_state.failure;
  PetscReal          idx = 0;
  PeriFailureCause   c   = PERI_CAUSE_CRACK;

  for (PetscInt i = 0; i < F->ncriteria; i++) {
    const PeriCriterion *crit = &F->criterion[i];
    PeriFailureCause     ci;
    PetscReal            v;
    if (!crit->active) continue;
    v = crit->type->ops.index(crit, sys->model, g, meas, &ci);
    if (v > idx) {
      idx = v;
      c   = ci;
    }
  }
  if (cause) *cause = c;
  return idx;
}

/*@C
  PeriFailureScreens - whether a bond's failure index is a bound on its linearized stretch alone:
  the model's measure is PeriBondStretch's and every active criterion has ops.stretch_limit, no
  bond softens, and -peri_failure_screen is not false. Then the smallest of the active criteria's
  stretch limits of a bond (act[], n of them; PERI_MAX_CRITERIA room) is the stretch below which
  none breaks it. Not collective.
@*/
PetscBool PeriFailureScreens(PeriSystem sys, PetscInt *n, const PeriCriterion *act[])
{
  const PeriFailure *F = &sys->bond_state.failure;

  *n = 0;
  if (!F->screen || sys->model->ops.bond_measures != PeriBondStretch || sys->disc.bonds.intact) return PETSC_FALSE;
  for (PetscInt i = 0; i < F->ncriteria; i++) {
    if (!F->criterion[i].active) continue;
    if (!F->criterion[i].type->ops.stretch_limit) return PETSC_FALSE;
    act[(*n)++] = &F->criterion[i];
  }
  return PETSC_TRUE;
}

/* The bond's failure index when its measures at unit load, meas1, are scaled by lam. */
static PetscReal IndexAt(PeriSystem sys, const PeriBondGeometry *g, const PetscReal meas1[], PetscInt nmeas, PetscReal lam)
{
  PetscReal m[PERI_MAX_MEASURE] = {0};
  for (PetscInt c = 0; c < nmeas && c < PERI_MAX_MEASURE; c++) m[c] = lam * meas1[c];
  return PeriBondFailureIndex(sys, g, m, NULL);
}

/*@C
  PeriBondCriticalLoad - the load factor at which a bond reaches the scene's criteria, from its
  measures at unit load (a linear response): 1/index where the index grows in proportion to the
  load (tension, compression, sliding, shear angle); by bisection where a cohesion makes it affine
  (friction, whose index still grows with the load). PETSC_INFINITY when it never fails. Not
  collective.
@*/
PetscReal PeriBondCriticalLoad(PeriSystem sys, const PeriBondGeometry *g, const PetscReal meas1[], PetscInt nmeas)
{
  PetscReal i1 = IndexAt(sys, g, meas1, nmeas, 1), lo = 0, hi;

  if (!(i1 > 0)) return PETSC_INFINITY;
  hi = 1 / i1;
  if (PetscAbsReal(IndexAt(sys, g, meas1, nmeas, hi) - 1) <= 1e-12) return hi;
  for (PetscInt k = 0; k < 64 && IndexAt(sys, g, meas1, nmeas, hi) < 1; k++) hi *= 2;
  if (IndexAt(sys, g, meas1, nmeas, hi) < 1) return PETSC_INFINITY;
  for (PetscInt k = 0; k < 80 && hi - lo > 1e-13 * hi; k++) {
    PetscReal mid = 0.5 * (lo + hi);
    if (IndexAt(sys, g, meas1, nmeas, mid) >= 1)
      hi = mid;
    else
      lo = mid;
  }
  return hi;
}

/*@C
  PeriBondSoftening - the share of its stiffness a bond keeps (Diana & Casolo eqs. 45-46): the
  smallest of the softening criteria's shares, 1 when none softens it. Not collective.
@*/
PetscReal PeriBondSoftening(PeriSystem sys, const PetscReal meas[])
{
  const PeriFailure *F  = &sys->bond_state.failure;
  PetscReal          mu = 1;

  for (PetscInt i = 0; i < F->ncriteria; i++) {
    const PeriCriterion *c = &F->criterion[i];
    if (c->active && c->softens) mu = PetscMin(mu, c->type->ops.softening(c, meas));
  }
  return mu;
}

/*@C
  PeriDamage - phi_i = 1 - (sum of live alpha V_j) / (sum over every bond found, the pre-cracked
  included) (Oterkus & Madenci eq. 79), softened bonds weighed by their remaining share; and per
  criterion (Diana & Casolo eqs. 47, 48, 51) the share of the family lost to it: PERI_NCAUSES + 1
  values per owned particle, the total, then one per PeriFailureCause. Collective.
@*/
PetscErrorCode PeriDamage(PeriSystem sys, PetscReal **damage)
{
  const PeriBonds     *b  = &sys->disc.bonds;
  const PeriParticles *pt = &sys->disc.particles;
  const PetscInt       w  = PERI_NCAUSES + 2; /* all, live, then the lost share per cause */
  PetscReal           *acc;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(w * pt->n, &acc));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscInt  j    = b->j[k];
      PetscReal left = b->live[k] ? (b->intact ? b->intact[k] : 1) : 0, alpha = PeriDiscBondAlpha(&sys->disc, i, k);
      for (PetscInt e = 0; e < 2; e++) {
        PetscReal *a = &acc[w * (e ? j : i)], V = alpha * pt->volume[e ? i : j];
        a[0] += V;
        a[1] += left * V;
        a[2 + (b->cause ? b->cause[k] : 0)] += (1 - left) * V;
      }
    }
  PetscCall(PeriDiscGhostsToOwners(&sys->disc, MPIU_REAL, w, MPI_SUM, acc));
  PetscCall(PetscFree(*damage));
  {
    PetscCall(PetscMalloc1((PERI_NCAUSES + 1) * sys->disc.nowned, damage));
    for (PetscInt i = 0; i < sys->disc.nowned; i++) {
      const PetscReal *a                = &acc[w * i];
      (*damage)[(PERI_NCAUSES + 1) * i] = a[0] > 0 ? 1 - a[1] / a[0] : 1;
      for (PetscInt c = 0; c < PERI_NCAUSES; c++) (*damage)[(PERI_NCAUSES + 1) * i + 1 + c] = a[0] > 0 ? a[2 + c] / a[0] : 0;
    }
  }
  PetscCall(PetscFree(acc));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static int ComparePair(const void *a, const void *b)
{
  const PetscInt *x = (const PetscInt *)a, *y = (const PetscInt *)b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return x[1] < y[1] ? -1 : x[1] > y[1];
}

/* The dead pairs (global indices, the smaller first) this rank's families need: those of its own
 * bonds, and those other ranks store towards a particle it owns (each rank sends a dead bond to
 * the owner of its other end when that end is a ghost there). *pairs is freed with PetscFree. */
static PetscErrorCode DeadPairs(PeriSystem sys, PetscInt *npairs, PetscInt **pairs)
{
  const PeriBonds *b = &sys->disc.bonds;
  const PetscInt  *G = sys->disc.particles.global;
  PeriExchange     ex;
  PetscMPIInt     *dest;
  PetscInt        *send, nself = 0, nsend = 0;

  PetscFunctionBeginUser;
  *npairs = 0;
  for (PetscInt k = 0; k < b->nbonds; k++)
    if (!b->live[k]) {
      nself++;
      nsend += b->j[k] >= sys->disc.nowned;
    }
  PetscCall(PetscMalloc2(nsend, &dest, 2 * nsend, &send));
  PetscCall(PetscMalloc1(2 * nself + 1, pairs));
  nsend = 0;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      const PetscInt j = b->j[k];
      if (b->live[k]) continue;
      (*pairs)[2 * *npairs]         = G[i];
      (*pairs)[2 * (*npairs)++ + 1] = G[j];
      if (j >= sys->disc.nowned) {
        dest[nsend]           = PeriDiscOwner(&sys->disc, G[j]);
        send[2 * nsend]       = G[i];
        send[2 * nsend++ + 1] = G[j];
      }
    }
  PetscCall(PeriExchangeCreate(sys->comm, nsend, dest, &ex));
  PetscCall(PetscRealloc(sizeof(PetscInt) * (2 * (nself + ex.nrecv) + 1), pairs));
  PetscCall(PeriExchangeSend(&ex, MPIU_INT, 2, send, *pairs + 2 * nself));
  *npairs = nself + ex.nrecv;
  PetscCall(PeriExchangeDestroy(&ex));
  PetscCall(PetscFree2(dest, send));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFamilySync - state-based models keep each particle's whole family (sys->disc.family, both
  directions); this marks dead every family entry whose bond is dead in sys->disc.bonds (stored
  once, in the row of the smaller global index, possibly on another rank): each rank gets the dead
  pairs that touch its own particles (DeadPairs), no more. Collective.
@*/
PetscErrorCode PeriFamilySync(PeriSystem sys)
{
  PeriBonds      *F = &sys->disc.family;
  const PetscInt *G = sys->disc.particles.global;
  PetscInt       *pairs, n;

  PetscFunctionBeginUser;
  if (!F->offset) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(DeadPairs(sys, &n, &pairs));
  qsort(pairs, (size_t)n, 2 * sizeof(PetscInt), ComparePair);
  for (PetscInt i = F->rstart; i < F->rend; i++)
    for (PetscInt k = F->offset[i - F->rstart]; k < F->offset[i - F->rstart + 1]; k++) {
      PetscInt key[2] = {PetscMin(G[i], G[F->j[k]]), PetscMax(G[i], G[F->j[k]])};
      F->live[k]      = bsearch(key, pairs, (size_t)n, 2 * sizeof(PetscInt), ComparePair) ? 0 : 1;
    }
  PetscCall(PetscFree(pairs));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Per owned particle: whether its piece is anchored (a prescribed DOF, or a fictitious particle of
 * a displacement layer) and loaded; ones for the pieces' sizes. */
static PetscErrorCode PieceFlags(PeriSystem sys, PetscInt flags[])
{
  const PeriParticles *pt = &sys->disc.particles;
  const PetscInt       bs = sys->model->dofs;
  const PetscScalar   *f;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->disc.nowned; i++) flags[2 * i] = flags[2 * i + 1] = 0;
  for (PetscInt k = 0; k < sys->conditions.nconstrained; k++) flags[2 * (sys->conditions.constrained[k] / bs - sys->disc.rstart)] = 1;
  PetscCall(VecGetArrayRead(sys->fields.f, &f));
  for (PetscInt i = 0; i < sys->disc.nowned; i++) {
    if (PeriParticleIsFictitious(pt, i)) {
      for (PetscInt face = 0; face < 4; face++)
        if ((pt->crossed[i] & (1 << face)) && sys->conditions.layers.kind[face] == PERI_LAYER_DISPLACEMENT) flags[2 * i] = 1;
    }
    for (PetscInt c = 0; c < bs; c++)
      if (f[i * bs + c] != 0) flags[2 * i + 1] = 1;
  }
  PetscCall(VecRestoreArrayRead(sys->fields.f, &f));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriPieces - the pieces of the body: a piece is anchored when it holds a prescribed DOF or a fictitious
 * particle of a displacement layer. With none anchored, the largest piece is the body (its rigid
 * motions are handled by the solve). Every other piece is held where it is (hold/held: owned DOFs
 * (global rows) and their current values, freed by the caller with PetscFree2); *lost when a held
 * piece carries load. The pieces come from PeriComponentsLabel over the live bonds, their flags
 * from PeriComponentsReduce: no array of the whole body. Collective.
@*/
PetscErrorCode PeriPieces(PeriSystem sys, PetscInt *nhold, PetscInt **hold, PetscReal **held, PetscInt *npieces, PetscBool *lost)
{
  const PeriBonds   *b  = &sys->disc.bonds;
  const PetscInt     bs = sys->model->dofs, no = sys->disc.nowned, r0 = sys->disc.rstart;
  const MPI_Op       ops[2] = {MPI_MAX, MPI_MAX};
  PetscInt          *label, *flags, main = -1, anchored = 0, lostl = 0;
  const PetscScalar *u = NULL;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(sys->disc.particles.n, &label, 2 * no, &flags));
  PetscCall(PeriComponentsLabel(sys->comm, &sys->disc.halo, b->offset, b->j, b->live, label, NULL));
  PetscCall(PieceFlags(sys, flags));
  PetscCall(PeriComponentsReduce(sys->comm, &sys->disc.halo, label, 2, ops, flags, npieces, &main));
  for (PetscInt i = 0; i < no; i++) anchored = PetscMax(anchored, flags[2 * i]);
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &anchored, 1, MPIU_INT, MPI_MAX, sys->comm));
  if (anchored) main = -1;
  PetscCall(PetscMalloc2(no * bs, hold, no * bs, held));
  *nhold = 0;
  if (sys->fields.u) PetscCall(VecGetArrayRead(sys->fields.u, &u));
  for (PetscInt i = 0; i < no; i++) {
    if (flags[2 * i] || label[i] == main) continue;
    if (flags[2 * i + 1]) lostl = 1;
    for (PetscInt c = 0; c < bs; c++) {
      (*hold)[*nhold]     = (r0 + i) * bs + c;
      (*held)[(*nhold)++] = u ? PetscRealPart(u[i * bs + c]) : 0;
    }
  }
  if (sys->fields.u) PetscCall(VecRestoreArrayRead(sys->fields.u, &u));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &lostl, 1, MPIU_INT, MPI_MAX, sys->comm));
  *lost = lostl ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PetscFree2(label, flags));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles.vtu's damage: the total, and the share lost to each criterion the scene uses (Diana &
 * Casolo eqs. 47, 48, 51). */
PetscErrorCode PeriFailureAddFields(PeriSystem sys, PeriFieldList fl)
{
  const PeriFailure *F      = &sys->bond_state.failure;
  PetscInt           causes = F->precracked_bonds > 0 ? 1 << PERI_CAUSE_CRACK : 0;
  const PetscInt     map0   = 0;

  PetscFunctionBeginUser;
  /* a pre-cracked body shows its cracks in every analysis, with failure: or without */
  if (!sys->bond_state.damage && F->precracked_bonds > 0) PetscCall(PeriDamage(sys, &sys->bond_state.damage));
  if (!sys->bond_state.damage) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt i = 0; i < F->ncriteria; i++)
    if (F->criterion[i].active) causes |= F->criterion[i].causes;
  PetscCall(PeriFieldListAddReal(fl, "damage", 1, sys->bond_state.damage, PERI_NCAUSES + 1, &map0));
  for (PetscInt c = 0; c < PERI_NCAUSES; c++) {
    char           name[32];
    const PetscInt map = 1 + c;
    if (!(causes & (1 << c))) continue;
    PetscCall(PetscSNPrintf(name, sizeof(name), "damage_%s", PeriFailureCauses[c]));
    PetscCall(PeriFieldListAddReal(fl, name, 1, sys->bond_state.damage, PERI_NCAUSES + 1, &map));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}
