/* The stiffness part (include/perilin/private/stiffness.h): K built as the scene and the analysis
 * ask (assembled, or matrix-free with its preconditioning matrix), changed bond by bond as bonds
 * break or soften, and freed. Assembly itself is in assembly.c, the matrix-free operator in
 * operator.c, the checked solve in solve.c. */
#include "perilin/private/system.h"

/* Why K cannot be matrix-free for this system and analysis, or NULL when it can. */
const char *PeriMatrixFreeWhyNot(PeriSystem sys)
{
  const char *why = PeriOperatorWhyNotModel(sys->model);

  if (why) return why;
  /* measured on examples/fracture/micropolar_shear.yaml: CG + GAMG on the short-range stiffness
     stopped converging after a few hundred breaks (at load factor 0.455 of 2) */
  if (!sys->model->central_force && sys->bond_state.failure.active) return "bond failure with shear or micropolar bonds: the short-range preconditioner does not follow their breaks well enough for CG to converge";
  if (!sys->stiffness.needs.matrix_free) return "the analysis needs K's entries (matrix_free serves the static, quasi-static, tune and explicit dynamic analyses)";
  if (sys->conditions.layers.T) return "fictitious layers eliminate K's rows through its entries";
  return NULL;
}

/* solver.operator: matrix_free applies to the bond-based models whose blocks operator.c knows
 * (central, 2D shear and micropolar) in the analyses that allow it, without fictitious layers
 * (and for shear and micropolar bonds without failure); auto takes it with GAMG (the default),
 * where it wins (docs/performance.md), and assembled K elsewhere. */
static PetscErrorCode UseMatrixFree(PeriSystem sys, PetscBool *mf)
{
  const char *why = PeriMatrixFreeWhyNot(sys);
  PeriNode    node;

  PetscFunctionBeginUser;
  *mf = (PetscBool)(!why && (sys->stiffness.operator_kind == PERI_OPERATOR_MATRIX_FREE || sys->stiffness.operator_kind == PERI_OPERATOR_AUTO));
  if (*mf && sys->stiffness.operator_kind == PERI_OPERATOR_AUTO) {
    /* the short-range stiffness serves AMG, the diagonal Jacobi; another -pc_type (a
       factorization) gets K itself */
    char pc[64] = PCGAMG;
    PetscCall(PetscOptionsGetString(NULL, NULL, "-pc_type", pc, sizeof(pc), NULL));
    *mf = PeriOperatorServesPC(pc);
    /* the patch calibration may make springs negative (an irregular family's correction), which
       the operator cannot apply: auto takes K assembled (matrix_free still tries, and says so) */
    if (sys->model->calibration == PERI_CALIBRATION_PATCH) *mf = PETSC_FALSE;
  }
  if (sys->stiffness.operator_kind != PERI_OPERATOR_MATRIX_FREE || !why) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetNode(sys->scene->root, "solver", &node)); /* locates the message only */
  PeriInputCheck(PETSC_FALSE, sys->scene, node, "operator", "matrix_free cannot apply here: %s; use assembled or auto", why);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the body is held along at least an edge's worth of DOFs (a clamp), not at a few points
 * (pins): as many constrained DOFs as the model's DOFs per particle times the span in spacings.
 * Collective. */
static PetscErrorCode Clamped(PeriSystem sys, PetscReal span, PetscBool *clamped)
{
  PetscInt n = sys->conditions.nconstrained, N;

  PetscFunctionBeginUser;
  PetscCallMPI(MPIU_Allreduce(&n, &N, 1, MPIU_INT, MPI_SUM, sys->comm));
  *clamped = (PetscBool)(N >= sys->model->dofs * span);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The static solves' default PC (docs/performance.md, "Defaults that pick the fastest" and
 * "Geometric multigrid"), from the measured crossovers:
 *   - Jacobi on a 2D body of shear or micropolar bonds up to PERI_JACOBI_MAX_SPAN_2D spacings
 *     across, where a few hundred cheap products beat any set-up (2x faster than GAMG); up to
 *     PERI_JACOBI_MAX_SPAN_2D_CLAMPED where the body is clamped (Clamped) and the multigrid
 *     applies: its coarse levels hold a clamp well and points poorly (the mppd lamina held by two
 *     pins: 32-34 CG iterations; clamped at its base: 13-17, as the gerstle one);
 *   - Jacobi on a 2D antiplane body (one DOF per particle) without failure up to
 *     PERI_JACOBI_MAX_SPAN_ANTIPLANE spacings (with failure GAMG's hierarchy serves the whole
 *     quasi-static run: cracked_bar 5.2 s against Jacobi's 9.1 s);
 *   - perilin's geometric multigrid on a matrix-free K of a grid body (src/system/multigrid.c),
 *     2D, or 3D from PERI_MG_MIN_PARTICLES_3D particles on (27,000: a tie with Jacobi; 64,000:
 *     1.4x faster); 1.8-2.4x faster than GAMG with 25-30 % less memory;
 *   - Jacobi on a matrix-free K of a smaller 3D body, up to about 5e5 particles and 200 spacings
 *     across where the multigrid does not apply (no stored preconditioning matrix);
 *   - GAMG elsewhere (assembled K, meshes, periodic bodies, failure). */
static PetscErrorCode DefaultPC(PeriSystem sys)
{
  const PeriParticles *pt     = &sys->disc.particles;
  const PeriModel      m      = sys->model;
  const char          *pc     = PCGAMG;
  const PetscBool      mg     = (PetscBool)(sys->stiffness.op && PeriMultigridApplies(sys) && (pt->dim == 2 || sys->disc.N >= PERI_MG_MIN_PARTICLES_3D));
  PetscReal            extent = 0, span;
  PetscBool            clamped;

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < pt->dim; d++) extent = PetscMax(extent, pt->upper[d] - pt->lower[d]);
  span = extent / pt->mean_spacing;
  PetscCall(Clamped(sys, span, &clamped));
  if (pt->dim == 2 && !m->central_force && m->dofs >= 2 && span <= (mg && clamped ? PERI_JACOBI_MAX_SPAN_2D_CLAMPED : PERI_JACOBI_MAX_SPAN_2D))
    pc = PCJACOBI;
  else if (pt->dim == 2 && m->dofs == 1 && !sys->bond_state.failure.active && span <= PERI_JACOBI_MAX_SPAN_ANTIPLANE)
    pc = PCJACOBI;
  else if (mg)
    pc = PCMG;
  else if (sys->stiffness.op && pt->dim == 3 && sys->disc.N <= PERI_JACOBI_MAX_PARTICLES && span <= PERI_JACOBI_MAX_SPAN)
    pc = PCJACOBI;
  PetscCall(PetscStrncpy(sys->stiffness.pc_default, pc, sizeof(sys->stiffness.pc_default)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriSystemAssemble(PeriSystem sys)
{
  PetscLogDouble t0, t1;
  PetscBool      mf;

  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PERI_STAGE_Assembly));
  PetscCall(PeriProgressUpdate(sys->run.progress, PERI_PROGRESS_PHASE, "assembly"));
  PetscCall(PetscTime(&t0));
  PetscCall(MatDestroy(&sys->stiffness.K));
  PetscCall(MatDestroy(&sys->stiffness.Kpc));
  PetscCall(PeriOperatorDestroy(&sys->stiffness.op));
  sys->stiffness.pc_default[0] = 0;
  PetscCall(UseMatrixFree(sys, &mf));
  if (mf) {
    PetscCall(PetscLogEventBegin(PERI_EVENT_Assembly, 0, 0, 0, 0));
    PetscCall(PeriOperatorCreate(sys, sys->stiffness.pc_radius, &sys->stiffness.op));
    PetscCall(DefaultPC(sys));
    PetscCall(PeriOperatorCreateMat(sys, &sys->stiffness.K));
    PetscCall(PetscLogEventEnd(PERI_EVENT_Assembly, 0, 0, 0, 0));
  } else {
    PetscCall(DefaultPC(sys));
    PetscCall(PeriAssembleStiffness(sys, &sys->stiffness.K));
  }
  PetscCall(PetscTime(&t1));
  sys->run.log.assembly_s = t1 - t0;
  if (sys->run.log.matrix_mb == 0) { /* the first assembly: K's size and the memory it took */
    PetscReal opmb = 0;
    if (sys->stiffness.op)
      PetscCall(PeriOperatorMemoryMB(sys, sys->stiffness.op, &opmb));
    else
      PetscCall(PeriMatrixMB(sys->stiffness.K, &sys->run.log.matrix_mb));
    sys->run.log.matrix_mb += opmb;
    sys->run.log.memory_phase_mb[1] = PeriPeakMemoryMB();
  }
  PetscCall(PetscLogStagePop());
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriStiffnessScaleBond - scales the stiffness of bond k of owned particle i (live, not a
  self-image) by factor >= 0 in K: 0 breaks it (PeriOperatorScaleBond says what a matrix-free K's
  preconditioning matrix does). Call PeriStiffnessScaled after the last. Not collective.
  With ue (the bond's DOFs: i's, then j's), *released is the strain energy the change takes out,
  -(1/2) ue^T dK_e ue: summed over every change it is (1/2) u^T (K_before - K_after) u exactly,
  without two products with K (the dynamic analysis' dissipated energy).
@*/
PetscErrorCode PeriStiffnessScaleBond(PeriSystem sys, PetscInt i, PetscInt k, PetscReal factor, const PetscReal ue[], PetscReal *released)
{
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF];
  PeriBondGeometry g;
  PetscInt         idx[2];
  const PetscInt   n = 2 * sys->model->dofs;

  PetscFunctionBeginUser;
  /* the matrix-free operator scales the bond's whole block; the matrix adds the change of it */
  PetscCall(PeriBondStiffness(sys, i, k, sys->stiffness.op ? 1 : factor - 1, &g, Ke));
  if (ue) {
    PetscReal e = 0;
    for (PetscInt r = 0; r < n; r++)
      for (PetscInt c = 0; c < n; c++) e += ue[r] * Ke[r * n + c] * ue[c];
    *released = -0.5 * (sys->stiffness.op ? factor - 1 : 1) * e;
  }
  if (sys->stiffness.op) {
    PetscCall(PeriOperatorScaleBond(sys, i, k, factor, Ke));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  idx[0] = sys->disc.particles.global[i];
  idx[1] = sys->disc.particles.global[g.j];
  PetscCall(MatSetValuesBlocked(sys->stiffness.K, 2, idx, 2, idx, Ke, ADD_VALUES));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* After the last PeriStiffnessScaleBond: the matrices' assembly. Collective. */
PetscErrorCode PeriStiffnessScaled(PeriSystem sys)
{
  PetscFunctionBeginUser;
  if (sys->stiffness.op)
    PetscCall(PeriOperatorScaled(sys));
  else {
    PetscCall(MatAssemblyBegin(sys->stiffness.K, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(sys->stiffness.K, MAT_FINAL_ASSEMBLY));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemGetJacobian - the linearized operator of the system's interaction terms (bonds,
  states): K, assembled or matrix-free as the scene and the analysis ask, built on first use. The
  analyses solve and multiply with it, never with the terms' data. Collective on first use.
@*/
PetscErrorCode PeriSystemGetJacobian(PeriSystem sys, Mat *K)
{
  PetscFunctionBeginUser;
  if (!sys->stiffness.K) PetscCall(PeriSystemAssemble(sys));
  *K = sys->stiffness.K;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemAddTerm - adds an interaction term to those the system applies besides the bonds
  (PeriTermOps). Not collective: every rank adds the same terms in the same order.
@*/
PetscErrorCode PeriSystemAddTerm(PeriSystem sys, const PeriTermOps *term)
{
  PeriStiffness *S = &sys->stiffness;

  PetscFunctionBeginUser;
  PetscCheck(S->nterms < PERI_MAX_TERMS, PETSC_COMM_SELF, PETSC_ERR_PLIB, "at most %d interaction terms besides the bonds (PERI_MAX_TERMS): %s is one too many", PERI_MAX_TERMS, term->name);
  S->terms[S->nterms++] = term;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemInternalForceParts - ku = K u, and f = K u + the terms' forces: the force the
  interactions exert at the displacements u (the bonds of the linear models: their Jacobian times
  u; the terms, such as contact, that are not linear add their own). f may be ku; ku is what
  PeriSystemStrainEnergyFromProduct takes. Collective.
@*/
PetscErrorCode PeriSystemInternalForceParts(PeriSystem sys, Vec u, Vec ku, Vec f)
{
  Mat K = NULL;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemGetJacobian(sys, &K));
  PetscCall(MatMult(K, u, ku));
  if (f != ku) PetscCall(VecCopy(ku, f));
  for (PetscInt k = 0; k < sys->stiffness.nterms; k++)
    if (sys->stiffness.terms[k]->add_force) PetscCall(sys->stiffness.terms[k]->add_force(sys, u, f));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemInternalForce - f = K u + the terms' forces (PeriSystemInternalForceParts). Collective.
@*/
PetscErrorCode PeriSystemInternalForce(PeriSystem sys, Vec u, Vec f)
{
  PetscFunctionBeginUser;
  PetscCall(PeriSystemInternalForceParts(sys, u, f, f));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* rows += the terms' bounds of their row sums. */
static PetscErrorCode TermsRowSums(PeriSystem sys, Vec rows)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < sys->stiffness.nterms; k++)
    if (sys->stiffness.terms[k]->add_row_sums) PetscCall(sys->stiffness.terms[k]->add_row_sums(sys, rows));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemStrainEnergyFromProduct - the energy the interactions hold at u, given ku = K u:
  (1/2) u^T K u of the bonds and the terms' own (contact). Collective.
@*/
PetscErrorCode PeriSystemStrainEnergyFromProduct(PeriSystem sys, Vec u, Vec ku, PetscReal *E)
{
  PetscScalar e;
  PetscReal   ec;

  PetscFunctionBeginUser;
  PetscCall(VecDot(u, ku, &e));
  *E = 0.5 * PetscRealPart(e);
  for (PetscInt k = 0; k < sys->stiffness.nterms; k++) {
    if (!sys->stiffness.terms[k]->energy) continue;
    PetscCall(sys->stiffness.terms[k]->energy(sys, u, &ec));
    *E += ec;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemStrainEnergy - the energy the interactions hold at u (PeriSystemStrainEnergyFromProduct
  after a product with K into work, a vector of u's layout). Collective.
@*/
PetscErrorCode PeriSystemStrainEnergy(PeriSystem sys, Vec u, Vec work, PetscReal *E)
{
  Mat K = NULL;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemGetJacobian(sys, &K));
  PetscCall(MatMult(K, u, work));
  PetscCall(PeriSystemStrainEnergyFromProduct(sys, u, work, E));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemStiffnessRowSums - the absolute row sums of K (Gershgorin's bound): from the rows of
  an assembled K (exact), or from the terms of a matrix-free one (from above). Collective.
@*/
PetscErrorCode PeriSystemStiffnessRowSums(PeriSystem sys, Vec rows)
{
  Mat          K = NULL;
  PetscInt     rstart, rend;
  PetscScalar *ra;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemGetJacobian(sys, &K));
  if (sys->stiffness.op) {
    PetscCall(PeriOperatorRowSums(sys, rows));
    PetscCall(TermsRowSums(sys, rows));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(MatGetOwnershipRange(K, &rstart, &rend));
  PetscCall(VecGetArray(rows, &ra));
  for (PetscInt r = rstart; r < rend; r++) {
    const PetscScalar *v;
    PetscInt           nc;
    ra[r - rstart] = 0;
    PetscCall(MatGetRow(K, r, &nc, NULL, &v));
    for (PetscInt k = 0; k < nc; k++) ra[r - rstart] += PetscAbsScalar(v[k]);
    PetscCall(MatRestoreRow(K, r, &nc, NULL, &v));
  }
  PetscCall(VecRestoreArray(rows, &ra));
  PetscCall(TermsRowSums(sys, rows));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Frees K, its preconditioning matrix and the matrix-free operator. */
PetscErrorCode PeriStiffnessDestroy(PeriStiffness *S)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&S->K));
  PetscCall(MatDestroy(&S->Kpc));
  PetscCall(PeriOperatorDestroy(&S->op));
  PetscFunctionReturn(PETSC_SUCCESS);
}
