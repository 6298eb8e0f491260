/* Modal analysis: natural frequencies and mode shapes from K x = omega^2 M x (SLEPc, EPS_GHEP),
 * shift-and-invert around a target with a direct factorization, or on large bodies LOBPCG with
 * algebraic multigrid (analysis.eigensolver), on the free DOFs only (prescribed DOFs are removed,
 * so they give no spurious eigenvalues). M is lumped: rho V_i per translation,
 * rho V_i (dx^2 + dy^2)/12 per rotation (Diana & Casolo sec. 3.1, with r_i^2 for their r_i). */
#include "perilin/private/analysis.h"
#include <slepceps.h>

/* analysis.eigensolver */
typedef enum {
  EIGENSOLVER_AUTO,
  EIGENSOLVER_SHIFT_INVERT,
  EIGENSOLVER_LOBPCG
} Eigensolver;
static const char *const eigensolvers[] = {"auto", "shift_invert", "lobpcg", NULL};

/* auto takes LOBPCG from this many DOFs on: below it the factorization is faster, above it its
 * fill outgrows the machine (docs/performance.md, "Modes at scale (issue 29, item 1)"); with the
 * geometric multigrid (a matrix-free K of a grid body) from MODAL_LOBPCG_MIN_DOFS_MG on (perilin's
 * LOBPCG on the gerstle lamina, 10 modes: a tie at 4,800 DOFs, 0.67 s against 0.76 s at 10,800,
 * 1.8 s against 2.8 s at 43,200); on a free body of a state-based model (whose two-horizon K
 * factorizes slowly) with a matrix-free K (GAMG on its shifted short-range stiffness,
 * ShiftFreeBody) from MODAL_LOBPCG_MIN_DOFS_FREE on (the free lps bar, 8 modes: 0.71 of the
 * factorization's wall at 7,500 DOFs, 0.50 at 30,720; 1.6 times it at 3,840; a free pmb bar,
 * examples/pmb/bar_modes.yaml, 9,600 DOFs: 1.6 times it, so bond-based free bodies keep the
 * factorization up to MODAL_LOBPCG_MIN_DOFS) */
#define MODAL_LOBPCG_MIN_DOFS      300000
#define MODAL_LOBPCG_MIN_DOFS_MG   8000
#define MODAL_LOBPCG_MIN_DOFS_FREE 8000
#define MODAL_FREE_SHIFT           1e-4

/* the analysis' results (its data) */
static inline PeriModal *Modal(PeriAnalysis an)
{
  return (PeriModal *)an->data;
}

/* The structure's main axis: away from its constraints (a cantilever's length), or, for a free
 * body, its longest extent. Components held at 0 because they are inactive do not count. */
static PetscErrorCode MainAxis(PeriAnalysis an, PetscInt *axis)
{
  const PeriParticles *pt   = &an->sys->disc.particles;
  PetscReal            s[4] = {0, 0, 0, 0}, best = -1;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < an->sys->conditions.nconstrained; k++) {
    PetscInt i = an->sys->conditions.constrained[k] / an->sys->model->dofs;
    if (an->sys->model->inactive[an->sys->conditions.constrained[k] % an->sys->model->dofs]) continue;
    for (PetscInt d = 0; d < pt->dim; d++) s[d] += pt->x[3 * i + d] - 0.5 * (pt->lower[d] + pt->upper[d]);
    s[3] += 1;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, s, 4, MPIU_REAL, MPI_SUM, an->comm));
  *axis = 0;
  for (PetscInt d = 0; d < pt->dim; d++) {
    PetscReal v = s[3] > 0 ? PetscAbsReal(s[d] / s[3]) / (pt->upper[d] - pt->lower[d]) : pt->upper[d] - pt->lower[d];
    if (v > best) {
      best  = v;
      *axis = d;
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.nev and analysis.target_hz, before any particle exists (the getters apply the declared
 * defaults and ranges). */
static PetscErrorCode SetFromScene_Modal(PeriAnalysis an, PeriScene s, PeriNode a)
{
  PeriModal *md;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&md));
  an->data = md;
  PetscCall(PeriSceneGetInt(s, a, "nev", PETSC_FALSE, &md->nev, NULL));
  PetscCall(PeriSceneGetReal(s, a, "target_hz", PETSC_FALSE, &md->target_hz, NULL));
  PetscCall(PeriSceneGetChoice(s, a, "eigensolver", eigensolvers, &md->eigensolver, NULL));
  /* the memory estimate's path: a factorization at any size where the scene asks for it (or for a
     target, which LOBPCG cannot take), none with lobpcg */
  if (md->eigensolver == EIGENSOLVER_SHIFT_INVERT || (md->eigensolver == EIGENSOLVER_AUTO && md->target_hz > 0)) an->needs.iterative_dofs = an->needs.iterative_dofs_grid = 0;
  if (md->eigensolver == EIGENSOLVER_LOBPCG) an->needs.iterative_dofs = an->needs.iterative_dofs_grid = 1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What the system must offer: a density, and bc only (no fictitious layers). */
static PetscErrorCode SetUp_Modal(PeriAnalysis an)
{
  PeriScene s = an->sys->scene;
  PeriNode  mat;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "material", &mat));
  PeriInputCheck(an->sys->model->material.rho > 0, s, mat, "rho", "a modal analysis needs the density (material.rho > 0)");
  PeriInputCheck(!an->sys->conditions.layers.nfaces, s, s->root, "boundary_layers", "the fictitious layers carry static conditions; a modal analysis takes bc only");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The owned DOFs that are not prescribed. */
static PetscErrorCode FreeDOFs(PeriAnalysis an, IS *is)
{
  const PetscInt bs = an->sys->model->dofs, nloc = (an->sys->disc.bonds.rend - an->sys->disc.bonds.rstart) * bs, r0 = an->sys->disc.rstart * bs; /* r0: the first owned global row */
  PetscInt      *idx, n = 0, c = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(nloc, &idx));
  /* an->sys->conditions.constrained is sorted: built by a loop over the owned DOFs */
  for (PetscInt k = 0; k < nloc; k++) {
    if (c < an->sys->conditions.nconstrained && an->sys->conditions.constrained[c] == r0 + k) {
      c++;
      continue;
    }
    idx[n++] = r0 + k;
  }
  PetscCall(ISCreateGeneral(an->comm, n, idx, PETSC_OWN_POINTER, is));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Shares of kinetic energy per component, effective modal masses per direction, and the kind. */
static PetscErrorCode Classify(PeriAnalysis an, Vec x, Vec mdiag, PeriMode *mode, PetscInt axis)
{
  const PetscInt     bs = an->sys->model->dofs, nloc = an->sys->disc.bonds.rend - an->sys->disc.bonds.rstart;
  const PetscScalar *xa, *ma;
  PetscReal          e[PERI_MAX_DOF + 4] = {0}, tot = 0, trans = 0, rot = 0, along = 0;
  PetscInt           comp[3];

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) comp[d] = PeriModelTranslation(an->sys->model, d);
  PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArrayRead(mdiag, &ma));
  for (PetscInt i = 0; i < nloc; i++)
    for (PetscInt c = 0; c < bs; c++) {
      PetscReal v = PetscRealPart(xa[i * bs + c]), m = PetscRealPart(ma[i * bs + c]);
      e[c] += m * v * v;
      for (PetscInt d = 0; d < 3; d++)
        if (comp[d] == c) e[PERI_MAX_DOF + d] += m * v; /* participation in a unit translation */
    }
  PetscCall(VecRestoreArrayRead(x, &xa));
  PetscCall(VecRestoreArrayRead(mdiag, &ma));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, e, PERI_MAX_DOF + 3, MPIU_REAL, MPI_SUM, an->comm));
  for (PetscInt c = 0; c < bs; c++) tot += e[c];
  for (PetscInt c = 0; c < bs; c++) {
    mode->energy_share[c] = e[c] / tot;
    if (an->sys->model->rotational[c])
      rot += e[c] / tot;
    else
      trans += e[c] / tot;
    if (c == comp[axis]) along = e[c] / tot;
  }
  /* effective mass = (phi^T M r)^2 / (phi^T M phi), as a fraction of the total mass */
  for (PetscInt d = 0; d < 3; d++) mode->effective_mass[d] = comp[d] >= 0 ? e[PERI_MAX_DOF + d] * e[PERI_MAX_DOF + d] / tot / Modal(an)->total_mass : 0;
  /* A mode that moves the mass as a whole moves it along the axis (axial) or across it (flexural);
   * symmetric structures separate the two exactly. Modes with no net momentum are told apart by
   * where their kinetic energy is. */
  {
    PetscReal maxis = mode->effective_mass[axis], macross = 0;
    for (PetscInt d = 0; d < an->sys->disc.particles.dim; d++)
      if (d != axis) macross = PetscMax(macross, mode->effective_mass[d]);
    if (rot > 0.5)
      PetscCall(PetscStrncpy(mode->kind, "rotational", sizeof(mode->kind)));
    else if (PetscMax(maxis, macross) > 1e-3 ? maxis > macross : along > 0.5 * trans)
      PetscCall(PetscStrncpy(mode->kind, an->sys->disc.particles.dim == 2 ? "axial" : "longitudinal", sizeof(mode->kind)));
    else
      PetscCall(PetscStrncpy(mode->kind, an->sys->disc.particles.dim == 2 ? "flexural" : "transverse", sizeof(mode->kind)));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Keeps this rank's part of the mode vector (its particles' DOFs: its piece of the output, no
 * gather), scaled to max |u| = 1 over the body. Collective. */
static PetscErrorCode StoreShape(PeriAnalysis an, Vec full, PetscInt k)
{
  const PetscScalar *a;
  PetscInt           nl;
  PetscReal          amax  = 0, *s;
  PetscBool          trans = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(full, &nl));
  s = &Modal(an)->shapes[k * nl];
  for (PetscInt c = 0; c < an->sys->model->dofs; c++) trans = (PetscBool)(trans || !an->sys->model->rotational[c]);
  PetscCall(VecGetArrayRead(full, &a));
  /* the largest displacement is 1 (rotations, in radians, do not set the scale); the local
     vector starts at a particle, so i % dofs is the component */
  for (PetscInt i = 0; i < nl; i++)
    if (!trans || !an->sys->model->rotational[i % an->sys->model->dofs]) amax = PetscMax(amax, PetscAbsReal(PetscRealPart(a[i])));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &amax, 1, MPIU_REAL, MPI_MAX, an->comm));
  for (PetscInt i = 0; i < nl; i++) s[i] = PetscRealPart(a[i]) / (amax > 0 ? amax : 1);
  PetscCall(VecRestoreArrayRead(full, &a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The true residual of every inner solve of the spectral transform, (K - sigma M) y = b. An
 * inexact one (an iterative KSP with a loose -st_ksp_rtol, or preonly with a mere preconditioner)
 * makes shift-and-invert converge to wrong modes, and SLEPc does not notice. */
typedef struct {
  PeriAnalysis an;
  Vec          r;
  PetscReal    worst; /* the largest ||b - A y|| / ||b|| so far */
  PetscInt     nsolves;
  char         failed[1024]; /* the first bad solve's message ("": none) */
} InnerCheck;

/* KSP post-solve hook. The first bad solve, on every rank at once (the norms are collective), is
 * kept and stops the eigensolver at its next stopping test (InnerStop), instead of letting it
 * iterate on wrong operators up to -eps_max_it. It is not raised here: an error returning through
 * EPSSolve leaks SLEPc's work vector (found by -malloc_dump in the modal_checks test). */
static PetscErrorCode InnerSolveCheck(KSP ksp, Vec b, Vec y, void *ctx)
{
  InnerCheck *c = (InnerCheck *)ctx;
  Mat         A;
  PetscReal   bn, rn, rel, rtol, tol;

  PetscFunctionBeginUser;
  PetscCall(KSPGetOperators(ksp, &A, NULL));
  if (!c->r) PetscCall(VecDuplicate(b, &c->r));
  PetscCall(MatMult(A, y, c->r));
  PetscCall(VecAYPX(c->r, -1.0, b));
  PetscCall(VecNorm(b, NORM_2, &bn));
  PetscCall(VecNorm(c->r, NORM_2, &rn));
  rel = bn > 0 ? rn / bn : (rn > 0 ? PETSC_INFINITY : 0);
  c->nsolves++;
  if (rel > c->worst || PetscIsNanReal(rel)) c->worst = rel;
  PetscCall(KSPGetTolerances(ksp, &rtol, NULL, NULL, NULL));
  tol = PeriResidualTolerance(c->an->sys, rtol);
  if (PetscUnlikely(!(rel <= tol))) {
    KSPType            kt;
    PCType             pt;
    PC                 pc;
    KSPConvergedReason reason;
    PetscInt           its;
    PetscCall(KSPGetType(ksp, &kt));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCGetType(pc, &pt));
    PetscCall(KSPGetConvergedReason(ksp, &reason));
    PetscCall(KSPGetIterationNumber(ksp, &its));
    if (c->failed[0]) PetscFunctionReturn(PETSC_SUCCESS);
    PetscCall(PetscSNPrintf(c->failed, sizeof(c->failed),
                            "%s: inner solve %" PetscInt_FMT " of the spectral transform, (K - sigma M) y = b, left the true relative residual ||b - (K - sigma M) y|| / ||b|| = %.3g, above the tolerance %.3g "
                            "(KSP %s, PC %s: %s after %" PetscInt_FMT " iterations): the modes would be wrong. Use a direct factorization (-st_ksp_type preonly -st_pc_type cholesky, the default) "
                            "or a tighter -st_ksp_rtol (now %g); solver.residual_tol raises the tolerance",
                            c->an->sys->scene->file, c->nsolves, (double)rel, (double)tol, kt, pt, KSPConvergedReasons[reason], its, (double)rtol));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The eigensolver's stopping test: SLEPc's, and a stop once an inner solve failed its check. */
static PetscErrorCode InnerStop(EPS eps, PetscInt its, PetscInt max_it, PetscInt nconv, PetscInt nev, EPSConvergedReason *reason, void *ctx)
{
  InnerCheck *c = (InnerCheck *)ctx;

  PetscFunctionBeginUser;
  PetscCall(EPSStoppingBasic(eps, its, max_it, nconv, nev, reason, NULL));
  if (c->failed[0]) *reason = EPS_DIVERGED_BREAKDOWN;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The status line's solver slot (src/sys/progress.c): the eigenpairs converged so far of those
 * asked for (nev, plus the rigid-body modes of a free body) and the eigensolver's iteration.
 * Installed only where the line is drawn. */
static PetscErrorCode ProgressMonitor(EPS eps, PetscInt its, PetscInt nconv, PetscScalar *eigr, PetscScalar *eigi, PetscReal *errest, PetscInt nest, void *ctx)
{
  PetscInt nreq;

  PetscFunctionBeginUser;
  (void)eigr, (void)eigi, (void)errest, (void)nest;
  PetscCall(EPSGetDimensions(eps, &nreq, NULL, NULL));
  PetscCall(PeriProgressUpdate((PeriProgress)ctx, PERI_PROGRESS_SOLVER, "%" PetscInt_FMT " of %" PetscInt_FMT " eigenpairs converged, iteration %" PetscInt_FMT, nconv, nreq, its));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The spectral transformation of the given type, its linear solver a single application of a PC
 * of the given type (returned, for its own settings). */
static PetscErrorCode SetTransform(EPS eps, STType st_type, PCType pc_type, PC *pc)
{
  ST  st;
  KSP ksp;

  PetscFunctionBeginUser;
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STSetType(st, st_type));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, pc));
  PetscCall(PCSetType(*pc, pc_type));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Krylov-Schur, shift-and-invert at sigma with a direct factorization (MUMPS Cholesky when PETSc
 * has it): the nreq pairs nearest sigma. */
static PetscErrorCode SetShiftInvert(EPS eps, PetscReal sigma)
{
  PC pc;

  PetscFunctionBeginUser;
  PetscCall(EPSSetTarget(eps, sigma));
  PetscCall(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
  PetscCall(EPSSetTolerances(eps, 1e-10, PETSC_DEFAULT));
  PetscCall(SetTransform(eps, STSINVERT, PCCHOLESKY, &pc));
#if defined(PETSC_HAVE_MUMPS)
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
#endif
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether LOBPCG is preconditioned by the geometric multigrid: a matrix-free K of a grid body
 * (PeriMultigridApplies), unless -st_pc_type asks for another PC. On the 230,400-particle gerstle
 * lamina it replaced GAMG on the short-range stiffness (docs/performance.md, "Modes at scale"). */
static PetscBool UseMultigrid(PeriAnalysis an)
{
  PetscBool set = PETSC_FALSE;

  /* a free body's coarse levels would be singular: GAMG on the shifted short-range stiffness */
  if (Modal(an)->eigensolver != EIGENSOLVER_LOBPCG || Modal(an)->free_body || !an->sys->stiffness.op || !PeriMultigridApplies(an->sys)) return PETSC_FALSE;
  PetscOptionsHasName(NULL, NULL, "-st_pc_type", &set);
  return (PetscBool)!set;
}

/* LOBPCG for the nreq lowest pairs, preconditioned by one V-cycle of the geometric multigrid
 * (UseMultigrid) or one GAMG cycle on P (the short-range
 * stiffness of a matrix-free K, or K itself). Its block holds two pairs more than asked for (on the
 * 14,400-particle lamina, 10 modes: blocks of 12, 16 and 20 took 7.0, 8.2 and 8.5 s). perilin's
 * mode residual is SLEPc's relative error times a factor that grows with the body (1e-8 left
 * 1.1e-6 at 57,600 particles, above the 1e-6 accepted; 1e-9 left 9.1e-7 at 921,600): 1e-10 leaves
 * 2.5e-8 at 57,600. The frequencies, quadratic in it, agree with the factorization's to 1e-12. */
static PetscErrorCode SetLOBPCG(PeriAnalysis an, EPS eps, Mat P, IS isfree, PetscInt nreq)
{
  ST st;
  PC pc;

  PetscFunctionBeginUser;
  PetscCall(EPSSetType(eps, PERI_EPSLOBPCG));
  PetscCall(EPSSetWhichEigenpairs(eps, EPS_SMALLEST_REAL));
  PetscCall(EPSSetTolerances(eps, 1e-10, PETSC_DEFAULT));
  PetscCall(EPSLOBPCGSetBlockSize(eps, nreq + 2)); /* for -eps_type lobpcg */
  if (UseMultigrid(an)) {                          /* one V-cycle of the geometric multigrid (src/system/multigrid.c) */
    PetscCall(SetTransform(eps, STPRECOND, PCSHELL, &pc));
    PetscCall(PeriMultigridSetUpFree(an->sys, isfree, pc));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(SetTransform(eps, STPRECOND, PCGAMG, &pc));
  PetscCall(EPSGetST(eps, &st));
  if (P) PetscCall(STSetPreconditionerMat(st, P));
  /* aggregates of the wide stencil's squared graph are too coarse: 58 LOBPCG iterations on the
     57,600-particle lamina with the squared graph, 37 without */
  PetscCall(PCGAMGSetAggressiveLevels(pc, 0));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The eigensolver analysis.eigensolver chose (SetShiftInvert or SetLOBPCG), then every -eps_* and
 * -st_* option; then the check of the inner solves. */
static PetscErrorCode CreateEPS(PeriAnalysis an, Mat Kff, Mat Mff, Mat Pff, IS isfree, PetscReal sigma, PetscInt nreq, InnerCheck *inner, EPS *eps)
{
  ST        st;
  KSP       ksp;
  PetscBool precond;

  PetscFunctionBeginUser;
  PetscCall(PeriEPSRegisterLOBPCG()); /* also for -eps_type perilin_lobpcg with shift_invert: refused with its reason */
  PetscCall(EPSCreate(an->comm, eps));
  PetscCall(EPSSetOperators(*eps, Kff, Mff));
  PetscCall(EPSSetProblemType(*eps, EPS_GHEP));
  PetscCall(EPSSetDimensions(*eps, nreq, PETSC_DEFAULT, PETSC_DEFAULT));
  if (Modal(an)->eigensolver == EIGENSOLVER_LOBPCG)
    PetscCall(SetLOBPCG(an, *eps, Pff, isfree, nreq));
  else
    PetscCall(SetShiftInvert(*eps, sigma));
  PetscCall(EPSSetFromOptions(*eps));
  if (PeriProgressActive(an->sys->run.progress)) PetscCall(EPSMonitorSet(*eps, ProgressMonitor, an->sys->run.progress, NULL));
  /* STPRECOND (Davidson methods, LOBPCG) solves only approximately by design: there only the
   * modes themselves are checked */
  PetscCall(EPSGetST(*eps, &st));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(PetscObjectTypeCompare((PetscObject)st, STPRECOND, &precond));
  inner->an        = an;
  inner->r         = NULL;
  inner->worst     = 0;
  inner->nsolves   = 0;
  inner->failed[0] = 0;
  if (!precond) PetscCall(KSPSetPostSolve(ksp, InnerSolveCheck, inner));
  if (!precond) PetscCall(EPSSetStoppingTestFunction(*eps, InnerStop, inner, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One converged pair as the selection sees it. */
typedef struct {
  PetscInt  k;        /* its index among SLEPc's converged pairs */
  PetscReal lam, key; /* omega^2; the sort key */
} Pair;

/* The frequency of omega^2 (negative for a negative omega^2, so that it sorts below 0). */
static PetscReal Frequency(PetscReal lam)
{
  return PetscCopysignReal(PetscSqrtReal(PetscAbsReal(lam)), lam) / (2 * PETSC_PI);
}

/* Stable insertion sort by key, ties to the lower omega^2: the converged pairs number about ncv,
 * small beside the cost of computing them. */
static void SortPairs(PetscInt n, Pair a[])
{
  for (PetscInt i = 1; i < n; i++) {
    Pair     t = a[i];
    PetscInt j = i;
    for (; j > 0 && (t.key < a[j - 1].key || (t.key == a[j - 1].key && t.lam < a[j - 1].lam)); j--) a[j] = a[j - 1];
    a[j] = t;
  }
}

/* The converged pairs the run may return, in the order it returns them: without a target
 * ascending; with one, by distance |f - target| (ties: the lower frequency first). Of a free body
 * the lowest nfree with |omega^2| < 1e-6 scale are its rigid-body modes: counted, not returned.
 * radius: the largest |omega^2 - sigma| among all converged pairs. */
static PetscErrorCode OrderPairs(EPS eps, PetscReal target_hz, PetscReal sigma, PetscReal shift, PetscInt nfree, PetscReal scale, PetscInt *nrigid, PetscInt *n, Pair **pairs, PetscReal *radius)
{
  PetscInt nconv, m = 0;
  Pair    *a;

  PetscFunctionBeginUser;
  PetscCall(EPSGetConverged(eps, &nconv));
  PetscCall(PetscMalloc1(nconv, &a));
  *radius = 0;
  for (PetscInt k = 0; k < nconv; k++) {
    PetscScalar kr;
    PetscCall(EPSGetEigenvalue(eps, k, &kr, NULL));
    a[k].k   = k;
    a[k].lam = a[k].key = PetscRealPart(kr) - shift; /* a free body's LOBPCG: (K + shift M, M) */
    *radius             = PetscMax(*radius, PetscAbsReal(a[k].lam - sigma));
  }
  SortPairs(nconv, a);
  *nrigid = 0;
  for (PetscInt s = 0; s < nconv; s++) {
    if (*nrigid < nfree && PetscAbsReal(a[s].lam) < 1e-6 * scale) {
      (*nrigid)++;
      continue;
    }
    a[m] = a[s];
    if (target_hz > 0) a[m].key = PetscAbsReal(Frequency(a[m].lam) - target_hz);
    m++;
  }
  SortPairs(m, a);
  *n     = m;
  *pairs = a;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* SLEPc converges the pairs nearest sigma in omega^2, which favours the modes below the target;
 * the nev nearest in frequency are surely among them when every omega^2 within the frequency
 * distance d of the farthest one chosen, up to (2 pi (target + d))^2, lies within the radius
 * SLEPc covered. */
static PetscBool Covered(const Pair a[], PetscInt n, PetscInt nev, PetscReal target_hz, PetscReal sigma, PetscReal radius)
{
  if (n < nev) return PETSC_FALSE;
  return (PetscBool)(PetscSqr(2 * PETSC_PI * (target_hz + a[nev - 1].key)) - sigma <= radius);
}

/* EPSSolve, then the pairs to return; with a target, solved again asking for twice as many
 * pairs until the nev nearest the target in frequency are surely among the converged ones. */
static PetscErrorCode SolveModes(PeriAnalysis an, EPS eps, const InnerCheck *inner, PetscInt nev, PetscReal target_hz, PetscReal sigma, PetscInt nfree, PetscReal scale, PetscInt *n, Pair **pairs)
{
  PeriModal *md = Modal(an);
  PetscInt   nreq, ncv;
  PetscReal  radius = 0;

  PetscFunctionBeginUser;
  PetscCall(EPSGetDimensions(eps, &nreq, NULL, NULL));
  for (;;) {
    PetscCall(EPSSolve(eps));
    PetscCheck(!inner->failed[0], an->comm, PETSC_ERR_NOT_CONVERGED, "%s", inner->failed);
    PetscCall(OrderPairs(eps, target_hz, sigma, md->shift, nfree, scale, &md->nrigid, n, pairs, &radius));
    if (target_hz == 0 || nreq >= md->nfree_dofs || Covered(*pairs, *n, nev, target_hz, sigma, radius)) break;
    PetscCall(PetscFree(*pairs));
    nreq = PetscMin(2 * nreq, md->nfree_dofs);
    PetscCall(EPSGetDimensions(eps, NULL, &ncv, NULL));
    PetscCall(PetscInfo(eps, "target %g Hz: the %" PetscInt_FMT " modes nearest in frequency may lie beyond the converged ones: asking for %" PetscInt_FMT "\n", (double)target_hz, nev, nreq));
    PetscCall(EPSSetDimensions(eps, nreq, ncv >= 2 * nreq && ncv <= md->nfree_dofs ? ncv : PETSC_DEFAULT, PETSC_DEFAULT));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* ||K x - lam M x|| / (max(|lam|, lam_floor) ||M x||): relative to the eigenvalue, unlike a residual
 * scaled by ||K||, which hides errors in the low modes. Below lam_floor = sqrt(eps) ||K||_1/||M||_1 an
 * omega^2 is at the round-off of K x itself: only its error relative to lam_floor can be asked for. */
static PetscErrorCode ModeResidual(Mat K, Mat M, Vec x, PetscReal lam, PetscReal shift, PetscReal lam_floor, Vec r, Vec y, PetscReal *res)
{
  PetscReal rn, yn;

  PetscFunctionBeginUser;
  PetscCall(MatMult(K, x, r)); /* K + shift M where the eigensolver was given that (ShiftFreeBody) */
  PetscCall(MatMult(M, x, y));
  PetscCall(VecNorm(y, NORM_2, &yn));
  PetscCall(VecAXPY(r, -(lam + shift), y));
  PetscCall(VecNorm(r, NORM_2, &rn));
  *res = rn / (PetscMax(PetscAbsReal(lam), lam_floor) * yn);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every returned mode must satisfy K x = omega^2 M x to PeriResidualTolerance(eps_tol). */
static PetscErrorCode CheckModes(PeriAnalysis an, PetscReal eps_tol)
{
  const PeriModal *md   = Modal(an);
  const PetscReal  tol  = PeriResidualTolerance(an->sys, eps_tol);
  PetscInt         nbad = 0, first = -1;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(an->sys->fields.solve.checked, "worst mode residual", sizeof(an->sys->fields.solve.checked)));
  an->sys->fields.solve.checked_value = 0;
  for (PetscInt k = 0; k < md->nmodes; k++) an->sys->fields.solve.checked_value = PetscMax(an->sys->fields.solve.checked_value, md->modes[k].residual);
  for (PetscInt k = 0; k < md->nmodes; k++)
    if (!(md->modes[k].residual <= tol)) {
      nbad++;
      if (first < 0) first = k;
    }
  PetscCheck(!nbad, an->comm, PETSC_ERR_NOT_CONVERGED,
             "%s: mode %" PetscInt_FMT " (%.6g Hz) has the relative residual ||K x - omega^2 M x|| / (omega^2 ||M x||) = %.3g, above the tolerance %.3g (%" PetscInt_FMT " of the %" PetscInt_FMT
             " modes fail): its frequency and shape cannot be trusted. Try a tighter -eps_tol (now %g), a larger -eps_ncv, a direct inner solve (-st_ksp_type preonly -st_pc_type cholesky), "
             "or accept it with a larger solver.residual_tol",
             an->sys->scene->file, first + 1, (double)md->modes[first].f_hz, (double)md->modes[first].residual, (double)tol, nbad, md->nmodes, (double)eps_tol);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The free block of a matrix-free K's short-range stiffness, for GAMG (*Pff), with the rigid
 * modes on the free DOFs; the full matrix is freed. */
static PetscErrorCode FreeShortRange(PeriAnalysis an, IS isfree, Mat *Pff)
{
  PeriStiffness *S = &an->sys->stiffness;

  PetscFunctionBeginUser;
  PetscCall(PeriOperatorPreconditioner(an->sys));
  PetscCall(MatCreateSubMatrix(S->Kpc, isfree, isfree, MAT_INITIAL_MATRIX, Pff));
  PetscCall(MatDestroy(&S->Kpc)); /* only its free block is used */
  PetscCall(MatSetOption(*Pff, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(PeriSetNearNullSpace(an->sys, *Pff, isfree));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* K on the free DOFs, and what preconditions it. A matrix-free K is restricted without a copy
 * (R K R^T), and the free block of its short-range stiffness serves GAMG (*Pff) unless the
 * geometric multigrid does (its levels are matrix-free too: *Pff NULL); an assembled K is copied.
 * Only the free blocks are used: the full matrices are freed (an assembled K of the
 * 230,400-particle lamina: 0.87 GB). */
static PetscErrorCode FreeStiffness(PeriAnalysis an, IS isfree, Mat *Kff, Mat *Pff)
{
  PeriStiffness *S = &an->sys->stiffness;

  PetscFunctionBeginUser;
  *Pff = NULL;
  if (S->op) {
    PetscCall(MatCreateSubMatrixVirtual(S->K, isfree, isfree, Kff));
    if (!UseMultigrid(an)) PetscCall(FreeShortRange(an, isfree, Pff));
  } else {
    PetscCall(MatCreateSubMatrix(S->K, isfree, isfree, MAT_INITIAL_MATRIX, Kff));
    PetscCall(MatDestroy(&S->K));
    /* for an inner solve by algebraic multigrid (-st_pc_type gamg): the rigid modes on the free DOFs */
    PetscCall(PeriSetNearNullSpace(an->sys, *Kff, isfree));
  }
  PetscCall(MatSetOption(*Kff, MAT_SYMMETRIC, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The mass, the free DOFs and the blocks of K and M on them. */
static PetscErrorCode SetUpModal(PeriAnalysis an, Mat *M, Vec *mdiag, IS *isfree, Mat *Kff, Mat *Mff, Mat *Pff)
{
  PeriModal *md = Modal(an);

  PetscFunctionBeginUser;
  /* the system's mass service (src/system/mass.c): borrowed */
  PetscCall(PeriMassGetMatrix(an->sys, M));
  PetscCall(PeriMassGetDiagonal(an->sys, mdiag));
  md->started = PETSC_TRUE;
  PetscCall(PeriMassGetTotal(an->sys, &md->total_mass));
  PetscCall(MainAxis(an, &md->axis));
  PetscCall(FreeDOFs(an, isfree));
  PetscCall(ISGetSize(*isfree, &md->nfree_dofs));
  PetscCheck(md->nfree_dofs > 0, an->comm, PETSC_ERR_USER_INPUT, "%s: every DOF is prescribed: there is no mode to compute", an->sys->scene->file);
  PetscCall(FreeStiffness(an, *isfree, Kff, Pff));
  PetscCall(MatCreateSubMatrix(*M, *isfree, *isfree, MAT_INITIAL_MATRIX, Mff));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Each chosen pair becomes a mode: frequency, residual, kind, shape. */
static PetscErrorCode CollectModes(PeriAnalysis an, EPS eps, Mat Kff, Mat Mff, IS isfree, Vec mdiag, PetscInt nev, PetscInt npairs, const Pair pairs[], PetscReal lam_floor)
{
  PeriModal *md = Modal(an);
  Vec        x, r, y, full;
  PetscInt   nl;

  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(Kff, &x, &r));
  PetscCall(VecDuplicate(r, &y));
  PetscCall(PeriSystemCreateVec(an->sys, &full));
  PetscCall(VecGetLocalSize(full, &nl));
  /* no more modes than free DOFs, whatever nev asks for */
  PetscCall(PetscCalloc1(PetscMin(nev, md->nfree_dofs), &md->modes));
  md->nshapes = PetscMin(PetscMin(nev, md->nfree_dofs), PERI_MAX_VTU_MODES);
  PetscCall(PetscCalloc1(md->nshapes * nl, &md->shapes)); /* the owned particles' DOFs of each shape */
  for (PetscInt s = 0; s < npairs && md->nmodes < nev; s++) {
    PeriMode *mode = &md->modes[md->nmodes];
    PetscReal l    = pairs[s].lam;
    PetscCheck(l > 0, an->comm, PETSC_ERR_NOT_CONVERGED, "%s: a negative eigenvalue omega^2 = %g: the stiffness is indefinite (Poisson ratio above the bond-based value?)", an->sys->scene->file, (double)l);
    PetscCall(EPSGetEigenvector(eps, pairs[s].k, x, NULL));
    PetscCall(ModeResidual(Kff, Mff, x, l, md->shift, lam_floor, r, y, &mode->residual));
    mode->omega2 = l;
    mode->f_hz   = Frequency(l);
    PetscCall(VecSet(full, 0));
    PetscCall(VecISCopy(full, isfree, SCATTER_FORWARD, x));
    PetscCall(Classify(an, full, mdiag, mode, md->axis));
    if (md->nmodes < md->nshapes) PetscCall(StoreShape(an, full, md->nmodes));
    md->nmodes++;
  }
  md->nshapes = PetscMin(md->nmodes, md->nshapes); /* only converged modes go to particles.vtu */
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&r));
  PetscCall(VecDestroy(&y));
  PetscCall(VecDestroy(&full));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What summary.json reports of the solver: the inner KSP, and its worst true residual. Partial:
 * fewer pairs converged than asked for, or fewer modes than nev where the body has more. */
static PetscErrorCode RecordSolver(PeriAnalysis an, EPS eps, PetscInt nev, const InnerCheck *inner)
{
  ST        st;
  KSP       ksp;
  PC        pc;
  KSPType   kt;
  PCType    pt;
  PetscInt  asked, nconv;
  PetscBool partial;

  PetscFunctionBeginUser;
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(KSPGetType(ksp, &kt));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCGetType(pc, &pt));
  PetscCall(PetscStrncpy(an->sys->fields.solve.ksp_type, kt, sizeof(an->sys->fields.solve.ksp_type)));
  PetscCall(PetscStrncpy(an->sys->fields.solve.pc_type, pt, sizeof(an->sys->fields.solve.pc_type)));
  PetscCall(EPSGetDimensions(eps, &asked, NULL, NULL));
  PetscCall(EPSGetConverged(eps, &nconv));
  partial = (PetscBool)(nconv < asked || Modal(an)->nmodes < PetscMin(nev, Modal(an)->nfree_dofs - Modal(an)->nrigid));
  PetscCall(PetscStrncpy(an->sys->fields.solve.converged_reason, partial ? "EPS_PARTIAL" : "EPS_CONVERGED", sizeof(an->sys->fields.solve.converged_reason)));
  PetscCall(EPSGetIterationNumber(eps, &an->sys->fields.solve.iterations));
  an->sys->fields.solve.residual_norm = inner->worst;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What one modal solve holds: freed whether it succeeds or a check stops it inside SLEPc. */
typedef struct {
  Mat        M, Kff, Mff, Pff; /* M: borrowed from the mass service; Pff: NULL but with a matrix-free K */
  Mat        Ks;               /* what the eigensolver is given: Kff, or a free body's K_ff + shift M_ff (ShiftFreeBody) */
  IS         isfree;
  Vec        mdiag; /* borrowed from the mass service */
  EPS        eps;
  InnerCheck inner;
  Pair      *pairs;
} ModalWork;

static PetscErrorCode ModalWorkDestroy(ModalWork *w)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(w->pairs));
  PetscCall(VecDestroy(&w->inner.r));
  PetscCall(EPSDestroy(&w->eps));
  PetscCall(MatDestroy(&w->Ks));
  PetscCall(MatDestroy(&w->Kff));
  PetscCall(MatDestroy(&w->Mff));
  PetscCall(MatDestroy(&w->Pff));
  PetscCall(ISDestroy(&w->isfree));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* LOBPCG on a free body: K_ff is singular, and so would be GAMG's matrix. The eigensolver is
 * given (K_ff + shift M_ff, M_ff), whose eigenvalues are omega^2 + shift, all positive, with the
 * same vectors; GAMG the short-range stiffness plus shift M_ff (an assembled K_ff is shifted in
 * place). The rigid-body modes come out at omega^2 = 0 and are counted as such (OrderPairs).
 * shift: MODAL_FREE_SHIFT of the scale of the largest omega^2, below the lowest elastic
 * omega^2 of the bodies measured (docs/modal.md, "Free bodies with LOBPCG"). */
static PetscErrorCode ShiftFreeBody(PeriAnalysis an, PetscReal scale, ModalWork *w)
{
  PeriModal *md = Modal(an);
  Mat        sM;

  PetscFunctionBeginUser;
  md->shift = 0;
  PetscCall(PetscObjectReference((PetscObject)w->Kff));
  w->Ks = w->Kff;
  if (md->eigensolver != EIGENSOLVER_LOBPCG || !md->free_body) PetscFunctionReturn(PETSC_SUCCESS);
  md->shift = MODAL_FREE_SHIFT * scale;
  if (w->Pff) {
    PetscCall(MatAXPY(w->Pff, md->shift, w->Mff, SUBSET_NONZERO_PATTERN));
    PetscCall(MatDestroy(&w->Ks));
    PetscCall(MatDuplicate(w->Mff, MAT_COPY_VALUES, &sM));
    PetscCall(MatScale(sM, md->shift));
    PetscCall(MatCreateComposite(an->comm, 2, (Mat[]){w->Kff, sM}, &w->Ks));
    PetscCall(MatDestroy(&sM));
  } else
    PetscCall(MatAXPY(w->Kff, md->shift, w->Mff, SUBSET_NONZERO_PATTERN));
  PetscCall(MatSetOption(w->Ks, MAT_SYMMETRIC, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ModalSolve(PeriAnalysis an, PetscInt nev, PetscReal target_hz, ModalWork *w)
{
  PeriModal     *md;
  PetscInt       nfree, npairs = 0;
  PetscReal      scale, sigma, Knorm, Mnorm, eps_tol;
  PetscLogDouble t0, t1, t2;
  char           what[128];

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&t0));
  PetscCall(SetUpModal(an, &w->M, &w->mdiag, &w->isfree, &w->Kff, &w->Mff, &w->Pff));
  md = Modal(an);
  PetscCall(PeriRigidMotionFree(an->sys, &nfree, what, sizeof(what), NULL));
  md->nrigid = 0;

  /* the scale of the largest omega^2 (a matrix-free K's from its short-range stiffness, whose
     diagonal is K's) */
  if (w->Pff || !an->sys->stiffness.op)
    PetscCall(MatNorm(w->Pff ? w->Pff : w->Kff, NORM_1, &Knorm));
  else { /* the multigrid's matrix-free K: twice its largest diagonal, a bound of its 1-norm's order */
    Vec d;
    PetscCall(MatCreateVecs(an->sys->stiffness.K, &d, NULL));
    PetscCall(MatGetDiagonal(an->sys->stiffness.K, d));
    PetscCall(VecMax(d, NULL, &Knorm));
    PetscCall(VecDestroy(&d));
    Knorm *= 2;
  }
  PetscCall(MatNorm(w->Mff, NORM_1, &Mnorm));
  scale = Knorm / Mnorm;
  sigma = PetscSqr(2 * PETSC_PI * target_hz);
  /* a free body makes K singular: shift just below its zero eigenvalues */
  if (nfree && target_hz == 0) sigma = -1e-8 * scale;
  PetscCall(ShiftFreeBody(an, scale, w));

  PetscCall(CreateEPS(an, w->Ks, w->Mff, w->Pff, w->isfree, sigma, PetscMin(PetscMin(nev, md->nfree_dofs) + nfree, md->nfree_dofs), &w->inner, &w->eps));
  /* the factorization (MUMPS) and its solves run with the BLAS threads (src/sys/threads.c) */
  PetscCall(PeriBLASThreads(PETSC_TRUE));
  PetscCall(PeriProgressUpdate(an->sys->run.progress, PERI_PROGRESS_PHASE, "factorization"));
  PetscCall(EPSSetUp(w->eps));
  PetscCall(PetscTime(&t1));
  PetscCall(PeriProgressUpdate(an->sys->run.progress, PERI_PROGRESS_PHASE, "eigensolve"));
  PetscCall(SolveModes(an, w->eps, &w->inner, nev, target_hz, sigma, nfree, scale, &npairs, &w->pairs));
  PetscCall(PeriBLASThreads(PETSC_FALSE));
  PetscCall(PetscTime(&t2));
  md->factor_s             = t1 - t0;
  md->solve_s              = t2 - t1;
  an->sys->run.log.solve_s = t2 - t0;
  PetscCheck(npairs + md->nrigid > 0, an->comm, PETSC_ERR_NOT_CONVERGED, "%s: the eigensolver converged no mode (try -eps_ncv, -eps_max_it, or a target with analysis.target_hz)", an->sys->scene->file);
  PetscCall(CollectModes(an, w->eps, w->Ks, w->Mff, w->isfree, w->mdiag, nev, npairs, w->pairs, PETSC_SQRT_MACHINE_EPSILON * scale));
  PetscCall(EPSGetTolerances(w->eps, &eps_tol, NULL));
  PetscCall(CheckModes(an, eps_tol));
  /* a free bar's lowest longitudinal mode is half a wave over its length */
  if (nfree)
    for (PetscInt k = 0; k < md->nmodes; k++)
      if (!strcmp(md->modes[k].kind, "longitudinal") || !strcmp(md->modes[k].kind, "axial")) {
        PetscReal L            = an->sys->disc.particles.upper[md->axis] - an->sys->disc.particles.lower[md->axis];
        md->longitudinal_speed = 2 * L * md->modes[k].f_hz;
        if (an->sys->disc.particles.dim == 3) md->theory_speed = PetscSqrtReal((an->sys->model->material.K + 4 * an->sys->model->material.G / 3) / an->sys->model->material.rho);
        break;
      }
  PetscCall(RecordSolver(an, w->eps, nev, &w->inner));
  /* LOBPCG stops at -eps_max_it with what it has: fewer modes than asked is a failure */
  PetscCheck(md->eigensolver != EIGENSOLVER_LOBPCG || md->nmodes >= PetscMin(nev, md->nfree_dofs), an->comm, PETSC_ERR_NOT_CONVERGED,
             "%s: LOBPCG converged %" PetscInt_FMT " of the %" PetscInt_FMT " modes asked for in %" PetscInt_FMT " iterations: raise -eps_max_it, or use analysis.eigensolver: shift_invert", an->sys->scene->file, md->nmodes,
             PetscMin(nev, md->nfree_dofs), an->sys->fields.solve.iterations);
  PetscCheck(md->nmodes > 0, an->comm, PETSC_ERR_NOT_CONVERGED, "%s: only rigid-body modes converged (%" PetscInt_FMT "): ask for more with analysis.nev", an->sys->scene->file, md->nrigid);
  if (md->nmodes < nev) PetscCall(PetscPrintf(an->comm, "perilin: warning: %" PetscInt_FMT " of the %" PetscInt_FMT " modes asked for converged (the body has %" PetscInt_FMT " free DOFs)\n", md->nmodes, nev, md->nfree_dofs));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.eigensolver as run. auto takes LOBPCG, without a target (LOBPCG finds the lowest modes
 * only), from MODAL_LOBPCG_MIN_DOFS_MG DOFs on where the geometric multigrid applies (a held grid
 * body, matrix-free), from MODAL_LOBPCG_MIN_DOFS_FREE on a free body of a state-based model with a
 * matrix-free K (GAMG on its shifted short-range stiffness), else from MODAL_LOBPCG_MIN_DOFS. LOBPCG applies K
 * matrix-free where the operator can (solver.operator auto); the factorization needs K's entries.
 * Before K is built. Collective. */
static PetscErrorCode ChooseEigensolver(PeriAnalysis an)
{
  PeriModal     *md = Modal(an);
  PeriStiffness *S  = &an->sys->stiffness;
  PeriNode       node;
  PetscInt       nfree;
  PetscBool      lowest;

  PetscFunctionBeginUser;
  PetscCall(PeriRigidMotionFree(an->sys, &nfree, NULL, 0, NULL));
  md->free_body = (PetscBool)(nfree > 0);
  lowest        = (PetscBool)(md->target_hz == 0);
  if (md->eigensolver == EIGENSOLVER_AUTO) {
    const PetscReal dofs = (PetscReal)an->sys->disc.N * an->sys->model->dofs;
    const PetscBool mf   = (PetscBool)(S->operator_kind != PERI_OPERATOR_ASSEMBLED && !PeriOperatorWhyNotModel(an->sys->model));
    const PetscBool mg   = (PetscBool)(mf && !md->free_body && !PeriMultigridWhyNotBody(an->sys));
    const PetscReal from = mg ? MODAL_LOBPCG_MIN_DOFS_MG : mf && md->free_body && PeriModelHasFamilies(an->sys->model) ? MODAL_LOBPCG_MIN_DOFS_FREE
                                                                                                                       : MODAL_LOBPCG_MIN_DOFS;
    md->eigensolver      = lowest && dofs >= from ? EIGENSOLVER_LOBPCG : EIGENSOLVER_SHIFT_INVERT;
  }
  PetscCall(PeriSceneGetNode(an->sys->scene->root, "analysis", &node));
  PeriInputCheck(md->eigensolver != EIGENSOLVER_LOBPCG || lowest, an->sys->scene, node, "eigensolver", "lobpcg computes the lowest modes, and this run asks for the modes nearest analysis.target_hz: use shift_invert (or auto)");
  if (md->eigensolver == EIGENSOLVER_SHIFT_INVERT) PetscFunctionReturn(PETSC_SUCCESS);
  S->needs.matrix_free = PETSC_TRUE;
  if (S->operator_kind == PERI_OPERATOR_AUTO && !PeriMatrixFreeWhyNot(an->sys)) S->operator_kind = PERI_OPERATOR_MATRIX_FREE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisRun_Modal - analysis.nev natural modes of the constrained body. Without a target
  (analysis.target_hz = 0) the lowest, in ascending frequency; with one, the nev whose frequencies
  lie nearest it, in order of |f - target| (ties: the lower first). Rigid-body modes of a free
  body are counted and skipped. The eigensolver is analysis.eigensolver's (ChooseEigensolver):
  shift-and-invert with a factorization, or perilin's LOBPCG (lobpcg.c) with the geometric
  multigrid or GAMG. Every inner solve of the spectral
  transform must leave a true relative residual below PeriResidualTolerance(-st_ksp_rtol) (LOBPCG's
  preconditioner excepted), every returned mode a relative residual ||K x - omega^2 M x|| /
  (omega^2 ||M x||) below PeriResidualTolerance(-eps_tol), and LOBPCG must return all the modes
  asked for: else the run fails with PETSC_ERR_NOT_CONVERGED. Options: every -eps_* and -st_* option (e.g.
  -st_pc_factor_mat_solver_type, -eps_tol). SLEPc must be initialized. Collective.
@*/
/* One attempt with the chosen eigensolver: a failed check may return from deep inside SLEPc, so
 * everything is freed before the error goes on. quiet: the error is returned without a message
 * (PETSc keeps it, PetscErrorMessage), for the caller to retry or to raise. */
static PetscErrorCode ModalAttempt(PeriAnalysis an, PetscBool quiet, PetscErrorCode *ierr)
{
  ModalWork w;
  Mat       K;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemGetJacobian(an->sys, &K));
  PetscCall(PetscMemzero(&w, sizeof(w)));
  PetscCall(PetscLogEventBegin(PERI_EVENT_Solve, 0, 0, 0, 0));
  if (quiet) PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  *ierr = ModalSolve(an, Modal(an)->nev, Modal(an)->target_hz, &w);
  if (quiet) PetscCall(PetscPopErrorHandler());
  PetscCall(PetscLogEventEnd(PERI_EVENT_Solve, 0, 0, 0, 0));
  PetscCall(ModalWorkDestroy(&w));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PeriAnalysisRun_Modal(PeriAnalysis an)
{
  PeriModal       *md     = Modal(an);
  PeriStiffness   *S      = &an->sys->stiffness;
  const PetscBool  chosen = (PetscBool)(md->eigensolver == EIGENSOLVER_AUTO);
  PeriOperatorKind kind   = S->operator_kind;
  PetscBool        retry;
  PetscErrorCode   ierr;
  const char      *msg = NULL;
  char             reason[512];

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(S->mat_type, MATAIJ, sizeof(S->mat_type)));
  PetscCall(ChooseEigensolver(an));
  retry = (PetscBool)(chosen && md->eigensolver == EIGENSOLVER_LOBPCG);
  PetscCall(ModalAttempt(an, retry, &ierr));
  if (retry && ierr) {
    PetscCall(PetscErrorMessage(ierr, NULL, (char **)&msg));
    PetscCall(PetscStrncpy(reason, msg ? msg : "no message", sizeof(reason)));
    /* auto's LOBPCG that does not converge gives way to the factorization: the default must not
       fail where shift-and-invert succeeds (the mppd lamina at nu = -0.99 took LOBPCG 387
       iterations on one machine and more than its 2,500 on another), nor where its basis lost its
       rank (PETSC_ERR_CONV_FAILED, lobpcg.c) */
    PetscCheck(ierr == PETSC_ERR_NOT_CONVERGED || ierr == PETSC_ERR_CONV_FAILED, an->comm, ierr, "%s", reason);
    PetscCall(PetscPrintf(an->comm, "perilin: note: LOBPCG did not converge (%s); retrying with shift-and-invert (analysis.eigensolver: shift_invert)\n", reason));
    PetscCall(PetscFree(md->modes));
    PetscCall(PetscFree(md->shapes));
    md->nmodes = md->nshapes = 0;
    md->eigensolver          = EIGENSOLVER_SHIFT_INVERT;
    S->operator_kind         = kind;
    S->needs.matrix_free     = PETSC_FALSE;
    PetscCall(PeriSystemAssemble(an->sys));
    PetscCall(ModalAttempt(an, PETSC_FALSE, &ierr));
  }
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWriteModesCSV - one row per mode: frequency, residual, kind, energy shares, effective
  masses. Rank 0 writes (temporary name, then rename). Collective.
@*/
static PetscErrorCode PeriWriteModesCSV(PeriAnalysis an, const char path[])
{
  char  tmp[PETSC_MAX_PATH_LEN];
  FILE *fp;
  int   bad = 0;

  PetscFunctionBeginUser;
  if (an->rank || !Modal(an)->started) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "mode,f_hz,omega2,residual,kind") < 0;
  for (PetscInt c = 0; c < an->sys->model->dofs; c++) bad |= fprintf(fp, ",share_%s", an->sys->model->components[c]) < 0;
  bad |= fprintf(fp, ",meff_x,meff_y,meff_z\n") < 0;
  for (PetscInt k = 0; k < Modal(an)->nmodes; k++) {
    const PeriMode *m = &Modal(an)->modes[k];
    bad |= fprintf(fp, "%" PetscInt_FMT ",%.10g,%.10g,%.3g,%s", k + 1, (double)m->f_hz, (double)m->omega2, (double)m->residual, m->kind) < 0;
    for (PetscInt c = 0; c < an->sys->model->dofs; c++) bad |= fprintf(fp, ",%.6f", (double)m->energy_share[c]) < 0;
    bad |= fprintf(fp, ",%.6f,%.6f,%.6f\n", (double)m->effective_mass[0], (double)m->effective_mass[1], (double)m->effective_mass[2]) < 0;
  }
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The stored mode shapes as fields of particles.vtu: mode_1, mode_1_theta, ... (this rank's
 * particles: its piece) */
static PetscErrorCode ModalAddFields(PeriAnalysis an, PeriFieldList fl)
{
  const PeriModal *md = Modal(an);
  const PetscInt   nd = (an->sys->disc.bonds.rend - an->sys->disc.bonds.rstart) * an->sys->model->dofs;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; md && k < md->nshapes; k++) {
    char prefix[32];
    PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "mode_%" PetscInt_FMT, k + 1));
    PetscCall(PeriFieldListAddSolution(fl, prefix, an->sys->model->dofs, an->sys->model->components, an->sys->model->axis, &md->shapes[k * nd]));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  WriteModeShapes - mode_NN.vtu (mode_NN.pvtu and its pieces on several ranks), one file per
  stored mode shape with the shape as its "displacement" (NN: the mode number of modes.csv), and
  modes.pvd listing them with each mode's
  frequency in Hz as its time, so that ParaView's time controls step through the modes and show
  the frequency. The frames are in ascending frequency (with analysis.target_hz the modes come by
  distance to the target instead); equal frequencies stay in mode order, PeriWritePVD makes their
  times distinct by 1e-12 relative. Collective: every rank writes its pieces, rank 0 the index.
@*/
static PetscErrorCode WriteModeShapes(PeriAnalysis an, const char dir[])
{
  PeriModal     *md = Modal(an);
  PetscReal     *times;
  PetscInt      *order;
  char         **files, path[PETSC_MAX_PATH_LEN], base[32];
  const PetscInt nd = (an->sys->disc.bonds.rend - an->sys->disc.bonds.rstart) * an->sys->model->dofs;

  PetscFunctionBeginUser;
  if (!md || !md->nshapes) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc3(md->nshapes, &times, md->nshapes, &files, md->nshapes, &order));
  /* each file is particles.vtu's layout with the mode as the displacement field */
  for (PetscInt k = 0; k < md->nshapes; k++) {
    PetscCall(PetscSNPrintf(base, sizeof(base), "mode_%02" PetscInt_FMT, k + 1));
    PetscCall(PetscMalloc1(40, &files[k]));
    PetscCall(PeriParticlesFileName(an->comm, base, files[k], 40));
    PetscCall(PeriSystemWriteParticles(an->sys, &md->shapes[k * nd], dir, base));
  }
  /* stable insertion sort of the mode numbers by frequency: few shapes (at most 12) */
  for (PetscInt k = 0; k < md->nshapes; k++) {
    PetscInt i = k;
    for (; i > 0 && md->modes[order[i - 1]].f_hz > md->modes[k].f_hz; i--) order[i] = order[i - 1];
    order[i] = k;
  }
  for (PetscInt k = 0; k < md->nshapes; k++) times[k] = md->modes[order[k]].f_hz;
  {
    const char *sorted[PERI_MAX_VTU_MODES];
    for (PetscInt k = 0; k < md->nshapes; k++) sorted[k] = files[order[k]];
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/modes.pvd", dir));
    if (an->rank == 0) PetscCall(PeriWritePVD(path, md->nshapes, times, sorted));
  }
  for (PetscInt k = 0; k < md->nshapes; k++) PetscCall(PetscFree(files[k]));
  PetscCall(PetscFree3(times, files, order));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* summary.json's "modal" object: frequencies, masses, and per mode its residual, kind, energy
 * shares and effective masses. */
static PetscErrorCode ModalSummary(PeriAnalysis an, PeriJSON j)
{
  const PetscInt bs = an->sys->model->dofs;

  PetscFunctionBeginUser;
  if (!Modal(an)->started) PetscFunctionReturn(PETSC_SUCCESS);
  const PeriModal *md = Modal(an);
  PetscReal        f[256];
  PetscCall(PeriJSONBeginObject(j, "modal"));
  for (PetscInt k = 0; k < PetscMin(md->nmodes, 256); k++) f[k] = md->modes[k].f_hz;
  PetscCall(PeriJSONRealArray(j, "frequencies_hz", PetscMin(md->nmodes, 256), f));
  PetscCall(PeriJSONInt(j, "rigid_modes", md->nrigid));
  PetscCall(PeriJSONInt(j, "free_dofs", md->nfree_dofs));
  PetscCall(PeriJSONReal(j, "total_mass", md->total_mass));
  PetscCall(PeriJSONString(j, "axis", (const char *[]){"x", "y", "z"}[md->axis]));
  PetscCall(PeriJSONString(j, "eigensolver", eigensolvers[md->eigensolver]));
  PetscCall(PeriJSONReal(j, "factorization_s", md->factor_s));
  PetscCall(PeriJSONReal(j, "eigensolve_s", md->solve_s));
  if (md->longitudinal_speed > 0) PetscCall(PeriJSONReal(j, "longitudinal_speed", md->longitudinal_speed));
  if (md->theory_speed > 0) PetscCall(PeriJSONReal(j, "theory_speed", md->theory_speed));
  PetscCall(PeriJSONBeginArray(j, "modes"));
  for (PetscInt k = 0; k < md->nmodes; k++) {
    const PeriMode *m = &md->modes[k];
    PetscCall(PeriJSONBeginObject(j, NULL));
    PetscCall(PeriJSONReal(j, "f_hz", m->f_hz));
    PetscCall(PeriJSONReal(j, "residual", m->residual));
    PetscCall(PeriJSONString(j, "kind", m->kind));
    PetscCall(PeriJSONBeginObject(j, "energy_share"));
    for (PetscInt c = 0; c < bs; c++) PetscCall(PeriJSONReal(j, an->sys->model->components[c], m->energy_share[c]));
    PetscCall(PeriJSONEndObject(j));
    PetscCall(PeriJSONRealArray(j, "effective_mass", an->sys->disc.particles.dim, m->effective_mass));
    PetscCall(PeriJSONEndObject(j));
  }
  PetscCall(PeriJSONEndArray(j));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ModalReport(PeriAnalysis an)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(an->comm, "perilin: %" PetscInt_FMT " modes (Hz):", Modal(an)->nmodes));
  for (PetscInt k = 0; k < Modal(an)->nmodes; k++) PetscCall(PetscPrintf(an->comm, " %.6g (%s)", (double)Modal(an)->modes[k].f_hz, Modal(an)->modes[k].kind));
  PetscCall(PetscPrintf(an->comm, "; results in %s/\n", an->output_dir));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* modes.csv, and with output.vtk the shapes mode_NN.vtu and modes.pvd. */
static PetscErrorCode ModalFiles(PeriAnalysis an, const char dir[])
{
  char path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  if (!Modal(an)->started) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/modes.csv", dir));
  PetscCall(PeriWriteModesCSV(an, path));
  if (an->vtk) PetscCall(WriteModeShapes(an, dir));
  /* the frequencies from modes.csv, the shapes from particles.vtu (.pvtu) when output.vtk */
  if (Modal(an)->nmodes) PetscCall(PeriPlotsDraw(an->comm, dir, "modal", NULL, &an->plots));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ModalDestroy(PeriAnalysis an)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(Modal(an)->modes));
  PetscCall(PetscFree(Modal(an)->shapes));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The analysis.* keys SetFromScene_Modal reads. */
static const PeriKey modal_keys[] = {
    {"nev", PERI_KEY_INT, "6", "[1, inf)", NULL, NULL, "number of modes"},
    {"target_hz", PERI_KEY_REAL, "0", "[0, inf)", "[1/time]", NULL, "compute the modes nearest this frequency (0: the lowest)"},
    {"eigensolver", PERI_KEY_CHOICE, "auto", NULL, NULL, eigensolvers, "shift_invert: Krylov-Schur, shift-and-invert with a direct factorization of K; lobpcg: LOBPCG preconditioned by multigrid (geometric on held grid bodies, else algebraic), K matrix-free where it can be (the lowest modes only; a free body's rigid-body modes counted); auto: lobpcg without a target from 8,000 DOFs on held grid bodies and on free bodies of a state-based model with a matrix-free K, from 300,000 elsewhere, else shift_invert (docs/modal.md)"},
    {NULL},
};
static const PeriSchema modal_schema[] = {{"analysis", modal_keys}, {NULL}};

/* The spectral transformation's linear solver, shift-and-invert as CreateEPS makes it, of the
 * given types and set from the options: for the unused-option check (src/scene/options.c). */
static PetscErrorCode SolversFromOptions_Modal(MPI_Comm comm, const char ksp_type[], const char pc_type[])
{
  EPS eps;
  ST  st;
  KSP ksp;
  PC  pc;

  PetscFunctionBeginUser;
  PetscCall(EPSCreate(comm, &eps));
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STSetType(st, STSINVERT));
  PetscCall(STGetKSP(st, &ksp));
  if (ksp_type[0]) PetscCall(KSPSetType(ksp, ksp_type));
  PetscCall(KSPGetPC(ksp, &pc));
  if (pc_type[0]) PetscCall(PCSetType(pc, pc_type));
  PetscCall(EPSSetFromOptions(eps));
  PetscCall(EPSDestroy(&eps));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static const char *const modal_files[] = {"modes.csv", "modes.pvd", "mode_#.vtu", "mode_#.pvtu", "mode_#", "modes.png", NULL};

/* K is assembled AIJ and factored (its fill measured in docs/performance.md), or from
 * MODAL_LOBPCG_MIN_DOFS DOFs on matrix-free for LOBPCG (analysis.eigensolver auto); the mass comes
 * from the system's mass service. */
const PeriAnalysisType PeriAnalysis_Modal = {
    .name          = "modal",
    .help          = "natural frequencies and mode shapes (SLEPc, shift-and-invert)",
    .schema        = modal_schema,
    .option_prefix = "st_",
    .files         = modal_files,
    .needs         = {.factor_fill = 0.45, .iterative_dofs = MODAL_LOBPCG_MIN_DOFS, .iterative_dofs_grid = MODAL_LOBPCG_MIN_DOFS_MG},
    .ops           = {.setfromscene = SetFromScene_Modal, .setup = SetUp_Modal, .run = PeriAnalysisRun_Modal, .fields = ModalAddFields, .files = ModalFiles, .summary = ModalSummary, .report = ModalReport, .solvers_from_options = SolversFromOptions_Modal, .destroy = ModalDestroy},
};

/*@C
  PeriAnalysisGetModes - a modal analysis' modes after its run (none before): their number and
  data (borrowed), and the shapes kept of the first nshapes (at most PERI_MAX_VTU_MODES; this rank's
  owned DOFs of each one after the other, in K's layout, scaled to max |u| = 1; borrowed). An error
  for another analysis. Not collective.
@*/
PetscErrorCode PeriAnalysisGetModes(PeriAnalysis an, PetscInt *n, const PeriMode **modes, PetscInt *nshapes, const PetscReal **shapes)
{
  const PeriModal *md = Modal(an);

  PetscFunctionBeginUser;
  PetscCheck(an->type == &PeriAnalysis_Modal, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "modes of a %s analysis: only analysis.type modal computes modes", an->type->name);
  *n       = md ? md->nmodes : 0;
  *modes   = md ? md->modes : NULL;
  *nshapes = md ? md->nshapes : 0;
  *shapes  = md ? md->shapes : NULL;
  PetscFunctionReturn(PETSC_SUCCESS);
}
