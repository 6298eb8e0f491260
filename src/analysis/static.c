/* Static analysis: K u = f with the prescribed DOFs eliminated symmetrically, solved with KSP
 * (CG + GAMG with the rigid-body near-null space unless the options say otherwise). */
#include "perilin.h"

/* What to tell the user when KSP stops without converging. */
static const char *Advice(KSPConvergedReason reason)
{
  switch (reason) {
  case KSP_DIVERGED_INDEFINITE_MAT:
  case KSP_DIVERGED_INDEFINITE_PC:
    return "the operator (or preconditioner) is not positive definite, so CG is unsafe: check the material constants and constraints, or use -ksp_type minres, or a direct solver (-ksp_type preonly -pc_type lu)";
  case KSP_DIVERGED_ITS:
    return "raise -ksp_max_it, or use a direct solver (-ksp_type preonly -pc_type cholesky)";
  case KSP_DIVERGED_BREAKDOWN:
  case KSP_DIVERGED_NANORINF:
    return "the operator may be singular (a part of the body not held?) or contain NaN";
  case KSP_DIVERGED_PC_FAILED:
    return "the preconditioner failed (a zero pivot: is the operator singular?)";
  default:
    return "see -ksp_converged_reason and -ksp_monitor_true_residual";
  }
}

/* What to tell the user when KSP claims convergence but the true residual is too large. */
static const char *AdviceResidual(PeriProblem p)
{
  if (!strcmp(p->results.ksp_type, KSPPREONLY)) return "preonly applies the preconditioner once, which solves the system only when it is a direct factorization: use -pc_type cholesky (or lu), or drop -ksp_type preonly for the default CG + GAMG";
  return "tighten -ksp_rtol, or check -ksp_norm_type (the preconditioned norm can be far below the true one); a larger solver.residual_tol accepts the answer as it is";
}

/* PETSc's own LU and Cholesky run on one rank only: on several, a factorization without a
 * -pc_factor_mat_solver_type is MUMPS's (when PETSc has it), so the README's direct-solver line
 * works on any number of ranks. */
static PetscBool ParallelFactor(void)
{
#if defined(PETSC_HAVE_MUMPS)
  PetscMPIInt size;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  return (PetscBool)(size > 1);
#else
  return PETSC_FALSE;
#endif
}

static PetscErrorCode DefaultFactorSolver(KSP ksp)
{
  PC        pc;
  PetscBool factor, set;

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &factor, PCLU, PCCHOLESKY, ""));
  PetscCall(PetscOptionsHasName(NULL, NULL, "-pc_factor_mat_solver_type", &set));
  if (factor && !set && ParallelFactor()) PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The block format (BAIJ) unless the preconditioner cannot take it: in PETSc 3.18 GAMG builds its
 * graph from AIJ only, and MUMPS factors BAIJ by LU only. -mat_type overrides this. */
PetscErrorCode PeriStaticDefaultMatType(char type[], size_t len)
{
  char      pc[64] = PCGAMG, solver[64] = "";
  PetscBool gamg, cholesky, mumps, aij;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-pc_type", pc, sizeof(pc), NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-pc_factor_mat_solver_type", solver, sizeof(solver), NULL));
  PetscCall(PetscStrcmp(pc, PCGAMG, &gamg));
  PetscCall(PetscStrcmp(pc, PCCHOLESKY, &cholesky));
  PetscCall(PetscStrcmp(solver, MATSOLVERMUMPS, &mumps));
  mumps = (PetscBool)(mumps || (!solver[0] && ParallelFactor()));
  /* other external factorizations (superlu_dist, umfpack, cholmod, ...) take AIJ only */
  aij = (PetscBool)(gamg || (cholesky && mumps) || (solver[0] && !mumps && strcmp(solver, MATSOLVERPETSC)));
  PetscCall(PetscStrncpy(type, aij ? MATAIJ : MATBAIJ, len));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* DOFs to hold at 0 so that the free rigid motions v[] (orthonormal) become determined: Gaussian
 * elimination with complete pivoting on the modes' entries picks well-separated DOFs. Collective;
 * each rank gets the pins it owns. */
static PetscErrorCode PinFreeMotions(PeriProblem p, PetscInt nfree, Vec v[], PetscInt *npin, PetscInt pins[])
{
  Vec      w[PERI_MAX_MODES], t;
  PetscInt rstart, rend;

  PetscFunctionBeginUser;
  *npin = 0;
  PetscCall(VecGetOwnershipRange(v[0], &rstart, &rend));
  PetscCall(VecDuplicate(v[0], &t));
  for (PetscInt q = 0; q < nfree; q++) {
    PetscCall(VecDuplicate(v[q], &w[q]));
    PetscCall(VecCopy(v[q], w[q]));
  }
  for (PetscInt q = 0; q < nfree; q++) {
    PetscInt  idx;
    PetscReal amax, pivot = 0;
    PetscCall(VecCopy(w[q], t));
    PetscCall(VecAbs(t));
    PetscCall(VecMax(t, &idx, &amax));
    if (idx >= rstart && idx < rend) {
      PetscCall(VecGetValues(w[q], 1, &idx, &pivot));
      pins[(*npin)++] = idx;
    }
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &pivot, 1, MPIU_REAL, MPI_SUM, p->comm));
    for (PetscInt r = q + 1; r < nfree; r++) {
      PetscReal c = 0;
      if (idx >= rstart && idx < rend) PetscCall(VecGetValues(w[r], 1, &idx, &c));
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &c, 1, MPIU_REAL, MPI_SUM, p->comm));
      PetscCall(VecAXPY(w[r], -c / pivot, w[q]));
    }
  }
  for (PetscInt q = 0; q < nfree; q++) PetscCall(VecDestroy(&w[q]));
  PetscCall(VecDestroy(&t));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rigid motions the constraints leave free: an error when the loads would accelerate the body;
 * otherwise (a self-equilibrated free body, a bar in torsion) the loads' round-off share along them
 * is removed, enough DOFs are pinned to make A regular, and the caller projects the solution. */
static PetscErrorCode HandleFreeMotions(PeriProblem p, Mat A, Vec u, Vec b, PetscReal diag, PetscInt nhold, const PetscInt hold[], PetscInt *nfree, Vec free[])
{
  char      what[128];
  PetscReal bnorm, share = 0;
  PetscInt  npin, pins[PERI_MAX_MODES], nkeep = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriRigidMotionFree(p, nfree, what, sizeof(what), free));
  /* held pieces do not move with the body: the motions live on the rest */
  for (PetscInt q = 0; q < *nfree; q++) {
    PetscReal norm;
    for (PetscInt k = 0; k < nhold; k++) PetscCall(VecSetValue(free[q], hold[k], 0.0, INSERT_VALUES));
    PetscCall(VecAssemblyBegin(free[q]));
    PetscCall(VecAssemblyEnd(free[q]));
    for (PetscInt r = 0; r < nkeep; r++) {
      PetscScalar dot;
      PetscCall(VecDot(free[q], free[r], &dot));
      PetscCall(VecAXPY(free[q], -dot, free[r]));
    }
    PetscCall(VecNormalize(free[q], &norm));
    if (norm > 1e-8)
      free[nkeep++] = free[q];
    else
      PetscCall(VecDestroy(&free[q]));
  }
  *nfree = nkeep;
  if (!*nfree) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecNorm(b, NORM_2, &bnorm));
  for (PetscInt q = 0; q < *nfree; q++) {
    PetscScalar dot;
    PetscCall(VecDot(b, free[q], &dot));
    share += PetscSqr(PetscRealPart(dot));
  }
  share                     = bnorm > 0 ? PetscSqrtReal(share) / bnorm : 0;
  p->results.free_modes     = *nfree;
  p->results.load_imbalance = share;
  PetscCheck(bnorm > 0 && share<1e-6, p->comm, PETSC_ERR_USER_INPUT, "%s: the boundary conditions leave a rigid-body motion free (mainly %s): the stiffness matrix is singular%s. Constrain it in bc (e.g. fix the component on a small region)", p->scene->file, what, bnorm> 0 ? " and the loads are not balanced along it" : "");
  for (PetscInt q = 0; q < *nfree; q++) {
    PetscScalar dot;
    PetscCall(VecDot(b, free[q], &dot));
    PetscCall(VecAXPY(b, -dot, free[q]));
  }
  PetscCall(PinFreeMotions(p, *nfree, free, &npin, pins));
  PetscCall(MatZeroRowsColumns(A, npin, pins, diag, u, b));
  if (!p->results.free_modes_noted) PetscCall(PetscPrintf(p->comm, "perilin: note: the constraints leave %" PetscInt_FMT " rigid motion(s) free (mainly %s) and the loads are balanced along them (share %.2e): the solution orthogonal to them is computed\n", *nfree, what, (double)share));
  p->results.free_modes_noted = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* KSP's own convergence test (default or from the options), and a signal check after it. */
typedef struct {
  PetscErrorCode (*test)(KSP, PetscInt, PetscReal, KSPConvergedReason *, void *);
  void *ctx;
  PetscErrorCode (*destroy)(void *);
  MPI_Comm comm;
} InterruptibleTest;

/* Stops the iteration (KSP_DIVERGED_NULL) once any rank has received SIGINT or SIGTERM: the
 * convergence test runs on every rank at every iteration, so all ranks stop together. */
static PetscErrorCode ConvergedOrInterrupted(KSP ksp, PetscInt it, PetscReal rnorm, KSPConvergedReason *reason, void *ctx)
{
  InterruptibleTest *t = (InterruptibleTest *)ctx;
  int                sig;

  PetscFunctionBeginUser;
  PetscCall((*t->test)(ksp, it, rnorm, reason, t->ctx));
  if (*reason) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSignalReceived(t->comm, &sig));
  if (sig) *reason = KSP_DIVERGED_NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode InterruptibleTestDestroy(void *ctx)
{
  InterruptibleTest *t = (InterruptibleTest *)ctx;

  PetscFunctionBeginUser;
  if (t->destroy) PetscCall((*t->destroy)(t->ctx));
  PetscCall(PetscFree(t));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode KSPSetInterruptible(KSP ksp, MPI_Comm comm)
{
  InterruptibleTest *t;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&t));
  t->comm = comm;
  PetscCall(KSPGetAndClearConvergenceTest(ksp, &t->test, &t->ctx, &t->destroy));
  PetscCall(KSPSetConvergenceTest(ksp, ConvergedOrInterrupted, t, InterruptibleTestDestroy));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* GAMG and its coarse LU hold absolute thresholds (a pivot below 2.2e-14 is zero; the
 * eigen-estimates of the smoothed prolongators collapse for K ~ 1e40), so the result depended on
 * the units of E. Solving A/diag u = b/diag gives the same u with O(1) matrix entries; what no
 * scaling can help (a stiffness or a displacement scale beyond double precision) is refused. */
static PetscErrorCode ScaleToUnits(PeriProblem p, Mat A, Vec b, PetscReal *diag)
{
  PeriNode mat;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(p->scene->root, "material", &mat));
  PeriInputCheck(*diag > 0 && PetscIsNormalReal(*diag) && *diag < 1e250 && *diag > 1e-250, p->scene, mat, "E", "the stiffness (mean diagonal of K: %g) is beyond what double precision can solve with: give the moduli, thickness and spacing in units that keep them within about 1e-100 to 1e100", (double)*diag);
  PetscCall(MatScale(A, 1 / *diag));
  PetscCall(VecScale(b, 1 / *diag));
  *diag = 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* After ScaleToUnits, b is of the order of the displacements: inf or NaN (loads or prescribed
 * values that overflow with K), or beyond 1e+-150 (where the squared norms of CG overflow or
 * underflow), is no problem a solver can help with; say so before KSP reports a breakdown that
 * looks like a singular operator. */
static PetscErrorCode CheckRightHandSide(PeriProblem p, Vec b)
{
  PetscReal norm, vmax = 0;

  PetscFunctionBeginUser;
  PetscCall(VecNorm(b, NORM_INFINITY, &norm));
  if (norm == 0 || (norm < 1e150 && norm > 1e-150)) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; k < p->nconstrained; k++) vmax = PetscMax(vmax, PetscAbsReal(p->constrained_value[k]));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &vmax, 1, MPIU_REAL, MPI_MAX, p->comm));
  PetscCheck(!PetscIsInfOrNanReal(norm), p->comm, PETSC_ERR_USER_INPUT, "%s: the loads and prescribed values overflow double precision (the right-hand side holds inf or NaN; largest prescribed value %g): give bc values and loads of a physical size", p->scene->file, (double)vmax);
  SETERRQ(p->comm, PETSC_ERR_USER_INPUT, "%s: the displacements would be of the order of %g (largest prescribed value %g), beyond what double precision can solve for (1e-150 to 1e150): check the units of the moduli, the loads and the bc values", p->scene->file, (double)norm, (double)vmax);
}

/* CG (GMRES for an unsymmetric operator) + GAMG, rtol 1e-10, then the options. */
static PetscErrorCode StaticKSPCreate(PeriProblem p, PetscBool symmetric, KSP *ksp)
{
  PC        pc;
  PetscBool cg, set;

  PetscFunctionBeginUser;
  PetscCall(KSPCreate(p->comm, ksp));
  PetscCall(KSPSetType(*ksp, symmetric ? KSPCG : KSPGMRES));
  PetscCall(KSPGetPC(*ksp, &pc));
  PetscCall(PCSetType(pc, PCGAMG));
  /* no absolute tolerance: the system is scaled to O(1) numbers (ScaleToUnits), and atol = 1e-50
     would stop CG at once on a tiny right-hand side */
  PetscCall(KSPSetTolerances(*ksp, 1e-10, 0.0, PETSC_DEFAULT, 10000));
  PetscCall(KSPSetFromOptions(*ksp));
  /* CG monitors the preconditioned residual by default, which GAMG lets sit 10-30x above the true
   * one: make -ksp_rtol bound the true relative residual unless the user chose a norm */
  PetscCall(PetscObjectTypeCompare((PetscObject)*ksp, KSPCG, &cg));
  PetscCall(PetscOptionsHasName(NULL, NULL, "-ksp_norm_type", &set));
  if (cg && !set) PetscCall(KSPSetNormType(*ksp, KSP_NORM_UNPRECONDITIONED));
  PetscCall(DefaultFactorSolver(*ksp));
  PetscCall(KSPSetInterruptible(*ksp, p->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* GAMG's default Chebyshev smoother misjudges the spectrum when the stiffness jumps by orders of
 * magnitude (an interface): switch the levels to symmetric SOR, unless told otherwise. Returns
 * whether it did. */
static PetscErrorCode SmootherFallback(PeriProblem p, KSP ksp, KSPConvergedReason reason, PetscBool *retry)
{
  PC        pc;
  PetscBool gamg, set;
  PetscInt  nl;

  PetscFunctionBeginUser;
  *retry = PETSC_FALSE;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCGAMG, &gamg));
  PetscCall(PetscOptionsHasName(NULL, NULL, "-mg_levels_ksp_type", &set));
  if (reason != KSP_DIVERGED_INDEFINITE_PC || !gamg || set) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PCMGGetLevels(pc, &nl));
  for (PetscInt l = 1; l < nl; l++) {
    KSP s;
    PC  sp;
    PetscCall(PCMGGetSmoother(pc, l, &s));
    PetscCall(KSPSetType(s, KSPRICHARDSON));
    PetscCall(KSPGetPC(s, &sp));
    PetscCall(PCSetType(sp, PCSOR));
  }
  PetscCall(PetscPrintf(p->comm, "perilin: note: GAMG with Chebyshev smoothing failed (%s); retrying with SOR smoothing (-mg_levels_ksp_type richardson -mg_levels_pc_type sor)\n", KSPConvergedReasons[reason]));
  *retry = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriStaticSolve - solves K u = lambda f for p->u with the prescribed values and the layers'
  offsets scaled by lambda, and the DOFs hold[] held at held[] (fragments). Fictitious layers are
  eliminated (A = R K T), prescribed DOFs symmetrically; a free body with balanced loads is solved
  orthogonal to its rigid motions. p->K is kept unless inplace. *ksp is created on first use
  (CG + GAMG, or GMRES for an unsymmetric operator, then the options). Sets p->results' solver
  fields and returns the converged reason instead of failing. Collective.
@*/
PetscErrorCode PeriStaticSolve(PeriProblem p, KSP *ksp, PetscReal lambda, PetscBool inplace, PetscInt nhold, const PetscInt hold[], const PetscReal held[], KSPConvergedReason *reason)
{
  Mat       A;
  Vec       r, b, free[PERI_MAX_MODES];
  PetscReal diag, fnorm, rnorm, *values;
  PetscInt  N, nfree = 0, nrows, *rows;
  PetscBool retry;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PERI_EVENT_Solve, 0, 0, 0, 0));
  if (!p->u) PetscCall(MatCreateVecs(p->K, &p->u, NULL));
  PetscCall(VecDuplicate(p->f, &b));
  PetscCall(VecCopy(p->f, b));
  PetscCall(VecScale(b, lambda));
  p->results.symmetric = PETSC_TRUE;
  if (p->layers.T)
    PetscCall(PeriLayersApply(p, lambda, &A, b));
  else if (inplace) {
    PetscCall(PetscObjectReference((PetscObject)p->K));
    A = p->K;
  } else
    PetscCall(MatDuplicate(p->K, MAT_COPY_VALUES, &A));
  PetscCall(PeriSetNearNullSpace(p, A));
  nrows = p->nconstrained + nhold;
  PetscCall(PetscMalloc2(nrows, &rows, nrows, &values));
  for (PetscInt k = 0; k < p->nconstrained; k++) {
    rows[k]   = p->constrained[k];
    values[k] = lambda * p->constrained_value[k];
  }
  for (PetscInt k = 0; k < nhold; k++) {
    rows[p->nconstrained + k]   = hold[k];
    values[p->nconstrained + k] = held[k];
  }
  PetscCall(VecSetValues(p->u, nrows, rows, values, INSERT_VALUES));
  PetscCall(VecAssemblyBegin(p->u));
  PetscCall(VecAssemblyEnd(p->u));
  /* a unit of the mean diagonal on eliminated rows keeps the conditioning of the free block */
  PetscCall(MatCreateVecs(A, &r, NULL));
  PetscCall(MatGetDiagonal(A, r));
  PetscCall(VecNorm(r, NORM_1, &diag));
  PetscCall(VecGetSize(r, &N));
  diag /= N;
  PetscCall(ScaleToUnits(p, A, b, &diag));
  {
    PetscBool mpisbaij;
    PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPISBAIJ, &mpisbaij));
    PetscCheck(!mpisbaij, p->comm, PETSC_ERR_SUP, "-mat_type sbaij on several ranks cannot eliminate the prescribed DOFs (PETSc has no MatZeroRowsColumns for MPISBAIJ): use -mat_type baij or aij (MUMPS Cholesky works on both)");
  }
  PetscCall(MatZeroRowsColumns(A, nrows, rows, diag, p->u, b));
  PetscCall(PetscFree2(rows, values));
  PetscCall(CheckRightHandSide(p, b));
  PetscCall(HandleFreeMotions(p, A, p->u, b, diag, nhold, hold, &nfree, free));

  if (!*ksp) PetscCall(StaticKSPCreate(p, p->results.symmetric, ksp));
  PetscCall(KSPSetOperators(*ksp, A, A));
  PetscCall(KSPSolve(*ksp, b, p->u));
  PetscCall(KSPGetConvergedReason(*ksp, reason));
  PetscCall(SmootherFallback(p, *ksp, *reason, &retry));
  if (retry) {
    PetscCall(KSPSolve(*ksp, b, p->u));
    PetscCall(KSPGetConvergedReason(*ksp, reason));
  }
  PetscCall(KSPGetIterationNumber(*ksp, &p->results.iterations));
  /* the true relative residual, whatever norm the KSP monitored */
  PetscCall(MatMult(A, p->u, r));
  PetscCall(VecAYPX(r, -1, b));
  PetscCall(VecNorm(r, NORM_2, &rnorm));
  PetscCall(VecNorm(b, NORM_2, &fnorm));
  p->results.residual_norm = fnorm > 0 ? rnorm / fnorm : rnorm;
  {
    KSPType kt;
    PCType  pt;
    PC      pc;
    PetscCall(KSPGetType(*ksp, &kt));
    PetscCall(KSPGetPC(*ksp, &pc));
    PetscCall(PCGetType(pc, &pt));
    PetscCall(PetscStrncpy(p->results.ksp_type, kt, sizeof(p->results.ksp_type)));
    PetscCall(PetscStrncpy(p->results.pc_type, pt, sizeof(p->results.pc_type)));
  }
  PetscCall(PetscStrncpy(p->results.converged_reason, KSPConvergedReasons[*reason], sizeof(p->results.converged_reason)));
  for (PetscInt q = 0; q < nfree; q++) {
    PetscScalar dot;
    PetscCall(VecDot(p->u, free[q], &dot));
    PetscCall(VecAXPY(p->u, -dot, free[q]));
    PetscCall(VecDestroy(&free[q]));
  }
  PetscCall(PeriLayersComplete(p, lambda, p->u));
  PetscCall(VecDestroy(&r));
  PetscCall(VecDestroy(&b));
  PetscCall(MatDestroy(&A));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Solve, 0, 0, 0, 0));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the last solve is trustworthy: KSP's reason is not enough (preonly reports
 * CONVERGED_ITS after one application of any preconditioner), so the true relative residual
 * ||b - A x|| / ||b|| must also lie below solver.residual_tol. */
PetscErrorCode PeriStaticConverged(PeriProblem p, KSP ksp, KSPConvergedReason reason, PetscBool *ok)
{
  PetscReal rtol;

  PetscFunctionBeginUser;
  PetscCall(KSPGetTolerances(ksp, &rtol, NULL, NULL, NULL));
  p->results.residual_tol = PeriResidualTolerance(p, rtol);
  *ok                     = (PetscBool)(reason > 0 && !PetscIsInfOrNanReal(p->results.residual_norm) && p->results.residual_norm <= p->results.residual_tol);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What a failed static solve tells the user (after PeriStaticConverged). */
PetscErrorCode PeriStaticCheckConverged(PeriProblem p, KSPConvergedReason reason)
{
  PetscBool ok = (PetscBool)(reason > 0 && p->results.residual_norm <= p->results.residual_tol);

  PetscFunctionBeginUser;
  PetscCheck(!PetscIsInfOrNanReal(p->results.residual_norm), p->comm, PETSC_ERR_NOT_CONVERGED, "the static solve did not converge: the solution contains NaN or Inf (%s/%s, %s): %s", p->results.ksp_type, p->results.pc_type, KSPConvergedReasons[reason], Advice(KSP_DIVERGED_NANORINF));
  PetscCheck(reason > 0, p->comm, PETSC_ERR_NOT_CONVERGED, "the static solve did not converge: true relative residual %.3g (tolerance %.3g), %s/%s stopped with %s after %" PetscInt_FMT " iterations: %s", (double)p->results.residual_norm, (double)p->results.residual_tol, p->results.ksp_type, p->results.pc_type, KSPConvergedReasons[reason], p->results.iterations, Advice(reason));
  PetscCheck(ok, p->comm, PETSC_ERR_NOT_CONVERGED, "the static solve did not converge: true relative residual %.3g > tolerance %.3g although %s/%s reported %s after %" PetscInt_FMT " iterations: %s", (double)p->results.residual_norm, (double)p->results.residual_tol, p->results.ksp_type, p->results.pc_type, KSPConvergedReasons[reason], p->results.iterations, AdviceResidual(p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisRun_Static - solves the linear static problem once and evaluates energies and probes.
  Options: every KSP/PC option (-ksp_type, -pc_type, -ksp_rtol, ...). Collective.
@*/
static PetscErrorCode PeriAnalysisRun_Static(PeriProblem p)
{
  KSP                ksp = NULL;
  PetscInt           nc;
  KSPConvergedReason reason;
  PetscLogDouble     t0, t1;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&p->nconstrained, &nc, 1, MPIU_INT, MPI_SUM, p->comm));
  if (nc == p->particles.n * p->model->dofs) {
    /* every DOF prescribed: the solution is known, K is not needed */
    PetscCall(VecDestroy(&p->u));
    PetscCall(PeriProblemCreateVec(p, &p->u));
    PetscCall(VecSetValues(p->u, p->nconstrained, p->constrained, p->constrained_value, INSERT_VALUES));
    PetscCall(VecAssemblyBegin(p->u));
    PetscCall(VecAssemblyEnd(p->u));
    PetscCall(PetscStrncpy(p->results.ksp_type, "none", sizeof(p->results.ksp_type)));
    PetscCall(PetscStrncpy(p->results.pc_type, "none", sizeof(p->results.pc_type)));
    PetscCall(PetscStrncpy(p->results.converged_reason, "ALL_DOFS_PRESCRIBED", sizeof(p->results.converged_reason)));
    PetscCall(PeriProblemEvaluateEnergy(p));
    PetscCall(PeriReferenceEvaluate(p));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PeriStaticDefaultMatType(p->mat_type, sizeof(p->mat_type)));
  if (!p->K) PetscCall(PeriProblemAssemble(p));
  PetscCall(PetscTime(&t0));
  PetscCall(VecDestroy(&p->u));
  {
    /* pieces cut off by cracks: held in place when unloaded, an error when loaded */
    PetscInt   nhold, npieces, *hold;
    PetscReal *held;
    PetscBool  lost;
    PetscCall(PeriPieces(p, &nhold, &hold, &held, &npieces, &lost));
    PetscCheck(!lost, p->comm, PETSC_ERR_USER_INPUT, "%s: the body is in %" PetscInt_FMT " pieces and a loaded one is not connected to the constraints: it cannot carry its load", p->scene->file, npieces);
    if (npieces > 1) PetscCall(PetscPrintf(p->comm, "perilin: note: the body is in %" PetscInt_FMT " pieces; those not connected to the constraints are unloaded and held in place\n", npieces));
    PetscCall(PeriStaticSolve(p, &ksp, 1.0, PETSC_TRUE, nhold, hold, held, &reason));
    PetscCall(PetscFree2(hold, held));
  }
  PetscCall(PeriSignalReceived(p->comm, &p->interrupted));
  if (p->interrupted) {
    /* an unfinished solve is no result: the output will say so and hold no fields */
    PetscCall(KSPDestroy(&ksp));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  {
    PetscBool ok;
    PetscCall(PeriStaticConverged(p, ksp, reason, &ok));
  }
  PetscCall(KSPDestroy(&ksp));
  PetscCall(PeriStaticCheckConverged(p, reason));
  PetscCall(PetscTime(&t1));
  p->results.solve_s = t1 - t0;
  PetscCall(PeriProblemEvaluateEnergy(p));
  PetscCall(PeriReferenceEvaluate(p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

const PeriAnalysisType PeriAnalysis_Static = {"static", NULL, PeriAnalysisRun_Static};
