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

/* The basis Z = [X W P] in one set of 3 bs columns, with its products by K and M beside it: X (the
 * Ritz vectors) in columns [0, bs), W (the new directions) in [bs, 2 bs), P (the previous steps) in
 * [2 bs, 3 bs); column j of each block belongs to pair j. Every update is a product Z Q made in
 * place (BVMultInPlace), where Q holds zeros for the columns that take no part: before, X, W and P
 * were separate and copied into a fourth basis for the Rayleigh-Ritz step, and SLEPc's basis held
 * X once more, 19 bs vectors where 9 bs do (the modal analysis' peak memory, docs/performance.md
 * "Modal peak memory"). Z is the EPS's own basis eps->V. */
typedef struct {
  BV         v, av, bv; /* Z, K Z, M Z */
  PetscReal *lam;       /* the block's Ritz values */
  Mat        Q;         /* 3 bs x 3 bs: the coefficients of an in-place update */
  Mat        GA, GB;    /* 3 bs x 3 bs: Z^T K Z and Z^T M Z */
  PetscInt  *idx;       /* the columns of Z in the Rayleigh-Ritz basis */
} LOBPCG;

/* The active columns [l, k) of Z and both products. */
static PetscErrorCode Active(LOBPCG *c, PetscInt l, PetscInt k)
{
  PetscFunctionBeginUser;
  PetscCall(BVSetActiveColumns(c->v, l, k));
  PetscCall(BVSetActiveColumns(c->av, l, k));
  PetscCall(BVSetActiveColumns(c->bv, l, k));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The products of the columns [l, k): M z, and K z if withK (the only products of K here). */
static PetscErrorCode Products(EPS eps, LOBPCG *c, PetscInt l, PetscInt k, PetscBool withK)
{
  Mat A, B;

  PetscFunctionBeginUser;
  PetscCall(Active(c, l, k));
  PetscCall(STGetMatrix(eps->st, 0, &A));
  PetscCall(STGetMatrix(eps->st, 1, &B));
  if (withK) PetscCall(BVMatMult(c->v, A, c->av));
  PetscCall(BVMatMult(c->v, B, c->bv));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Z(:, s:e) = Z Q(:, s:e) in place, for v, and for av and bv if withProducts. */
static PetscErrorCode Update(LOBPCG *c, PetscInt s, PetscInt e, PetscBool withProducts)
{
  PetscInt m;

  PetscFunctionBeginUser;
  PetscCall(BVGetSizes(c->v, NULL, NULL, &m));
  PetscCall(Active(c, 0, m));
  PetscCall(BVMultInPlace(c->v, c->Q, s, e));
  if (withProducts) {
    PetscCall(BVMultInPlace(c->av, c->Q, s, e));
    PetscCall(BVMultInPlace(c->bv, c->Q, s, e));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Scales the columns [l, k) to unit M-norm (v, av and bv alike). */
static PetscErrorCode Normalize(LOBPCG *c, PetscInt l, PetscInt k)
{
  PetscFunctionBeginUser;
  for (PetscInt j = l; j < k; j++) {
    Vec         v, bv;
    PetscScalar d;
    PetscReal   s;
    PetscCall(BVGetColumn(c->v, j, &v));
    PetscCall(BVGetColumn(c->bv, j, &bv));
    PetscCall(VecDot(bv, v, &d));
    PetscCall(BVRestoreColumn(c->bv, j, &bv));
    PetscCall(BVRestoreColumn(c->v, j, &v));
    PetscCheck(PetscRealPart(d) > 0, PetscObjectComm((PetscObject)c->v), PETSC_ERR_CONV_FAILED, "perilin_lobpcg: a direction of zero M-norm (the preconditioner returned zero)");
    s = 1 / PetscSqrtReal(PetscRealPart(d));
    PetscCall(BVScaleColumn(c->v, j, s));
    PetscCall(BVScaleColumn(c->av, j, s));
    PetscCall(BVScaleColumn(c->bv, j, s));
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

/* The Gram matrices Z^T K Z and Z^T M Z of the first k columns, from the kept products. */
static PetscErrorCode Gram(LOBPCG *c, PetscInt k)
{
  PetscFunctionBeginUser;
  PetscCall(Active(c, 0, k));
  PetscCall(BVMatProject(c->av, NULL, c->v, c->GA));
  PetscCall(BVMatProject(c->bv, NULL, c->v, c->GB));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The DS matrix m = the rows and columns idx[0:nv) of the Gram matrix G. */
static PetscErrorCode Gather(DS ds, DSMatType m, Mat G, const PetscInt *idx, PetscInt nv)
{
  Mat                D;
  PetscScalar       *d;
  const PetscScalar *g;
  PetscInt           ld, lg;

  PetscFunctionBeginUser;
  PetscCall(DSGetMat(ds, m, &D));
  PetscCall(MatDenseGetArray(D, &d));
  PetscCall(MatDenseGetLDA(D, &ld));
  PetscCall(MatDenseGetArrayRead(G, &g));
  PetscCall(MatDenseGetLDA(G, &lg));
  for (PetscInt j = 0; j < nv; j++)
    for (PetscInt i = 0; i < nv; i++) d[i + j * ld] = g[idx[i] + idx[j] * lg];
  PetscCall(MatDenseRestoreArrayRead(G, &g));
  PetscCall(MatDenseRestoreArray(D, &d));
  PetscCall(DSRestoreMat(ds, m, &D));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Q for the Rayleigh-Ritz update from the Ritz coefficients R (nv x nv): column j < bs makes the
 * new x_j from the whole basis; column 2 bs + j (j >= nc, if na) the new p_j from the W and P rows
 * only (the step just taken). */
static PetscErrorCode RitzUpdateMatrix(LOBPCG *c, PetscInt bs, PetscInt nc, PetscInt na, PetscInt nv, Mat R)
{
  PetscScalar       *q;
  const PetscScalar *r;
  PetscInt           lq, lr;

  PetscFunctionBeginUser;
  PetscCall(MatZeroEntries(c->Q));
  PetscCall(MatDenseGetArray(c->Q, &q));
  PetscCall(MatDenseGetLDA(c->Q, &lq));
  PetscCall(MatDenseGetArrayRead(R, &r));
  PetscCall(MatDenseGetLDA(R, &lr));
  for (PetscInt j = 0; j < bs; j++)
    for (PetscInt i = 0; i < nv; i++) q[c->idx[i] + j * lq] = r[i + j * lr];
  for (PetscInt j = nc; j < bs && na; j++)
    for (PetscInt i = bs; i < nv; i++) q[c->idx[i] + (2 * bs + j) * lq] = r[i + j * lr];
  PetscCall(MatDenseRestoreArrayRead(R, &r));
  PetscCall(MatDenseRestoreArray(c->Q, &q));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rayleigh-Ritz on [X, W(nc:bs), P(nc:bs) if withP] from the Gram matrices (Gram): the new Ritz
 * pairs in X and lam, and the new P(nc:bs) = [W P] times the Ritz coefficients. ok = PETSC_FALSE,
 * and nothing changed, where the basis' M Gram matrix is not positive definite. */
static PetscErrorCode RayleighRitz(EPS eps, LOBPCG *c, PetscInt nc, PetscBool withW, PetscBool withP, PetscBool *ok)
{
  const PetscInt bs = eps->ncv, na = withW ? bs - nc : 0;
  PetscInt       nv = 0;
  PetscScalar   *eig;
  Mat            R;

  PetscFunctionBeginUser;
  for (PetscInt j = 0; j < bs; j++) c->idx[nv++] = j;
  for (PetscInt j = nc; j < bs && na; j++) c->idx[nv++] = bs + j;
  for (PetscInt j = nc; j < bs && na && withP; j++) c->idx[nv++] = 2 * bs + j;
  PetscCall(DSSetDimensions(eps->ds, nv, 0, 0));
  PetscCall(Gather(eps->ds, DS_MAT_A, c->GA, c->idx, nv));
  PetscCall(Gather(eps->ds, DS_MAT_B, c->GB, c->idx, nv));
  PetscCall(Symmetrize(eps->ds, DS_MAT_A, nv, NULL));
  PetscCall(Symmetrize(eps->ds, DS_MAT_B, nv, ok));
  if (!*ok) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc1(nv, &eig));
  PetscCall(DSSetState(eps->ds, DS_STATE_RAW));
  PetscCall(DSSolve(eps->ds, eig, NULL));
  PetscCall(DSSort(eps->ds, eig, NULL, NULL, NULL, NULL));
  PetscCall(DSSynchronize(eps->ds, eig, NULL));
  PetscCall(DSVectors(eps->ds, DS_MAT_X, NULL, NULL));
  for (PetscInt j = 0; j < bs; j++) c->lam[j] = eps->eigr[j] = PetscRealPart(eig[j]);
  PetscCall(PetscFree(eig));
  PetscCall(DSGetMat(eps->ds, DS_MAT_X, &R));
  PetscCall(RitzUpdateMatrix(c, bs, nc, na, nv, R));
  PetscCall(DSRestoreMat(eps->ds, DS_MAT_X, &R));
  PetscCall(Update(c, 0, bs, PETSC_FALSE)); /* X first: P's update reads no X row */
  if (na) PetscCall(Update(c, 2 * bs + nc, 3 * bs, PETSC_TRUE));
  PetscCall(Products(eps, c, 0, bs, PETSC_TRUE)); /* K X and M X afresh */
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The residuals K x_j - lam_j M x_j of the whole block into W, their errors (SLEPc's convergence
 * test), and the number of leading pairs that pass it. */
static PetscErrorCode Residuals(EPS eps, LOBPCG *c, PetscInt *nc)
{
  const PetscInt bs    = eps->ncv;
  PetscBool      count = PETSC_TRUE;

  PetscFunctionBeginUser;
  PetscCall(BVSetActiveColumns(c->av, 0, bs));
  PetscCall(BVSetActiveColumns(c->v, bs, 2 * bs));
  PetscCall(BVCopy(c->av, c->v));
  *nc = 0;
  for (PetscInt j = 0; j < bs; j++) {
    Vec       r, bx;
    PetscReal norm;
    PetscCall(BVGetColumn(c->v, bs + j, &r));
    PetscCall(BVGetColumn(c->bv, j, &bx));
    PetscCall(VecAXPY(r, -c->lam[j], bx));
    PetscCall(VecNorm(r, NORM_2, &norm));
    PetscCall(BVRestoreColumn(c->bv, j, &bx));
    PetscCall(BVRestoreColumn(c->v, bs + j, &r));
    PetscCall((*eps->converged)(eps, c->lam[j], 0, norm, &eps->errest[j], eps->convergedctx));
    if (count && eps->errest[j] < eps->tol)
      (*nc)++;
    else
      count = PETSC_FALSE;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The new directions W(nc:bs): the preconditioned residuals, M-orthogonal to X (W -= X X^T M W,
 * in place), M-normalized, and their products by K (the iteration's only products of K). */
static PetscErrorCode Directions(EPS eps, LOBPCG *c, PetscInt nc)
{
  const PetscInt bs = eps->ncv;
  PetscScalar   *q;
  PetscInt       lq;
  Vec            t;

  PetscFunctionBeginUser;
  PetscCall(BVCreateVec(c->v, &t));
  for (PetscInt j = nc; j < bs; j++) {
    Vec r;
    PetscCall(BVGetColumn(c->v, bs + j, &r));
    PetscCall(STApply(eps->st, r, t));
    PetscCall(VecCopy(t, r));
    PetscCall(BVRestoreColumn(c->v, bs + j, &r));
  }
  PetscCall(VecDestroy(&t));
  PetscCall(Products(eps, c, bs + nc, 2 * bs, PETSC_FALSE));
  PetscCall(MatZeroEntries(c->Q));
  PetscCall(BVSetActiveColumns(c->v, 0, bs));
  PetscCall(BVDot(c->bv, c->v, c->Q)); /* Q(0:bs, bs+nc:2bs) = X^T M W */
  PetscCall(MatDenseGetArray(c->Q, &q));
  PetscCall(MatDenseGetLDA(c->Q, &lq));
  for (PetscInt j = bs + nc; j < 2 * bs; j++) {
    for (PetscInt i = 0; i < bs; i++) q[i + j * lq] = -q[i + j * lq];
    q[j + j * lq] = 1;
  }
  PetscCall(MatDenseRestoreArray(c->Q, &q));
  PetscCall(Update(c, bs + nc, 2 * bs, PETSC_FALSE));
  PetscCall(Active(c, 0, 2 * bs));
  PetscCall(BVMultInPlace(c->bv, c->Q, bs + nc, 2 * bs));
  PetscCall(Normalize(c, bs + nc, 2 * bs));
  PetscCall(Products(eps, c, bs + nc, 2 * bs, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode EPSSolve_PeriLOBPCG(EPS eps)
{
  LOBPCG        *c   = (LOBPCG *)eps->data;
  const PetscInt bs  = eps->ncv;
  PetscInt       its = 0, nc = 0, m;
  PetscBool      ok, withP   = PETSC_FALSE, indef;
  Mat            B;

  PetscFunctionBeginUser;
  /* Z = eps->V: plain dot products while it iterates (an M inner product would also cache M Z, as
     many vectors again); the first Rayleigh-Ritz step makes the random block M-orthonormal */
  PetscCall(BVGetMatrix(eps->V, &B, &indef));
  if (B) PetscCall(PetscObjectReference((PetscObject)B));
  PetscCall(BVSetMatrix(eps->V, NULL, PETSC_FALSE));
  PetscCall(BVGetSizes(eps->V, NULL, NULL, &m));
  if (m < 3 * bs) PetscCall(BVResize(eps->V, 3 * bs, PETSC_TRUE)); /* solved before: the end of the last solve left X only */
  for (PetscInt k = eps->nini; k < bs; k++) PetscCall(BVSetRandomColumn(eps->V, k));
  PetscCall(Products(eps, c, 0, bs, PETSC_TRUE));
  PetscCall(Gram(c, bs));
  PetscCall(RayleighRitz(eps, c, bs, PETSC_FALSE, PETSC_FALSE, &ok));
  PetscCheck(ok, PetscObjectComm((PetscObject)eps), PETSC_ERR_CONV_FAILED, "perilin_lobpcg: the initial block is linearly dependent");
  while (eps->reason == EPS_CONVERGED_ITERATING) {
    PetscCall(Residuals(eps, c, &nc));
    eps->nconv = nc;
    PetscCall(EPSMonitor(eps, its, nc, eps->eigr, eps->eigi, eps->errest, bs));
    PetscCall((*eps->stopping)(eps, its, eps->max_it, nc, eps->nev, &eps->reason, eps->stoppingctx));
    if (eps->reason != EPS_CONVERGED_ITERATING) break;
    PetscCall(Directions(eps, c, nc));
    if (withP) PetscCall(Normalize(c, 2 * bs + nc, 3 * bs));
    PetscCall(Gram(c, withP ? 3 * bs : 2 * bs));
    PetscCall(RayleighRitz(eps, c, nc, PETSC_TRUE, withP, &ok));
    if (!ok && withP) PetscCall(RayleighRitz(eps, c, nc, PETSC_TRUE, PETSC_FALSE, &ok));
    PetscCheck(ok, PetscObjectComm((PetscObject)eps), PETSC_ERR_CONV_FAILED, "perilin_lobpcg: the basis [X W] lost its rank at iteration %" PetscInt_FMT " (a preconditioner that is not positive definite?)", its);
    withP = PETSC_TRUE;
    its++;
  }
  eps->its = its;
  /* X, the Ritz vectors, are its first bs columns: W and P go, so that SLEPc's use of the M inner
     product afterwards caches bs vectors, not 3 bs */
  PetscCall(BVResize(eps->V, bs, PETSC_TRUE));
  PetscCall(BVSetMatrix(eps->V, B, indef));
  PetscCall(MatDestroy(&B));
  PetscCall(BVSetActiveColumns(eps->V, 0, bs));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The basis (m = 3 bs columns, zero: the columns an update leaves out meet zeros in Q), the
 * coefficient and Gram matrices, and the index and Ritz value arrays. */
static PetscErrorCode Allocate(BV V, PetscInt m, LOBPCG *c)
{
  BV *all[3] = {&c->v, &c->av, &c->bv};

  PetscFunctionBeginUser;
  /* Z is the eigensolver's own basis (m columns, EPSAllocateSolution): X in its first columns,
     where SLEPc takes the eigenvectors from, without a copy of its own */
  PetscCall(PetscObjectReference((PetscObject)V));
  c->v = V;
  for (PetscInt i = 0; i < 3; i++) {
    if (i) PetscCall(BVDuplicateResize(V, m, all[i]));
    if (i) PetscCall(BVSetMatrix(*all[i], NULL, PETSC_FALSE)); /* plain dot products: M is applied explicitly */
    PetscCall(BVSetActiveColumns(*all[i], 0, m));
    PetscCall(BVScale(*all[i], 0)); /* zeroes (SLEPc writes zeros for 0, not 0 times the old) */
  }
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, m, m, NULL, &c->Q));
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, m, m, NULL, &c->GA));
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, m, m, NULL, &c->GB));
  PetscCall(PetscMalloc1(m, &c->idx));
  PetscCall(PetscCalloc1(m / 3, &c->lam));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Release(LOBPCG *c)
{
  PetscFunctionBeginUser;
  PetscCall(BVDestroy(&c->v));
  PetscCall(BVDestroy(&c->av));
  PetscCall(BVDestroy(&c->bv));
  PetscCall(MatDestroy(&c->Q));
  PetscCall(MatDestroy(&c->GA));
  PetscCall(MatDestroy(&c->GB));
  PetscCall(PetscFree(c->idx));
  PetscCall(PetscFree(c->lam));
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
  PetscCall(EPSAllocateSolution(eps, 2 * eps->ncv)); /* [X W P] */
  PetscCall(EPS_SetInnerProduct(eps));
  PetscCall(DSSetType(eps->ds, DSGHEP));
  PetscCall(DSAllocate(eps->ds, eps->mpd));
  PetscCall(Release(ctx));
  PetscCall(Allocate(eps->V, eps->mpd, ctx));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode EPSDestroy_PeriLOBPCG(EPS eps)
{
  LOBPCG *ctx = (LOBPCG *)eps->data;

  PetscFunctionBeginUser;
  PetscCall(Release(ctx));
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
