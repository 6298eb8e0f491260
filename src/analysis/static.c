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

/* The block format (BAIJ) unless the preconditioner cannot take it: in PETSc 3.18 GAMG builds its
 * graph from AIJ only, and MUMPS factors BAIJ by LU only. -mat_type overrides this. */
static PetscErrorCode DefaultMatType(char type[], size_t len)
{
  char      pc[64] = PCGAMG, solver[64] = "";
  PetscBool gamg, cholesky, mumps;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetString(NULL, NULL, "-pc_type", pc, sizeof(pc), NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-pc_factor_mat_solver_type", solver, sizeof(solver), NULL));
  PetscCall(PetscStrcmp(pc, PCGAMG, &gamg));
  PetscCall(PetscStrcmp(pc, PCCHOLESKY, &cholesky));
  PetscCall(PetscStrcmp(solver, MATSOLVERMUMPS, &mumps));
  PetscCall(PetscStrncpy(type, gamg || (cholesky && mumps) ? MATAIJ : MATBAIJ, len));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisRun_Static - solves the linear static problem and evaluates energies and probes.
  Options: every KSP/PC option (-ksp_type, -pc_type, -ksp_rtol, ...). Collective.
@*/
PetscErrorCode PeriAnalysisRun_Static(PeriProblem p)
{
  KSP                ksp;
  PC                 pc;
  Vec                r;
  PetscReal          diag, fnorm, rnorm;
  PetscInt           N, nc;
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
  PetscCall(PeriCheckRigidMotion(p));
  PetscCall(DefaultMatType(p->mat_type, sizeof(p->mat_type)));
  if (!p->K) PetscCall(PeriProblemAssemble(p));
  PetscCall(PetscTime(&t0));
  PetscCall(PetscLogEventBegin(PERI_EVENT_Solve, 0, 0, 0, 0));
  PetscCall(VecDestroy(&p->u));
  PetscCall(MatCreateVecs(p->K, &p->u, NULL));
  PetscCall(PeriSetNearNullSpace(p, p->K));
  PetscCall(VecSetValues(p->u, p->nconstrained, p->constrained, p->constrained_value, INSERT_VALUES));
  PetscCall(VecAssemblyBegin(p->u));
  PetscCall(VecAssemblyEnd(p->u));
  /* a unit of the mean diagonal on eliminated rows keeps the conditioning of the free block */
  PetscCall(MatCreateVecs(p->K, &r, NULL));
  PetscCall(MatGetDiagonal(p->K, r));
  PetscCall(VecNorm(r, NORM_1, &diag));
  PetscCall(VecGetSize(r, &N));
  diag /= N;
  {
    PetscBool mpisbaij;
    PetscCall(PetscObjectTypeCompare((PetscObject)p->K, MATMPISBAIJ, &mpisbaij));
    PetscCheck(!mpisbaij, p->comm, PETSC_ERR_SUP, "-mat_type sbaij on several ranks cannot eliminate the prescribed DOFs (PETSc has no MatZeroRowsColumns for MPISBAIJ): use -mat_type baij or aij (MUMPS Cholesky works on both)");
  }
  PetscCall(MatZeroRowsColumns(p->K, p->nconstrained, p->constrained, diag, p->u, p->f));

  PetscCall(KSPCreate(p->comm, &ksp));
  PetscCall(KSPSetOperators(ksp, p->K, p->K));
  PetscCall(KSPSetType(ksp, KSPCG));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCGAMG));
  PetscCall(KSPSetTolerances(ksp, 1e-10, PETSC_DEFAULT, PETSC_DEFAULT, 10000));
  PetscCall(KSPSetFromOptions(ksp));
  {
    /* CG monitors the preconditioned residual by default, which GAMG lets sit 10-30x above the true
     * one: make -ksp_rtol bound the true relative residual unless the user chose a norm */
    PetscBool cg, set;
    PetscCall(PetscObjectTypeCompare((PetscObject)ksp, KSPCG, &cg));
    PetscCall(PetscOptionsHasName(NULL, NULL, "-ksp_norm_type", &set));
    if (cg && !set) PetscCall(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED));
  }
  PetscCall(KSPSolve(ksp, p->f, p->u));
  PetscCall(KSPGetConvergedReason(ksp, &reason));
  PetscCall(KSPGetIterationNumber(ksp, &p->results.iterations));
  /* the true relative residual, whatever norm the KSP monitored */
  PetscCall(MatMult(p->K, p->u, r));
  PetscCall(VecAYPX(r, -1, p->f));
  PetscCall(VecNorm(r, NORM_2, &rnorm));
  PetscCall(VecNorm(p->f, NORM_2, &fnorm));
  p->results.residual_norm = fnorm > 0 ? rnorm / fnorm : rnorm;
  {
    KSPType kt;
    PCType  pt;
    PetscCall(KSPGetType(ksp, &kt));
    PetscCall(PCGetType(pc, &pt));
    PetscCall(PetscStrncpy(p->results.ksp_type, kt, sizeof(p->results.ksp_type)));
    PetscCall(PetscStrncpy(p->results.pc_type, pt, sizeof(p->results.pc_type)));
  }
  PetscCall(PetscStrncpy(p->results.converged_reason, KSPConvergedReasons[reason], sizeof(p->results.converged_reason)));
  PetscCall(KSPDestroy(&ksp));
  PetscCall(VecDestroy(&r));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Solve, 0, 0, 0, 0));
  PetscCheck(reason > 0, p->comm, PETSC_ERR_NOT_CONVERGED, "the static solve did not converge: %s after %" PetscInt_FMT " iterations (relative residual %g): %s", KSPConvergedReasons[reason], p->results.iterations, (double)p->results.residual_norm, Advice(reason));
  PetscCheck(!PetscIsInfOrNanReal(p->results.residual_norm), p->comm, PETSC_ERR_FP, "the static solution contains NaN or Inf: %s", Advice(KSP_DIVERGED_NANORINF));
  PetscCall(PetscTime(&t1));
  p->results.solve_s = t1 - t0;
  PetscCall(PeriProblemEvaluateEnergy(p));
  PetscCall(PeriReferenceEvaluate(p));
  PetscFunctionReturn(PETSC_SUCCESS);
}
