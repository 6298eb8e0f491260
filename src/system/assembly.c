/* Assembly of the linearized stiffness K from the model's bond blocks into a block matrix (BAIJ by
 * default, block size = DOFs per particle) with exact preallocation, and the rigid-body modes
 * that serve as AMG's near-null space and as the check for unconstrained motion; and the loop over
 * the elements of the energy (bonds or families) that the energy and the torsion loads share. */
#include "perilin/private/system.h"

/* Which bonds enter the matrix and how: those of the short range sr (K itself: NULL, all), their
 * blocks times its factor; broken ones with broken_share of their block (0: left out). */
typedef struct {
  const PeriShortRange *sr;
  PetscReal             broken_share;
  const PeriDisc       *disc; /* whose bonds these are (sr reads their lengths) */
} BondFilter;

static inline PetscBool Kept(const PeriBonds *b, PetscInt i, PetscInt k, const BondFilter *f)
{
  return (PetscBool)((b->live[k] || f->broken_share > 0) && PeriShortRangeHolds(f->sr, f->disc, i, k));
}

/* Distinct partners of owned particle i among its stored bonds (periodic images repeat them). */
static PetscInt RowPartners(const PeriBonds *b, const BondFilter *f, PetscInt i, PetscInt buf[])
{
  PetscInt n = 0, m = 0;
  for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++)
    if (Kept(b, i, k, f) && b->j[k] != i) buf[n++] = b->j[k];
  PetscSortInt(n, buf);
  for (PetscInt k = 0; k < n; k++)
    if (!m || buf[k] != buf[m - 1]) buf[m++] = buf[k];
  return m;
}

/* Block counts per owned row: diagonal/off-diagonal part, and their upper-triangular share for
 * SBAIJ. Row i sees its stored partners (j > i, upper) and the particles that store a bond to i
 * (lower): those on other ranks count i as a ghost, and their counts reach i's owner through the
 * halo. */
static PetscErrorCode Preallocation(PeriSystem sys, const BondFilter *f, PetscInt **dnz, PetscInt **onz, PetscInt **dnzu, PetscInt **onzu)
{
  const PeriBonds *b = &sys->disc.bonds;
  const PetscInt   n = sys->disc.particles.n, nloc = b->rend - b->rstart;
  PetscInt        *cnt, *buf, maxrow = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(2 * n, &cnt)); /* (diag, offdiag) counts of every local particle's row */
  PetscCall(PetscMalloc4(nloc, dnz, nloc, onz, nloc, dnzu, nloc, onzu));
  for (PetscInt i = b->rstart; i < b->rend; i++) maxrow = PetscMax(maxrow, b->offset[i - b->rstart + 1] - b->offset[i - b->rstart]);
  PetscCall(PetscMalloc1(maxrow + 1, &buf));
  for (PetscInt i = b->rstart; i < b->rend; i++) {
    PetscInt m = RowPartners(b, f, i, buf), du = 1, ou = 0;
    for (PetscInt k = 0; k < m; k++) {
      PetscInt  j    = buf[k];
      PetscBool same = (PetscBool)(j < sys->disc.nowned);
      if (same)
        du++;
      else
        ou++;
      cnt[2 * j + (same ? 0 : 1)]++; /* row j, column i */
    }
    (*dnzu)[i - b->rstart] = du;
    (*onzu)[i - b->rstart] = ou;
    cnt[2 * i] += du;
    cnt[2 * i + 1] += ou;
  }
  PetscCall(PetscFree(buf));
  PetscCall(PeriDiscGhostsToOwners(&sys->disc, MPIU_INT, 2, MPI_SUM, cnt));
  for (PetscInt i = 0; i < nloc; i++) {
    (*dnz)[i] = cnt[2 * i];
    (*onz)[i] = cnt[2 * i + 1];
  }
  PetscCall(PetscFree(cnt));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Adds the bs x bs block B (row stride ld) to the row's block for column j. */
static void RowAdd(PetscInt bs, PetscInt j, const PetscReal *B, PetscInt ld, PetscInt slot[], PetscInt col[], PetscReal blocks[], PetscInt *ncol)
{
  PetscReal *dst;
  if (slot[j] < 0) {
    slot[j]      = (*ncol)++;
    col[slot[j]] = j;
    for (PetscInt a = 0; a < bs * bs; a++) blocks[slot[j] * bs * bs + a] = 0;
  }
  dst = &blocks[slot[j] * bs * bs];
  for (PetscInt a = 0; a < bs; a++)
    for (PetscInt c = 0; c < bs; c++) dst[a * bs + c] += B[a * ld + c];
}

/* The family block of state s of a model with per-particle states (ops.bond_state): A_is G G^T
 * with G = (-sum_t g_t, g_1, ..., g_n), g_t the weights of bond t toward theta_is. */
static void StateFamilyBlock(PeriModel m, PetscInt s, PetscInt n, const PeriBondGeometry fam[], PetscReal G[], PetscReal Ke[])
{
  const PetscInt  bs = m->dofs, N = (n + 1) * bs;
  const PetscReal A = n ? m->ops.state_modulus(m, fam[0].i, s) : 0;
  PetscReal       gj[PERI_MAX_DOF];

  for (PetscInt c = 0; c < bs; c++) G[c] = 0;
  for (PetscInt t = 0; t < n; t++) {
    m->ops.bond_state(m, &fam[t], s, &G[(t + 1) * bs], gj);
    for (PetscInt c = 0; c < bs; c++) G[c] -= G[(t + 1) * bs + c];
  }
  if (!Ke) return; /* the gradient only */
  for (PetscInt a = 0; a < N; a++)
    for (PetscInt c = 0; c < N; c++) Ke[a * N + c] = A * G[a] * G[c];
}

/* Visits the families of the owned particles (state-based models): their dense blocks, or the
 * rank-one blocks of state s. */
static PetscErrorCode FamiliesForEach(PeriSystem sys, PetscInt s, PeriElementFn fn, void *ctx)
{
  PeriModel         m  = sys->model;
  const PetscInt    bs = m->dofs, nmax = PeriSystemMaxFamily(sys);
  PeriBondGeometry *fam;
  PetscReal        *Ke, *work;
  PetscInt         *idx, *gidx;
  PeriElement       el;

  PetscFunctionBeginUser;
  /* a rank-one block (states) keeps its gradient G in Ke, not the dense block */
  PetscCall(PetscMalloc5(nmax, &fam, m->ops.bond_state ? (nmax + 1) * bs : PetscSqr((nmax + 1) * bs), &Ke, 2 * (nmax + 1) * bs, &work, nmax + 1, &idx, nmax + 1, &gidx));
  el.idx    = idx;
  el.gidx   = gidx;
  el.nshare = 1;
  el.K      = Ke;
  el.G      = NULL;
  el.g      = fam;
  el.work   = work;
  for (PetscInt i = sys->disc.family.rstart; i < sys->disc.family.rend; i++) {
    PetscInt n;
    PetscCall(PeriSystemFamilyGeometry(sys, i, &n, fam));
    if (m->ops.family_stiffness)
      PetscCall(m->ops.family_stiffness(m, n, fam, Ke));
    else {
      StateFamilyBlock(m, s, n, fam, Ke, NULL);
      el.K = NULL;
      el.G = Ke;
      el.A = n ? m->ops.state_modulus(m, i, s) : 0;
    }
    idx[0] = i;
    for (PetscInt t = 0; t < n; t++) idx[t + 1] = fam[t].j;
    for (PetscInt t = 0; t <= n; t++) gidx[t] = sys->disc.particles.global[idx[t]];
    el.n = n + 1;
    PetscCall((*fn)(sys, &el, ctx));
  }
  PetscCall(PetscFree5(fam, Ke, work, idx, gidx));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Visits the live bonds of the owned particles (bond-based models); self-image bonds move both
 * ends alike and carry no energy. */
static PetscErrorCode BondsForEach(PeriSystem sys, PeriElementFn fn, void *ctx)
{
  const PeriBonds *b = &sys->disc.bonds;
  PeriModel        m = sys->model;
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF], work[4 * PERI_MAX_DOF];
  PetscInt         idx[2], gidx[2];
  PeriBondGeometry g;
  PeriElement      el = {2, idx, gidx, 2, Ke, NULL, 0, &g, work};

  PetscFunctionBeginUser;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      if (!b->live[k] || b->j[k] == i) continue;
      PetscCall(PeriSystemBondGeometry(sys, i, k, &g));
      m->ops.bond_stiffness(m, &g, Ke);
      idx[0]  = i;
      idx[1]  = g.j;
      gidx[0] = sys->disc.particles.global[i];
      gidx[1] = sys->disc.particles.global[g.j];
      PetscCall((*fn)(sys, &el, ctx));
    }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The element's DOFs u_e (u: the DOFs of the local view, PeriSystemLocalDOFs) into el->work[0, N) and its
 * forces f = K_e u_e into el->work[N, 2N), N = el->n dofs: what the stress and the reactions of an
 * element share. */
void PeriElementForces(PeriSystem sys, const PeriElement *el, const PetscScalar u[])
{
  const PetscInt bs = sys->model->dofs, N = el->n * bs;
  PetscReal     *ue = el->work, *f = el->work + N;
  for (PetscInt t = 0; t < el->n; t++)
    for (PetscInt c = 0; c < bs; c++) ue[t * bs + c] = PetscRealPart(u[el->idx[t] * bs + c]);
  if (el->G) { /* A G (G . u_e): O(N), not O(N^2) */
    PetscReal s = 0;
    for (PetscInt c = 0; c < N; c++) s += el->G[c] * ue[c];
    for (PetscInt a = 0; a < N; a++) f[a] = el->A * s * el->G[a];
    return;
  }
  for (PetscInt a = 0; a < N; a++) {
    f[a] = 0;
    for (PetscInt c = 0; c < N; c++) f[a] += el->K[a * N + c] * ue[c];
  }
}

/* An element's energy u_e^T K_e u_e / 2 over its N DOFs ue. */
PetscReal PeriElementEnergy(const PeriElement *el, PetscInt N, const PetscReal ue[])
{
  PetscReal e = 0;
  if (el->G) {
    for (PetscInt c = 0; c < N; c++) e += el->G[c] * ue[c];
    return 0.5 * el->A * e * e;
  }
  for (PetscInt a = 0; a < N; a++)
    for (PetscInt c = 0; c < N; c++) e += 0.5 * ue[a] * el->K[a * N + c] * ue[c];
  return e;
}

/*@C
  PeriElementsForEach - calls fn on every element of this rank's energy with its stiffness block:
  each live bond of an owned particle (bond-based models), or each owned particle's family
  (state-based models), in the order of the owned particles. Not collective.
@*/
PetscErrorCode PeriElementsForEach(PeriSystem sys, PeriElementFn fn, void *ctx)
{
  PetscFunctionBeginUser;
  if (sys->model->ops.family_stiffness)
    PetscCall(FamiliesForEach(sys, 0, fn, ctx));
  else
    PetscCall(BondsForEach(sys, fn, ctx));
  if (sys->model->ops.bond_state) /* the springs, then the states */
    for (PetscInt s = 0; s < sys->model->nstates; s++) PetscCall(FamiliesForEach(sys, s, fn, ctx));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Adds an element's block to the matrix ctx. */
static PetscErrorCode InsertElement(PeriSystem sys, const PeriElement *el, void *ctx)
{
  PetscFunctionBeginUser;
  (void)sys;
  PetscCall(MatSetValuesBlocked((Mat)ctx, el->n, el->gidx, el->n, el->gidx, el->K, ADD_VALUES));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Inserts every element's block into K one by one: state-based models, whose families overlap too
 * much for the row gathering of bond-based models. */
static PetscErrorCode InsertElements(PeriSystem sys, Mat K)
{
  PetscFunctionBeginUser;
  PetscCall(PeriElementsForEach(sys, InsertElement, K));
  PetscCall(MatAssemblyBegin(K, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(K, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* An empty block matrix of K's layout and the given type: the options and preallocation follow. */
static PetscErrorCode CreateBlockMatrix(PeriSystem sys, MatType type, Mat *K)
{
  const PetscInt bs = sys->model->dofs, nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart;

  PetscFunctionBeginUser;
  PetscCall(MatCreate(sys->comm, K));
  PetscCall(MatSetSizes(*K, nloc * bs, nloc * bs, sys->disc.N * bs, sys->disc.N * bs));
  PetscCall(MatSetBlockSize(*K, bs));
  PetscCall(MatSetType(*K, type));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* State-based models: particle i's energy couples every pair of its family, so K reaches 2 delta.
 * The pattern is exact from a first pass into PETSc's preallocator. */
static PetscErrorCode AssembleFamilies(PeriSystem sys, Mat *K)
{
  Mat pre;

  PetscFunctionBeginUser;
  PetscCall(CreateBlockMatrix(sys, MATPREALLOCATOR, &pre));
  PetscCall(MatSetUp(pre));
  PetscCall(InsertElements(sys, pre));
  PetscCall(CreateBlockMatrix(sys, sys->stiffness.mat_type[0] ? sys->stiffness.mat_type : MATBAIJ, K));
  PetscCall(MatSetFromOptions(*K));
  PetscCall(MatPreallocatorPreallocate(pre, PETSC_TRUE, *K));
  PetscCall(MatDestroy(&pre));
  PetscCall(MatSetOption(*K, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(InsertElements(sys, *K));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Bond-based models: K of the default type or -mat_type, with the exact pattern from the bonds;
 * *maxcol gets the most blocks of a row (the size of the row buffers). */
static PetscErrorCode CreateBondStiffness(PeriSystem sys, const BondFilter *f, Mat *K, PetscInt *maxcol)
{
  const PetscInt nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart;
  PetscInt      *dnz, *onz, *dnzu, *onzu;
  PetscBool      sym;

  PetscFunctionBeginUser;
  PetscCall(Preallocation(sys, f, &dnz, &onz, &dnzu, &onzu));
  *maxcol = 1;
  for (PetscInt i = 0; i < nloc; i++) *maxcol = PetscMax(*maxcol, dnz[i] + onz[i]);
  PetscCall(CreateBlockMatrix(sys, sys->stiffness.mat_type[0] ? sys->stiffness.mat_type : MATBAIJ, K));
  PetscCall(MatSetFromOptions(*K));
  PetscCall(MatXAIJSetPreallocation(*K, sys->model->dofs, dnz, onz, dnzu, onzu));
  PetscCall(PetscFree4(dnz, onz, dnzu, onzu));
  PetscCall(MatSetOption(*K, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)*K, &sym, MATSBAIJ, MATSEQSBAIJ, MATMPISBAIJ, ""));
  if (sym) PetscCall(MatSetOption(*K, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether stored bond k of owned row r points to another owned particle: then that particle's row
 * gathers the bond's lower blocks itself, without the stash. */
static PetscBool IsIncoming(const PeriBonds *b, const BondFilter *f, PetscInt r, PetscInt k)
{
  PetscInt j = b->j[k];
  return (PetscBool)(Kept(b, r, k, f) && j != r && j >= b->rstart && j < b->rend);
}

/* The incoming bonds of every owned particle j as a CSR (ptr, bond, row): bond k stored at owned
 * row r towards owned particle j, listed under j. */
typedef struct {
  PetscInt *ptr, *bond, *row;
} Incoming;

/* Builds the incoming-bond CSR (the transpose of the owned block of the bond list). */
static PetscErrorCode IncomingBonds(const PeriBonds *b, const BondFilter *f, Incoming *in)
{
  const PetscInt nloc = b->rend - b->rstart, rstart = b->rstart;
  PetscInt      *fill;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(nloc + 1, &in->ptr));
  for (PetscInt r = rstart; r < b->rend; r++)
    for (PetscInt k = b->offset[r - rstart]; k < b->offset[r - rstart + 1]; k++)
      if (IsIncoming(b, f, r, k)) in->ptr[b->j[k] - rstart + 1]++;
  for (PetscInt i = 0; i < nloc; i++) in->ptr[i + 1] += in->ptr[i];
  PetscCall(PetscMalloc2(in->ptr[nloc], &in->bond, in->ptr[nloc], &in->row));
  PetscCall(PetscMalloc1(nloc, &fill));
  PetscCall(PetscArraycpy(fill, in->ptr, nloc));
  for (PetscInt r = rstart; r < b->rend; r++)
    for (PetscInt k = b->offset[r - rstart]; k < b->offset[r - rstart + 1]; k++) {
      PetscInt j = b->j[k];
      if (!IsIncoming(b, f, r, k)) continue;
      in->bond[fill[j - rstart]]  = k;
      in->row[fill[j - rstart]++] = r;
    }
  PetscCall(PetscFree(fill));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One block row being gathered: slot[j] is column j's place in col[] and blocks[] (-1: none yet). */
typedef struct {
  PetscInt   ncol, *slot, *col, *perm;
  PetscReal *blocks, *row;
} RowBuffer;

/* Adds bond k of owned particle i to acc (bs*bs + bs per local particle: the signed diagonal
 * block, then the absolute row sums of the off-diagonal blocks) at both ends. */
static PetscErrorCode AddBondRowSums(PeriSystem sys, PetscInt i, PetscInt k, PetscReal *acc)
{
  const PetscInt   bs = sys->model->dofs, n = 2 * bs, w = bs * bs + bs;
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF];
  PeriBondGeometry g;

  PetscFunctionBeginUser;
  PetscCall(PeriBondStiffness(sys, i, k, 1, &g, Ke));
  for (PetscInt e = 0; e < 2; e++) { /* e = 0: i's rows, e = 1: j's */
    PetscReal *a = &acc[w * (e ? g.j : i)];
    for (PetscInt r = 0; r < bs; r++)
      for (PetscInt c = 0; c < bs; c++) {
        a[r * bs + c] += Ke[(e * bs + r) * n + e * bs + c];
        a[bs * bs + r] += PetscAbsReal(Ke[(e * bs + r) * n + (1 - e) * bs + c]);
      }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriStiffnessRowSums - the absolute row sums of K (sum over c of |K_rc|, held DOFs as free ones)
  from the live bonds' blocks, without K: the diagonal blocks summed with their signs, the
  off-diagonal ones bond by bond (an upper bound where a pair has several periodic images). For
  a Gershgorin bound of an assembled or a matrix-free K alike. Models with per-bond blocks only.
  Collective.
@*/
PetscErrorCode PeriStiffnessRowSums(PeriSystem sys, Vec sums)
{
  const PeriBonds *b  = &sys->disc.bonds;
  const PetscInt   bs = sys->model->dofs, w = bs * bs + bs;
  PetscReal       *acc;
  PetscScalar     *s;

  PetscFunctionBeginUser;
  PetscCheck(sys->model->ops.bond_stiffness, sys->comm, PETSC_ERR_SUP, "Model %s has no per-bond blocks", sys->model->type);
  PetscCall(PetscCalloc1(w * sys->disc.particles.n, &acc));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++)
      if (b->live[k] && b->j[k] != i) PetscCall(AddBondRowSums(sys, i, k, acc));
  PetscCall(PeriDiscGhostsToOwners(&sys->disc, MPIU_REAL, w, MPI_SUM, acc));
  PetscCall(VecGetArray(sums, &s));
  for (PetscInt i = 0; i < sys->disc.nowned; i++)
    for (PetscInt r = 0; r < bs; r++) {
      PetscReal sum = acc[w * i + bs * bs + r];
      for (PetscInt c = 0; c < bs; c++) sum += PetscAbsReal(acc[w * i + r * bs + c]);
      s[i * bs + r] = sum;
    }
  PetscCall(VecRestoreArray(sums, &s));
  PetscCall(PetscFree(acc));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The block of bond k of owned particle i, times the filter's scale. */
/*@C
  PeriBondStiffness - the (2 dofs)^2 stiffness block of bond k of particle i times scale, and the
  bond's geometry. Not collective.
@*/
PetscErrorCode PeriBondStiffness(PeriSystem sys, PetscInt i, PetscInt k, PetscReal scale, PeriBondGeometry *g, PetscReal Ke[])
{
  const PetscInt nb = 2 * sys->model->dofs;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemBondGeometry(sys, i, k, g));
  sys->model->ops.bond_stiffness(sys->model, g, Ke);
  if (scale != 1)
    for (PetscInt a = 0; a < nb * nb; a++) Ke[a] *= scale;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The block of bond k under the filter: scaled, broken bonds by their share. */
static PetscErrorCode BondBlock(PeriSystem sys, const BondFilter *f, PetscInt i, PetscInt k, PeriBondGeometry *g, PetscReal Ke[])
{
  const PetscReal scale = PeriShortRangeFactor(f->sr, &sys->disc, i, k);

  PetscFunctionBeginUser;
  PetscCall(PeriBondStiffness(sys, i, k, sys->disc.bonds.live[k] ? scale : scale * f->broken_share, g, Ke));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Gathers owned row i in w: the blocks of its stored bonds and of the bonds other owned particles
 * store towards it. Blocks of rows owned by other ranks go to K through the stash. */
static PetscErrorCode GatherBondRow(PeriSystem sys, const BondFilter *f, const Incoming *in, PetscInt i, RowBuffer *w, Mat K)
{
  const PeriBonds *b  = &sys->disc.bonds;
  PeriModel        m  = sys->model;
  const PetscInt   bs = m->dofs, nb = 2 * bs, rstart = b->rstart, *G = sys->disc.particles.global;
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF];
  PeriBondGeometry g;

  PetscFunctionBeginUser;
  w->ncol    = 0;
  w->slot[i] = w->ncol++; /* the diagonal block is always there */
  w->col[0]  = i;
  for (PetscInt a = 0; a < bs * bs; a++) w->blocks[a] = 0;
  for (PetscInt k = b->offset[i - rstart]; k < b->offset[i - rstart + 1]; k++) {
    PetscInt j = b->j[k];
    /* a self-image bond moves both ends alike: its blocks cancel */
    if (!Kept(b, i, k, f) || j == i) continue;
    PetscCall(BondBlock(sys, f, i, k, &g, Ke));
    RowAdd(bs, i, &Ke[0], nb, w->slot, w->col, w->blocks, &w->ncol);
    RowAdd(bs, j, &Ke[bs], nb, w->slot, w->col, w->blocks, &w->ncol);
    if (j >= sys->disc.nowned) { /* row j is another rank's */
      PetscInt idx[2] = {G[i], G[j]};
      PetscCall(MatSetValuesBlocked(K, 1, &idx[1], 2, idx, &Ke[bs * nb], ADD_VALUES));
    }
  }
  for (PetscInt t = in->ptr[i - rstart]; t < in->ptr[i - rstart + 1]; t++) {
    PetscCall(BondBlock(sys, f, in->row[t], in->bond[t], &g, Ke));
    RowAdd(bs, i, &Ke[bs * nb + bs], nb, w->slot, w->col, w->blocks, &w->ncol);
    RowAdd(bs, in->row[t], &Ke[bs * nb], nb, w->slot, w->col, w->blocks, &w->ncol);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Inserts the gathered row i with one call, its columns in global numbering and sorted (the
 * insertion is then a merge), and clears the slots for the next row. */
static PetscErrorCode InsertRow(PetscInt bs, const PetscInt G[], PetscInt i, RowBuffer *w, Mat K)
{
  const PetscInt ncol = w->ncol;

  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < ncol; c++) {
    w->slot[w->col[c]] = -1;
    w->col[c]          = G[w->col[c]];
    w->perm[c]         = c;
  }
  PetscCall(PetscSortIntWithArray(ncol, w->col, w->perm));
  for (PetscInt c = 0; c < ncol; c++) {
    for (PetscInt a = 0; a < bs; a++)
      for (PetscInt e = 0; e < bs; e++) w->row[a * ncol * bs + c * bs + e] = w->blocks[w->perm[c] * bs * bs + a * bs + e];
  }
  PetscCall(MatSetValuesBlocked(K, 1, &G[i], ncol, w->col, w->row, ADD_VALUES));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Bond-based models: each owned block row gathered in full and inserted with one call. */
static PetscErrorCode AssembleBonds(PeriSystem sys, const BondFilter *f, Mat *K)
{
  const PeriBonds *b  = &sys->disc.bonds;
  const PetscInt   bs = sys->model->dofs;
  PetscInt         maxcol;
  Incoming         in;
  RowBuffer        w;

  PetscFunctionBeginUser;
  PetscCall(CreateBondStiffness(sys, f, K, &maxcol));
  PetscCall(IncomingBonds(b, f, &in));
  PetscCall(PetscMalloc1(sys->disc.particles.n, &w.slot));
  for (PetscInt i = 0; i < sys->disc.particles.n; i++) w.slot[i] = -1;
  PetscCall(PetscMalloc4(maxcol, &w.col, maxcol, &w.perm, maxcol * bs * bs, &w.blocks, maxcol * bs * bs, &w.row));
  for (PetscInt i = b->rstart; i < b->rend; i++) {
    PetscCall(GatherBondRow(sys, f, &in, i, &w, *K));
    PetscCall(InsertRow(bs, sys->disc.particles.global, i, &w, *K));
  }
  PetscCall(PetscFree4(w.col, w.perm, w.blocks, w.row));
  PetscCall(PetscFree(w.slot));
  PetscCall(PetscFree2(in.bond, in.row));
  PetscCall(PetscFree(in.ptr));
  PetscCall(MatAssemblyBegin(*K, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*K, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Inserts the state rows of the owned particles from row r (nstates each: the gradients G_qs of
 * StateFamilyBlock) and their moduli into d (the rows from row0); advances r. */
static PetscErrorCode StateRows(PeriSystem sys, Mat B, PetscScalar d[], PetscInt row0, PetscInt *r, PeriBondGeometry fam[], PetscInt cols[], PetscReal vals[])
{
  PeriModel        m  = sys->model;
  const PeriBonds *b  = &sys->disc.bonds;
  const PetscInt   bs = m->dofs, *G = sys->disc.particles.global;

  PetscFunctionBeginUser;
  for (PetscInt i = b->rstart; i < b->rend; i++) {
    PetscInt n;
    PetscCall(PeriSystemFamilyGeometry(sys, i, &n, fam));
    for (PetscInt t = 0; t <= n; t++)
      for (PetscInt c = 0; c < bs; c++) cols[t * bs + c] = G[t ? fam[t - 1].j : i] * bs + c;
    for (PetscInt s = 0; s < m->nstates; s++, (*r)++) {
      StateFamilyBlock(m, s, n, fam, vals, NULL);
      PetscCall(MatSetValues(B, 1, r, (n + 1) * bs, cols, vals, ADD_VALUES)); /* periodic images repeat a column */
      d[*r - row0] = n ? m->ops.state_modulus(m, i, s) : 0;
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The rows of a family model's measures (the interaction terms as linear maps of the DOFs):
 * nstates per owned particle, its states' gradients G_qs (StateFamilyBlock), and one per live bond
 * of an owned row, sqrt(k) n . (u_j - u_i) (the spring). K = B^T diag(A_qs, 1) B. */
static PetscErrorCode StateMeasures(PeriSystem sys, Mat *B, Vec *D)
{
  PeriModel         m  = sys->model;
  const PeriBonds  *b  = &sys->disc.bonds;
  const PetscInt    bs = m->dofs, nown = b->rend - b->rstart, nmax = PeriSystemMaxFamily(sys), *G = sys->disc.particles.global;
  PetscInt          nrow = nown * m->nstates, row0, *dnz, *onz, *cols, r = 0;
  PetscReal        *vals, *work, Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF];
  PeriBondGeometry *fam, g;
  PetscScalar      *d;

  PetscFunctionBeginUser;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) nrow += b->live[k] && b->j[k] != i;
  PetscCall(PetscMalloc2(nrow, &dnz, nrow, &onz));
  PetscCall(PetscMalloc4(nmax, &fam, (nmax + 1) * bs, &cols, (nmax + 1) * bs, &vals, (nmax + 1) * bs, &work));
  for (PetscInt i = b->rstart; i < b->rend; i++) { /* the state rows' columns, then the springs' */
    PetscInt n;
    PetscCall(PeriSystemFamilyGeometry(sys, i, &n, fam));
    dnz[r] = bs;
    for (PetscInt t = 0; t < n; t++) dnz[r] += fam[t].j < sys->disc.nowned ? bs : 0;
    onz[r] = (n + 1) * bs - dnz[r];
    for (PetscInt s = 1; s < m->nstates; s++, r++) {
      dnz[r + 1] = dnz[r];
      onz[r + 1] = onz[r];
    }
    r++;
  }
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++)
      if (b->live[k] && b->j[k] != i) {
        dnz[r] = bs * (1 + (b->j[k] < sys->disc.nowned));
        onz[r] = 2 * bs - dnz[r];
        r++;
      }
  PetscCall(MatCreateAIJ(sys->comm, nrow, nown * bs, PETSC_DETERMINE, sys->disc.N * bs, 0, dnz, 0, onz, B));
  PetscCall(MatSetBlockSizes(*B, 1, bs));
  PetscCall(MatCreateVecs(*B, NULL, D));
  PetscCall(MatGetOwnershipRange(*B, &row0, NULL));
  PetscCall(VecGetArray(*D, &d));
  r = row0;
  PetscCall(StateRows(sys, *B, d, row0, &r, fam, cols, vals));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscReal kb = 0;
      if (!b->live[k] || b->j[k] == i) continue;
      PetscCall(PeriSystemBondGeometry(sys, i, k, &g));
      m->ops.bond_stiffness(m, &g, Ke);
      for (PetscInt a = 0; a < bs; a++) kb += Ke[a * 2 * bs + a];
      for (PetscInt c = 0; c < bs; c++) {
        const PetscReal v = PetscSqrtReal(PetscMax(kb, 0)) * (c < m->dim ? g.xi[c] / g.length : 0);
        cols[c]           = G[i] * bs + c;
        cols[bs + c]      = G[g.j] * bs + c;
        vals[c]           = -v;
        vals[bs + c]      = v;
      }
      PetscCall(MatSetValues(*B, 1, &r, 2 * bs, cols, vals, ADD_VALUES));
      d[r++ - row0] = 1;
    }
  PetscCall(VecRestoreArray(*D, &d));
  PetscCall(MatAssemblyBegin(*B, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*B, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscFree4(fam, cols, vals, work));
  PetscCall(PetscFree2(dnz, onz));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* K of a family model with states (ops.bond_state) as the sparse product B^T D B of its measures
 * (StateMeasures): PETSc's sparse product finds the two-horizon pattern itself, where inserting
 * every family's dense block took 15 s for 3,200 particles (13 times the product's time). AIJ,
 * converted when the scene or -mat_type asks for another type. */
static PetscErrorCode AssembleStates(PeriSystem sys, Mat *K)
{
  Mat       B, DB;
  Vec       D;
  char      type[PERI_NAME_LEN] = MATAIJ;
  PetscBool set, aij;

  PetscFunctionBeginUser;
  PetscCall(StateMeasures(sys, &B, &D));
  PetscCall(MatDuplicate(B, MAT_COPY_VALUES, &DB));
  PetscCall(MatDiagonalScale(DB, D, NULL));
  PetscCall(MatTransposeMatMult(B, DB, MAT_INITIAL_MATRIX, PETSC_DEFAULT, K));
  PetscCall(MatDestroy(&B));
  PetscCall(MatDestroy(&DB));
  PetscCall(VecDestroy(&D));
  if (sys->stiffness.mat_type[0]) PetscCall(PetscStrncpy(type, sys->stiffness.mat_type, sizeof(type)));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-mat_type", type, sizeof(type), &set));
  PetscCall(PetscStrbeginswith(type, MATAIJ, &aij));
  if (!aij) PetscCall(MatConvert(*K, type, MAT_INPLACE_MATRIX, K));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAssembleStiffness - assembles K = sum over live bonds of the model's bond blocks. The type is
  sys->stiffness.mat_type (BAIJ when unset) unless -mat_type says otherwise (sbaij stores the upper triangle
  only). Collective.

  Each owned block row is gathered in full (its stored bonds and the bonds other owned particles
  store towards it) and inserted with one call: inserting bond by bond costs a search per entry.
  Only rows owned by other ranks receive bond blocks through the stash.
@*/
PetscErrorCode PeriAssembleStiffness(PeriSystem sys, Mat *K)
{
  const BondFilter all = {NULL, 0, &sys->disc};

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PERI_EVENT_Assembly, 0, 0, 0, 0));
  if (sys->model->ops.bond_state)
    PetscCall(AssembleStates(sys, K));
  else if (sys->model->ops.family_stiffness)
    PetscCall(AssembleFamilies(sys, K));
  else
    PetscCall(AssembleBonds(sys, &all, K));
  PetscCall(MatSetOption(*K, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(*K, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Assembly, 0, 0, 0, 0));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAssembleShortRange - assembles the blocks of the bonds of the short range sr, each times its
  factor (PeriShortRangeFactor), broken ones with broken_share of theirs (bond-based models), as
  PeriAssembleStiffness does K. Collective.
@*/
PetscErrorCode PeriAssembleShortRange(PeriSystem sys, const PeriShortRange *sr, PetscReal broken_share, Mat *P)
{
  const BondFilter shorter = {sr, broken_share, &sys->disc};

  PetscFunctionBeginUser;
  PetscCheck(!sys->model->ops.family_stiffness, sys->comm, PETSC_ERR_SUP, "a short-range stiffness needs a bond-based model");
  PetscCall(AssembleBonds(sys, &shorter, P));
  PetscCall(MatSetOption(*P, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(*P, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriRigidModes - the model's rigid-body modes as vectors (coordinates relative to the body's
  centre, so translations and rotations are nearly orthogonal), each scaled to unit norm; zero on
  fictitious layer particles, whose rows the static solve replaces. norm[k] (may be NULL) gets the
  norm that mode k had before scaling. Collective; modes[] must hold PERI_MAX_MODES vectors,
  created here.
@*/
PetscErrorCode PeriRigidModes(PeriSystem sys, PetscInt *nmodes, Vec modes[], PetscReal norm[])
{
  const PeriParticles *pt = &sys->disc.particles;
  PeriModel            m  = sys->model;
  PetscReal            centre[3], vals[PERI_MAX_MODES][PERI_MAX_DOF], X[3];
  PetscScalar         *a[PERI_MAX_MODES];
  PetscInt             nm = 0, rstart = sys->disc.bonds.rstart;

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) centre[d] = 0.5 * (pt->lower[d] + pt->upper[d]);
  X[0] = X[1] = X[2] = 0;
  nm                 = m->ops.rigid_modes(m, X, vals);
  for (PetscInt k = 0; k < nm; k++) {
    PetscCall(PeriSystemCreateVec(sys, &modes[k]));
    PetscCall(VecGetArray(modes[k], &a[k]));
  }
  for (PetscInt i = rstart; i < sys->disc.bonds.rend; i++) {
    for (PetscInt d = 0; d < 3; d++) X[d] = pt->x[3 * i + d] - centre[d];
    m->ops.rigid_modes(m, X, vals);
    for (PetscInt k = 0; k < nm; k++)
      for (PetscInt c = 0; c < m->dofs; c++) a[k][(i - rstart) * m->dofs + c] = m->inactive[c] || PeriParticleIsFictitious(pt, i) ? 0 : vals[k][c];
  }
  for (PetscInt k = 0; k < nm; k++) {
    PetscCall(VecRestoreArray(modes[k], &a[k]));
    PetscCall(VecNormalize(modes[k], norm ? &norm[k] : NULL));
  }
  *nmodes = nm;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSetNearNullSpace - gives A the orthonormalized rigid-body modes, for algebraic multigrid;
  with rows (an IS of the global DOFs that are A's rows), the modes restricted to them.
  Collective.
@*/
PetscErrorCode PeriSetNearNullSpace(PeriSystem sys, Mat A, IS rows)
{
  Vec          modes[PERI_MAX_MODES], kept[PERI_MAX_MODES];
  PetscInt     nm, nk = 0;
  MatNullSpace nsp;

  PetscFunctionBeginUser;
  PetscCall(PeriRigidModes(sys, &nm, modes, NULL));
  for (PetscInt k = 0; k < nm; k++) {
    PetscReal before, after;
    if (rows) { /* the modes on the rows of A only (the free DOFs of the modal analysis) */
      Vec sub;
      PetscCall(VecGetSubVector(modes[k], rows, &sub));
      PetscCall(VecDuplicate(sub, &kept[nk]));
      PetscCall(VecCopy(sub, kept[nk]));
      PetscCall(VecRestoreSubVector(modes[k], rows, &sub));
    } else {
      PetscCall(VecDuplicate(modes[k], &kept[nk]));
      PetscCall(VecCopy(modes[k], kept[nk]));
    }
    /* Gram-Schmidt: MatNullSpaceCreate wants an orthonormal set; a restricted mode that became
       dependent on the others is dropped */
    PetscCall(VecNorm(kept[nk], NORM_2, &before));
    for (PetscInt l = 0; l < nk; l++) {
      PetscScalar dot;
      PetscCall(VecDot(kept[nk], kept[l], &dot));
      PetscCall(VecAXPY(kept[nk], -dot, kept[l]));
    }
    PetscCall(VecNormalize(kept[nk], &after));
    if (!rows || after > 1e-8 * before)
      nk++;
    else
      PetscCall(VecDestroy(&kept[nk]));
  }
  PetscCall(MatNullSpaceCreate(sys->comm, PETSC_FALSE, nk, kept, &nsp));
  PetscCall(MatSetNearNullSpace(A, nsp));
  PetscCall(MatNullSpaceDestroy(&nsp));
  for (PetscInt k = 0; k < nk; k++) PetscCall(VecDestroy(&kept[k]));
  for (PetscInt k = 0; k < nm; k++) PetscCall(VecDestroy(&modes[k]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bytes PETSc holds for an assembled matrix, all ranks. Collective. */
PetscErrorCode PeriMatrixMB(Mat K, PetscReal *mb)
{
  MatInfo   info;
  PetscBool blocked;
  PetscInt  bs;

  PetscFunctionBeginUser;
  PetscCall(MatGetInfo(K, MAT_GLOBAL_SUM, &info));
  PetscCall(MatGetBlockSize(K, &bs));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)K, &blocked, MATSEQBAIJ, MATMPIBAIJ, MATSEQSBAIJ, MATMPISBAIJ, ""));
  /* PETSc 3.18 leaves info.memory 0 for AIJ: the values and the column indices (one per block) */
  *mb = (info.memory > 0 ? info.memory : info.nz_allocated * (sizeof(PetscScalar) + (PetscReal)sizeof(PetscInt) / (blocked ? bs * bs : 1))) / 1048576.0;
  PetscFunctionReturn(PETSC_SUCCESS);
}
