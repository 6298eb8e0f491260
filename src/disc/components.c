/* Connected pieces of a distributed body (issue 17, docs/distributed.md): the fragments of a
 * broken body without any array of the whole body. A rank joins the links it stores (a union-find
 * over its owned particles and ghosts), then the ranks agree on each piece's smallest global
 * index by exchanging labels between ghosts and their owners (the halo's PetscSF) and with the
 * owners of the labels (hooking and pointer jumping, so long pieces take few rounds); per-piece
 * totals travel to the owner of the piece's label and back (a PetscSF built from the labels). */
#include "perilin/private/disc.h"

/* The global index of local particle l (owned, then ghosts). */
static inline PetscInt Global(const PeriHalo *h, PetscInt l)
{
  return l < h->nowned ? h->rstart + l : h->global[l - h->nowned];
}

static PetscInt Root(PetscInt parent[], PetscInt l)
{
  while (parent[l] != l) {
    parent[l] = parent[parent[l]];
    l         = parent[l];
  }
  return l;
}

/* root[l] = the particle of smallest global index in l's piece through this rank's links alone. */
static PetscErrorCode LocalForest(const PeriHalo *h, const PetscInt offset[], const PetscInt j[], const unsigned char live[], PetscInt root[])
{
  const PetscInt n = h->nowned + h->nghost;

  PetscFunctionBeginUser;
  for (PetscInt l = 0; l < n; l++) root[l] = l;
  for (PetscInt i = 0; i < h->nowned; i++)
    for (PetscInt k = offset[i]; k < offset[i + 1]; k++) {
      PetscInt a, b;
      PetscCheck(j[k] >= 0 && j[k] < n, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "link %" PetscInt_FMT " of particle %" PetscInt_FMT ": local index %" PetscInt_FMT " outside 0..%" PetscInt_FMT, k, i, j[k], n - 1);
      if (live && !live[k]) continue;
      a = Root(root, i);
      b = Root(root, j[k]);
      if (a == b) continue;
      if (Global(h, a) < Global(h, b))
        root[b] = a;
      else
        root[a] = b;
    }
  for (PetscInt l = 0; l < n; l++) root[l] = Root(root, l);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every local piece takes the smallest label among its particles. */
static void Spread(PetscInt n, const PetscInt root[], PetscInt label[])
{
  for (PetscInt l = 0; l < n; l++) label[root[l]] = PetscMin(label[root[l]], label[l]);
  for (PetscInt l = 0; l < n; l++) label[l] = label[root[l]];
}

/* An SF from nleaves values to the owned particles of the global indices target[] (on their owners). */
static PetscErrorCode TargetSF(MPI_Comm comm, PetscLayout layout, PetscInt nleaves, const PetscInt target[], PetscSF *sf)
{
  PetscFunctionBeginUser;
  PetscCall(PetscSFCreate(comm, sf));
  PetscCall(PetscSFSetGraphLayout(*sf, layout, nleaves, NULL, PETSC_COPY_VALUES, target));
  PetscCall(PetscSFSetUp(*sf));
  PetscFunctionReturn(PETSC_SUCCESS);
}

typedef struct {
  MPI_Comm    comm;
  PetscLayout layout;                   /* the owned ranges */
  PetscInt   *before, *buf, *tgt, *idx; /* n each */
} Work;

/* Hooking: a local piece whose label dropped to m sends m to the particles its members' previous
 * labels name (the roots of the trees it joins), and the ghosts send theirs to their owners. */
static PetscErrorCode Hook(Work *w, const PeriHalo *h, PetscInt label[])
{
  const PetscInt n  = h->nowned + h->nghost;
  PetscInt       nl = 0;
  PetscSF        sf;

  PetscFunctionBeginUser;
  for (PetscInt l = 0; l < n; l++)
    if (label[l] < w->before[l]) {
      w->tgt[nl]   = w->before[l];
      w->buf[nl++] = label[l];
    }
  PetscCall(TargetSF(w->comm, w->layout, nl, w->tgt, &sf));
  PetscCall(PetscSFReduceBegin(sf, MPIU_INT, w->buf, label, MPI_MIN));
  PetscCall(PetscSFReduceEnd(sf, MPIU_INT, w->buf, label, MPI_MIN));
  PetscCall(PetscSFDestroy(&sf));
  PetscCall(PetscSFReduceBegin(h->sf, MPIU_INT, label + h->nowned, label, MPI_MIN));
  PetscCall(PetscSFReduceEnd(h->sf, MPIU_INT, label + h->nowned, label, MPI_MIN));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Shortcutting: every owned particle takes the label of the particle its label names (pointer
 * jumping: a chain of labels halves each round). */
static PetscErrorCode Shortcut(Work *w, const PeriHalo *h, PetscInt label[])
{
  PetscInt nl = 0;
  PetscSF  sf;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < h->nowned; i++)
    if (label[i] != h->rstart + i) {
      w->idx[nl]   = i;
      w->tgt[nl++] = label[i];
    }
  PetscCall(TargetSF(w->comm, w->layout, nl, w->tgt, &sf));
  PetscCall(PetscSFBcastBegin(sf, MPIU_INT, label, w->buf, MPI_REPLACE));
  PetscCall(PetscSFBcastEnd(sf, MPIU_INT, label, w->buf, MPI_REPLACE));
  PetscCall(PetscSFDestroy(&sf));
  for (PetscInt s = 0; s < nl; s++) label[w->idx[s]] = PetscMin(label[w->idx[s]], w->buf[s]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One round of hooking and shortcutting (Shiloach and Vishkin's scheme, with the rank's local
 * pieces as its vertices); the ghosts then take their owners' labels (a minimum: a ghost may hold
 * a smaller label than its owner, learnt on this rank, which the next round delivers). A label is
 * always a global index in its particle's piece and only decreases, so a round that changes none
 * on any rank is the fixed point, where every piece carries its smallest index. */
static PetscErrorCode Round(Work *w, const PeriHalo *h, const PetscInt root[], PetscInt label[])
{
  const PetscInt n = h->nowned + h->nghost;

  PetscFunctionBeginUser;
  Spread(n, root, label);
  PetscCall(Hook(w, h, label));
  PetscCall(Shortcut(w, h, label));
  Spread(n, root, label);
  PetscCall(PetscSFBcastBegin(h->sf, MPIU_INT, label, label + h->nowned, MPI_MIN));
  PetscCall(PetscSFBcastEnd(h->sf, MPIU_INT, label, label + h->nowned, MPI_MIN));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriComponentsLabel - the connected pieces of a distributed body through its live links.

  Input: h, the rank's local view (owned particles 0..nowned-1, then the ghosts); a CSR over the
  owned particles: row i holds links offset[i]..offset[i+1]-1 to the local particles j[k]
  (owned or ghost); live[k] (NULL: every link is live). A pair may be stored once, on either
  rank, or twice.
  Output: label[l] for every local particle (owned and ghosts) = the smallest global index of its
  piece; *rounds (may be NULL) = the exchange rounds it took.

  Rounds: each round does what plain label propagation does (the smallest label crosses at least
  one rank boundary: ghosts to owners, owners to ghosts) and, in addition, hooks and shortcuts
  (Shiloach and Vishkin): a local piece sends its new label to the particles its old labels name
  and every owned particle takes the label of the particle its label names. Labels only decrease,
  so the rounds are never more than propagation's, which is one per rank boundary crossed on the
  way from a piece's smallest particle to its farthest one, plus one round to confirm. The
  shortcuts make long chains halve instead: a snake through 16, 32, 64, 128 columns with the ranks
  as horizontal slabs (crossing every slab boundary once per column) took 7, 7, 9, 10 rounds on 4
  ranks, against 35 for 16 columns by propagation alone; compact pieces under a block partition
  take 2 or 3 (tests/unit/test_components.c). A round costs two exchanges of ghost labels, two
  PetscSFs built from labels (each a sparse exchange with the ranks owning them) and an all-reduce
  of one flag.
  Collective; no array of the whole body.
@*/
PetscErrorCode PeriComponentsLabel(MPI_Comm comm, const PeriHalo *h, const PetscInt offset[], const PetscInt j[], const unsigned char live[], PetscInt label[], PetscInt *rounds)
{
  const PetscInt n = h->nowned + h->nghost;
  PetscInt      *root, count = 0;
  PetscMPIInt    changed = 1;
  Work           w       = {comm, NULL, NULL, NULL, NULL, NULL};

  PetscFunctionBeginUser;
  PetscCall(PetscLayoutCreateFromSizes(comm, h->nowned, PETSC_DECIDE, 1, &w.layout));
  PetscCall(PetscMalloc5(n, &root, n, &w.before, n, &w.buf, n, &w.tgt, n, &w.idx));
  PetscCall(LocalForest(h, offset, j, live, root));
  for (PetscInt l = 0; l < n; l++) label[l] = Global(h, root[l]);
  while (changed) {
    PetscCall(PetscArraycpy(w.before, label, n));
    PetscCall(Round(&w, h, root, label));
    changed = 0;
    for (PetscInt l = 0; l < n && !changed; l++) changed = label[l] != w.before[l];
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &changed, 1, MPI_INT, MPI_LOR, comm));
    count++;
  }
  if (rounds) *rounds = count;
  PetscCall(PetscFree5(root, w.before, w.buf, w.tgt, w.idx));
  PetscCall(PetscLayoutDestroy(&w.layout));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The starting value of an accumulation under op. */
static PetscErrorCode Identity(MPI_Op op, PetscInt *e)
{
  PetscFunctionBeginUser;
  if (op == MPI_SUM)
    *e = 0;
  else if (op == MPI_MAX)
    *e = PETSC_MIN_INT;
  else if (op == MPI_MIN)
    *e = PETSC_MAX_INT;
  else
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "per-piece reductions take MPI_SUM, MPI_MAX or MPI_MIN");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* leaf[] (one per owned particle) reduced over each piece into acc[] at the owner of the piece's
 * label (acc of the other roots keeps the identity), then the totals back into leaf[]. */
static PetscErrorCode ReducePieces(PetscSF sf, PetscInt nowned, MPI_Op op, PetscInt leaf[], PetscInt acc[])
{
  PetscInt e;

  PetscFunctionBeginUser;
  PetscCall(Identity(op, &e));
  for (PetscInt i = 0; i < nowned; i++) acc[i] = e;
  PetscCall(PetscSFReduceBegin(sf, MPIU_INT, leaf, acc, op));
  PetscCall(PetscSFReduceEnd(sf, MPIU_INT, leaf, acc, op));
  PetscCall(PetscSFBcastBegin(sf, MPIU_INT, acc, leaf, MPI_REPLACE));
  PetscCall(PetscSFBcastEnd(sf, MPIU_INT, acc, leaf, MPI_REPLACE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The number of pieces and the largest one (ties: the smallest label); size[i] is piece i's size
 * where owned particle i is its piece's smallest (label[i] == its global index). */
static PetscErrorCode Largest(MPI_Comm comm, const PeriHalo *h, const PetscInt label[], const PetscInt size[], PetscInt *npieces, PetscInt *largest)
{
  PetscInt count = 0, big = 0, mine = PETSC_MAX_INT;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < h->nowned; i++) /* ascending labels: the first of equal sizes is the smallest */
    if (label[i] == h->rstart + i) {
      count++;
      if (size[i] > big) {
        big  = size[i];
        mine = label[i];
      }
    }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPIU_INT, MPI_SUM, comm));
  {
    PetscInt most = big;
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &most, 1, MPIU_INT, MPI_MAX, comm));
    if (big < most) mine = PETSC_MAX_INT;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &mine, 1, MPIU_INT, MPI_MIN, comm));
  if (npieces) *npieces = count;
  if (largest) *largest = count ? mine : -1;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriComponentsReduce - per-piece totals without arrays of the whole body.

  Input: h and label[] of PeriComponentsLabel (only the owned labels are read); values, nv
  integers per owned particle (row i = values[i*nv .. i*nv+nv-1]), and op[c] (MPI_SUM, MPI_MAX or
  MPI_MIN) for column c (e.g. a column of ones with MPI_SUM gives each piece's size, flags with
  MPI_MAX whether any member has it).
  Output: each owned particle's row replaced by its piece's totals; *npieces the number of pieces
  of the body, *largest the label of the piece with the most particles (ties: the smallest
  label; -1 for an empty body). Either may be NULL.

  Each piece's values meet at the owner of its label and return (a PetscSF from every owned
  particle to the owned particle its label names): two neighbour exchanges per column and one
  more for the sizes, plus three all-reduces of one integer. Collective.
@*/
PetscErrorCode PeriComponentsReduce(MPI_Comm comm, const PeriHalo *h, const PetscInt label[], PetscInt nv, const MPI_Op op[], PetscInt values[], PetscInt *npieces, PetscInt *largest)
{
  PetscLayout layout;
  PetscSF     sf;
  PetscInt   *leaf, *acc;

  PetscFunctionBeginUser;
  PetscCall(PetscLayoutCreateFromSizes(comm, h->nowned, PETSC_DECIDE, 1, &layout));
  PetscCall(TargetSF(comm, layout, h->nowned, label, &sf));
  PetscCall(PetscMalloc2(h->nowned, &leaf, h->nowned, &acc));
  for (PetscInt c = 0; c < nv; c++) {
    for (PetscInt i = 0; i < h->nowned; i++) leaf[i] = values[i * nv + c];
    PetscCall(ReducePieces(sf, h->nowned, op[c], leaf, acc));
    for (PetscInt i = 0; i < h->nowned; i++) values[i * nv + c] = leaf[i];
  }
  for (PetscInt i = 0; i < h->nowned; i++) leaf[i] = 1;
  PetscCall(ReducePieces(sf, h->nowned, MPI_SUM, leaf, acc));
  PetscCall(Largest(comm, h, label, acc, npieces, largest));
  PetscCall(PetscFree2(leaf, acc));
  PetscCall(PetscSFDestroy(&sf));
  PetscCall(PetscLayoutDestroy(&layout));
  PetscFunctionReturn(PETSC_SUCCESS);
}
