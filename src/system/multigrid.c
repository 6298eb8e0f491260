/* The geometric multigrid of a matrix-free K on a grid body (-pc_type mg; issue 29, item 3).
 * PETSc's PCMG with levels that perilin builds: level l is the same scene discretized at 2^l times
 * the spacing with the same m (the system's level factory, PeriSystemCreate: the grid's cells halved about the box's
 * centre, the bonds, corrections and calibration of that grid), applied matrix-free like the
 * finest; the coarsest is assembled and factored. Interpolation is bilinear (trilinear) from the
 * coarser grid's particles, clamped at the edges; restriction its transpose. A rediscretized
 * peridynamic body stores the energy of the continuum for smooth fields as the finer one does, so
 * the coarse levels correct what Chebyshev-Jacobi smoothing leaves (the smooth errors), and no
 * level keeps an assembled matrix but the coarsest: no short-range stiffness, no AMG hierarchy.
 * Held DOFs: a fine held DOF gets no correction (its interpolation row is zero) and holds the
 * same component of the coarse particle it leans on most, so that every level keeps the body
 * fixed where the finest is. The coarse levels are built once per KSP: bonds that break later
 * are not seen by them (the finest level is the operator itself, so the solve stays exact; only
 * the iterations may grow). */
#include "perilin/private/system.h"

/* Coarsening stops at a level of at most this many particles (assembled and factored), or before
 * any axis would have fewer than PERI_MG_MIN_CELLS cells. */
#define PERI_MG_COARSEST  500
#define PERI_MG_MIN_CELLS 6
/* The coarsest level's solve (CoarseSolve). */
#define PERI_MG_FACTOR_2D    2000
#define PERI_MG_COARSE_STEPS 20

/* The grid's cells per axis of particles p (a grid's box and spacing). */
static void GridCells(const PeriParticles *p, PetscInt cells[3])
{
  for (PetscInt d = 0; d < 3; d++) cells[d] = d < p->dim ? (PetscInt)PetscFloorReal((p->upper[d] - p->lower[d]) / p->mean_spacing + 0.5) : 1;
}

/* The most levels the grid allows (each halves the cells, keeping PERI_MG_MIN_CELLS along every
 * axis), and the levels to take: halving until a level has at most PERI_MG_COARSEST particles. */
static void LevelsAllowed(PeriSystem sys, PetscInt *most, PetscInt *take)
{
  PetscInt cells[3];

  GridCells(&sys->disc.particles, cells);
  *most = 1;
  *take = 0;
  for (;;) {
    PetscInt  n    = 1;
    PetscBool thin = PETSC_FALSE;
    for (PetscInt d = 0; d < sys->model->dim; d++) n *= cells[d];
    if (!*take && n <= PERI_MG_COARSEST) *take = *most;
    for (PetscInt d = 0; d < sys->model->dim; d++) thin = (PetscBool)(thin || (cells[d] + 1) / 2 < PERI_MG_MIN_CELLS);
    if (thin) break;
    for (PetscInt d = 0; d < sys->model->dim; d++) cells[d] = (cells[d] + 1) / 2;
    (*most)++;
  }
  if (!*take) *take = *most;
  *take = PetscMin(PetscMax(*take, 2), *most);
}

/* Why the multigrid cannot serve this system, or NULL. */
static const char *WhyNot(PeriSystem sys)
{
  if (!sys->stiffness.op) return "K is assembled (the multigrid's levels apply K matrix-free: solver.operator matrix_free or auto)";
  return PeriMultigridWhyNotBody(sys);
}

/*@C
  PeriMultigridWhyNotBody - why the body cannot have the geometric multigrid's levels (not from a
  grid, a grid with holes, periodic, per-particle horizons), or NULL; the operator is not looked at. Not collective.
@*/
const char *PeriMultigridWhyNotBody(PeriSystem sys)
{
  PeriNode grid = NULL, holes = NULL;
  PetscInt most, take;

  (void)PeriSceneGetNode(sys->scene->root, "grid", &grid); /* the scene was read: no error here */
  if (!grid) return "the body does not come from a grid (its coarse levels are the grid at twice the spacing)";
  if (PeriSceneGetNode(grid, "holes", &holes) == PETSC_SUCCESS && holes) return "the grid has holes (a coarse level's cell at a hole's edge may hold no particle)";
  for (PetscInt d = 0; d < 3; d++)
    if (sys->disc.particles.periodic[d]) return "the body is periodic";
  if (sys->disc.horizon_m > 0 || sys->disc.horizon_k > 0) return "the particles have their own horizons";
  LevelsAllowed(sys, &most, &take);
  if (most < 2) return "the body is too thin to coarsen (a level at twice the spacing would have fewer than " PetscStringize(PERI_MG_MIN_CELLS) " cells along an axis)";
  return NULL;
}

/*@C
  PeriMultigridApplies - whether the geometric multigrid serves this system as the static
  solves' default PC: a matrix-free K of a grid body (not periodic, one horizon) that allows two
  levels or more, without bond failure (the coarse levels would not follow the breaks). Not
  collective.
@*/
PetscBool PeriMultigridApplies(PeriSystem sys)
{
  return (PetscBool)(!WhyNot(sys) && !sys->bond_state.failure.active);
}

/* The levels: -pc_mg_levels when given (checked against what the grid allows), else halving the
 * cells until a level has at most PERI_MG_COARSEST particles. */
static PetscErrorCode Levels(PeriSystem sys, PC pc, PetscInt *L)
{
  PetscInt    most, take, asked = 0;
  const char *prefix;

  PetscFunctionBeginUser;
  LevelsAllowed(sys, &most, &take);
  PetscCall(PCGetOptionsPrefix(pc, &prefix));
  PetscCall(PetscOptionsGetInt(NULL, prefix, "-pc_mg_levels", &asked, NULL));
  *L = asked > 0 ? asked : take;
  PetscCheck(*L >= 2 && *L <= most, sys->comm, PETSC_ERR_USER_INPUT, "%s: -pc_mg_levels %" PetscInt_FMT ": this grid allows 2 to %" PetscInt_FMT " levels (each halves the cells; at least %d along every axis)", sys->scene->file, *L, most, PERI_MG_MIN_CELLS);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The cell of the grid (cells, box of p) whose centre is nearest x along each axis, below x where
 * it can: the 2^dim corners around x, their keys (x fastest) and bilinear weights, clamped at the
 * edges (an axis of one cell has one corner: the others get weight 0). */
static void Corners(const PeriParticles *p, const PetscInt cells[3], const PetscReal x[], PetscInt key[], PetscReal w[])
{
  PetscInt  i0[3] = {0, 0, 0};
  PetscReal t[3]  = {0, 0, 0};

  for (PetscInt d = 0; d < p->dim; d++) {
    const PetscReal s = (x[d] - p->lower[d]) / p->mean_spacing - 0.5;
    if (cells[d] < 2) continue;
    i0[d] = PetscMin(PetscMax((PetscInt)PetscFloorReal(s), 0), cells[d] - 2);
    t[d]  = PetscMin(PetscMax(s - i0[d], 0), 1);
  }
  for (PetscInt k = 0; k < (1 << p->dim); k++) {
    PetscInt c[3] = {0, 0, 0};
    w[k]          = 1;
    for (PetscInt d = 0; d < p->dim; d++) {
      const PetscInt up = (k >> d) & 1;
      c[d]              = PetscMin(i0[d] + up, cells[d] - 1);
      w[k] *= up ? t[d] : 1 - t[d];
    }
    key[k] = c[0] + cells[0] * (c[1] + cells[1] * c[2]);
  }
}

/* The global particle numbers of the coarse grid's cells key[0..n-1]: each rank brokers a range
 * of cells (a PetscLayout), the owners register theirs, the askers read them. Collective. */
static PetscErrorCode CellOwners(PeriSystem c, const PetscInt cells[3], PetscInt n, const PetscInt key[], PetscInt glob[])
{
  const PeriParticles *p = &c->disc.particles;
  PetscLayout          lay;
  PetscSF              reg, ask;
  PetscInt            *mine, *mykey, *broker, nb;

  PetscFunctionBeginUser;
  PetscCall(PetscLayoutCreateFromSizes(c->comm, PETSC_DECIDE, cells[0] * cells[1] * cells[2], 1, &lay));
  PetscCall(PetscLayoutGetLocalSize(lay, &nb));
  PetscCall(PetscMalloc3(c->disc.nowned, &mine, c->disc.nowned, &mykey, nb, &broker));
  for (PetscInt q = 0; q < c->disc.nowned; q++) { /* a particle sits at its cell's centre */
    PetscInt cq[3] = {0, 0, 0};
    for (PetscInt d = 0; d < p->dim; d++) cq[d] = PetscMin(PetscMax((PetscInt)PetscFloorReal((p->x[3 * q + d] - p->lower[d]) / p->mean_spacing), 0), cells[d] - 1);
    mykey[q] = cq[0] + cells[0] * (cq[1] + cells[1] * cq[2]);
    mine[q]  = c->disc.rstart + q;
  }
  for (PetscInt b = 0; b < nb; b++) broker[b] = -1;
  PetscCall(PetscSFCreate(c->comm, &reg));
  PetscCall(PetscSFSetGraphLayout(reg, lay, c->disc.nowned, NULL, PETSC_COPY_VALUES, mykey));
  PetscCall(PetscSFReduceBegin(reg, MPIU_INT, mine, broker, MPI_REPLACE));
  PetscCall(PetscSFReduceEnd(reg, MPIU_INT, mine, broker, MPI_REPLACE));
  PetscCall(PetscSFCreate(c->comm, &ask));
  PetscCall(PetscSFSetGraphLayout(ask, lay, n, NULL, PETSC_COPY_VALUES, key));
  PetscCall(PetscSFBcastBegin(ask, MPIU_INT, broker, glob, MPI_REPLACE));
  PetscCall(PetscSFBcastEnd(ask, MPIU_INT, broker, glob, MPI_REPLACE));
  PetscCall(PetscSFDestroy(&reg));
  PetscCall(PetscSFDestroy(&ask));
  PetscCall(PetscFree3(mine, mykey, broker));
  PetscCall(PetscLayoutDestroy(&lay));
  for (PetscInt k = 0; k < n; k++) PetscCheck(glob[k] >= 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "multigrid: cell %" PetscInt_FMT " of a coarse grid has no particle", key[k]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The interpolation from level c to the finer level f (rows: f's DOFs, zero where heldf), and the
 * coarse DOFs held in turn (heldc, c's owned DOFs: each held fine DOF holds its component at the
 * corner of largest weight). Collective. */
static PetscErrorCode Interpolation(PeriSystem f, PeriSystem c, const PetscBool heldf[], Mat *T, PetscBool **heldc)
{
  const PetscInt bs = f->model->dofs, nn = 1 << f->model->dim, nf = f->disc.nowned;
  PetscInt       cells[3], *key, *glob;
  PetscReal     *w;
  Vec            mark;
  PetscScalar   *ma;

  PetscFunctionBeginUser;
  GridCells(&c->disc.particles, cells);
  PetscCall(PetscMalloc3(nf * nn, &key, nf * nn, &glob, nf * nn, &w));
  for (PetscInt p = 0; p < nf; p++) Corners(&c->disc.particles, cells, &f->disc.particles.x[3 * p], &key[nn * p], &w[nn * p]);
  PetscCall(CellOwners(c, cells, nf * nn, key, glob));
  PetscCall(MatCreateAIJ(f->comm, bs * nf, bs * c->disc.nowned, PETSC_DETERMINE, PETSC_DETERMINE, nn, NULL, nn, NULL, T));
  PetscCall(MatSetOption(*T, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(VecCreateMPI(f->comm, bs * c->disc.nowned, PETSC_DETERMINE, &mark));
  PetscCall(VecSet(mark, 0));
  for (PetscInt p = 0; p < nf; p++)
    for (PetscInt d = 0; d < bs; d++) {
      const PetscInt row  = bs * (f->disc.rstart + p) + d;
      PetscInt       best = 0;
      for (PetscInt k = 0; k < nn; k++) {
        const PetscInt col = bs * glob[nn * p + k] + d;
        if (w[nn * p + k] > w[nn * p + best]) best = k;
        if (!heldf[bs * p + d] && w[nn * p + k] > 0) PetscCall(MatSetValues(*T, 1, &row, 1, &col, &w[nn * p + k], ADD_VALUES));
      }
      if (heldf[bs * p + d]) PetscCall(VecSetValue(mark, bs * glob[nn * p + best] + d, 1, INSERT_VALUES));
    }
  PetscCall(MatAssemblyBegin(*T, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*T, MAT_FINAL_ASSEMBLY));
  PetscCall(VecAssemblyBegin(mark));
  PetscCall(VecAssemblyEnd(mark));
  PetscCall(PetscMalloc1(bs * c->disc.nowned, heldc));
  PetscCall(VecGetArray(mark, &ma));
  for (PetscInt r = 0; r < bs * c->disc.nowned; r++) {
    (*heldc)[r] = (PetscBool)(PetscRealPart(ma[r]) > 0);
    ma[r]       = (*heldc)[r] ? 0 : 1;
  }
  PetscCall(VecRestoreArray(mark, &ma));
  /* nor does a held coarse DOF: its column goes, so that no residual reaches it and no correction
     leaves it (else the coarse solve turns the residual restricted there into a correction of the
     size of 1 / its unit diagonal: on an unscaled K, 10^7 times too large) */
  PetscCall(MatDiagonalScale(*T, NULL, mark));
  PetscCall(VecDestroy(&mark));
  PetscCall(PetscFree3(key, glob, w));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Level c's operator: matrix-free (or assembled, the coarsest), scaled as the finest and with
 * the held DOFs of heldc on a unit diagonal. Collective. */
static PetscErrorCode LevelOperator(PeriSystem c, PetscBool coarsest, PetscReal scale, const PetscBool heldc[], Mat *A)
{
  const PetscInt bs = c->model->dofs;
  PetscInt      *rows, n = 0;

  PetscFunctionBeginUser;
  if (coarsest) {
    PetscCall(PetscStrncpy(c->stiffness.mat_type, MATAIJ, sizeof(c->stiffness.mat_type)));
    PetscCall(PeriAssembleStiffness(c, A));
  } else {
    PetscCall(PeriOperatorCreate(c, c->stiffness.pc_radius, &c->stiffness.op));
    PetscCall(PeriOperatorCreateMat(c, A));
  }
  PetscCall(MatScale(*A, scale));
  PetscCall(PetscMalloc1(bs * c->disc.nowned, &rows));
  for (PetscInt r = 0; r < bs * c->disc.nowned; r++)
    if (heldc[r]) rows[n++] = bs * c->disc.rstart + r;
  PetscCall(MatZeroRowsColumns(*A, n, rows, 1, NULL, NULL));
  PetscCall(PetscFree(rows));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Level k's smoother: Chebyshev (2 steps) on Jacobi over [0.1, 1.1] times the largest eigenvalue,
 * estimated by CG, then -mg_levels_* options. */
static PetscErrorCode Smoother(PC pc, PetscInt k, Mat A)
{
  KSP s, est;
  PC  sp;

  PetscFunctionBeginUser;
  PetscCall(PCMGGetSmoother(pc, k, &s));
  PetscCall(KSPSetOperators(s, A, A));
  PetscCall(KSPSetType(s, KSPCHEBYSHEV));
  PetscCall(KSPChebyshevEstEigSet(s, 0, 0.1, 0, 1.1));
  PetscCall(KSPChebyshevEstEigGetKSP(s, &est));
  if (est) PetscCall(KSPSetType(est, KSPCG));
  PetscCall(KSPSetTolerances(s, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, 2));
  PetscCall(KSPSetNormType(s, KSP_NORM_NONE));
  PetscCall(KSPSetConvergenceTest(s, KSPConvergedSkip, NULL, NULL));
  PetscCall(KSPGetPC(s, &sp));
  PetscCall(PCSetType(sp, PCJACOBI));
  PetscCall(KSPSetFromOptions(s));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The coarsest level's solve, then -mg_coarse_*: a factorization (redundant on several ranks) in
 * 2D up to PERI_MG_FACTOR_2D particles; else, where the factor of a wide 3D stencil costs more than
 * the whole solve (1,000 particles with m = 3: 1.0 s of LU against 0.16 s of CG), a fixed
 * PERI_MG_COARSE_STEPS of Chebyshev on Jacobi, which keeps the V-cycle a linear operator for CG. */
static PetscErrorCode CoarseSolve(PeriSystem sys, PeriSystem c, PC pc, Mat A)
{
  KSP k;
  PC  cp;

  PetscFunctionBeginUser;
  PetscCall(PCMGGetCoarseSolve(pc, &k));
  PetscCall(KSPSetOperators(k, A, A));
  PetscCall(KSPGetPC(k, &cp));
  if (c->model->dim == 2 && c->disc.N <= PERI_MG_FACTOR_2D) {
    PetscCall(KSPSetType(k, KSPPREONLY));
    PetscCall(PCSetType(cp, sys->size > 1 ? PCREDUNDANT : PCLU));
  } else {
    KSP est;
    PetscCall(KSPSetType(k, KSPCHEBYSHEV));
    PetscCall(KSPChebyshevEstEigSet(k, 0, 0.1, 0, 1.1));
    PetscCall(KSPChebyshevEstEigGetKSP(k, &est));
    if (est) PetscCall(KSPSetType(est, KSPCG));
    PetscCall(KSPSetTolerances(k, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, PERI_MG_COARSE_STEPS));
    PetscCall(KSPSetNormType(k, KSP_NORM_NONE));
    PetscCall(KSPSetConvergenceTest(k, KSPConvergedSkip, NULL, NULL));
    PetscCall(PCSetType(cp, PCJACOBI));
  }
  PetscCall(KSPSetFromOptions(k));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMultigridSetUp - makes ksp's PCMG the geometric multigrid of the matrix-free K (A: the
  solve's shell, scaled and with its held DOFs): the levels' systems, operators, interpolations,
  smoothers and coarse solve (top of the file). Refused, with the reason, where it cannot apply:
  an assembled K, a body not from a grid, periodic axes, per-particle horizons, too thin a body.
  Collective.
@*/
PetscErrorCode PeriMultigridSetUp(PeriSystem sys, KSP ksp, Mat A)
{
  const char     *why = WhyNot(sys);
  const PetscInt  bs  = sys->model->dofs;
  PC              pc;
  PetscInt        L = 0, nheld;
  const PetscInt *held;
  PetscReal       scale;
  PetscBool      *heldf, *heldc;
  PeriSystem      f = sys, c;

  PetscFunctionBeginUser;
  PetscCheck(!why, sys->comm, PETSC_ERR_USER_INPUT, "%s: -pc_type mg (perilin's geometric multigrid) cannot apply: %s; use -pc_type gamg", sys->scene->file, why);
  PetscCall(PetscLogEventBegin(PERI_EVENT_Multigrid, 0, 0, 0, 0));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(Levels(sys, pc, &L));
  PetscCall(PCMGSetLevels(pc, L, NULL));
  PetscCall(PCMGSetGalerkin(pc, PC_MG_GALERKIN_NONE));
  PetscCall(Smoother(pc, L - 1, A));
  PetscCall(PeriOperatorMatHeld(A, &scale, &nheld, &held));
  PetscCall(PetscCalloc1(bs * sys->disc.nowned, &heldf));
  for (PetscInt k = 0; k < nheld; k++) heldf[held[k]] = PETSC_TRUE;
  for (PetscInt l = 1; l < L; l++) {
    Mat T, Al;
    PetscCall(sys->stiffness.levels.create(sys, l, &c));
    PetscCall(Interpolation(f, c, heldf, &T, &heldc));
    PetscCall(PCMGSetInterpolation(pc, L - l, T));
    PetscCall(MatDestroy(&T));
    PetscCall(LevelOperator(c, (PetscBool)(l == L - 1), scale, heldc, &Al));
    if (l < L - 1)
      PetscCall(Smoother(pc, L - 1 - l, Al));
    else
      PetscCall(CoarseSolve(sys, c, pc, Al));
    PetscCall(MatDestroy(&Al));
    PetscCall(PetscFree(heldf));
    if (f != sys) PetscCall(sys->stiffness.levels.destroy(&f));
    f     = c;
    heldf = heldc;
  }
  PetscCall(PetscFree(heldf));
  PetscCall(sys->stiffness.levels.destroy(&f));
  /* -pc_mg_* once more, now that the levels exist: PCMGSetLevels forgets what the KSP's
     set-up read before (-pc_mg_multiplicative_cycles, -pc_mg_cycle_type) */
  PetscCall(PCSetFromOptions(pc));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Multigrid, 0, 0, 0, 0));
  PetscCall(PetscInfo(pc, "perilin multigrid: %" PetscInt_FMT " levels\n", L));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One V-cycle of the multigrid on the free DOFs of K (PeriMultigridSetUpFree): the full-space
 * cycle of a shell with the other DOFs held, between copies in and out of the free ones. */
typedef struct {
  KSP ksp;  /* preonly + PCMG on every DOF */
  IS  free; /* the free DOFs (global rows of K) */
  Vec b, x; /* full-space work vectors */
} FreeCycle;

static PetscErrorCode FreeCycleApply(PC pc, Vec r, Vec z)
{
  FreeCycle *c;

  PetscFunctionBeginUser;
  PetscCall(PCShellGetContext(pc, &c));
  PetscCall(VecSet(c->b, 0));
  PetscCall(VecISCopy(c->b, c->free, SCATTER_FORWARD, r));
  PetscCall(KSPSolve(c->ksp, c->b, c->x));
  PetscCall(VecISCopy(c->x, c->free, SCATTER_REVERSE, z));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode FreeCycleDestroy(PC pc)
{
  FreeCycle *c;

  PetscFunctionBeginUser;
  PetscCall(PCShellGetContext(pc, &c));
  PetscCall(KSPDestroy(&c->ksp));
  PetscCall(ISDestroy(&c->free));
  PetscCall(VecDestroy(&c->b));
  PetscCall(VecDestroy(&c->x));
  PetscCall(PetscFree(c));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One Chebyshev step per level instead of two, unless -modal_mg_levels_ksp_max_it says otherwise:
 * LOBPCG needs a rough inverse more often (the 230,400-particle gerstle lamina: 27 iterations and
 * 46.7 s against 24 and 51.5 s with two steps). */
static PetscErrorCode OneStepSmoothing(PC mg)
{
  PetscInt L;

  PetscFunctionBeginUser;
  PetscCall(PCMGGetLevels(mg, &L));
  for (PetscInt k = 1; k < L; k++) {
    KSP s;
    PetscCall(PCMGGetSmoother(mg, k, &s));
    PetscCall(KSPSetTolerances(s, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, 1));
    PetscCall(KSPSetFromOptions(s));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMultigridSetUpFree - makes pc (of an eigensolver's or solver's operator on the free DOFs
  isfree of the matrix-free K, such as R K R^T) one V-cycle of the geometric multigrid: K's levels
  with every other DOF held. Options: -modal_pc_mg_levels, -modal_mg_levels_*, -modal_mg_coarse_*.
  Collective.
@*/
PetscErrorCode PeriMultigridSetUpFree(PeriSystem sys, IS isfree, PC pc)
{
  const PetscInt  bs = sys->model->dofs;
  FreeCycle      *c;
  Mat             A;
  IS              held;
  PC              mg;
  PetscInt        n;
  const PetscInt *rows;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&c));
  PetscCall(PeriOperatorCreateMat(sys, &A));
  PetscCall(ISComplement(isfree, bs * sys->disc.rstart, bs * (sys->disc.rstart + sys->disc.nowned), &held));
  PetscCall(ISGetLocalSize(held, &n));
  PetscCall(ISGetIndices(held, &rows));
  PetscCall(MatZeroRowsColumns(A, n, rows, 1, NULL, NULL));
  PetscCall(ISRestoreIndices(held, &rows));
  PetscCall(ISDestroy(&held));
  PetscCall(KSPCreate(sys->comm, &c->ksp));
  PetscCall(KSPSetOptionsPrefix(c->ksp, "modal_"));
  PetscCall(KSPSetType(c->ksp, KSPPREONLY));
  PetscCall(KSPGetPC(c->ksp, &mg));
  PetscCall(PCSetType(mg, PCMG));
  PetscCall(KSPSetOperators(c->ksp, A, A));
  PetscCall(PeriMultigridSetUp(sys, c->ksp, A));
  PetscCall(OneStepSmoothing(mg));
  PetscCall(KSPSetUp(c->ksp));
  PetscCall(MatCreateVecs(A, &c->x, &c->b));
  PetscCall(MatDestroy(&A));
  PetscCall(PetscObjectReference((PetscObject)isfree));
  c->free = isfree;
  PetscCall(PCSetType(pc, PCSHELL));
  PetscCall(PCShellSetContext(pc, c));
  PetscCall(PCShellSetApply(pc, FreeCycleApply));
  PetscCall(PCShellSetDestroy(pc, FreeCycleDestroy));
  PetscCall(PCShellSetName(pc, "perilin geometric multigrid (one V-cycle)"));
  PetscFunctionReturn(PETSC_SUCCESS);
}
