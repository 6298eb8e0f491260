/* Static solves of K u = f with held DOFs, free rigid motions, fallbacks and a true-residual check. */
#include "perilin/private/system.h"
#include "perilin/private/sys.h"

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
static const char *AdviceResidual(PeriSystem sys)
{
  if (sys->stiffness.op && !strcmp(sys->fields.solve.ksp_type, KSPPREONLY)) return "with solver.operator: matrix_free the preconditioner is built from the short-range stiffness only, so preonly cannot solve the system: use solver.operator: assembled (-solver_operator assembled) for a direct solve, or drop -ksp_type preonly";
  if (!strcmp(sys->fields.solve.ksp_type, KSPPREONLY)) return "preonly applies the preconditioner once, which solves the system only when it is a direct factorization: use -pc_type cholesky (or lu), or drop -ksp_type preonly for the default CG + GAMG";
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
static PetscErrorCode PinFreeMotions(PeriSystem sys, PetscInt nfree, Vec v[], PetscInt *npin, PetscInt pins[])
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
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &pivot, 1, MPIU_REAL, MPI_SUM, sys->comm));
    for (PetscInt r = q + 1; r < nfree; r++) {
      PetscReal c = 0;
      if (idx >= rstart && idx < rend) PetscCall(VecGetValues(w[r], 1, &idx, &c));
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &c, 1, MPIU_REAL, MPI_SUM, sys->comm));
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
static PetscErrorCode HandleFreeMotions(PeriSystem sys, Mat A, Mat P, Vec u, Vec b, PetscReal diag, PetscInt nhold, const PetscInt hold[], PetscInt *nfree, Vec free[])
{
  char      what[128];
  PetscReal bnorm, share = 0;
  PetscInt  npin, pins[PERI_MAX_MODES], nkeep = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriRigidMotionFree(sys, nfree, what, sizeof(what), free));
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
  share                            = bnorm > 0 ? PetscSqrtReal(share) / bnorm : 0;
  sys->fields.solve.free_modes     = *nfree;
  sys->fields.solve.load_imbalance = share;
  PetscCheck(bnorm > 0 && share<1e-6, sys->comm, PETSC_ERR_USER_INPUT, "%s: the boundary conditions leave a rigid-body motion free (mainly %s): the stiffness matrix is singular%s. Constrain it in bc (e.g. fix the component on a small region)", sys->scene->file, what, bnorm> 0 ? " and the loads are not balanced along it" : "");
  for (PetscInt q = 0; q < *nfree; q++) {
    PetscScalar dot;
    PetscCall(VecDot(b, free[q], &dot));
    PetscCall(VecAXPY(b, -dot, free[q]));
  }
  PetscCall(PinFreeMotions(sys, *nfree, free, &npin, pins));
  PetscCall(MatZeroRowsColumns(A, npin, pins, diag, u, b));
  if (P != A) PetscCall(MatZeroRowsColumns(P, npin, pins, diag, NULL, NULL));
  if (!sys->run.log.free_modes_noted) PetscCall(PetscPrintf(sys->comm, "perilin: note: the constraints leave %" PetscInt_FMT " rigid motion(s) free (mainly %s) and the loads are balanced along them (share %.2e): the solution orthogonal to them is computed\n", *nfree, what, (double)share));
  sys->run.log.free_modes_noted = PETSC_TRUE;
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
static PetscErrorCode ScaleToUnits(PeriSystem sys, Mat A, Mat P, Vec b, PetscReal *diag)
{
  PeriNode mat;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(sys->scene->root, "material", &mat));
  PeriInputCheck(*diag > 0 && PetscIsNormalReal(*diag) && *diag < 1e250 && *diag > 1e-250, sys->scene, mat, "E", "the stiffness (mean diagonal of K: %g) is beyond what double precision can solve with: give the moduli, thickness and spacing in units that keep them within about 1e-100 to 1e100", (double)*diag);
  PetscCall(MatScale(A, 1 / *diag));
  if (P != A) PetscCall(MatScale(P, 1 / *diag));
  PetscCall(VecScale(b, 1 / *diag));
  *diag = 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* After ScaleToUnits, b is of the order of the displacements: inf or NaN (loads or prescribed
 * values that overflow with K), or beyond 1e+-150 (where the squared norms of CG overflow or
 * underflow), is no problem a solver can help with; say so before KSP reports a breakdown that
 * looks like a singular operator. */
static PetscErrorCode CheckRightHandSide(PeriSystem sys, Vec b)
{
  PetscReal norm, vmax = 0;

  PetscFunctionBeginUser;
  PetscCall(VecNorm(b, NORM_INFINITY, &norm));
  if (norm == 0 || (norm < 1e150 && norm > 1e-150)) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; k < sys->conditions.nconstrained; k++) vmax = PetscMax(vmax, PetscAbsReal(sys->conditions.constrained_value[k]));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &vmax, 1, MPIU_REAL, MPI_MAX, sys->comm));
  PetscCheck(!PetscIsInfOrNanReal(norm), sys->comm, PETSC_ERR_USER_INPUT, "%s: the loads and prescribed values overflow double precision (the right-hand side holds inf or NaN; largest prescribed value %g): give bc values and loads of a physical size", sys->scene->file, (double)vmax);
  SETERRQ(sys->comm, PETSC_ERR_USER_INPUT, "%s: the displacements would be of the order of %g (largest prescribed value %g), beyond what double precision can solve for (1e-150 to 1e150): check the units of the moduli, the loads and the bc values", sys->scene->file, (double)norm, (double)vmax);
}

/* Whether the PC is the default Jacobi of a small 3D body (PeriSystemAssemble), not chosen by the
 * options: it then gets PERI_JACOBI_BUDGET iterations, and GAMG takes over after them. */
static PetscBool DefaultJacobi(PeriSystem sys)
{
  PetscBool pc, maxit;

  PetscOptionsHasName(NULL, NULL, "-pc_type", &pc);
  PetscOptionsHasName(NULL, NULL, "-ksp_max_it", &maxit);
  return (PetscBool)(!strcmp(sys->stiffness.pc_default, PCJACOBI) && !pc && !maxit);
}

/* The status line's solver slot (src/sys/progress.c): the iteration and the residual norm KSP
 * monitors, of the system scaled to O(1) numbers (ScaleToUnits). Installed beside the options'
 * monitors, and only where the line is drawn: it reads, and changes nothing of the solve. */
static PetscErrorCode ProgressMonitor(KSP ksp, PetscInt it, PetscReal rnorm, void *ctx)
{
  PetscFunctionBeginUser;
  (void)ksp;
  PetscCall(PeriProgressUpdate((PeriProgress)ctx, PERI_PROGRESS_SOLVER, "KSP iteration %" PetscInt_FMT ", residual norm %.3e", it, (double)rnorm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriStaticKSPCreate - the KSP of static solves: CG (GMRES for an unsymmetric operator) + GAMG (or
  the default Jacobi, PERI_JACOBI_BUDGET iterations), rtol 1e-10, then the options. PeriStaticSolve
  creates it on first use; a caller creates it ahead to set it up first (a restart's initial
  guess). Collective.
@*/
PetscErrorCode PeriStaticKSPCreate(PeriSystem sys, PetscBool symmetric, KSP *ksp)
{
  PC        pc;
  PetscBool cg, set;

  PetscFunctionBeginUser;
  PetscCall(KSPCreate(sys->comm, ksp));
  PetscCall(KSPSetType(*ksp, symmetric ? KSPCG : KSPGMRES));
  PetscCall(KSPGetPC(*ksp, &pc));
  PetscCall(PCSetType(pc, sys->stiffness.pc_default[0] ? sys->stiffness.pc_default : PCGAMG));
  /* no absolute tolerance: the system is scaled to O(1) numbers (ScaleToUnits), and atol = 1e-50
     would stop CG at once on a tiny right-hand side */
  PetscCall(KSPSetTolerances(*ksp, 1e-10, 0.0, PETSC_DEFAULT, DefaultJacobi(sys) ? PERI_JACOBI_BUDGET : 10000));
  PetscCall(KSPSetFromOptions(*ksp));
  /* CG monitors the preconditioned residual by default, which GAMG lets sit 10-30x above the true
   * one: make -ksp_rtol bound the true relative residual unless the user chose a norm */
  PetscCall(PetscObjectTypeCompare((PetscObject)*ksp, KSPCG, &cg));
  PetscCall(PetscOptionsHasName(NULL, NULL, "-ksp_norm_type", &set));
  if (cg && !set) PetscCall(KSPSetNormType(*ksp, KSP_NORM_UNPRECONDITIONED));
  PetscCall(DefaultFactorSolver(*ksp));
  PetscCall(KSPSetInterruptible(*ksp, sys->comm));
  if (PeriProgressActive(sys->run.progress)) PetscCall(KSPMonitorSet(*ksp, ProgressMonitor, sys->run.progress, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The default geometric multigrid (not one asked for by -pc_type) whose V-cycle is not positive
 * definite: the coarse levels' springs of a body at its model's limit (pds at nu = 1/3: no shear
 * springs) can leave them indefinite. Jacobi needs no levels: retried with it, said. */
static PetscErrorCode MultigridFallback(PeriSystem sys, KSP ksp, KSPConvergedReason reason, PetscBool *retry)
{
  PC        pc;
  PetscBool mg, set;

  PetscFunctionBeginUser;
  *retry = PETSC_FALSE;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCMG, &mg));
  PetscCall(PetscOptionsHasName(NULL, NULL, "-pc_type", &set));
  if (reason != KSP_DIVERGED_INDEFINITE_PC || !mg || set) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PCSetType(pc, PCJACOBI));
  PetscCall(KSPSetTolerances(ksp, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, 10000));
  PetscCall(PetscPrintf(sys->comm, "perilin: note: the geometric multigrid's V-cycle is not positive definite here (%s); retrying with Jacobi (-pc_type jacobi)\n", KSPConvergedReasons[reason]));
  *retry = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* GAMG's default Chebyshev smoother misjudges the spectrum when the stiffness jumps by orders of
 * magnitude (an interface): switch the levels to symmetric SOR, unless told otherwise. Returns
 * whether it did. */
static PetscErrorCode SmootherFallback(PeriSystem sys, KSP ksp, KSPConvergedReason reason, PetscBool *retry)
{
  PC        pc;
  PetscBool gamg, set;
  PetscInt  nl;

  PetscFunctionBeginUser;
  *retry = PETSC_FALSE;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(MultigridFallback(sys, ksp, reason, retry));
  if (*retry) PetscFunctionReturn(PETSC_SUCCESS);
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
  PetscCall(PetscPrintf(sys->comm, "perilin: note: GAMG with Chebyshev smoothing failed (%s); retrying with SOR smoothing (-mg_levels_ksp_type richardson -mg_levels_pc_type sor)\n", KSPConvergedReasons[reason]));
  *retry = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the PC the static solve will use (-pc_type, else the default) needs matrix entries:
 * all but Jacobi and none, which a matrix-free K serves itself. */
static PetscBool NeedsPreconditioningMatrix(PeriSystem sys)
{
  char pc[64];

  PetscStrncpy(pc, sys->stiffness.pc_default[0] ? sys->stiffness.pc_default : PCGAMG, sizeof(pc));
  PetscOptionsGetString(NULL, NULL, "-pc_type", pc, sizeof(pc), NULL);
  return (PetscBool)!PeriOperatorPCWithoutMatrix(pc);
}

static PetscErrorCode ReferenceOrCopy(Mat K, PetscBool inplace, Mat *A)
{
  PetscFunctionBeginUser;
  if (inplace) {
    PetscCall(PetscObjectReference((PetscObject)K));
    *A = K;
  } else
    PetscCall(MatDuplicate(K, MAT_COPY_VALUES, A));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The operator A, the preconditioning matrix P and the right-hand side b = lambda f of the solve: K
 * with the fictitious layers eliminated (A = R K T), else K itself (inplace) or a copy; P is A,
 * or with a matrix-free K the short-range stiffness (itself or a copy). Both carry the rigid-body
 * modes. */
static PetscErrorCode StaticOperator(PeriSystem sys, PetscReal lambda, PetscBool inplace, Mat *A, Mat *P, Vec *b)
{
  PetscFunctionBeginUser;
  if (!sys->fields.u) PetscCall(MatCreateVecs(sys->stiffness.K, &sys->fields.u, NULL));
  PetscCall(VecDuplicate(sys->fields.f, b));
  PetscCall(VecCopy(sys->fields.f, *b));
  PetscCall(VecScale(*b, lambda));
  sys->fields.solve.symmetric = PETSC_TRUE;
  if (sys->conditions.layers.T)
    PetscCall(PeriLayersApply(sys, lambda, A, *b));
  else if (sys->stiffness.op)
    PetscCall(PeriOperatorCreateMat(sys, A)); /* a fresh shell: the held DOFs are its own */
  else
    PetscCall(ReferenceOrCopy(sys->stiffness.K, inplace, A));
  if (sys->stiffness.op && NeedsPreconditioningMatrix(sys)) {
    PetscCall(PeriOperatorPreconditioner(sys));
    PetscCall(ReferenceOrCopy(sys->stiffness.Kpc, inplace, P));
  } else {
    PetscCall(PetscObjectReference((PetscObject)*A));
    *P = *A;
  }
  PetscCall(PeriSetNearNullSpace(sys, *A, NULL));
  if (*P != *A) PetscCall(PeriSetNearNullSpace(sys, *P, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sets the prescribed (lambda times their values) and held DOFs in sys->fields.u and eliminates them
 * symmetrically from A and b, with the system scaled to O(1) numbers first (ScaleToUnits); *diag
 * gets the value left on the eliminated rows, *scale the factor b was divided by. */
static PetscErrorCode EliminatePrescribed(PeriSystem sys, Mat A, Mat P, Vec b, PetscReal lambda, PetscInt nhold, const PetscInt hold[], const PetscReal held[], PetscReal *diag, PetscReal *scale)
{
  const PetscInt nrows = sys->conditions.nconstrained + nhold;
  PetscReal     *values;
  PetscInt      *rows, N;
  PetscBool      mpisbaij;
  Vec            d;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(nrows, &rows, nrows, &values));
  for (PetscInt k = 0; k < sys->conditions.nconstrained; k++) {
    rows[k]   = sys->conditions.constrained[k];
    values[k] = lambda * sys->conditions.constrained_value[k];
  }
  for (PetscInt k = 0; k < nhold; k++) {
    rows[sys->conditions.nconstrained + k]   = hold[k];
    values[sys->conditions.nconstrained + k] = held[k];
  }
  PetscCall(VecSetValues(sys->fields.u, nrows, rows, values, INSERT_VALUES));
  PetscCall(VecAssemblyBegin(sys->fields.u));
  PetscCall(VecAssemblyEnd(sys->fields.u));
  /* a unit of the mean diagonal on eliminated rows keeps the conditioning of the free block */
  PetscCall(MatCreateVecs(A, &d, NULL));
  PetscCall(MatGetDiagonal(A, d));
  PetscCall(VecNorm(d, NORM_1, diag));
  PetscCall(VecGetSize(d, &N));
  PetscCall(VecDestroy(&d));
  *diag /= N;
  *scale = *diag;
  PetscCall(ScaleToUnits(sys, A, P, b, diag));
  PetscCall(PetscObjectTypeCompare((PetscObject)P, MATMPISBAIJ, &mpisbaij));
  PetscCheck(!mpisbaij, sys->comm, PETSC_ERR_SUP, "-mat_type sbaij on several ranks cannot eliminate the prescribed DOFs (PETSc has no MatZeroRowsColumns for MPISBAIJ): use -mat_type baij or aij (MUMPS Cholesky works on both)");
  PetscCall(MatZeroRowsColumns(A, nrows, rows, *diag, sys->fields.u, b));
  if (P != A) PetscCall(MatZeroRowsColumns(P, nrows, rows, *diag, NULL, NULL));
  PetscCall(PetscFree2(rows, values));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* -pc_type mg: the geometric multigrid's levels on the first solve (PeriMultigridSetUp); a later
 * solve's fresh shell A becomes the finest level's operator, the coarse levels stay. */
static PetscErrorCode MultigridLevels(PeriSystem sys, KSP ksp, Mat A)
{
  PC          pc;
  PetscBool   mg;
  PetscObject built;

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCMG, &mg));
  if (!mg) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscObjectQuery((PetscObject)pc, "perilin_multigrid", &built));
  if (!built) {
    PetscCall(PeriMultigridSetUp(sys, ksp, A));
    PetscCall(PetscObjectCompose((PetscObject)pc, "perilin_multigrid", (PetscObject)A));
  } else {
    KSP      fine;
    PetscInt L;
    PetscCall(PCMGGetLevels(pc, &L));
    PetscCall(PCMGGetSmoother(pc, L - 1, &fine));
    PetscCall(KSPSetOperators(fine, A, A));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Solves A u = b for sys->fields.u with *ksp (created on first use), once more with SOR smoothing when
 * GAMG's Chebyshev smoother fails (SmootherFallback). */
static PetscErrorCode SolveWithFallback(PeriSystem sys, KSP *ksp, Mat A, Mat P, Vec b, KSPConvergedReason *reason)
{
  PetscBool      retry, factor;
  PC             pc;
  PetscLogDouble t0, t1, t2;

  PetscFunctionBeginUser;
  if (!*ksp) PetscCall(PeriStaticKSPCreate(sys, sys->fields.solve.symmetric, ksp));
  PetscCall(KSPSetOperators(*ksp, A, P));
  /* a factorization uses the BLAS threads (src/sys/threads.c) */
  PetscCall(KSPGetPC(*ksp, &pc));
  PetscCall(MultigridLevels(sys, *ksp, A));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &factor, PCLU, PCCHOLESKY, ""));
  PetscCall(PeriBLASThreads(factor));
  PetscCall(PeriProgressUpdate(sys->run.progress, PERI_PROGRESS_PHASE, "solve"));
  /* the PC's set-up on its own, so that its cost and the iterations' can be told apart (tune) */
  PetscCall(PetscTime(&t0));
  PetscCall(KSPSetUp(*ksp));
  PetscCall(PetscTime(&t1));
  PetscCall(KSPSolve(*ksp, b, sys->fields.u));
  PetscCall(PeriBLASThreads(PETSC_FALSE));
  PetscCall(KSPGetConvergedReason(*ksp, reason));
  PetscCall(SmootherFallback(sys, *ksp, *reason, &retry));
  if (retry) {
    PetscCall(KSPSolve(*ksp, b, sys->fields.u));
    PetscCall(KSPGetConvergedReason(*ksp, reason));
  }
  PetscCall(PetscTime(&t2));
  sys->fields.solve.setup_s += t1 - t0;
  sys->fields.solve.ksp_solve_s += t2 - t1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* sys->fields.solve: iterations, the true relative residual (whatever norm the KSP
 * monitored), the KSP and PC types and the converged reason. */
static PetscErrorCode RecordSolve(PeriSystem sys, KSP ksp, Mat A, Vec b, KSPConvergedReason reason)
{
  Vec       r;
  PetscReal rnorm, fnorm;
  KSPType   kt;
  PCType    pt;
  PC        pc;

  PetscFunctionBeginUser;
  PetscCall(KSPGetIterationNumber(ksp, &sys->fields.solve.iterations));
  PetscCall(MatCreateVecs(A, &r, NULL));
  PetscCall(MatMult(A, sys->fields.u, r));
  PetscCall(VecAYPX(r, -1, b));
  PetscCall(VecNorm(r, NORM_2, &rnorm));
  PetscCall(VecNorm(b, NORM_2, &fnorm));
  PetscCall(VecDestroy(&r));
  sys->fields.solve.residual_norm = fnorm > 0 ? rnorm / fnorm : rnorm;
  sys->fields.solve.rhs_norm      = fnorm; /* of the scaled system: SolveAttempt restores the units */
  PetscCall(KSPGetType(ksp, &kt));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCGetType(pc, &pt));
  PetscCall(PetscStrncpy(sys->fields.solve.ksp_type, kt, sizeof(sys->fields.solve.ksp_type)));
  PetscCall(PetscStrncpy(sys->fields.solve.pc_type, pt, sizeof(sys->fields.solve.pc_type)));
  PetscCall(PetscStrncpy(sys->fields.solve.converged_reason, KSPConvergedReasons[reason], sizeof(sys->fields.solve.converged_reason)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One static solve with the present PC (PeriStaticSolve). Its operators, right-hand side and free
 * motions are freed whatever the outcome: a refused scene (loads unbalanced along a free motion)
 * is an input error of a process that may go on (the Python module; found by -malloc_dump). */
static PetscErrorCode SolveAttempt(PeriSystem sys, KSP *ksp, PetscReal lambda, PetscBool inplace, PetscInt nhold, const PetscInt hold[], const PetscReal held[], KSPConvergedReason *reason)
{
  Mat            A, P;
  Vec            b, free[PERI_MAX_MODES];
  PetscReal      diag, scale = 1;
  PetscInt       nfree = 0;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(StaticOperator(sys, lambda, inplace, &A, &P, &b));
  ierr = EliminatePrescribed(sys, A, P, b, lambda, nhold, hold, held, &diag, &scale);
  if (!ierr) ierr = CheckRightHandSide(sys, b);
  if (!ierr) ierr = HandleFreeMotions(sys, A, P, sys->fields.u, b, diag, nhold, hold, &nfree, free);
  if (!ierr) ierr = SolveWithFallback(sys, ksp, A, P, b, reason);
  if (!ierr) ierr = RecordSolve(sys, *ksp, A, b, *reason);
  /* the residual's scale in the scene's units and the load factor: the equilibrium check of the
     reactions (reactions.c) allows what this residual explains */
  sys->fields.solve.rhs_norm *= scale;
  sys->fields.solve.load_factor = lambda;
  /* the solution orthogonal to the free rigid motions */
  for (PetscInt q = 0; q < nfree; q++) {
    PetscScalar dot;
    if (!ierr) ierr = VecDot(sys->fields.u, free[q], &dot);
    if (!ierr) ierr = VecAXPY(sys->fields.u, -dot, free[q]);
    PetscCall(VecDestroy(&free[q]));
  }
  if (!ierr) ierr = PeriLayersComplete(sys, lambda, sys->fields.u);
  PetscCall(VecDestroy(&b));
  PetscCall(MatDestroy(&A));
  PetscCall(MatDestroy(&P));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriStaticSolve - solves K u = lambda f for sys->fields.u with the prescribed values and the layers'
  offsets scaled by lambda, and the DOFs hold[] held at held[] (fragments). Fictitious layers are
  eliminated (A = R K T), prescribed DOFs symmetrically; a free body with balanced loads is solved
  orthogonal to its rigid motions. sys->stiffness.K is kept unless inplace. *ksp is created on first use
  (CG + GAMG, or Jacobi for a small 3D body with a matrix-free K, or GMRES for an unsymmetric
  operator, then the options). A default Jacobi that has not converged after PERI_JACOBI_BUDGET
  iterations hands over to GAMG, which starts from its iterate, for this solve and the next ones.
  Sets sys->fields.solve's solver fields and returns the converged reason instead of failing. Collective.
@*/
PetscErrorCode PeriStaticSolve(PeriSystem sys, KSP *ksp, PetscReal lambda, PetscBool inplace, PetscInt nhold, const PetscInt hold[], const PetscReal held[], KSPConvergedReason *reason)
{
  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PERI_EVENT_Solve, 0, 0, 0, 0));
  sys->fields.solve.setup_s = sys->fields.solve.ksp_solve_s = 0;
  PetscCall(SolveAttempt(sys, ksp, lambda, inplace, nhold, hold, held, reason));
  if (*reason == KSP_DIVERGED_ITS && DefaultJacobi(sys)) {
    PetscCall(PetscPrintf(sys->comm, "perilin: note: CG + Jacobi did not converge in %d iterations; GAMG on the short-range stiffness goes on from there\n", PERI_JACOBI_BUDGET));
    PetscCall(PetscStrncpy(sys->stiffness.pc_default, PCGAMG, sizeof(sys->stiffness.pc_default)));
    PetscCall(KSPDestroy(ksp));
    PetscCall(PeriStaticKSPCreate(sys, sys->fields.solve.symmetric, ksp));
    PetscCall(KSPSetInitialGuessNonzero(*ksp, PETSC_TRUE));
    PetscCall(SolveAttempt(sys, ksp, lambda, inplace, nhold, hold, held, reason));
  }
  PetscCall(PetscLogEventEnd(PERI_EVENT_Solve, 0, 0, 0, 0));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriStaticPieces - the DOFs a static solve holds (PeriPieces): pieces cut off by cracks are held
  in place when unloaded, an error when loaded. Free hold and held with PetscFree2. Collective.
@*/
PetscErrorCode PeriStaticPieces(PeriSystem sys, PetscInt *nhold, PetscInt **hold, PetscReal **held)
{
  PetscInt  npieces;
  PetscBool lost;

  PetscFunctionBeginUser;
  PetscCall(PeriPieces(sys, nhold, hold, held, &npieces, &lost));
  if (lost) PetscCall(PetscFree2(*hold, *held)); /* refused: the caller gets nothing to free */
  PetscCheck(!lost, sys->comm, PETSC_ERR_USER_INPUT, "%s: the body is in %" PetscInt_FMT " pieces and a loaded one is not connected to the constraints: it cannot carry its load", sys->scene->file, npieces);
  if (npieces > 1) PetscCall(PetscPrintf(sys->comm, "perilin: note: the body is in %" PetscInt_FMT " pieces; those not connected to the constraints are unloaded and held in place\n", npieces));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the last solve is trustworthy: KSP's reason is not enough (preonly reports
 * CONVERGED_ITS after one application of any preconditioner), so the true relative residual
 * ||b - A x|| / ||b|| must also lie below solver.residual_tol. */
PetscErrorCode PeriStaticConverged(PeriSystem sys, KSP ksp, KSPConvergedReason reason, PetscBool *ok)
{
  PetscReal rtol;

  PetscFunctionBeginUser;
  PetscCall(KSPGetTolerances(ksp, &rtol, NULL, NULL, NULL));
  sys->fields.solve.residual_tol = PeriResidualTolerance(sys, rtol);
  *ok                            = (PetscBool)(reason > 0 && !PetscIsInfOrNanReal(sys->fields.solve.residual_norm) && sys->fields.solve.residual_norm <= sys->fields.solve.residual_tol);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What a failed static solve tells the user (after PeriStaticConverged). */
PetscErrorCode PeriStaticCheckConverged(PeriSystem sys, KSPConvergedReason reason)
{
  PetscBool ok = (PetscBool)(reason > 0 && sys->fields.solve.residual_norm <= sys->fields.solve.residual_tol);

  PetscFunctionBeginUser;
  PetscCheck(!PetscIsInfOrNanReal(sys->fields.solve.residual_norm), sys->comm, PETSC_ERR_NOT_CONVERGED, "the static solve did not converge: the solution contains NaN or Inf (%s/%s, %s): %s", sys->fields.solve.ksp_type, sys->fields.solve.pc_type, KSPConvergedReasons[reason], Advice(KSP_DIVERGED_NANORINF));
  PetscCheck(reason > 0, sys->comm, PETSC_ERR_NOT_CONVERGED, "the static solve did not converge: true relative residual %.3g (tolerance %.3g), %s/%s stopped with %s after %" PetscInt_FMT " iterations: %s", (double)sys->fields.solve.residual_norm, (double)sys->fields.solve.residual_tol, sys->fields.solve.ksp_type, sys->fields.solve.pc_type, KSPConvergedReasons[reason], sys->fields.solve.iterations, Advice(reason));
  PetscCheck(ok, sys->comm, PETSC_ERR_NOT_CONVERGED, "the static solve did not converge: true relative residual %.3g > tolerance %.3g although %s/%s reported %s after %" PetscInt_FMT " iterations: %s", (double)sys->fields.solve.residual_norm, (double)sys->fields.solve.residual_tol, sys->fields.solve.ksp_type, sys->fields.solve.pc_type, KSPConvergedReasons[reason], sys->fields.solve.iterations, AdviceResidual(sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriResidualTolerance - the largest true relative residual a solve run with relative tolerance
  rtol may leave: solver.residual_tol, or by default max(100 rtol, 1e-6), but never above 1e-3.
  The factor 100 leaves room for the preconditioned norm that some KSPs monitor; the floor, for
  round-off in K; the cap keeps a loose -ksp_rtol from passing a wrong answer (an answer that
  crude must be asked for with solver.residual_tol).
@*/
PetscReal PeriResidualTolerance(PeriSystem sys, PetscReal rtol)
{
  return sys->stiffness.residual_tol > 0 ? sys->stiffness.residual_tol : PetscMin(PetscMax(100 * rtol, 1e-6), 1e-3);
}
