/* Assembly of the linearized stiffness K from the model's bond blocks into a block matrix (BAIJ by
 * default, block size = DOFs per particle) with exact preallocation, and the rigid-body modes
 * that serve as AMG's near-null space and as the check for unconstrained motion. */
#include "perilin/private/system.h"

/* Distinct partners of owned particle i among its stored bonds (periodic images repeat them). */
static PetscInt RowPartners(const PeriBonds *b, PetscInt i, PetscInt buf[])
{
  PetscInt n = 0, m = 0;
  for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++)
    if (b->live[k] && b->j[k] != i) buf[n++] = b->j[k];
  PetscSortInt(n, buf);
  for (PetscInt k = 0; k < n; k++)
    if (!m || buf[k] != buf[m - 1]) buf[m++] = buf[k];
  return m;
}

/* Block counts per owned row: diagonal/off-diagonal part, and their upper-triangular share for
 * SBAIJ. Row i sees its stored partners (j > i, upper) and the particles that store a bond to i
 * (lower), which may live on other ranks: counts for those are summed with MPI_Reduce_scatter. */
static PetscErrorCode Preallocation(PeriSystem sys, PetscInt **dnz, PetscInt **onz, PetscInt **dnzu, PetscInt **onzu)
{
  const PeriBonds *b = &sys->bonds;
  const PetscInt   n = sys->particles.n, nloc = b->rend - b->rstart;
  PetscInt        *cnt, *buf, maxrow = 0;
  PetscMPIInt     *recv;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(2 * n, &cnt)); /* [diag | offdiag] counts of every global row */
  PetscCall(PetscMalloc4(nloc, dnz, nloc, onz, nloc, dnzu, nloc, onzu));
  for (PetscInt i = b->rstart; i < b->rend; i++) maxrow = PetscMax(maxrow, b->offset[i - b->rstart + 1] - b->offset[i - b->rstart]);
  PetscCall(PetscMalloc1(maxrow + 1, &buf));
  for (PetscInt i = b->rstart; i < b->rend; i++) {
    PetscInt m = RowPartners(b, i, buf), du = 1, ou = 0;
    for (PetscInt k = 0; k < m; k++) {
      PetscInt  j    = buf[k];
      PetscBool same = (PetscBool)(sys->owner[j] == sys->rank);
      if (same)
        du++;
      else
        ou++;
      cnt[(same ? 0 : n) + j]++; /* row j, column i */
    }
    (*dnzu)[i - b->rstart] = du;
    (*onzu)[i - b->rstart] = ou;
    cnt[i] += du;
    cnt[n + i] += ou;
  }
  PetscCall(PetscFree(buf));
  /* owners hold contiguous ranges, so the rows in global order are already grouped by rank */
  PetscCall(PetscCalloc1(sys->size, &recv));
  for (PetscInt i = 0; i < n; i++) recv[sys->owner[i]] += 2;
  {
    PetscInt *mine, *sendbuf;
    PetscCall(PetscMalloc2(2 * nloc, &mine, 2 * n, &sendbuf));
    for (PetscInt i = 0; i < n; i++) {
      sendbuf[2 * i]     = cnt[i];
      sendbuf[2 * i + 1] = cnt[n + i];
    }
    PetscCallMPI(MPI_Reduce_scatter(sendbuf, mine, recv, MPIU_INT, MPI_SUM, sys->comm));
    for (PetscInt i = 0; i < nloc; i++) {
      (*dnz)[i] = mine[2 * i];
      (*onz)[i] = mine[2 * i + 1];
    }
    PetscCall(PetscFree2(mine, sendbuf));
  }
  PetscCall(PetscFree(recv));
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

/* Inserts every owned particle's family stiffness (state-based models) into K. */
static PetscErrorCode InsertFamilies(PeriSystem sys, Mat K)
{
  PeriModel         m  = sys->model;
  const PetscInt    bs = m->dofs, nmax = PeriSystemMaxFamily(sys);
  PeriBondGeometry *fam;
  PetscReal        *Ke;
  PetscInt         *idx;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc3(nmax, &fam, PetscSqr((nmax + 1) * bs), &Ke, nmax + 1, &idx));
  for (PetscInt i = sys->family.rstart; i < sys->family.rend; i++) {
    PetscInt n;
    PetscCall(PeriSystemFamilyGeometry(sys, i, &n, fam));
    PetscCall(m->ops.family_stiffness(m, n, fam, Ke));
    idx[0] = i;
    for (PetscInt t = 0; t < n; t++) idx[t + 1] = fam[t].j;
    PetscCall(MatSetValuesBlocked(K, n + 1, idx, n + 1, idx, Ke, ADD_VALUES));
  }
  PetscCall(PetscFree3(fam, Ke, idx));
  PetscCall(MatAssemblyBegin(K, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(K, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* State-based models: particle i's energy couples every pair of its family, so K reaches 2 delta.
 * The pattern is exact from a first pass into PETSc's preallocator. */
static PetscErrorCode AssembleFamilies(PeriSystem sys, Mat *K)
{
  const PetscInt bs = sys->model->dofs, nloc = sys->bonds.rend - sys->bonds.rstart;
  Mat            pre;

  PetscFunctionBeginUser;
  PetscCall(MatCreate(sys->comm, &pre));
  PetscCall(MatSetSizes(pre, nloc * bs, nloc * bs, sys->particles.n * bs, sys->particles.n * bs));
  PetscCall(MatSetBlockSize(pre, bs));
  PetscCall(MatSetType(pre, MATPREALLOCATOR));
  PetscCall(MatSetUp(pre));
  PetscCall(InsertFamilies(sys, pre));
  PetscCall(MatCreate(sys->comm, K));
  PetscCall(MatSetSizes(*K, nloc * bs, nloc * bs, sys->particles.n * bs, sys->particles.n * bs));
  PetscCall(MatSetBlockSize(*K, bs));
  PetscCall(MatSetType(*K, sys->mat_type[0] ? sys->mat_type : MATBAIJ));
  PetscCall(MatSetFromOptions(*K));
  PetscCall(MatPreallocatorPreallocate(pre, PETSC_TRUE, *K));
  PetscCall(MatDestroy(&pre));
  PetscCall(MatSetOption(*K, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(InsertFamilies(sys, *K));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAssembleStiffness - assembles K = sum over live bonds of the model's bond blocks. The type is
  sys->mat_type (BAIJ when unset) unless -mat_type says otherwise (sbaij stores the upper triangle
  only). Collective.

  Each owned block row is gathered in full (its stored bonds and the bonds other owned particles
  store towards it) and inserted with one call: inserting bond by bond costs a search per entry.
  Only rows owned by other ranks receive bond blocks through the stash.
@*/
PetscErrorCode PeriAssembleStiffness(PeriSystem sys, Mat *K)
{
  const PeriBonds *b  = &sys->bonds;
  PeriModel        m  = sys->model;
  const PetscInt   bs = m->dofs, nb = 2 * bs, nloc = b->rend - b->rstart, rstart = b->rstart;
  PetscInt        *dnz, *onz, *dnzu, *onzu, *tptr, *tbond, *trow, *slot, *col, *perm, maxcol = 1;
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF], *blocks, *row;
  PetscBool        sym;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PERI_EVENT_Assembly, 0, 0, 0, 0));
  if (m->ops.family_stiffness) {
    PetscCall(AssembleFamilies(sys, K));
    PetscCall(MatSetOption(*K, MAT_SYMMETRIC, PETSC_TRUE));
    PetscCall(MatSetOption(*K, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
    PetscCall(PetscLogEventEnd(PERI_EVENT_Assembly, 0, 0, 0, 0));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(Preallocation(sys, &dnz, &onz, &dnzu, &onzu));
  for (PetscInt i = 0; i < nloc; i++) maxcol = PetscMax(maxcol, dnz[i] + onz[i]);
  PetscCall(MatCreate(sys->comm, K));
  PetscCall(MatSetSizes(*K, nloc * bs, nloc * bs, sys->particles.n * bs, sys->particles.n * bs));
  PetscCall(MatSetBlockSize(*K, bs));
  PetscCall(MatSetType(*K, sys->mat_type[0] ? sys->mat_type : MATBAIJ));
  PetscCall(MatSetFromOptions(*K));
  PetscCall(MatXAIJSetPreallocation(*K, bs, dnz, onz, dnzu, onzu));
  PetscCall(PetscFree4(dnz, onz, dnzu, onzu));
  PetscCall(MatSetOption(*K, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)*K, &sym, MATSBAIJ, MATSEQSBAIJ, MATMPISBAIJ, ""));
  if (sym) PetscCall(MatSetOption(*K, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE));

  /* incoming bonds: stored at owned row r towards owned particle j > r, listed under j */
  PetscCall(PetscCalloc1(nloc + 1, &tptr));
  for (PetscInt r = rstart; r < b->rend; r++)
    for (PetscInt k = b->offset[r - rstart]; k < b->offset[r - rstart + 1]; k++) {
      PetscInt j = b->j[k];
      if (b->live[k] && j != r && j >= rstart && j < b->rend) tptr[j - rstart + 1]++;
    }
  for (PetscInt i = 0; i < nloc; i++) tptr[i + 1] += tptr[i];
  PetscCall(PetscMalloc2(tptr[nloc], &tbond, tptr[nloc], &trow));
  {
    PetscInt *fill;
    PetscCall(PetscMalloc1(nloc, &fill));
    PetscCall(PetscArraycpy(fill, tptr, nloc));
    for (PetscInt r = rstart; r < b->rend; r++)
      for (PetscInt k = b->offset[r - rstart]; k < b->offset[r - rstart + 1]; k++) {
        PetscInt j = b->j[k];
        if (!b->live[k] || j == r || j < rstart || j >= b->rend) continue;
        tbond[fill[j - rstart]]  = k;
        trow[fill[j - rstart]++] = r;
      }
    PetscCall(PetscFree(fill));
  }

  PetscCall(PetscMalloc1(sys->particles.n, &slot));
  for (PetscInt i = 0; i < sys->particles.n; i++) slot[i] = -1;
  PetscCall(PetscMalloc4(maxcol, &col, maxcol, &perm, maxcol * bs * bs, &blocks, maxcol * bs * bs, &row));
  for (PetscInt i = rstart; i < b->rend; i++) {
    PetscInt         ncol = 0;
    PeriBondGeometry g;
    slot[i] = ncol++; /* the diagonal block is always there */
    col[0]  = i;
    for (PetscInt a = 0; a < bs * bs; a++) blocks[a] = 0;
    for (PetscInt k = b->offset[i - rstart]; k < b->offset[i - rstart + 1]; k++) {
      PetscInt j = b->j[k];
      /* a self-image bond moves both ends alike: its blocks cancel */
      if (!b->live[k] || j == i) continue;
      PetscCall(PeriSystemBondGeometry(sys, i, k, &g));
      m->ops.bond_stiffness(m, &g, Ke);
      RowAdd(bs, i, &Ke[0], nb, slot, col, blocks, &ncol);
      RowAdd(bs, j, &Ke[bs], nb, slot, col, blocks, &ncol);
      if (sys->owner[j] != sys->rank) {
        PetscInt idx[2] = {i, j};
        PetscCall(MatSetValuesBlocked(*K, 1, &j, 2, idx, &Ke[bs * nb], ADD_VALUES));
      }
    }
    for (PetscInt t = tptr[i - rstart]; t < tptr[i - rstart + 1]; t++) {
      PetscCall(PeriSystemBondGeometry(sys, trow[t], tbond[t], &g));
      m->ops.bond_stiffness(m, &g, Ke);
      RowAdd(bs, i, &Ke[bs * nb + bs], nb, slot, col, blocks, &ncol);
      RowAdd(bs, trow[t], &Ke[bs * nb], nb, slot, col, blocks, &ncol);
    }
    /* sorted columns make the insertion a merge */
    for (PetscInt c = 0; c < ncol; c++) perm[c] = c;
    PetscCall(PetscSortIntWithArray(ncol, col, perm));
    for (PetscInt c = 0; c < ncol; c++) {
      slot[col[c]] = -1;
      for (PetscInt a = 0; a < bs; a++)
        for (PetscInt e = 0; e < bs; e++) row[a * ncol * bs + c * bs + e] = blocks[perm[c] * bs * bs + a * bs + e];
    }
    PetscCall(MatSetValuesBlocked(*K, 1, &i, ncol, col, row, ADD_VALUES));
  }
  PetscCall(PetscFree4(col, perm, blocks, row));
  PetscCall(PetscFree(slot));
  PetscCall(PetscFree2(tbond, trow));
  PetscCall(PetscFree(tptr));
  PetscCall(MatAssemblyBegin(*K, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*K, MAT_FINAL_ASSEMBLY));
  PetscCall(MatSetOption(*K, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(*K, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Assembly, 0, 0, 0, 0));
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
  const PeriParticles *pt = &sys->particles;
  PeriModel            m  = sys->model;
  PetscReal            centre[3], vals[PERI_MAX_MODES][PERI_MAX_DOF], X[3];
  PetscScalar         *a[PERI_MAX_MODES];
  PetscInt             nm = 0, rstart = sys->bonds.rstart;

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) centre[d] = 0.5 * (pt->lower[d] + pt->upper[d]);
  X[0] = X[1] = X[2] = 0;
  nm                 = m->ops.rigid_modes(m, X, vals);
  for (PetscInt k = 0; k < nm; k++) {
    PetscCall(PeriSystemCreateVec(sys, &modes[k]));
    PetscCall(VecGetArray(modes[k], &a[k]));
  }
  for (PetscInt i = rstart; i < sys->bonds.rend; i++) {
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
  PeriSetNearNullSpace - gives A the orthonormalized rigid-body modes, for algebraic multigrid.
  Collective.
@*/
PetscErrorCode PeriSetNearNullSpace(PeriSystem sys, Mat A)
{
  Vec          modes[PERI_MAX_MODES];
  PetscInt     nm;
  MatNullSpace nsp;

  PetscFunctionBeginUser;
  PetscCall(PeriRigidModes(sys, &nm, modes, NULL));
  /* Gram-Schmidt: MatNullSpaceCreate wants an orthonormal set */
  for (PetscInt k = 0; k < nm; k++) {
    for (PetscInt l = 0; l < k; l++) {
      PetscScalar dot;
      PetscCall(VecDot(modes[k], modes[l], &dot));
      PetscCall(VecAXPY(modes[k], -dot, modes[l]));
    }
    PetscCall(VecNormalize(modes[k], NULL));
  }
  PetscCall(MatNullSpaceCreate(sys->comm, PETSC_FALSE, nm, modes, &nsp));
  PetscCall(MatSetNearNullSpace(A, nsp));
  PetscCall(MatNullSpaceDestroy(&nsp));
  for (PetscInt k = 0; k < nm; k++) PetscCall(VecDestroy(&modes[k]));
  PetscFunctionReturn(PETSC_SUCCESS);
}
