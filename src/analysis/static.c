/* Static analysis: K u = f with the prescribed DOFs eliminated symmetrically, solved with KSP
 * (CG + GAMG with the rigid-body near-null space unless the options say otherwise). */
#include "perilin/private/problem.h"

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
  PetscCallMPI(MPI_Allreduce(&p->sys->nconstrained, &nc, 1, MPIU_INT, MPI_SUM, p->comm));
  if (nc == p->sys->particles.n * p->sys->model->dofs) {
    /* every DOF prescribed: the solution is known, K is not needed */
    PetscCall(VecDestroy(&p->sys->u));
    PetscCall(PeriSystemCreateVec(p->sys, &p->sys->u));
    PetscCall(VecSetValues(p->sys->u, p->sys->nconstrained, p->sys->constrained, p->sys->constrained_value, INSERT_VALUES));
    PetscCall(VecAssemblyBegin(p->sys->u));
    PetscCall(VecAssemblyEnd(p->sys->u));
    PetscCall(PetscStrncpy(p->sys->results.ksp_type, "none", sizeof(p->sys->results.ksp_type)));
    PetscCall(PetscStrncpy(p->sys->results.pc_type, "none", sizeof(p->sys->results.pc_type)));
    PetscCall(PetscStrncpy(p->sys->results.converged_reason, "ALL_DOFS_PRESCRIBED", sizeof(p->sys->results.converged_reason)));
    PetscCall(PeriSystemEvaluateEnergy(p->sys));
    PetscCall(PeriReferenceEvaluate(p->sys));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PeriStaticDefaultMatType(p->sys->mat_type, sizeof(p->sys->mat_type)));
  if (!p->sys->K) PetscCall(PeriSystemAssemble(p->sys));
  PetscCall(PetscTime(&t0));
  PetscCall(VecDestroy(&p->sys->u));
  {
    /* pieces cut off by cracks: held in place when unloaded, an error when loaded */
    PetscInt   nhold, npieces, *hold;
    PetscReal *held;
    PetscBool  lost;
    PetscCall(PeriPieces(p->sys, &nhold, &hold, &held, &npieces, &lost));
    PetscCheck(!lost, p->comm, PETSC_ERR_USER_INPUT, "%s: the body is in %" PetscInt_FMT " pieces and a loaded one is not connected to the constraints: it cannot carry its load", p->scene->file, npieces);
    if (npieces > 1) PetscCall(PetscPrintf(p->comm, "perilin: note: the body is in %" PetscInt_FMT " pieces; those not connected to the constraints are unloaded and held in place\n", npieces));
    PetscCall(PeriStaticSolve(p->sys, &ksp, 1.0, PETSC_TRUE, nhold, hold, held, &reason));
    PetscCall(PetscFree2(hold, held));
  }
  PetscCall(PeriSignalReceived(p->comm, &p->sys->interrupted));
  if (p->sys->interrupted) {
    /* an unfinished solve is no result: the output will say so and hold no fields */
    PetscCall(KSPDestroy(&ksp));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  {
    PetscBool ok;
    PetscCall(PeriStaticConverged(p->sys, ksp, reason, &ok));
  }
  PetscCall(KSPDestroy(&ksp));
  PetscCall(PeriStaticCheckConverged(p->sys, reason));
  PetscCall(PetscTime(&t1));
  p->sys->results.solve_s = t1 - t0;
  PetscCall(PeriSystemEvaluateEnergy(p->sys));
  PetscCall(PeriReferenceEvaluate(p->sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The static analysis reads no analysis.* key besides type: the empty section says so, and makes
 * another analysis' key (nev) an error naming its owner. */
static const PeriKey    static_keys[]       = {{NULL}};
static const PeriSchema static_schema[]     = {{"analysis", static_keys}, {NULL}};
const PeriAnalysisType  PeriAnalysis_Static = {"static", "one linear solve K u = f", static_schema, PETSC_FALSE, {PeriAnalysisRun_Static, NULL, NULL, NULL, NULL, NULL}};
