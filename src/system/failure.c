/* Bond failure: the scene's criteria (failure:), pre-existing cracks (cracks:), the damage per
 * particle and the connected pieces of the body. Sources: Ganzenmueller sec. 3.2 and Diehl &
 * Schweitzer (critical stretch from G), Diana & Casolo eqs. 44-58 (tension, compression, sliding,
 * friction), Oterkus & Madenci eqs. 70, 78-79 (critical shear angle, damage). docs/failure.md. */
#include "perilin/private/system.h"

const char *const PeriFailureCauses[] = {"crack", "tension", "compression", "sliding", "shear_angle", NULL};

/* failure.* (read in this order into PeriFailure) and cracks.<k>. */
static const PeriKey failure_keys[] = {
    {"critical_stretch", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "critical tensile stretch s_c (models with a stretch: pmb, npmb, cpmb, pds, mppd, gerstle); not with G"},
    {"G", PERI_KEY_REAL, NULL, "(0, inf)", "[energy/length^2]", NULL, "energy release rate: each bond's critical stretch or shear angle from its model"},
    {"compressive_stretch", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "critical compressive stretch: a bond breaks when s < -value"},
    {"sliding", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "pds/mppd/gerstle: critical sliding gamma_0"},
    {"friction_angle", PERI_KEY_REAL, NULL, "(0, 90)", "[degrees]", NULL, "pds/mppd/gerstle: frictional sliding gamma_l = cohesion - s tan(angle); with cohesion"},
    {"cohesion", PERI_KEY_REAL, NULL, NULL, NULL, NULL, "pds/mppd/gerstle: the sliding limit without stretch; with friction_angle"},
    {"shear_angle", PERI_KEY_REAL, NULL, "(0, inf)", NULL, NULL, "antiplane: critical shear angle r_c; not with G"},
    {"ultimate_stretch", PERI_KEY_REAL, NULL, "(critical_stretch, inf)", NULL, NULL, "softening (eq. 45): the stiffness falls linearly from critical_stretch to 0 here"},
    {"ultimate_compressive_stretch", PERI_KEY_REAL, NULL, "(compressive_stretch, inf)", NULL, NULL, "softening in compression (eq. 46)"},
    {NULL},
};
static const PeriKey crack_keys[] = {
    {"from", PERI_KEY_REALS, "required", NULL, "[length]", NULL, "a pre-existing crack, a 2D segment: its first end [x, y]; bonds crossing it are removed before the first step"},
    {"to", PERI_KEY_REALS, "required", NULL, "[length]", NULL, "its other end"},
    {NULL},
};
const PeriSchema PeriFailureSchema[] = {
    {"failure", failure_keys},
    {"cracks.<k>", crack_keys},
    {NULL},
};

/*@C
  PeriFailureSetUp - reads failure: and checks each criterion against the model's measures.
  Not collective.
@*/
PetscErrorCode PeriFailureSetUp(PeriSystem sys)
{
  PeriScene    s = sys->scene;
  PeriFailure *F = &sys->bond_state.failure;
  PeriModel    m = sys->model;
  PeriNode     node;
  PetscBool    has[9];
  PetscReal   *val[9] = {&F->stretch, &F->G, &F->compressive, &F->sliding, &F->friction_angle, &F->cohesion, &F->shear_angle, &F->ultimate, &F->ultimate_compressive};

  PetscFunctionBeginUser;
  F->istretch = F->isliding = F->ishear = -1;
  for (PetscInt k = 0; k < m->nmeasures; k++) {
    if (!strcmp(m->measure_names[k], "stretch")) F->istretch = k;
    if (!strcmp(m->measure_names[k], "sliding")) F->isliding = k;
    if (!strcmp(m->measure_names[k], "shear_angle")) F->ishear = k;
  }
  PetscCall(PeriSceneGetMap(s, s->root, "failure", PETSC_FALSE, &node));
  if (!node) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneCheckSection(s, node, "failure"));
  for (PetscInt k = 0; failure_keys[k].name; k++) {
    PetscCall(PeriSceneGetReal(s, node, failure_keys[k].name, PETSC_FALSE, val[k], &has[k]));
    PeriInputCheck(!has[k] || *val[k] > 0 || k == 5, s, node, failure_keys[k].name, "must be positive, got %g", (double)*val[k]);
  }
  PeriInputCheck(!has[5] || F->cohesion >= 0, s, node, "cohesion", "must not be negative, got %g", (double)F->cohesion);
  PeriInputCheck(has[0] || has[1] || has[2] || has[3] || has[4] || has[6], s, node, NULL, "give at least one criterion: %s", "critical_stretch, G, compressive_stretch, sliding, friction_angle with cohesion, shear_angle");
  PeriInputCheck(!(has[0] && has[1]), s, node, "G", "give critical_stretch or G, not both");
  PeriInputCheck(!(has[6] && has[1]), s, node, "G", "give shear_angle or G, not both");
  PeriInputCheck(!(has[0] || has[2]) || F->istretch >= 0, s, node, has[0] ? "critical_stretch" : "compressive_stretch", "model %s has no stretch measure", m->type);
  PeriInputCheck(!(has[3] || has[4] || has[5]) || F->isliding >= 0, s, node, has[3] ? "sliding" : "friction_angle", "model %s has no sliding measure (pds, mppd, gerstle have)", m->type);
  PeriInputCheck(!has[6] || F->ishear >= 0, s, node, "shear_angle", "model %s has no shear angle (antiplane models have)", m->type);
  PeriInputCheck(!has[1] || m->ops.critical_from_G, s, node, "G", "model %s cannot convert an energy release rate into a critical measure; give it directly", m->type);
  PeriInputCheck(has[4] == has[5], s, node, has[4] ? "cohesion" : "friction_angle", "frictional sliding needs both friction_angle (degrees) and cohesion");
  PeriInputCheck(!has[4] || F->friction_angle < 90, s, node, "friction_angle", "must lie in (0, 90) degrees, got %g", (double)F->friction_angle);
  PeriInputCheck(!has[7] || (has[0] && F->ultimate > F->stretch), s, node, "ultimate_stretch", "softening needs critical_stretch (where it starts) below ultimate_stretch (where the bond is gone)");
  PeriInputCheck(!has[8] || (has[2] && F->ultimate_compressive > F->compressive), s, node, "ultimate_compressive_stretch", "softening needs compressive_stretch below ultimate_compressive_stretch");
  PetscCall(PetscCalloc1(sys->disc.bonds.nbonds, &sys->disc.bonds.cause));
  if (has[7] || has[8]) {
    PetscCall(PetscMalloc1(sys->disc.bonds.nbonds, &sys->disc.bonds.intact));
    for (PetscInt k = 0; k < sys->disc.bonds.nbonds; k++) sys->disc.bonds.intact[k] = 1;
  }
  F->active = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Do the open segments P0P1 and Q0Q1 cross (a touch at an end point does not count)? */
static PetscBool SegmentsCross(const PetscReal P0[], const PetscReal P1[], const PetscReal Q0[], const PetscReal Q1[])
{
  PetscReal d1 = (P1[0] - P0[0]) * (Q0[1] - P0[1]) - (P1[1] - P0[1]) * (Q0[0] - P0[0]);
  PetscReal d2 = (P1[0] - P0[0]) * (Q1[1] - P0[1]) - (P1[1] - P0[1]) * (Q1[0] - P0[0]);
  PetscReal d3 = (Q1[0] - Q0[0]) * (P0[1] - Q0[1]) - (Q1[1] - Q0[1]) * (P0[0] - Q0[0]);
  PetscReal d4 = (Q1[0] - Q0[0]) * (P1[1] - Q0[1]) - (Q1[1] - Q0[1]) * (P1[0] - Q0[0]);
  return (PetscBool)(d1 * d2 < 0 && d3 * d4 < 0);
}

static PetscInt CutBonds(const PeriParticles *pt, PeriBonds *b, PetscInt nc, const PetscReal seg[])
{
  PetscInt cut = 0;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscReal X1[2] = {pt->x[3 * i] + b->xi[3 * k], pt->x[3 * i + 1] + b->xi[3 * k + 1]};
      for (PetscInt c = 0; c < nc && b->live[k]; c++)
        if (SegmentsCross(&pt->x[3 * i], X1, &seg[4 * c], &seg[4 * c + 2])) {
          b->live[k] = 0;
          cut++;
        }
    }
  return cut;
}

/* Whether the 2D segment s = (x0, y0, x1, y1) meets the box [lo, hi] (Liang-Barsky clipping). A
   crack that misses the body entirely cuts nothing, which is almost always a mistake of units or
   coordinates, so it is reported rather than ignored. */
static PetscBool SegmentMeetsBox(const PetscReal s[], const PetscReal lo[], const PetscReal hi[])
{
  PetscReal t0 = 0, t1 = 1;
  for (PetscInt d = 0; d < 2; d++) {
    PetscReal dx = s[2 + d] - s[d], tol = 1e-9 * (hi[d] - lo[d]);
    PetscReal pq[2][2] = {
        {-dx, s[d] - (lo[d] - tol)},
        {dx, (hi[d] + tol) - s[d]}};
    for (PetscInt k = 0; k < 2; k++) {
      if (pq[k][0] == 0) {
        if (pq[k][1] < 0) return PETSC_FALSE;
      } else if (pq[k][0] < 0)
        t0 = PetscMax(t0, pq[k][1] / pq[k][0]);
      else
        t1 = PetscMin(t1, pq[k][1] / pq[k][0]);
    }
  }
  return t0 <= t1 ? PETSC_TRUE : PETSC_FALSE;
}

/*@C
  PeriCracksApply - reads cracks: (2D segments {from: [x, y], to: [x, y]}) and removes every bond
  that crosses one, before the family volumes and the calibration see the body. Collective.
@*/
PetscErrorCode PeriCracksApply(PeriSystem sys)
{
  PeriScene  s = sys->scene;
  PeriNode   list;
  PetscReal *seg;
  PetscInt   cut, n;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "cracks", &list));
  if (!list) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(list->kind == PERI_NODE_SEQ, s, list, NULL, "must be a list of segments, each {from: [x, y], to: [x, y]}");
  PeriInputCheck(sys->disc.particles.dim == 2, s, list, NULL, "cracks are 2D segments; 3D scenes cannot have them yet");
  PetscCall(PetscMalloc1(4 * list->n, &seg));
  for (PetscInt c = 0; c < list->n; c++) {
    PeriNode item = list->child[c];
    PeriInputCheck(item->kind == PERI_NODE_MAP, s, item, NULL, "a crack is a segment {from: [x, y], to: [x, y]}");
    PetscCall(PeriSceneCheckSection(s, item, "cracks.<k>"));
    PetscCall(PeriSceneGetRealArray(s, item, "from", PETSC_TRUE, 2, 2, &seg[4 * c], &n));
    PetscCall(PeriSceneGetRealArray(s, item, "to", PETSC_TRUE, 2, 2, &seg[4 * c + 2], &n));
    PeriInputCheck(seg[4 * c] != seg[4 * c + 2] || seg[4 * c + 1] != seg[4 * c + 3], s, item, "to", "the segment has zero length");
    PeriInputCheck(SegmentMeetsBox(&seg[4 * c], sys->disc.particles.lower, sys->disc.particles.upper), s, item, NULL, "the segment from (%g, %g) to (%g, %g) lies outside the body [%g, %g] x [%g, %g]: it would cut no bond", (double)seg[4 * c], (double)seg[4 * c + 1], (double)seg[4 * c + 2], (double)seg[4 * c + 3], (double)sys->disc.particles.lower[0], (double)sys->disc.particles.upper[0], (double)sys->disc.particles.lower[1], (double)sys->disc.particles.upper[1]);
  }
  cut = CutBonds(&sys->disc.particles, &sys->disc.bonds, list->n, seg);
  if (sys->disc.family.offset) CutBonds(&sys->disc.particles, &sys->disc.family, list->n, seg);
  PetscCall(PetscFree(seg));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &cut, 1, MPIU_INT, MPI_SUM, sys->comm));
  sys->bond_state.failure.precracked_bonds = cut;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriBondFailureIndex - how far the bond is past the scene's criteria: the largest of s/s_c
  (tension), -s/s_cc (compression), |gamma|/gamma_0, |gamma|/(a - s tan beta) (friction) and
  |r|/r_c; the bond breaks when it reaches 1. meas[] are the model's measures; cause (may be NULL)
  gets the criterion that gave the index. Not collective.
@*/
PetscReal PeriBondFailureIndex(PeriSystem sys, const PeriBondGeometry *g, const PetscReal meas[], PeriFailureCause *cause)
{
  const PeriFailure *F   = &sys->bond_state.failure;
  PetscReal          idx = 0, crit = 0;
  PeriFailureCause   c = PERI_CAUSE_CRACK;

  if (F->G > 0) crit = sys->model->ops.critical_from_G(sys->model, g, F->G);
  if (F->istretch >= 0) {
    /* with softening the bond is gone at the ultimate stretch; before, PeriBondSoftening weakens it */
    PetscReal s = meas[F->istretch], sc = F->ultimate > 0 ? F->ultimate : F->stretch > 0 ? F->stretch
                                                                                         : crit;
    PetscReal scc = F->ultimate_compressive > 0 ? F->ultimate_compressive : F->compressive;
    if (s > 0 && sc > 0 && s / sc > idx) {
      idx = s / sc;
      c   = PERI_CAUSE_TENSION;
    }
    if (s < 0 && scc > 0 && -s / scc > idx) {
      idx = -s / scc;
      c   = PERI_CAUSE_COMPRESSION;
    }
  }
  if (F->isliding >= 0) {
    PetscReal gam = PetscAbsReal(meas[F->isliding]), v = 0;
    if (F->sliding > 0) v = gam / F->sliding;
    if (F->friction_angle > 0) {
      /* Diana & Casolo's frictional sliding: the limit grows with compression, vanishes in tension */
      PetscReal s = F->istretch >= 0 ? meas[F->istretch] : 0, lim = F->cohesion - s * PetscTanReal(F->friction_angle * PETSC_PI / 180);
      v = PetscMax(v, lim > 0 ? gam / lim : (gam > 0 ? PETSC_MAX_REAL : 0));
    }
    if (v > idx) {
      idx = v;
      c   = PERI_CAUSE_SLIDING;
    }
  }
  if (F->ishear >= 0) {
    PetscReal rc = F->shear_angle > 0 ? F->shear_angle : crit;
    if (rc > 0 && PetscAbsReal(meas[F->ishear]) / rc > idx) {
      idx = PetscAbsReal(meas[F->ishear]) / rc;
      c   = PERI_CAUSE_SHEAR_ANGLE;
    }
  }
  if (cause) *cause = c;
  return idx;
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
  PeriBondSoftening - the share of its stiffness a bond keeps at stretch s (Diana & Casolo eqs.
  45-46): 1 below the critical stretch, falling linearly to 0 at the ultimate stretch, in tension
  and (when given) in compression. Not collective.
@*/
PetscReal PeriBondSoftening(PeriSystem sys, const PetscReal meas[])
{
  const PeriFailure *F = &sys->bond_state.failure;
  PetscReal          s = F->istretch >= 0 ? meas[F->istretch] : 0, mu = 1;

  if (F->ultimate > 0 && s > F->stretch) mu = PetscMax(0, (F->ultimate - s) / (F->ultimate - F->stretch));
  if (F->ultimate_compressive > 0 && -s > F->compressive) mu = PetscMax(0, (F->ultimate_compressive + s) / (F->ultimate_compressive - F->compressive));
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
      PetscReal left = b->live[k] ? (b->intact ? b->intact[k] : 1) : 0;
      for (PetscInt e = 0; e < 2; e++) {
        PetscReal *a = &acc[w * (e ? j : i)], V = b->alpha[k] * pt->volume[e ? i : j];
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
  const PetscBool    used[] = {(PetscBool)(sys->bond_state.failure.precracked_bonds > 0), (PetscBool)(F->stretch > 0 || (F->G > 0 && F->istretch >= 0)), (PetscBool)(F->compressive > 0), (PetscBool)(F->sliding > 0 || F->friction_angle > 0), (PetscBool)(F->ishear >= 0)};
  const PetscInt     map0   = 0;

  PetscFunctionBeginUser;
  if (!sys->bond_state.damage) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriFieldListAddReal(fl, "damage", 1, sys->bond_state.damage, PERI_NCAUSES + 1, &map0));
  for (PetscInt c = 0; c < PERI_NCAUSES; c++) {
    char           name[32];
    const PetscInt map = 1 + c;
    if (!used[c]) continue;
    PetscCall(PetscSNPrintf(name, sizeof(name), "damage_%s", PeriFailureCauses[c]));
    PetscCall(PeriFieldListAddReal(fl, name, 1, sys->bond_state.damage, PERI_NCAUSES + 1, &map));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}
