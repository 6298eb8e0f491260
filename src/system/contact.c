/* Contact between particles (include/perilin/private/contact.h; docs/contact.md): the scene's
 * contact section, the candidate pairs over the deformed body, their force and energy, and the
 * bound they add to the explicit step's Gershgorin estimate. */
#include "perilin/private/system.h"
#include "perilin/private/contact.h"

#define CONTACT_FACTOR 15 /* k = 15 c, c the pmb micromodulus of the material (LAMMPS pair peri, after Silling's EMU manual) */

static const PeriKey contact_keys[] = {
    {"radius", PERI_KEY_REAL, "1.35 x the mean spacing", "(0, inf)", "[length]", NULL, "r_c: pairs closer than min(0.9 |X_j - X_i|, r_c) repel (LAMMPS's pair peri)"},
    {"stiffness", PERI_KEY_REAL, "15 c (c = 18K/(pi delta^4) in 3D, 9E/(pi t delta^3) in 2D)", "(0, inf)", "[stress/length^4]", NULL, "k: the force k V_i V_j (d - r)/delta of a pair at distance r < d"},
    {"skin", PERI_KEY_REAL, "0.3 x the mean spacing", "(0, inf)", "[length]", NULL, "the candidate list holds pairs within r_c + skin, rebuilt when a particle has moved more than skin/2"},
    {"ghosts", PERI_KEY_REAL, "the horizon", "[0, inf)", "[length]", NULL, "several ranks: each rank also holds the other ranks' particles this much beyond the bonds' reach, so that it sees every pair while no two particles have moved relative to each other by more than the horizon plus this, less r_c and the skin (the run stops past it)"},
    {NULL},
};
/* impactors.<k>: read by src/system/impactors.c */
static const PeriKey impactor_keys[] = {
    {"shape", PERI_KEY_STRING, "required", NULL, NULL, NULL, "sphere (a disc in 2D), cylinder (3D) or punch (a flat circular face)"},
    {"center", PERI_KEY_REALS, "required", NULL, "[length]", NULL, "the centre (of the sphere, of the cylinder's axis, of the punch's face) at t = 0"},
    {"radius", PERI_KEY_REAL, "required", "(0, inf)", "[length]", NULL, "the radius (of the sphere, the cylinder, the punch's face)"},
    {"axis", PERI_KEY_REALS, NULL, NULL, NULL, NULL, "cylinder: the direction of its axis"},
    {"length", PERI_KEY_REAL, NULL, "(0, inf)", "[length]", NULL, "cylinder: its length along the axis"},
    {"normal", PERI_KEY_REALS, NULL, NULL, NULL, NULL, "punch: the face's normal, pointing towards the body"},
    {"mass", PERI_KEY_REAL, "required", "(0, inf)", "[mass]", NULL, "its mass"},
    {"velocity", PERI_KEY_REALS, "required", NULL, "[length/time]", NULL, "its velocity at t = 0, one number per dimension"},
    {"stiffness", PERI_KEY_REAL, "contact.stiffness, or its default", "(0, inf)", "[stress/length^4]", NULL, "k: a particle at depth p inside it is pushed out by k V_i^2 p / delta"},
    {NULL},
};
const PeriSchema PeriContactSchema[] = {
    {"contact", contact_keys},
    {"impactors.<k>", impactor_keys},
    {NULL},
};

/* The pmb micromodulus of the material over the scene's horizon: the stiffness scale of contact. */
static PetscReal Micromodulus(PeriSystem sys)
{
  return 4 * PeriModelIsotropicEnergy(sys->model) / PeriModelHorizonMoment(sys->model, 1);
}

static PetscErrorCode ReadContact(PeriSystem sys, PeriNode node)
{
  PeriContact *C = &sys->contact;
  PeriScene    s = sys->scene;
  PetscBool    given;

  PetscFunctionBeginUser;
  PeriInputCheck(node->kind == PERI_NODE_MAP, s, node, NULL, "must be a map of contact's keys ({} for the defaults)");
  PetscCall(PeriSceneCheckSection(s, node, "contact"));
  C->on     = PETSC_TRUE;
  C->radius = 1.35 * sys->disc.particles.mean_spacing;
  C->skin   = 0.3 * sys->disc.particles.mean_spacing;
  PetscCall(PeriSceneGetReal(s, node, "radius", PETSC_FALSE, &C->radius, NULL));
  PetscCall(PeriSceneGetReal(s, node, "skin", PETSC_FALSE, &C->skin, NULL));
  PetscCall(PeriSceneGetReal(s, node, "stiffness", PETSC_FALSE, &C->k, &given));
  C->reach = sys->disc.ghost_radius - C->radius - C->skin;
  PeriInputCheck(C->radius < sys->disc.delta, s, node, "radius", "%g reaches beyond the horizon %g: contact acts closer than the bonds reach", (double)C->radius, (double)sys->disc.delta);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriContactGhostMargin - how much farther than the bonds' search radius the ghosts reach: on
  several ranks with contact on, contact.ghosts (default the horizon), else 0. Read before the
  local view is built (the rest of contact after it, PeriContactSetUp). Not collective.
@*/
PetscErrorCode PeriContactGhostMargin(PeriSystem sys, PetscReal *margin)
{
  PeriNode node;

  PetscFunctionBeginUser;
  *margin = 0;
  PetscCall(PeriSceneGetNode(sys->scene->root, "contact", &node));
  if (sys->size == 1 || !node || node->kind != PERI_NODE_MAP || !(sys->stiffness.needs.transient || sys->stiffness.needs.dry_run)) PetscFunctionReturn(PETSC_SUCCESS);
  *margin = sys->disc.delta;
  PetscCall(PeriSceneGetReal(sys->scene, node, "ghosts", PETSC_FALSE, margin, NULL));
  sys->contact.ghost_margin = *margin;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ContactAddForce(PeriSystem, Vec, Vec);
static PetscErrorCode ContactEnergy(PeriSystem, Vec, PetscReal *);
static PetscErrorCode ContactAddRowSums(PeriSystem, Vec);

/* Contact and the impactors as one interaction term of the system (PeriTermOps). */
static const PeriTermOps contact_term = {"contact", ContactAddForce, ContactEnergy, ContactAddRowSums};

/*@C
  PeriContactSetUp - reads contact and impactors (a transient analysis only; none: nothing),
  checks the impactors clear of the body at t = 0, and adds the contact term to the system's.
  Collective.
@*/
PetscErrorCode PeriContactSetUp(PeriSystem sys)
{
  PeriContact *C = &sys->contact;
  PeriScene    s = sys->scene;
  PeriNode     node, imp;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "contact", &node));
  PetscCall(PeriSceneGetNode(s->root, "impactors", &imp));
  if (!node && !imp) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(sys->stiffness.needs.transient || sys->stiffness.needs.dry_run, s, node ? node : imp, NULL, "contact and impactors act in time: analysis.type dynamic");
  for (PetscInt d = 0; d < 3; d++) PeriInputCheck(!sys->disc.particles.periodic[d], s, node ? node : imp, NULL, "contact and impactors need a body without periodic axes");
  C->k     = CONTACT_FACTOR * Micromodulus(sys);
  C->delta = sys->disc.delta;
  if (node) PetscCall(ReadContact(sys, node));
  if (imp) PetscCall(PeriImpactorsSetUp(sys));
  PetscCall(PeriSystemAddTerm(sys, &contact_term));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscBool PeriContactActive(PeriSystem sys)
{
  return (PetscBool)(sys->contact.on || sys->contact.nimpactors);
}

/*@C
  PeriContactSetTime - the time of the next force evaluation (where the impactors are), and whether
  it is the step's force, whose share on the impactors PeriImpactorsAdvance applies. Not collective.
@*/
PetscErrorCode PeriContactSetTime(PeriSystem sys, PetscReal t, PetscBool step)
{
  PetscFunctionBeginUser;
  sys->contact.t      = t;
  sys->contact.record = step;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The translations of local particle i from the local DOFs ul (0 where the model has none). */
static void Translation(PeriSystem sys, const PetscScalar ul[], PetscInt i, PetscReal u[3])
{
  const PetscInt bs = sys->model->dofs;

  for (PetscInt d = 0; d < 3; d++) {
    const PetscInt c = d < sys->disc.particles.dim ? PeriModelTranslation(sys->model, d) : -1;
    u[d]             = c >= 0 ? PetscRealPart(ul[i * bs + c]) : 0;
  }
}

/* The cell key of position y: cells of side h from lo, n[] per axis. */
static PetscInt64 CellKey(const PetscReal y[3], const PetscReal lo[3], PetscReal h, const PetscInt64 n[3], PetscInt64 shift[3])
{
  PetscInt64 c[3];

  for (PetscInt d = 0; d < 3; d++) c[d] = (PetscInt64)PetscFloorReal((y[d] - lo[d]) / h) + shift[d];
  for (PetscInt d = 0; d < 3; d++)
    if (c[d] < 0 || c[d] >= n[d]) return -1;
  return c[0] + n[0] * (c[1] + n[1] * c[2]);
}

typedef struct {
  PetscInt64 key;
  PetscInt   i;
} CellEntry;

/* By cell, then by particle: the same list on every run (the forces' order of summation). */
static int CompareCells(const void *a, const void *b)
{
  const CellEntry *x = (const CellEntry *)a, *y = (const CellEntry *)b;

  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  return x->i < y->i ? -1 : (x->i > y->i);
}

/* The bond joining owned i and local j, or -1: while it lives they interact through it, not by
 * contact. A bond lives in the row of its smaller global index: a ghost's own row is on its rank,
 * and such a pair counts as unbonded (its contact force acts only past 10 % compression). */
static PetscInt BondOf(const PeriSystem sys, PetscInt i, PetscInt j)
{
  const PeriBonds *b   = &sys->disc.bonds;
  const PetscInt  *g   = sys->disc.particles.global;
  PetscInt         row = i, other = j;

  if (g ? g[j] < g[i] : j < i) {
    if (j >= sys->disc.nowned) return -1;
    row = j, other = i;
  }
  for (PetscInt k = b->offset[row - b->rstart]; k < b->offset[row - b->rstart + 1]; k++)
    if (b->j[k] == other) return k;
  return -1;
}

/* Appends the candidate (i, j) with the bond that joins them (-1: none). */
static PetscErrorCode AddPair(PeriSystem sys, PetscInt i, PetscInt j)
{
  PeriContact *C = &sys->contact;

  PetscFunctionBeginUser;
  if (C->npairs == C->cap) {
    C->cap = PetscMax(1024, 2 * C->cap);
    PetscCall(PetscRealloc(sizeof(PetscInt) * 3 * C->cap, &C->pair));
  }
  C->pair[3 * C->npairs]     = i;
  C->pair[3 * C->npairs + 1] = j;
  C->pair[3 * C->npairs + 2] = BondOf(sys, i, j);
  C->npairs++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The candidates of owned i among the sorted cells (keys[], idx[]): its own and the adjacent ones. */
static PetscErrorCode CandidatesOf(PeriSystem sys, PetscInt i, const PetscReal *y, const PetscReal lo[3], PetscReal h, const PetscInt64 n[3], PetscInt nl, const PetscInt64 keys[], const PetscInt idx[])
{
  const PetscInt zr = sys->disc.particles.dim == 3 ? 1 : 0;

  PetscFunctionBeginUser;
  for (PetscInt64 a = -1; a <= 1; a++)
    for (PetscInt64 b = -1; b <= 1; b++)
      for (PetscInt64 c = -zr; c <= zr; c++) {
        PetscInt64 shift[3] = {a, b, c};
        PetscInt64 key      = CellKey(&y[3 * i], lo, h, n, shift);
        PetscInt   lo_k = 0, hi_k = nl;
        if (key < 0) continue;
        while (lo_k < hi_k) { /* the first index with keys >= key */
          PetscInt mid = (lo_k + hi_k) / 2;
          if (keys[mid] < key)
            lo_k = mid + 1;
          else
            hi_k = mid;
        }
        for (PetscInt k = lo_k; k < nl && keys[k] == key; k++) {
          const PetscInt j  = idx[k];
          PetscReal      r2 = 0;
          if (j == i) continue;
          for (PetscInt d = 0; d < 3; d++) r2 += PetscSqr(y[3 * j + d] - y[3 * i + d]);
          if (r2 < h * h) PetscCall(AddPair(sys, i, j));
        }
      }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The candidate pairs at the local DOFs ul: cells of side r_c + skin over the deformed positions,
 * sorted by cell; each owned particle with every local one within r_c + skin. Not collective. */
static PetscErrorCode BuildPairs(PeriSystem sys, const PetscScalar ul[])
{
  PeriContact    *C  = &sys->contact;
  const PetscInt  nl = sys->disc.particles.n;
  const PetscReal h  = C->radius + C->skin;
  PetscReal      *y, lo[3] = {PETSC_MAX_REAL, PETSC_MAX_REAL, PETSC_MAX_REAL}, hi[3] = {-PETSC_MAX_REAL, -PETSC_MAX_REAL, -PETSC_MAX_REAL};
  PetscInt64     *keys, n[3], zero[3]                                                = {0, 0, 0};
  PetscInt       *idx;
  CellEntry      *cell;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc4(3 * nl, &y, nl, &keys, nl, &idx, nl, &cell));
  if (!C->ubuild) PetscCall(PetscMalloc1(3 * nl, &C->ubuild));
  for (PetscInt i = 0; i < nl; i++) {
    Translation(sys, ul, i, &C->ubuild[3 * i]);
    for (PetscInt d = 0; d < 3; d++) {
      y[3 * i + d] = sys->disc.particles.x[3 * i + d] + C->ubuild[3 * i + d];
      lo[d]        = PetscMin(lo[d], y[3 * i + d]);
      hi[d]        = PetscMax(hi[d], y[3 * i + d]);
    }
  }
  for (PetscInt d = 0; d < 3; d++) n[d] = nl ? (PetscInt64)PetscFloorReal((hi[d] - lo[d]) / h) + 1 : 1;
  for (PetscInt i = 0; i < nl; i++) {
    cell[i].key = CellKey(&y[3 * i], lo, h, n, zero);
    cell[i].i   = i;
  }
  qsort(cell, (size_t)nl, sizeof(CellEntry), CompareCells);
  for (PetscInt i = 0; i < nl; i++) keys[i] = cell[i].key, idx[i] = cell[i].i;
  C->npairs = 0;
  for (PetscInt i = 0; i < sys->disc.nowned; i++) PetscCall(CandidatesOf(sys, i, y, lo, h, n, nl, keys, idx));
  C->builds++;
  PetscCall(PetscFree4(y, keys, idx, cell));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether a local particle has moved more than half the skin since the last build. */
static PetscBool Moved(PeriSystem sys, const PetscScalar ul[])
{
  const PeriContact *C = &sys->contact;

  if (!C->ubuild) return PETSC_TRUE;
  for (PetscInt i = 0; i < sys->disc.particles.n; i++) {
    PetscReal u[3], d2 = 0;
    Translation(sys, ul, i, u);
    for (PetscInt d = 0; d < 3; d++) d2 += PetscSqr(u[d] - C->ubuild[3 * i + d]);
    if (4 * d2 > C->skin * C->skin) return PETSC_TRUE;
  }
  return PETSC_FALSE;
}

/* Pair p's force on its owned particle i (the gradient of the pair's energy at y_i, into g) and
 * the pair's energy; 0 when apart. */
static PetscReal PairTerm(PeriSystem sys, const PetscScalar ul[], PetscInt p, PetscReal g[3])
{
  const PeriContact *C = &sys->contact;
  const PetscInt     i = C->pair[3 * p], j = C->pair[3 * p + 1], bond = C->pair[3 * p + 2];
  const PetscReal   *X = sys->disc.particles.x, *V = sys->disc.particles.volume;
  PetscReal          ui[3], uj[3], e[3], r2 = 0, X2 = 0, r, d, k;

  if (bond >= 0 && sys->disc.bonds.live[bond]) return 0; /* the bond acts */
  Translation(sys, ul, i, ui);
  Translation(sys, ul, j, uj);
  for (PetscInt a = 0; a < 3; a++) {
    e[a] = X[3 * i + a] + ui[a] - X[3 * j + a] - uj[a]; /* from j to i */
    r2 += e[a] * e[a];
    X2 += PetscSqr(X[3 * i + a] - X[3 * j + a]);
  }
  d = PetscMin(0.9 * PetscSqrtReal(X2), C->radius);
  r = PetscSqrtReal(r2);
  if (r >= d || r == 0) return 0;
  k = C->k * V[i] * V[j] / C->delta;
  for (PetscInt a = 0; a < 3; a++) g[a] -= k * (d - r) * e[a] / r; /* dE/dy_i: the pair pushes i away from j */
  return 0.5 * k * (d - r) * (d - r);
}

/* The local DOFs of u, with the candidate list rebuilt when particles have moved. */
static PetscErrorCode LocalState(PeriSystem sys, Vec u, PetscScalar **ul)
{
  PetscFunctionBeginUser;
  PetscCall(PeriSystemLocalDOFs(sys, u, ul));
  if (sys->contact.on && Moved(sys, *ul)) PetscCall(BuildPairs(sys, *ul));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Over the pairs and the impactors at the local DOFs ul: the internal force into fa (owned DOFs;
 * may be NULL) and this rank's share of the energy (each pair is visited from each owned end). */
static PetscReal Evaluate(PeriSystem sys, const PetscScalar ul[], PetscScalar fa[])
{
  PeriContact   *C  = &sys->contact;
  const PetscInt bs = sys->model->dofs;
  PetscReal      E = 0, Ei = 0, F[12];

  for (PetscInt p = 0; C->on && p < C->npairs; p++) {
    PetscReal      g[3] = {0, 0, 0};
    const PetscInt i    = C->pair[3 * p];
    E += 0.5 * PairTerm(sys, ul, p, g);
    for (PetscInt d = 0; fa && d < sys->disc.particles.dim; d++) {
      const PetscInt c = PeriModelTranslation(sys->model, d);
      if (c >= 0) fa[i * bs + c] += g[d];
    }
  }
  PeriImpactorsAddForce(sys, ul, fa, F, &Ei);
  if (fa && C->record) {
    for (PetscInt k = 0; k < 3 * C->nimpactors; k++) C->fstep[k] = F[k];
    C->record = PETSC_FALSE;
  }
  return E + Ei;
}

/* ContactAddForce - f += the contact and impactor forces at u (internal: the gradient of their
 * energy), at the time PeriContactSetTime set. Collective (the ghosts' DOFs). */
static PetscErrorCode ContactAddForce(PeriSystem sys, Vec u, Vec f)
{
  PetscScalar   *ul, *fa;
  PetscLogDouble t0, t1;

  PetscFunctionBeginUser;
  if (!PeriContactActive(sys)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscTime(&t0));
  PetscCall(LocalState(sys, u, &ul));
  PetscCall(VecGetArray(f, &fa));
  (void)Evaluate(sys, ul, fa);
  PetscCall(VecRestoreArray(f, &fa));
  PetscCall(PetscFree(ul));
  PetscCall(PetscTime(&t1));
  sys->contact.seconds += t1 - t0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* ContactEnergy - the energy of the contact pairs and the impactors' penalty at u. Collective. */
static PetscErrorCode ContactEnergy(PeriSystem sys, Vec u, PetscReal *E)
{
  PetscScalar *ul;
  PetscReal    e;

  PetscFunctionBeginUser;
  *E = 0;
  if (!PeriContactActive(sys)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(LocalState(sys, u, &ul));
  e = Evaluate(sys, ul, NULL);
  PetscCall(PetscFree(ul));
  PetscCallMPI(MPI_Allreduce(&e, E, 1, MPIU_REAL, MPI_SUM, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* ContactAddRowSums - adds to Gershgorin's row sums what contact can add to a row of the
 * Jacobian: k V_i V_max/delta for each particle a particle can touch across a face (3 in 2D, 5 in
 * 3D: the one opposite and its lattice neighbours within r_c), and the impactors' penalty
 * k V_i^2/delta. Bonded pairs would add more only when compressed by 10 %, beyond what a linear
 * model describes. Not collective. */
static PetscErrorCode ContactAddRowSums(PeriSystem sys, Vec rows)
{
  PeriContact    *C     = &sys->contact;
  const PetscInt  bs    = sys->model->dofs;
  const PetscReal touch = sys->disc.particles.dim == 3 ? 5 : 3;
  PetscReal       vmax  = 0;
  PetscScalar    *ra;

  PetscFunctionBeginUser;
  if (!PeriContactActive(sys)) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt i = 0; i < sys->disc.particles.n; i++) vmax = PetscMax(vmax, sys->disc.particles.volume[i]);
  PetscCall(VecGetArray(rows, &ra));
  for (PetscInt i = 0; C->on && i < sys->disc.nowned; i++)
    for (PetscInt c = 0; c < bs; c++) ra[i * bs + c] += touch * C->k * sys->disc.particles.volume[i] * vmax / C->delta;
  PeriImpactorsAddRowSums(sys, ra);
  PetscCall(VecRestoreArray(rows, &ra));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriContactCheckReach - on several ranks a rank sees the pairs among its particles and ghosts
  (all within the horizon of an owned one at rest): they are all the pairs while no two particles
  have moved relative to each other by more than delta - r_c. A rigid motion moves none closer, so
  the bound is on the spread of u: per component its largest less its smallest value. Past it the
  run stops rather than miss a pair. Collective.
@*/
PetscErrorCode PeriContactCheckReach(PeriSystem sys, Vec u)
{
  const PetscInt     bs = sys->model->dofs;
  const PetscScalar *a;
  PetscReal          hi[3] = {-PETSC_MAX_REAL, -PETSC_MAX_REAL, -PETSC_MAX_REAL}, lo[3], spread = 0;

  PetscFunctionBeginUser;
  if (!sys->contact.on || sys->size == 1) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt d = 0; d < 3; d++) lo[d] = hi[d];
  PetscCall(VecGetArrayRead(u, &a));
  for (PetscInt i = 0; i < sys->disc.nowned; i++)
    for (PetscInt d = 0; d < sys->disc.particles.dim; d++) {
      const PetscInt c = PeriModelTranslation(sys->model, d);
      if (c < 0) continue;
      hi[d] = PetscMax(hi[d], PetscRealPart(a[i * bs + c]));
      lo[d] = PetscMax(lo[d], -PetscRealPart(a[i * bs + c])); /* -min */
    }
  PetscCall(VecRestoreArrayRead(u, &a));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPIU_REAL, MPI_MAX, sys->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPIU_REAL, MPI_MAX, sys->comm));
  for (PetscInt d = 0; d < sys->disc.particles.dim; d++) spread += hi[d] + lo[d] > 0 ? PetscSqr(hi[d] + lo[d]) : 0;
  spread = PetscSqrtReal(spread);
  PetscCheck(spread <= sys->contact.reach, sys->comm, PETSC_ERR_SUP, "%s: contact on %d ranks: two particles have moved %g relative to each other, farther than the %g (the ghosts' reach less the contact radius and skin) within which each rank sees every pair it owns: give a larger contact.ghosts (now %g; above %g for this step, more for the rest of the run), or run on one rank", sys->scene->file, sys->size, (double)spread, (double)sys->contact.reach, (double)sys->contact.ghost_margin, (double)(sys->contact.ghost_margin + spread - sys->contact.reach));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriContactTally - the totals over the ranks that the summary reports: the candidate pairs of the
  last lists, the most lists a rank built, the longest time a rank spent. Collective.
@*/
PetscErrorCode PeriContactTally(PeriSystem sys)
{
  PeriContact *C = &sys->contact;

  PetscFunctionBeginUser;
  if (!PeriContactActive(sys)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCallMPI(MPI_Allreduce(&C->npairs, &C->tally_pairs, 1, MPIU_INT, MPI_SUM, sys->comm));
  PetscCallMPI(MPI_Allreduce(&C->builds, &C->tally_builds, 1, MPIU_INT, MPI_MAX, sys->comm));
  PetscCallMPI(MPI_Allreduce(&C->seconds, &C->tally_seconds, 1, MPI_DOUBLE, MPI_MAX, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriContactSummary - summary.json's "contact" (radius, stiffness, skin, candidate lists built,
  the pairs of the last, seconds: PeriContactTally's) and "impactors" (each one's state at the
  end). Not collective (rank 0 writes the summary).
@*/
PetscErrorCode PeriContactSummary(PeriSystem sys, PeriJSON j)
{
  const PeriContact *C   = &sys->contact;
  const PetscInt     dim = sys->disc.particles.dim;

  PetscFunctionBeginUser;
  if (!PeriContactActive(sys)) PetscFunctionReturn(PETSC_SUCCESS);
  if (C->on) {
    PetscCall(PeriJSONBeginObject(j, "contact"));
    PetscCall(PeriJSONReal(j, "radius", C->radius));
    PetscCall(PeriJSONReal(j, "stiffness", C->k));
    PetscCall(PeriJSONReal(j, "skin", C->skin));
    PetscCall(PeriJSONInt(j, "list_builds", C->tally_builds));
    PetscCall(PeriJSONInt(j, "candidate_pairs", C->tally_pairs));
    PetscCall(PeriJSONReal(j, "seconds", C->tally_seconds));
    PetscCall(PeriJSONEndObject(j));
  }
  if (!C->nimpactors) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginArray(j, "impactors"));
  for (PetscInt k = 0; k < C->nimpactors; k++) {
    const PeriImpactor *imp = &C->impactors[k];
    PetscCall(PeriJSONBeginObject(j, NULL));
    PetscCall(PeriJSONString(j, "shape", PeriImpactorShapes[imp->shape]));
    PetscCall(PeriJSONReal(j, "mass", imp->mass));
    PetscCall(PeriJSONReal(j, "stiffness", imp->k));
    PetscCall(PeriJSONRealArray(j, "center", dim, imp->x));
    PetscCall(PeriJSONRealArray(j, "velocity", dim, imp->v));
    PetscCall(PeriJSONRealArray(j, "force", dim, imp->force));
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONEndArray(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriContactDestroy(PeriContact *C)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(C->pair));
  PetscCall(PetscFree(C->ubuild));
  PetscFunctionReturn(PETSC_SUCCESS);
}
