/* Static analysis: K u = f with the prescribed DOFs eliminated symmetrically, solved with KSP
 * (CG + GAMG with the rigid-body near-null space unless the options say otherwise). */
#include "perilin/private/analysis.h"

/*@C
  PeriAnalysisRun_Static - solves the linear static problem once and evaluates energies and probes.
  Options: every KSP/PC option (-ksp_type, -pc_type, -ksp_rtol, ...). Collective.
@*/
static PetscErrorCode PeriAnalysisRun_Static(PeriAnalysis an)
{
  KSP                ksp = NULL;
  PetscInt           nc;
  KSPConvergedReason reason;
  PetscLogDouble     t0, t1;
  PetscBool          released = PETSC_FALSE;
  Mat                K;
  PetscErrorCode     ierr;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&an->sys->conditions.nconstrained, &nc, 1, MPIU_INT, MPI_SUM, an->comm));
  if (nc == an->sys->disc.N * an->sys->model->dofs) {
    /* every DOF prescribed: the solution is known, K is not needed */
    PetscCall(VecDestroy(&an->sys->fields.u));
    PetscCall(PeriSystemCreateVec(an->sys, &an->sys->fields.u));
    PetscCall(VecSetValues(an->sys->fields.u, an->sys->conditions.nconstrained, an->sys->conditions.constrained, an->sys->conditions.constrained_value, INSERT_VALUES));
    PetscCall(VecAssemblyBegin(an->sys->fields.u));
    PetscCall(VecAssemblyEnd(an->sys->fields.u));
    PetscCall(PetscStrncpy(an->sys->fields.solve.ksp_type, "none", sizeof(an->sys->fields.solve.ksp_type)));
    PetscCall(PetscStrncpy(an->sys->fields.solve.pc_type, "none", sizeof(an->sys->fields.solve.pc_type)));
    PetscCall(PetscStrncpy(an->sys->fields.solve.converged_reason, "ALL_DOFS_PRESCRIBED", sizeof(an->sys->fields.solve.converged_reason)));
    PetscCall(PeriSystemEvaluateEnergy(an->sys));
    PetscCall(PeriSystemEvaluateReactions(an->sys, 1.0));
    PetscCall(PeriReferenceEvaluate(an->sys));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PeriStaticDefaultMatType(an->sys->stiffness.mat_type, sizeof(an->sys->stiffness.mat_type)));
  PetscCall(PeriSystemGetJacobian(an->sys, &K));
  PetscCall(PetscTime(&t0));
  PetscCall(VecDestroy(&an->sys->fields.u));
  {
    PetscInt   nhold, *hold;
    PetscReal *held;
    PetscCall(PeriStaticPieces(an->sys, &nhold, &hold, &held));
    /* the solve reads K only: the bonds' geometry makes room for GAMG, and comes back after it */
    PetscCall(PeriSystemReleaseBondGeometry(an->sys, &released));
    ierr = PeriStaticSolve(an->sys, &ksp, 1.0, PETSC_TRUE, nhold, hold, held, &reason);
    PetscCall(PetscFree2(hold, held)); /* and the solver, when the solve refused the scene */
    if (ierr) PetscCall(KSPDestroy(&ksp));
    PetscCall(ierr);
  }
  PetscCall(PeriSignalReceived(an->comm, &an->sys->run.interrupted));
  if (an->sys->run.interrupted) {
    /* an unfinished solve is no result: the output will say so and hold no fields */
    PetscCall(KSPDestroy(&ksp));
    PetscCall(PeriSystemRestoreBondGeometry(an->sys, released));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  {
    PetscBool ok;
    PetscCall(PeriStaticConverged(an->sys, ksp, reason, &ok));
  }
  PetscCall(KSPDestroy(&ksp));
  PetscCall(PeriSystemRestoreBondGeometry(an->sys, released));
  PetscCall(PeriStaticCheckConverged(an->sys, reason));
  PetscCall(PetscTime(&t1));
  an->sys->run.log.solve_s = t1 - t0;
  PetscCall(PeriSystemEvaluateEnergy(an->sys));
  PetscCall(PeriSystemEvaluateReactions(an->sys, 1.0));
  PetscCall(PeriReferenceEvaluate(an->sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The static analysis reads no analysis.* key besides type: the empty section says so, and makes
 * another analysis' key (nev) an error naming its owner. */
static const PeriKey    static_keys[]       = {{NULL}};
static const PeriSchema static_schema[]     = {{"analysis", static_keys}, {NULL}};
const PeriAnalysisType  PeriAnalysis_Static = {
     .name          = "static",
     .help          = "one linear solve K u = f",
     .schema        = static_schema,
     .option_prefix = "",
     .needs         = {.matrix_free = PETSC_TRUE, .static_solver = PETSC_TRUE},
     .ops           = {.run = PeriAnalysisRun_Static},
};
