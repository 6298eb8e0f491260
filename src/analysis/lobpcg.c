/* perilin's LOBPCG, the SLEPc eigensolver type "perilin_lobpcg": the lowest pairs of K x = lambda M x
 * (EPS_GHEP, STPRECOND) by Knyazev's locally optimal block preconditioned conjugate gradient [1]
 * with soft locking, as SLEPc's EPSLOBPCG, but with fewer products of K. SLEPc 3.18's LOBPCG
 * projects K on its whole basis [X W P] by multiplying every column again at every iteration
 * (BVMatProject), then K X once more: 46 products per iteration for a block of 12. Here K W is
 * computed for the new directions and K P is kept, updated with the same combinations as P; K X is
 * computed afresh after each Rayleigh-Ritz step: 24 products. (Keeping K X too, as BLOPEX does,
 * needs only 12, but the kept K X is a combination of vectors as large as lambda_max ||x|| summing
 * to one as small as lambda_min ||x||: its rounding, eps lambda_max / lambda_min relative, held the
 * residuals of mppd at nu = -0.99 at 3e-7 against the 1e-10 asked for, where fresh products
 * converge in 387 iterations, as SLEPc's does in 386.) On the 230,400-particle gerstle lamina
 * (10 modes, 27 iterations either way) the run takes 32.7 s against SLEPc's 44.6 s
 * (docs/performance.md, "Modes at scale").
 *
 * X is M-orthonormal (Ritz vectors); W, the preconditioned residuals, is made M-orthogonal to X and
 * M-normalized; P is M-normalized. Where the basis has become nearly dependent (its M Gram matrix
 * is not numerically positive definite) the step is taken without P, as BLOPEX does.
 *
 * [1] A. V. Knyazev, SIAM J. Sci. Comput. 23(2):517-541, 2001. */
#include "perilin/private/analysis.h"
#include <slepc/private/epsimpl.h>
#include <petscblaslapack.h>

/* A block of vectors with their products by K and M, kept side by side. */
typedef struct {
  BV v, av, bv;
} Block;

typedef struct {
  Block      x, w, p, z; /* Ritz vectors, new directions (first the residuals), previous steps; z: [x w p] */
  PetscReal *lam;        /* the block's Ritz values */
  Mat        H;          /* bs x bs work matrix (the M-products of W with X) */
} LOBPCG;

static PetscErrorCode BlockCreate(BV tmpl, PetscInt m, Block *b)
{
  BV *all[3] = {&b->v, &b->av, &b->bv};

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < 3; i++) {
    PetscCall(BVDuplicateResize(tmpl, m, all[i]));
    PetscCall(BVSetMatrix(*all[i], NULL, PETSC_FALSE)); /* plain dot products: M is applied explicitly */
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode BlockDestroy(Block *b)
{
  PetscFunctionBeginUser;
  PetscCall(BVDestroy(&b->v));
  PetscCall(BVDestroy(&b->av));
  PetscCall(BVDestroy(&b->bv));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The active columns [l, k) of all three. */
static PetscErrorCode BlockActive(Block *b, PetscInt l, PetscInt k)
{
  PetscFunctionBeginUser;
  PetscCall(BVSetActiveColumns(b->v, l, k));
  PetscCall(BVSetActiveColumns(b->av, l, k));
  PetscCall(BVSetActiveColumns(b->bv, l, k));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* dst's active columns = src's (as many). */
static PetscErrorCode BlockCopy(Block *src, Block *dst)
{
  PetscFunctionBeginUser;
  PetscCall(BVCopy(src->v, dst->v));
  PetscCall(BVCopy(src->av, dst->av));
  PetscCall(BVCopy(src->bv, dst->bv));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* dst = beta dst + alpha src Q on the active columns (BVMult), for v and bv, and for av if withK. */
static PetscErrorCode BlockMult(Block *dst, PetscScalar alpha, PetscScalar beta, Block *src, Mat Q, PetscBool withK)
{
  PetscFunctionBeginUser;
  PetscCall(BVMult(dst->v, alpha, beta, src->v, Q));
  if (withK) PetscCall(BVMult(dst->av, alpha, beta, src->av, Q));
  PetscCall(BVMult(dst->bv, alpha, beta, src->bv, Q));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The products of the active columns: M v, and K v if withK (the only products of K here). */
static PetscErrorCode BlockProducts(EPS eps, Block *b, PetscBool withK)
{
  Mat A, B;

  PetscFunctionBeginUser;
  PetscCall(STGetMatrix(eps->st, 0, &A));
  PetscCall(STGetMatrix(eps->st, 1, &B));
  if (withK) PetscCall(BVMatMult(b->v, A, b->av));
  PetscCall(BVMatMult(b->v, B, b->bv));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Scales the active columns to unit M-norm (v, av and bv alike). */
static PetscErrorCode BlockNormalize(Block *b)
{
  PetscInt l, k;

  PetscFunctionBeginUser;
  PetscCall(BVGetActiveColumns(b->v, &l, &k));
  for (PetscInt j = l; j < k; j++) {
    Vec         v, bv;
    PetscScalar d;
    PetscReal   s;
    PetscCall(BVGetColumn(b->v, j, &v));
    PetscCall(BVGetColumn(b->bv, j, &bv));
    PetscCall(VecDot(bv, v, &d));
    PetscCall(BVRestoreColumn(b->bv, j, &bv));
    PetscCall(BVRestoreColumn(b->v, j, &v));
    PetscCheck(PetscRealPart(d) > 0, PetscObjectComm((PetscObject)b->v), PETSC_ERR_CONV_FAILED, "perilin_lobpcg: a direction of zero M-norm (the preconditioner returned zero)");
    s = 1 / PetscSqrtReal(PetscRealPart(d));
    PetscCall(BVScaleColumn(b->v, j, s));
    PetscCall(BVScaleColumn(b->av, j, s));
    PetscCall(BVScaleColumn(b->bv, j, s));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The symmetric part of the leading n x n block of the DS matrix m, and (chol) whether it is
 * numerically positive definite (a Cholesky factorization of a copy succeeds). */
static PetscErrorCode Symmetrize(DS ds, DSMatType m, PetscInt n, PetscBool *chol)
{
  Mat          G;
  PetscScalar *g, *c;
  PetscInt     ld;
  PetscBLASInt bn, info = 0;

  PetscFunctionBeginUser;
  PetscCall(DSGetMat(ds, m, &G));
  PetscCall(MatDenseGetArray(G, &g));
  PetscCall(MatDenseGetLDA(G, &ld));
  for (PetscInt j = 0; j < n; j++)
    for (PetscInt i = 0; i < j; i++) g[i + j * ld] = g[j + i * ld] = (g[i + j * ld] + g[j + i * ld]) / 2;
  if (chol) {
    PetscCall(PetscMalloc1(n * n, &c));
    for (PetscInt j = 0; j < n; j++)
      for (PetscInt i = 0; i < n; i++) c[i + j * n] = g[i + j * ld];
    PetscCall(PetscBLASIntCast(n, &bn));
    PetscCallBLAS("LAPACKpotrf", LAPACKpotrf_("U", &bn, c, &bn, &info));
    PetscCall(PetscFree(c));
    *chol = (PetscBool)(info == 0);
  }
  PetscCall(MatDenseRestoreArray(G, &g));
  PetscCall(DSRestoreMat(ds, m, &G));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rayleigh-Ritz on [X, W(nc:bs), P(nc:bs) if withP]: the new Ritz pairs in X and lam, and the new
 * P(nc:bs) = [W P] times the Ritz coefficients (the step just taken). ok = PETSC_FALSE, and
 * nothing changed, where the basis' M Gram matrix is not positive definite. */
static PetscErrorCode RayleighRitz(EPS eps, LOBPCG *ctx, PetscInt nc, PetscBool withW, PetscBool withP, PetscBool *ok)
{
  const PetscInt bs = eps->ncv, na = withW ? bs - nc : 0, nv = bs + na + (withP ? na : 0);
  PetscScalar   *eig;
  Mat            G, Q;

  PetscFunctionBeginUser;
  PetscCall(BlockActive(&ctx->x, 0, bs));
  PetscCall(BlockActive(&ctx->z, 0, bs));
  PetscCall(BlockCopy(&ctx->x, &ctx->z));
  if (na) {
    PetscCall(BlockActive(&ctx->w, nc, bs));
    PetscCall(BlockActive(&ctx->z, bs, bs + na));
    PetscCall(BlockCopy(&ctx->w, &ctx->z));
  }
  if (withP) {
    PetscCall(BlockActive(&ctx->p, nc, bs));
    PetscCall(BlockActive(&ctx->z, bs + na, nv));
    PetscCall(BlockCopy(&ctx->p, &ctx->z));
  }
  PetscCall(BlockActive(&ctx->z, 0, nv));
  PetscCall(DSSetDimensions(eps->ds, nv, 0, 0));
  PetscCall(DSGetMat(eps->ds, DS_MAT_A, &G));
  PetscCall(BVMatProject(ctx->z.av, NULL, ctx->z.v, G)); /* Z^T K Z from the kept K Z */
  PetscCall(DSRestoreMat(eps->ds, DS_MAT_A, &G));
  PetscCall(DSGetMat(eps->ds, DS_MAT_B, &G));
  PetscCall(BVMatProject(ctx->z.bv, NULL, ctx->z.v, G));
  PetscCall(DSRestoreMat(eps->ds, DS_MAT_B, &G));
  PetscCall(Symmetrize(eps->ds, DS_MAT_A, nv, NULL));
  PetscCall(Symmetrize(eps->ds, DS_MAT_B, nv, ok));
  if (!*ok) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc1(nv, &eig));
  PetscCall(DSSetState(eps->ds, DS_STATE_RAW));
  PetscCall(DSSolve(eps->ds, eig, NULL));
  PetscCall(DSSort(eps->ds, eig, NULL, NULL, NULL, NULL));
  PetscCall(DSSynchronize(eps->ds, eig, NULL));
  PetscCall(DSVectors(eps->ds, DS_MAT_X, NULL, NULL));
  for (PetscInt j = 0; j < bs; j++) ctx->lam[j] = eps->eigr[j] = PetscRealPart(eig[j]);
  PetscCall(PetscFree(eig));
  PetscCall(DSGetMat(eps->ds, DS_MAT_X, &Q));
  if (na) { /* P(nc:bs) = Z(bs:nv) Q(bs:nv, nc:bs) */
    PetscCall(BlockActive(&ctx->z, bs, nv));
    PetscCall(BlockActive(&ctx->p, nc, bs));
    PetscCall(BlockMult(&ctx->p, 1, 0, &ctx->z, Q, PETSC_TRUE));
  }
  PetscCall(BlockActive(&ctx->z, 0, nv)); /* X = Z Q(:, 0:bs), K X afresh */
  PetscCall(BlockActive(&ctx->x, 0, bs));
  PetscCall(BlockMult(&ctx->x, 1, 0, &ctx->z, Q, PETSC_FALSE));
  PetscCall(DSRestoreMat(eps->ds, DS_MAT_X, &Q));
  PetscCall(BlockProducts(eps, &ctx->x, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The residuals K x_j - lam_j M x_j of the whole block into W, their errors (SLEPc's convergence
 * test), and the number of leading pairs that pass it. */
static PetscErrorCode Residuals(EPS eps, LOBPCG *ctx, PetscInt *nc)
{
  const PetscInt bs    = eps->ncv;
  PetscBool      count = PETSC_TRUE;

  PetscFunctionBeginUser;
  PetscCall(BVSetActiveColumns(ctx->x.av, 0, bs));
  PetscCall(BVSetActiveColumns(ctx->w.v, 0, bs));
  PetscCall(BVCopy(ctx->x.av, ctx->w.v));
  *nc = 0;
  for (PetscInt j = 0; j < bs; j++) {
    Vec       r, bx;
    PetscReal norm;
    PetscCall(BVGetColumn(ctx->w.v, j, &r));
    PetscCall(BVGetColumn(ctx->x.bv, j, &bx));
    PetscCall(VecAXPY(r, -ctx->lam[j], bx));
    PetscCall(VecNorm(r, NORM_2, &norm));
    PetscCall(BVRestoreColumn(ctx->x.bv, j, &bx));
    PetscCall(BVRestoreColumn(ctx->w.v, j, &r));
    PetscCall((*eps->converged)(eps, ctx->lam[j], 0, norm, &eps->errest[j], eps->convergedctx));
    if (count && eps->errest[j] < eps->tol)
      (*nc)++;
    else
      count = PETSC_FALSE;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The new directions W(nc:bs): the preconditioned residuals, M-orthogonal to X, M-normalized, and
 * their products by K (the iteration's only products of K). */
static PetscErrorCode Directions(EPS eps, LOBPCG *ctx, PetscInt nc)
{
  const PetscInt bs = eps->ncv;
  Vec            t;

  PetscFunctionBeginUser;
  PetscCall(BVCreateVec(ctx->w.v, &t));
  for (PetscInt j = nc; j < bs; j++) {
    Vec r;
    PetscCall(BVGetColumn(ctx->w.v, j, &r));
    PetscCall(STApply(eps->st, r, t));
    PetscCall(VecCopy(t, r));
    PetscCall(BVRestoreColumn(ctx->w.v, j, &r));
  }
  PetscCall(VecDestroy(&t));
  PetscCall(BlockActive(&ctx->w, nc, bs));
  PetscCall(BlockProducts(eps, &ctx->w, PETSC_FALSE));
  PetscCall(BlockActive(&ctx->x, 0, bs));
  PetscCall(BVDot(ctx->w.bv, ctx->x.v, ctx->H)); /* H(0:bs, nc:bs) = X^T M W */
  PetscCall(BlockMult(&ctx->w, -1, 1, &ctx->x, ctx->H, PETSC_FALSE));
  PetscCall(BlockNormalize(&ctx->w));
  PetscCall(BlockProducts(eps, &ctx->w, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode EPSSolve_PeriLOBPCG(EPS eps)
{
  LOBPCG        *ctx = (LOBPCG *)eps->data;
  const PetscInt bs  = eps->ncv;
  PetscInt       its = 0, nc = 0;
  PetscBool      ok, withP   = PETSC_FALSE;

  PetscFunctionBeginUser;
  for (PetscInt k = eps->nini; k < bs; k++) PetscCall(BVSetRandomColumn(eps->V, k));
  PetscCall(BVSetActiveColumns(eps->V, 0, bs));
  PetscCall(BVOrthogonalize(eps->V, NULL)); /* M-orthonormal: eps->V has M as its inner product */
  PetscCall(BlockActive(&ctx->x, 0, bs));
  PetscCall(BVCopy(eps->V, ctx->x.v));
  PetscCall(BlockProducts(eps, &ctx->x, PETSC_TRUE));
  PetscCall(RayleighRitz(eps, ctx, bs, PETSC_FALSE, PETSC_FALSE, &ok));
  PetscCheck(ok, PetscObjectComm((PetscObject)eps), PETSC_ERR_CONV_FAILED, "perilin_lobpcg: the initial block is not M-orthonormal");
  while (eps->reason == EPS_CONVERGED_ITERATING) {
    PetscCall(Residuals(eps, ctx, &nc));
    eps->nconv = nc;
    PetscCall(EPSMonitor(eps, its, nc, eps->eigr, eps->eigi, eps->errest, bs));
    PetscCall((*eps->stopping)(eps, its, eps->max_it, nc, eps->nev, &eps->reason, eps->stoppingctx));
    if (eps->reason != EPS_CONVERGED_ITERATING) break;
    PetscCall(Directions(eps, ctx, nc));
    if (withP) {
      PetscCall(BlockActive(&ctx->p, nc, bs));
      PetscCall(BlockNormalize(&ctx->p));
    }
    PetscCall(RayleighRitz(eps, ctx, nc, PETSC_TRUE, withP, &ok));
    if (!ok && withP) PetscCall(RayleighRitz(eps, ctx, nc, PETSC_TRUE, PETSC_FALSE, &ok));
    PetscCheck(ok, PetscObjectComm((PetscObject)eps), PETSC_ERR_CONV_FAILED, "perilin_lobpcg: the basis [X W] lost its rank at iteration %" PetscInt_FMT " (a preconditioner that is not positive definite?)", its);
    withP = PETSC_TRUE;
    its++;
  }
  eps->its = its;
  PetscCall(BVSetActiveColumns(eps->V, 0, bs));
  PetscCall(BVSetActiveColumns(ctx->x.v, 0, bs));
  PetscCall(BVCopy(ctx->x.v, eps->V));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sorting by the smallest real part, for the EPS and its DS (the only order this solver gives). */
static PetscErrorCode EPSSetUpSort_PeriLOBPCG(EPS eps)
{
  SlepcSC sc;

  PetscFunctionBeginUser;
  eps->sc->comparison    = SlepcCompareSmallestReal;
  eps->sc->comparisonctx = NULL;
  eps->sc->map           = NULL;
  eps->sc->mapobj        = NULL;
  eps->sc->rg            = NULL;
  PetscCall(DSGetSlepcSC(eps->ds, &sc));
  *sc = *eps->sc;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* STPRECOND, whose KSP has K as its operator (what GAMG on the short-range P needs to set up). */
static PetscErrorCode EPSSetDefaultST_PeriLOBPCG(EPS eps)
{
  PetscFunctionBeginUser;
  if (!((PetscObject)eps->st)->type_name) PetscCall(STSetType(eps->st, STPRECOND));
  PetscCall(STPrecondSetKSPHasMat(eps->st, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The block: ncv columns (default nev + 2), the projected problem 3 ncv. */
static PetscErrorCode EPSSetUp_PeriLOBPCG(EPS eps)
{
  LOBPCG *ctx = (LOBPCG *)eps->data;

  PetscFunctionBeginUser;
  EPSCheckHermitianDefinite(eps);
  PetscCheck(eps->isgeneralized, PetscObjectComm((PetscObject)eps), PETSC_ERR_SUP, "perilin_lobpcg solves K x = lambda M x (EPS_GHEP)");
  if (!eps->which) eps->which = EPS_SMALLEST_REAL;
  PetscCheck(eps->which == EPS_SMALLEST_REAL, PetscObjectComm((PetscObject)eps), PETSC_ERR_SUP, "perilin_lobpcg computes the smallest eigenvalues only");
  if (eps->ncv == PETSC_DEFAULT || eps->ncv == PETSC_DETERMINE) eps->ncv = eps->nev + 2;
  PetscCheck(eps->ncv >= eps->nev, PetscObjectComm((PetscObject)eps), PETSC_ERR_ARG_OUTOFRANGE, "perilin_lobpcg: ncv (%" PetscInt_FMT ") below nev (%" PetscInt_FMT ")", eps->ncv, eps->nev);
  PetscCheck(eps->n >= 5 * eps->ncv, PetscObjectComm((PetscObject)eps), PETSC_ERR_SUP, "perilin_lobpcg: %" PetscInt_FMT " unknowns are too few for a block of %" PetscInt_FMT, eps->n, eps->ncv);
  eps->mpd = 3 * eps->ncv;
  if (eps->max_it == PETSC_DEFAULT || eps->max_it == PETSC_DETERMINE) eps->max_it = PetscMax(100, 2 * eps->n / eps->ncv);
  PetscCall(EPSAllocateSolution(eps, 0));
  PetscCall(EPS_SetInnerProduct(eps));
  PetscCall(DSSetType(eps->ds, DSGHEP));
  PetscCall(DSAllocate(eps->ds, eps->mpd));
  PetscCall(BlockDestroy(&ctx->x));
  PetscCall(BlockDestroy(&ctx->w));
  PetscCall(BlockDestroy(&ctx->p));
  PetscCall(BlockDestroy(&ctx->z));
  PetscCall(BlockCreate(eps->V, eps->ncv, &ctx->x));
  PetscCall(BlockCreate(eps->V, eps->ncv, &ctx->w));
  PetscCall(BlockCreate(eps->V, eps->ncv, &ctx->p));
  PetscCall(BlockCreate(eps->V, eps->mpd, &ctx->z));
  PetscCall(PetscFree(ctx->lam));
  PetscCall(PetscCalloc1(eps->ncv, &ctx->lam));
  PetscCall(MatDestroy(&ctx->H));
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, eps->ncv, eps->ncv, NULL, &ctx->H));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode EPSDestroy_PeriLOBPCG(EPS eps)
{
  LOBPCG *ctx = (LOBPCG *)eps->data;

  PetscFunctionBeginUser;
  PetscCall(BlockDestroy(&ctx->x));
  PetscCall(BlockDestroy(&ctx->w));
  PetscCall(BlockDestroy(&ctx->p));
  PetscCall(BlockDestroy(&ctx->z));
  PetscCall(PetscFree(ctx->lam));
  PetscCall(MatDestroy(&ctx->H));
  PetscCall(PetscFree(eps->data));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode EPSCreate_PeriLOBPCG(EPS eps)
{
  LOBPCG *ctx;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&ctx));
  eps->data              = (void *)ctx;
  eps->useds             = PETSC_TRUE;
  eps->categ             = EPS_CATEGORY_PRECOND;
  eps->ops->solve        = EPSSolve_PeriLOBPCG;
  eps->ops->setup        = EPSSetUp_PeriLOBPCG;
  eps->ops->setupsort    = EPSSetUpSort_PeriLOBPCG;
  eps->ops->destroy      = EPSDestroy_PeriLOBPCG;
  eps->ops->setdefaultst = EPSSetDefaultST_PeriLOBPCG;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriEPSRegisterLOBPCG - registers perilin's LOBPCG with SLEPc as the EPS type PERI_EPSLOBPCG
  ("perilin_lobpcg", also for -eps_type). Not collective; once is enough, again is harmless.
@*/
PetscErrorCode PeriEPSRegisterLOBPCG(void)
{
  PetscFunctionBeginUser;
  PetscCall(EPSRegister(PERI_EPSLOBPCG, EPSCreate_PeriLOBPCG));
  PetscFunctionReturn(PETSC_SUCCESS);
}
