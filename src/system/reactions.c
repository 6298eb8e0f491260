/* Reactions of the constrained regions and the check of global equilibrium (docs/reactions.md).
 *
 * The solve eliminates the prescribed DOFs from K (MatZeroRowsColumns), so the forces there are not
 * in the solver's matrix: they come from the bonds themselves. The internal force f_int = K u is
 * summed element by element with the model's blocks (the same loop as the energy and the stress),
 * which serves an assembled and a matrix-free K alike, broken and softened bonds included. The
 * reaction of a region is the sum of f_int - lambda f over the DOFs its bc items constrain: the
 * force the support exerts on the body (a couple for theta). Every element's block is
 * translation-invariant, so the internal forces sum to zero and the reactions balance the loads
 * up to what the free DOFs' residual leaves: that is the check. */
#include "perilin/private/system.h"

/* Which components are translations (the model's axis[]): the ones a force balance sums. */
static PetscErrorCode Translations(PeriModel m, PetscBool trans[])
{
  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < PERI_MAX_DOF; c++) trans[c] = (PetscBool)(c < m->dofs && m->axis[c] >= 0);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriReactionsSetUp - after bc: which components each region constrains and whether a nonzero value
  is prescribed on it (the default reaction region of a load-displacement curve). Collective.
@*/
PetscErrorCode PeriReactionsSetUp(PeriSystem sys)
{
  PeriReactions *R  = &sys->conditions.reactions;
  const PetscInt bs = sys->model->dofs, nr = sys->disc.nregions;

  PetscFunctionBeginUser;
  PetscCall(PeriReactionsDestroy(R));
  R->nregions = nr;
  PetscCall(PetscCalloc3(nr * PERI_MAX_DOF, &R->holds, nr, &R->moves, nr * PERI_MAX_DOF, &R->force));
  for (PetscInt k = 0; k < sys->conditions.nconstrained; k++) {
    PetscInt r = sys->conditions.constrained_region[k], c = sys->conditions.constrained[k] % bs;
    if (r < 0) continue;
    R->holds[r * PERI_MAX_DOF + c] = PETSC_TRUE;
    if (sys->conditions.constrained_value[k] != 0) R->moves[r] = PETSC_TRUE;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, R->holds, (PetscMPIInt)(nr * PERI_MAX_DOF), MPIU_BOOL, MPI_LOR, sys->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, R->moves, (PetscMPIInt)nr, MPIU_BOOL, MPI_LOR, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriReactionsDestroy(PeriReactions *R)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree3(R->holds, R->moves, R->force));
  R->nregions  = 0;
  R->evaluated = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The region named name among those with a reaction (a bc item holds some DOF of it), or -1. */
PetscErrorCode PeriReactionsFindRegion(PeriSystem sys, const char name[], PetscInt *r)
{
  PetscFunctionBeginUser;
  *r = -1;
  for (PetscInt k = 0; k < sys->conditions.reactions.nregions; k++) {
    PetscBool any = PETSC_FALSE;
    for (PetscInt c = 0; c < PERI_MAX_DOF; c++) any = (PetscBool)(any || sys->conditions.reactions.holds[k * PERI_MAX_DOF + c]);
    if (any && !strcmp(sys->disc.regions[k].name, name)) *r = k;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

typedef struct {
  const PetscScalar *u; /* the local view's DOFs */
  Vec                fint;
  PetscInt          *rows;
} ForceCtx;

/* f_e = K_e u_e added to the element's particles */
static PetscErrorCode ElementForce(PeriSystem sys, const PeriElement *el, void *ctx)
{
  ForceCtx        *F  = (ForceCtx *)ctx;
  const PetscInt   bs = sys->model->dofs, N = el->n * bs;
  const PetscReal *f = el->work + N;

  PetscFunctionBeginUser;
  PeriElementForces(sys, el, F->u);
  for (PetscInt t = 0; t < el->n; t++)
    for (PetscInt c = 0; c < bs; c++) F->rows[t * bs + c] = el->gidx[t] * bs + c;
  PetscCall(VecSetValues(F->fint, N, F->rows, f, ADD_VALUES));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* fint = K u with the unconstrained stiffness, from the model's element blocks. Collective. */
static PetscErrorCode InternalForce(PeriSystem sys, Vec fint)
{
  ForceCtx     F;
  PetscInt     nmax = PetscMax(1, PeriSystemMaxFamily(sys));
  PetscScalar *u;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemLocalDOFs(sys, sys->fields.u, &u));
  F.u = u;
  PetscCall(PetscMalloc1((nmax + 1) * sys->model->dofs, &F.rows));
  F.fint = fint;
  PetscCall(VecZeroEntries(fint));
  PetscCall(PeriElementsForEach(sys, ElementForce, &F));
  PetscCall(VecAssemblyBegin(fint));
  PetscCall(VecAssemblyEnd(fint));
  PetscCall(PetscFree(F.rows));
  PetscCall(PetscFree(u));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What the sums over this rank's DOFs give, reduced over ranks in one call. */
typedef struct {
  PetscReal total[PERI_MAX_DOF];   /* sum of f_int: 0 for a translation-invariant K */
  PetscReal freesum[PERI_MAX_DOF]; /* sum of f_int - lambda f over the DOFs no bc item holds */
  PetscReal scale;                 /* sum over particles of |f_int - lambda f| on held DOFs + |lambda f| */
  PetscReal magnitude;             /* sum of |f_int| + |lambda f| over the DOFs: the round-off's scale */
  PetscReal load2;                 /* ||lambda f||^2 */
  PetscReal moment[3];             /* per rotation: the moment of the reactions and the loads */
  PetscReal mscale;                /* sum of |rotation mode| (|reaction| + |load|): the moments' scale */
  PetscReal mmagnitude;            /* sum of |rotation mode| (|f_int| + |lambda f|): their round-off's scale */
} Sums;

/* The rotations whose moment balance holds exactly: for a rotation-invariant model the rigid
 * rotation r is in K's null space, and K is symmetric, so r . K u = 0 and the moments of the
 * reactions and loads sum to -r . (the free DOFs' residual). Not with periodic axes (a bond across
 * a face joins minimum images: a rotation stretches it) nor with fictitious layers (their faces'
 * forces are in mirror relations). *ntrans: the rigid modes before the rotations. */
static PetscErrorCode MomentModes(PeriSystem sys, const PetscBool trans[], PetscInt *ntrans, PetscInt *nrot)
{
  const PeriModelType *desc;
  PetscReal            X[3] = {0, 0, 0}, vals[PERI_MAX_MODES][PERI_MAX_DOF];
  PetscInt             nm;

  PetscFunctionBeginUser;
  *ntrans = *nrot = 0;
  for (PetscInt c = 0; c < PERI_MAX_DOF; c++) *ntrans += trans[c];
  PetscCall(PeriModelTypeGet(sys->model->type, &desc));
  nm = sys->model->ops.rigid_modes(sys->model, X, vals);
  if (!desc->rotation_invariant || sys->conditions.layers.T) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt d = 0; d < 3; d++)
    if (sys->disc.particles.periodic[d]) PetscFunctionReturn(PETSC_SUCCESS);
  *nrot = PetscMax(0, nm - *ntrans);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Adds DOF c of particle i (at X from the box centre) to the moment sums: its reaction (held) and load. */
static void MomentAdd(PeriSystem sys, const PetscReal X[], PetscInt ntrans, PetscInt nrot, PetscInt c, PetscBool held, PetscReal Fi, PetscReal F, Sums *S)
{
  PetscReal vals[PERI_MAX_MODES][PERI_MAX_DOF];
  if (!nrot) return;
  sys->model->ops.rigid_modes(sys->model, X, vals);
  for (PetscInt q = 0; q < nrot; q++) {
    PetscReal w = vals[ntrans + q][c], R = held ? Fi - F : 0;
    S->moment[q] += w * (R + F);
    S->mscale += PetscAbsReal(w) * (PetscAbsReal(R) + PetscAbsReal(F));
    S->mmagnitude += PetscAbsReal(w) * (PetscAbsReal(Fi) + PetscAbsReal(F));
  }
}

/* The per-region reactions (R->force, R->applied) and the sums of the check over the owned DOFs. */
static PetscErrorCode SumOwned(PeriSystem sys, Vec fint, PetscReal lambda, const PetscBool trans[], Sums *S)
{
  PeriReactions       *R  = &sys->conditions.reactions;
  const PeriParticles *pt = &sys->disc.particles;
  const PetscInt       bs = sys->model->dofs, nloc = sys->disc.nowned, r0 = sys->disc.rstart * bs; /* r0: the first owned global row */
  const PetscScalar   *fi, *fa;
  PetscInt             k = 0, ntrans, nrot;

  PetscFunctionBeginUser;
  PetscCall(MomentModes(sys, trans, &ntrans, &nrot));
  R->nmoments = nrot;
  PetscCall(VecGetArrayRead(fint, &fi));
  PetscCall(VecGetArrayRead(sys->fields.f, &fa));
  for (PetscInt i = 0; i < nloc; i++) {
    PetscReal p2 = 0, r2 = 0, X[3];
    for (PetscInt d = 0; d < 3; d++) X[d] = pt->x[3 * i + d] - 0.5 * (pt->lower[d] + pt->upper[d]);
    for (PetscInt c = 0; c < bs; c++) {
      const PetscInt  row = i * bs + c;
      const PetscReal F = lambda * PetscRealPart(fa[row]), Fi = PetscRealPart(fi[row]);
      PetscInt        region = -1;
      PetscBool       held   = PETSC_FALSE;
      /* the constrained rows are sorted: walk them alongside */
      while (k < sys->conditions.nconstrained && sys->conditions.constrained[k] < r0 + row) k++;
      if (k < sys->conditions.nconstrained && sys->conditions.constrained[k] == r0 + row) {
        held   = PETSC_TRUE;
        region = sys->conditions.constrained_region[k];
      }
      if (region >= 0) R->force[region * PERI_MAX_DOF + c] += Fi - F;
      MomentAdd(sys, X, ntrans, nrot, c, held, Fi, F, S);
      if (!trans[c]) continue;
      R->applied[c] += F;
      S->total[c] += Fi;
      if (!held)
        S->freesum[c] += Fi - F;
      else
        r2 += PetscSqr(Fi - F);
      S->magnitude += PetscAbsReal(Fi) + PetscAbsReal(F);
      S->load2 += F * F;
      p2 += F * F;
    }
    S->scale += PetscSqrtReal(p2) + PetscSqrtReal(r2);
  }
  PetscCall(VecRestoreArrayRead(sys->fields.f, &fa));
  PetscCall(VecRestoreArrayRead(fint, &fi));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The moment balance (MomentModes): the free DOFs' residual r gives at most L sum |r_i| <= L sqrt(n)
 * ||r||, L the largest lever (half the box diagonal; at least 1 for the couples of theta DOFs, whose
 * weight is 1), so the force bound times L; round-off 1e-9 of the moments' magnitude. */
static PetscErrorCode CheckMoments(PeriSystem sys, PetscReal force_allowed, const Sums *S)
{
  PeriReactions       *R  = &sys->conditions.reactions;
  const PeriParticles *pt = &sys->disc.particles;
  PetscReal            L2 = 0, m2 = 0, allowed;

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) L2 += PetscSqr(0.5 * (pt->upper[d] - pt->lower[d]));
  for (PetscInt q = 0; q < 3; q++) R->moment[q] = q < R->nmoments ? S->moment[q] : 0;
  for (PetscInt q = 0; q < R->nmoments; q++) m2 += PetscSqr(S->moment[q]);
  allowed                      = PetscMax(PetscSqrtReal(L2), 1) * (force_allowed - 1e-9 * S->magnitude) + 1e-9 * S->mmagnitude;
  R->relative_moment_imbalance = S->mscale > 0 ? PetscSqrtReal(m2) / S->mscale : 0;
  R->moment_allowed            = S->mscale > 0 ? allowed / S->mscale : 0;
  PetscCheck(!R->nmoments || PetscSqrtReal(m2) <= allowed, sys->comm, PETSC_ERR_PLIB, "global equilibrium fails at load factor %g: the moments of the reactions and the applied loads about the body's centre sum to a relative imbalance of %.3g, more than the solve's residual tolerance allows (%.3g); the forces balance, so the internal forces of this rotation-invariant model carry a moment (a bond force not along its bond) or the free DOFs are not in equilibrium", (double)R->load_factor, (double)R->relative_moment_imbalance, (double)R->moment_allowed);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The force balance of the body: the reactions and the loads sum to R->imbalance. The solve leaves
 * on the free DOFs a residual r with ||r|| <= residual_tol ||b|| (b its right-hand side, scaled to
 * this load factor), whose sum over n particles is at most sqrt(n) ||r|| per component; a removed
 * load share along free rigid motions adds its own; round-off the rest. More than that is an error:
 * then either the internal forces do not sum to zero (a stiffness that is not translation-invariant)
 * or the free DOFs are not in equilibrium (K u differs from what the solver applied). */
static PetscErrorCode CheckEquilibrium(PeriSystem sys, PetscReal lambda, const PetscBool trans[], const Sums *S)
{
  PeriReactions  *R    = &sys->conditions.reactions;
  const PetscReal sqn  = PetscSqrtReal((PetscReal)sys->disc.N);
  PetscReal       imb2 = 0, allowed, factor = 0;
  char            what[256] = "";

  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < PERI_MAX_DOF; c++) {
    R->imbalance[c] = 0;
    if (!trans[c]) continue;
    R->imbalance[c] = R->applied[c];
    for (PetscInt r = 0; r < R->nregions; r++) R->imbalance[c] += R->force[r * PERI_MAX_DOF + c];
    imb2 += PetscSqr(R->imbalance[c]);
  }
  if (sys->fields.solve.load_factor != 0) factor = PetscAbsReal(lambda / sys->fields.solve.load_factor);
  allowed               = sqn * (sys->fields.solve.residual_tol * sys->fields.solve.rhs_norm * factor + sys->fields.solve.load_imbalance * PetscSqrtReal(S->load2)) + 1e-9 * S->magnitude;
  R->scale              = S->scale;
  R->relative_imbalance = S->scale > 0 ? PetscSqrtReal(imb2) / S->scale : 0;
  R->allowed            = S->scale > 0 ? allowed / S->scale : 0;
  R->load_factor        = lambda;
  R->evaluated          = PETSC_TRUE;
  /* fictitious layers carry their faces' forces in mirror relations, not in constrained DOFs */
  R->checked = sys->conditions.layers.T ? PETSC_FALSE : PETSC_TRUE;
  PetscCall(CheckMoments(sys, allowed, S));
  if (!R->checked || PetscSqrtReal(imb2) <= allowed) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt c = 0; c < sys->model->dofs; c++)
    if (trans[c]) {
      char item[96];
      PetscCall(PetscSNPrintf(item, sizeof(item), "%s%s: internal forces %g, free DOFs %g", what[0] ? "; " : "", sys->model->components[c], (double)S->total[c], (double)S->freesum[c]));
      PetscCall(PetscStrlcat(what, item, sizeof(what)));
    }
  SETERRQ(sys->comm, PETSC_ERR_PLIB, "global equilibrium fails at load factor %g: the reactions and the applied loads sum to a relative imbalance of %.3g, more than the solve's residual tolerance allows (%.3g). The sums (%s) say which: the internal forces of a translation-invariant stiffness sum to 0, and the free DOFs carry only the solver's residual", (double)lambda, (double)R->relative_imbalance, (double)R->allowed, what);
}

/*@C
  PeriSystemEvaluateReactions - from sys->fields.u at load factor lambda: the reaction of every constrained
  region (sum of K u - lambda f over the DOFs its bc items hold, K the unconstrained stiffness), the
  total applied load, and the check that they balance (an error when they do not). Collective.
@*/
PetscErrorCode PeriSystemEvaluateReactions(PeriSystem sys, PetscReal lambda)
{
  PeriReactions *R = &sys->conditions.reactions;
  PetscBool      trans[PERI_MAX_DOF];
  Sums           S;
  Vec            fint;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&S, sizeof(S)));
  PetscCall(Translations(sys->model, trans));
  for (PetscInt k = 0; k < R->nregions * PERI_MAX_DOF; k++) R->force[k] = 0;
  for (PetscInt c = 0; c < PERI_MAX_DOF; c++) R->applied[c] = 0;
  PetscCall(PeriSystemCreateVec(sys, &fint));
  PetscCall(InternalForce(sys, fint));
  PetscCall(SumOwned(sys, fint, lambda, trans, &S));
  PetscCall(VecDestroy(&fint));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, R->force, (PetscMPIInt)(R->nregions * PERI_MAX_DOF), MPIU_REAL, MPI_SUM, sys->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, R->applied, PERI_MAX_DOF, MPIU_REAL, MPI_SUM, sys->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &S, (PetscMPIInt)(sizeof(S) / sizeof(PetscReal)), MPIU_REAL, MPI_SUM, sys->comm));
  PetscCall(CheckEquilibrium(sys, lambda, trans, &S));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* a vector by component name: the components c with use[c] */
static PetscErrorCode ComponentObject(PeriSystem sys, PeriJSON j, const char name[], const PetscReal v[], const PetscBool use[])
{
  PetscFunctionBeginUser;
  PetscCall(PeriJSONBeginObject(j, name));
  for (PetscInt c = 0; c < sys->model->dofs; c++)
    if (use[c]) PetscCall(PeriJSONReal(j, sys->model->components[c], v[c]));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* applied_load, reactions (per region, the components it holds) and equilibrium, when evaluated. */
PetscErrorCode PeriReactionsSummary(PeriSystem sys, PeriJSON j)
{
  const PeriReactions *R = &sys->conditions.reactions;
  PetscBool            trans[PERI_MAX_DOF];

  PetscFunctionBeginUser;
  if (!R->evaluated || !sys->fields.has_solution) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(Translations(sys->model, trans));
  PetscCall(ComponentObject(sys, j, "applied_load", R->applied, trans));
  PetscCall(PeriJSONBeginObject(j, "reactions"));
  for (PetscInt r = 0; r < R->nregions; r++) {
    PetscBool any = PETSC_FALSE;
    for (PetscInt c = 0; c < PERI_MAX_DOF; c++) any = (PetscBool)(any || R->holds[r * PERI_MAX_DOF + c]);
    if (any) PetscCall(ComponentObject(sys, j, sys->disc.regions[r].name, &R->force[r * PERI_MAX_DOF], &R->holds[r * PERI_MAX_DOF]));
  }
  PetscCall(PeriJSONEndObject(j));
  PetscCall(PeriJSONBeginObject(j, "equilibrium"));
  PetscCall(ComponentObject(sys, j, "imbalance", R->imbalance, trans));
  PetscCall(PeriJSONReal(j, "relative_imbalance", R->relative_imbalance));
  PetscCall(PeriJSONReal(j, "allowed", R->allowed));
  PetscCall(PeriJSONReal(j, "force_scale", R->scale));
  PetscCall(PeriJSONBool(j, "checked", R->checked));
  PetscCall(PeriJSONBool(j, "moment_checked", R->nmoments > 0 ? PETSC_TRUE : PETSC_FALSE));
  if (R->nmoments) {
    static const char *const axes[] = {"x", "y", "z"};
    PetscCall(PeriJSONBeginObject(j, "moment_imbalance"));
    for (PetscInt q = 0; q < R->nmoments; q++) PetscCall(PeriJSONReal(j, axes[R->nmoments == 1 ? 2 : q], R->moment[q]));
    PetscCall(PeriJSONEndObject(j));
    PetscCall(PeriJSONReal(j, "relative_moment_imbalance", R->relative_moment_imbalance));
    PetscCall(PeriJSONReal(j, "moment_allowed", R->moment_allowed));
  }
  PetscCall(PeriJSONReal(j, "load_factor", R->load_factor));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}
