/* The bond state service (include/perilin/private/bondstate.h): breaking bonds by the scene's
 * criteria and returning to a saved equilibrium. Any analysis that lets bonds fail (quasi-static,
 * transient) breaks them here; the criteria themselves are in failure.c. */
#include "perilin/private/system.h"

/* The DOFs of a bond from i to j (local indices) in the local array u: i's, then j's. */
static void BondDOFs(PetscInt bs, const PetscScalar *u, PetscInt i, PetscInt j, PetscReal ue[])
{
  for (PetscInt c = 0; c < bs; c++) {
    ue[c]      = PetscRealPart(u[i * bs + c]);
    ue[bs + c] = PetscRealPart(u[j * bs + c]);
  }
}

/* Bond k of owned particle i against the criterion at the local DOFs u: its failure index, the
 * stiffness share softening leaves it and the cause. */
static PetscErrorCode EvaluateBond(PeriSystem sys, const PetscScalar *u, PetscInt i, PetscInt k, PetscReal *index, PetscReal *soft, PeriFailureCause *cause)
{
  PeriModel        m  = sys->model;
  const PetscInt   bs = m->dofs;
  PeriBondGeometry g;
  PetscReal        ue[2 * PERI_MAX_DOF], meas[PERI_MAX_MEASURE];

  PetscFunctionBeginUser;
  PetscCall(PeriSystemBondGeometry(sys, i, k, &g));
  BondDOFs(bs, u, i, g.j, ue);
  m->ops.bond_measures(m, &g, ue, ue + bs, meas);
  *index = PeriBondFailureIndex(sys, &g, meas, cause);
  *soft  = sys->disc.bonds.intact ? PeriBondSoftening(sys, meas) : 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the screen may form the bond vectors from the coordinates, which stay in cache, instead
 * of reading 24 bytes a bond (PeriSystemBondVectorsFromCoordinates; not across a periodic axis).
 * Asked once: bonds that break later only shrink the set it holds for. */
static PetscBool ScreenFromCoordinates(PeriSystem sys)
{
  PeriFailure *F = &sys->bond_state.failure;

  if (F->screen_xi < 0) F->screen_xi = PeriSystemBondVectorsFromCoordinates(sys);
  return (PetscBool)F->screen_xi;
}

/* With PeriFailureScreens: whether bond k of owned particle i is surely below its criteria at the
 * local DOFs u, from its linearized stretch against its limit, without the full evaluation (the
 * every-step check of a time loop: the geometry, the model's measures and each criterion's index
 * cost four times the force). The margin keeps every bond that the full evaluation could break.
 * No array for the bond's vector: a vector load of scalars just stored stalls the loop. */
static inline PetscBool SurelyHolds(PeriSystem sys, PetscInt nact, const PeriCriterion *act[], PetscBool coords, const PetscScalar *u, PetscInt i, PetscInt k)
{
  const PeriBonds *b   = &sys->disc.bonds;
  const PetscInt   dim = sys->model->dim, bs = sys->model->dofs, j = b->j[k];
  const PetscReal *x     = sys->disc.particles.x;
  PetscReal        limit = PETSC_MAX_REAL, len2 = 0, t = 0;

  for (PetscInt c = 0; c < nact; c++) {
    const PetscReal v = act[c]->type->ops.stretch_limit(act[c], sys->model, k);
    if (v < 0) return PETSC_FALSE; /* not known yet: the full evaluation finds it */
    limit = PetscMin(limit, v);
  }
  for (PetscInt d = 0; d < dim; d++) {
    const PetscReal e = coords ? x[3 * j + d] - x[3 * i + d] : b->xi[3 * k + d];
    t += e * (PetscRealPart(u[j * bs + d]) - PetscRealPart(u[i * bs + d]));
    len2 += e * e;
  }
  return (PetscBool)(t < (1 - 1e-9) * limit * len2);
}

/* Bond k of owned particle i breaks (breaks) or keeps the share soft of its stiffness: K follows
 * (its block's energy at u added to *energy with released; state-based models: K is reassembled
 * from the synchronized families by the caller), then its flags; *mine counts the bonds broken or
 * softened by more than 1 %. */
static PetscErrorCode ChangeBond(PeriSystem sys, const PetscScalar *u, PetscInt i, PetscInt k, PetscBool breaks, PetscReal soft, PeriFailureCause cause, PetscBool released, PetscReal *energy, PetscInt *mine)
{
  PeriBonds *b = &sys->disc.bonds;

  PetscFunctionBeginUser;
  if (sys->model->ops.bond_stiffness) {
    PetscReal        ue[2 * PERI_MAX_DOF], e = 0;
    PeriBondGeometry g;
    if (released) {
      PetscCall(PeriSystemBondGeometry(sys, i, k, &g));
      BondDOFs(sys->model->dofs, u, i, g.j, ue);
    }
    PetscCall(PeriStiffnessScaleBond(sys, i, k, breaks ? 0 : soft / b->intact[k], released ? ue : NULL, &e));
    *energy += e;
  }
  if (breaks || soft <= 0) {
    b->live[k]  = 0;
    b->cause[k] = (unsigned char)cause;
    (*mine)++;
  } else {
    /* softening: iterate until no bond loses more than 1 % of its stiffness */
    if (b->intact[k] - soft > 1e-2) (*mine)++;
    b->intact[k] = soft;
    b->cause[k]  = (unsigned char)cause;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether a bond with this index and softened share changes: it breaks, or softens further. */
static inline PetscBool Changes(const PeriBonds *b, PetscInt k, PetscBool breaks, PetscReal soft)
{
  return (PetscBool)(breaks || (b->intact && soft < b->intact[k]));
}

/*@C
  PeriBondsBreak - evaluates every live bond of this rank against the criterion and breaks those past it (all, or
 * those within the top fraction of the worst index), subtracting their blocks from K; softening
 * bonds lose stiffness by eqs. 45-46 (irreversibly). Returns the global number of bonds broken or
 * softened by more than 1 %. With all, every bond past its criterion breaks, in one pass (a bond's
  index does not depend on another's state: the explicit step's every-step check holds no
  per-bond arrays); else those within the top fraction of [1, worst index]. Collective.
@*/
PetscErrorCode PeriBondsBreak(PeriSystem sys, Vec U, PetscBool all, PetscReal fraction, PetscInt *nbroken, PetscReal *released)
{
  PeriBonds        *b = &sys->disc.bonds;
  PeriModel         m = sys->model;
  PetscScalar      *u;
  PeriFailureCause *cause, c1;
  PetscReal        *index, *soft, worst = 0, threshold = 1, energy = 0, index1, soft1;
  PetscInt          mine = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriFailureCacheBonds(sys));
  PetscCall(PeriSystemLocalDOFs(sys, U, &u));
  if (all) {
    const PeriCriterion *act[PERI_MAX_CRITERIA];
    PetscInt             nact;
    const PetscBool      screen = PeriFailureScreens(sys, &nact, act), coords = (PetscBool)(screen && ScreenFromCoordinates(sys));
    for (PetscInt i = b->rstart; i < b->rend; i++)
      for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
        if (!b->live[k] || b->j[k] == i || (screen && SurelyHolds(sys, nact, act, coords, u, i, k))) continue;
        PetscCall(EvaluateBond(sys, u, i, k, &index1, &soft1, &c1));
        if (Changes(b, k, (PetscBool)(index1 >= 1), soft1)) PetscCall(ChangeBond(sys, u, i, k, (PetscBool)(index1 >= 1), soft1, c1, (PetscBool) !!released, &energy, &mine));
      }
  } else {
    PetscCall(PetscMalloc3(b->nbonds, &index, b->nbonds, &soft, b->nbonds, &cause));
    for (PetscInt i = b->rstart; i < b->rend; i++)
      for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
        index[k] = 0;
        if (!b->live[k] || b->j[k] == i) continue;
        PetscCall(EvaluateBond(sys, u, i, k, &index[k], &soft[k], &cause[k]));
        worst = PetscMax(worst, index[k]);
      }
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPIU_REAL, MPI_MAX, sys->comm));
    /* the fraction policy breaks the bonds whose index is within the top fraction of [1, worst] */
    if (worst > 1) threshold = worst - fraction * (worst - 1);
    for (PetscInt i = b->rstart; i < b->rend; i++)
      for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
        PetscBool breaks = (PetscBool)(index[k] >= threshold && index[k] >= 1);
        if (!b->live[k] || b->j[k] == i || !Changes(b, k, breaks, soft[k])) continue;
        PetscCall(ChangeBond(sys, u, i, k, breaks, soft[k], cause[k], (PetscBool) !!released, &energy, &mine));
      }
    PetscCall(PetscFree3(index, soft, cause));
  }
  PetscCall(PetscFree(u));
  PetscCall(PeriStiffnessScaled(sys));
  PetscCallMPI(MPI_Allreduce(&mine, nbroken, 1, MPIU_INT, MPI_SUM, sys->comm));
  if (released) PetscCallMPI(MPI_Allreduce(&energy, released, 1, MPIU_REAL, MPI_SUM, sys->comm));
  /* state-based models: the families follow the bonds (the energy, stresses and reactions read
     them); an assembled K of a family model is reassembled from them (a matrix-free one dropped
     the bonds' springs and state weights together, PeriOperatorScaleBond) */
  if (*nbroken && PeriModelHasFamilies(m)) PetscCall(PeriFamilySync(sys));
  if (*nbroken && PeriModelHasFamilies(m) && (!m->ops.bond_stiffness || !sys->stiffness.op)) PetscCall(PeriSystemAssemble(sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The state of the last equilibrium: what the outputs describe when a later step fails or the
 * run is interrupted, so that every file of the set shows one state. */
PetscErrorCode PeriCheckpointCreate(PeriSystem sys, PeriCheckpoint *e)
{
  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(sys->stiffness.K, &e->u, NULL)); /* lambda = 0: no displacement */
  e->live = NULL;                                          /* a scene without failure has no flags */
  if (sys->disc.bonds.live) {
    PetscCall(PetscMalloc1(sys->disc.bonds.nbonds, &e->live));
    PetscCall(PetscArraycpy(e->live, sys->disc.bonds.live, sys->disc.bonds.nbonds));
  }
  e->intact = NULL;
  if (sys->disc.bonds.intact) {
    PetscCall(PetscMalloc1(sys->disc.bonds.nbonds, &e->intact));
    PetscCall(PetscArraycpy(e->intact, sys->disc.bonds.intact, sys->disc.bonds.nbonds));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriCheckpointSave(PeriSystem sys, PeriCheckpoint *e)
{
  PetscFunctionBeginUser;
  PetscCall(VecCopy(sys->fields.u, e->u));
  e->solve = sys->fields.solve;
  if (e->live) PetscCall(PetscArraycpy(e->live, sys->disc.bonds.live, sys->disc.bonds.nbonds));
  if (e->intact) PetscCall(PetscArraycpy(e->intact, sys->disc.bonds.intact, sys->disc.bonds.nbonds));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Back to the last equilibrium: bonds (and the families and K built from them when the loop goes
 * on), and, with restore_u, the displacements. */
PetscErrorCode PeriCheckpointRestore(PeriSystem sys, PeriCheckpoint *e, PetscBool reassemble, PetscBool restore_u)
{
  PetscFunctionBeginUser;
  if (e->live) PetscCall(PetscArraycpy(sys->disc.bonds.live, e->live, sys->disc.bonds.nbonds));
  if (e->intact) PetscCall(PetscArraycpy(sys->disc.bonds.intact, e->intact, sys->disc.bonds.nbonds));
  PetscCall(PeriFamilySync(sys));
  if (reassemble) {
    PetscCall(PeriSystemAssemble(sys));
    if (sys->conditions.torsion.active && !sys->conditions.layers.nfaces) PetscCall(PeriLoadsAssemble(sys, sys->fields.f));
  }
  if (restore_u) {
    if (!sys->fields.u) PetscCall(VecDuplicate(e->u, &sys->fields.u));
    PetscCall(VecCopy(e->u, sys->fields.u));
    /* summary.json's solver section describes the solve of this state, not the abandoned one */
    if (e->solve.ksp_type[0]) sys->fields.solve = e->solve;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The solve that reached a checkpoint, as PETSc binary data: its names as bytes, then its numbers
 * (a viewer has no struct type). write: into v, else from v. Collective. */
static PetscErrorCode SolveInfoBinary(PetscViewer v, PeriSolveInfo *s, PetscBool write)
{
  PetscInt  n[3] = {s->iterations, s->symmetric, s->free_modes};
  PetscReal r[7] = {s->setup_s, s->ksp_solve_s, s->residual_norm, s->residual_tol, s->load_imbalance, s->rhs_norm, s->load_factor};

  PetscFunctionBeginUser;
  if (write) {
    PetscCall(PetscViewerBinaryWrite(v, s->ksp_type, sizeof(s->ksp_type), PETSC_CHAR));
    PetscCall(PetscViewerBinaryWrite(v, s->pc_type, sizeof(s->pc_type), PETSC_CHAR));
    PetscCall(PetscViewerBinaryWrite(v, s->converged_reason, sizeof(s->converged_reason), PETSC_CHAR));
    PetscCall(PetscViewerBinaryWrite(v, n, 3, PETSC_INT));
    PetscCall(PetscViewerBinaryWrite(v, r, 7, PETSC_REAL));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscViewerBinaryRead(v, s->ksp_type, sizeof(s->ksp_type), NULL, PETSC_CHAR));
  PetscCall(PetscViewerBinaryRead(v, s->pc_type, sizeof(s->pc_type), NULL, PETSC_CHAR));
  PetscCall(PetscViewerBinaryRead(v, s->converged_reason, sizeof(s->converged_reason), NULL, PETSC_CHAR));
  PetscCall(PetscViewerBinaryRead(v, n, 3, NULL, PETSC_INT));
  PetscCall(PetscViewerBinaryRead(v, r, 7, NULL, PETSC_REAL));
  s->iterations     = n[0];
  s->symmetric      = (PetscBool)n[1];
  s->free_modes     = n[2];
  s->setup_s        = r[0];
  s->ksp_solve_s    = r[1];
  s->residual_norm  = r[2];
  s->residual_tol   = r[3];
  s->load_imbalance = r[4];
  s->rhs_norm       = r[5];
  s->load_factor    = r[6];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCheckpointView - writes the equilibrium e (just saved from sys) into a checkpoint file: every
  rank's bond count and flags in rank order (live, the cause of each dead bond, which the in-memory
  checkpoint does not need since a dead bond's cause never changes, and with softening the shares),
  the solve that reached it, and the displacements (VecView). PeriCheckpointLoad reads it back on
  the same ranks and partition. Collective.
@*/
PetscErrorCode PeriCheckpointView(PeriSystem sys, const PeriCheckpoint *e, PetscViewer v)
{
  const PeriBonds *b     = &sys->disc.bonds;
  PeriSolveInfo    s     = e->solve;
  PetscInt         flags = b->cause && e->live ? 1 : 0; /* a scene without failure breaks no bond: no flags */

  PetscFunctionBeginUser;
  PetscCall(PetscViewerBinaryWriteAll(v, &b->nbonds, 1, PETSC_DETERMINE, PETSC_DETERMINE, PETSC_INT));
  PetscCall(PetscViewerBinaryWrite(v, &flags, 1, PETSC_INT));
  if (flags) PetscCall(PetscViewerBinaryWriteAll(v, e->live, b->nbonds, PETSC_DETERMINE, PETSC_DETERMINE, PETSC_CHAR));
  if (flags) PetscCall(PetscViewerBinaryWriteAll(v, b->cause, b->nbonds, PETSC_DETERMINE, PETSC_DETERMINE, PETSC_CHAR));
  if (e->intact) PetscCall(PetscViewerBinaryWriteAll(v, e->intact, b->nbonds, PETSC_DETERMINE, PETSC_DETERMINE, PETSC_REAL));
  PetscCall(SolveInfoBinary(v, &s, PETSC_TRUE));
  PetscCall(VecView(e->u, v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What a checkpoint holds must be a state this run could have reached: flags 0 or 1, causes
 * among PeriFailureCauses, shares in [0, 1], finite displacements, the solve's names ended. A
 * damaged file is refused here, not met as a solver failure or an overrun later (found by
 * tests/fuzz/fuzz_checkpoint.c). Collective. */
static PetscErrorCode CheckLoaded(PeriSystem sys, PeriCheckpoint *e, const char file[])
{
  const PeriBonds *b   = &sys->disc.bonds;
  PetscInt         bad = 0;
  PetscReal        norm;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; b->cause && e->live && k < b->nbonds && !bad; k++)
    bad = (e->live[k] != 0 && e->live[k] != 1) || b->cause[k] >= PERI_NCAUSES || (e->intact && !(e->intact[k] >= 0 && e->intact[k] <= 1));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_MAX, sys->comm));
  PetscCall(VecNorm(e->u, NORM_INFINITY, &norm));
  PetscCheck(!bad && PetscIsNormalReal(norm + 1), sys->comm, PETSC_ERR_USER_INPUT, "-restart: %s is damaged (a bond flag, cause or share out of its range, or displacements not finite): restart from an undamaged checkpoint, or run the scene from the start", file);
  e->solve.ksp_type[sizeof(e->solve.ksp_type) - 1]                 = 0;
  e->solve.pc_type[sizeof(e->solve.pc_type) - 1]                   = 0;
  e->solve.converged_reason[sizeof(e->solve.converged_reason) - 1] = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCheckpointLoad - reads what PeriCheckpointView wrote into e (created by PeriCheckpointCreate)
  and the causes into sys; PeriCheckpointRestore then makes it the system's state. The bond counts
  of every rank must be this run's: the same scene on the same number of ranks. Collective.
@*/
PetscErrorCode PeriCheckpointLoad(PeriSystem sys, PeriCheckpoint *e, PetscViewer v, const char file[])
{
  PeriBonds *b = &sys->disc.bonds;
  PetscInt   n, bad, flags;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerBinaryReadAll(v, &n, 1, PETSC_DETERMINE, PETSC_DETERMINE, PETSC_INT));
  bad = n != b->nbonds;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_MAX, sys->comm));
  PetscCheck(!bad, sys->comm, PETSC_ERR_USER_INPUT, "%s: its bonds are not shared out between the ranks as in this run (was it written by another perilin or with another -peri_partition?): restart with the options of the run that wrote it", file);
  PetscCall(PetscViewerBinaryRead(v, &flags, 1, NULL, PETSC_INT));
  PetscCheck(flags == (b->cause && e->live ? 1 : 0), sys->comm, PETSC_ERR_USER_INPUT, "-restart: %s is damaged (its bond flags are %s, and this scene's bonds %s)", file, flags ? "there" : "absent", b->cause ? "break" : "do not");
  if (flags) PetscCall(PetscViewerBinaryReadAll(v, e->live, b->nbonds, PETSC_DETERMINE, PETSC_DETERMINE, PETSC_CHAR));
  if (flags) PetscCall(PetscViewerBinaryReadAll(v, b->cause, b->nbonds, PETSC_DETERMINE, PETSC_DETERMINE, PETSC_CHAR));
  if (e->intact) PetscCall(PetscViewerBinaryReadAll(v, e->intact, b->nbonds, PETSC_DETERMINE, PETSC_DETERMINE, PETSC_REAL));
  PetscCall(SolveInfoBinary(v, &e->solve, PETSC_FALSE));
  PetscCall(VecLoad(e->u, v));
  PetscCall(CheckLoaded(sys, e, file));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriCheckpointDestroy(PeriCheckpoint *e)
{
  PetscFunctionBeginUser;
  PetscCall(VecDestroy(&e->u));
  PetscCall(PetscFree(e->live));
  PetscCall(PetscFree(e->intact));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Frees what the bond state holds. */
/*@C
  PeriBondsCount - the bonds the run has broken (dead, less those the scene's cracks removed) and
  those softened (alive with less than their whole stiffness), over all ranks: what a step reports,
  where summing PeriBondsBreak's counts would count a bond that softens in several rounds each
  time. Collective.
@*/
PetscErrorCode PeriBondsCount(PeriSystem sys, PetscInt *broken, PetscInt *softened)
{
  const PeriBonds *b    = &sys->disc.bonds;
  PetscInt         n[2] = {0, 0};

  PetscFunctionBeginUser;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      if (b->j[k] == i) continue;
      if (!b->live[k])
        n[0]++;
      else if (b->intact && b->intact[k] < 1)
        n[1]++;
    }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, n, 2, MPIU_INT, MPI_SUM, sys->comm));
  *broken   = n[0] - sys->bond_state.failure.precracked_bonds;
  *softened = n[1];
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriBondStateDestroy(PeriBondState *B)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(B->damage));
  for (PetscInt c = 0; c < B->failure.ncriteria; c++) PetscCall(PetscFree(B->failure.criterion[c].critical));
  PetscFunctionReturn(PETSC_SUCCESS);
}
