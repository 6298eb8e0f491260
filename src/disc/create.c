/* Creating the body where it is owned (issue 17, docs/distributed.md): no rank ever holds the whole
 * body, except rank 0 while Gmsh reads a mesh. Each rank first gets a block of the body, rank r
 * the contiguous particles floor(r N / P) .. floor((r + 1) N / P) - 1 of the order of
 * PeriParticlesCreateFromScene:
 *   grid            each rank generates its block of cells (x fastest);
 *   particles.file  rank 0 reads the file twice: once to check every line and count the
 *                   particles (with the messages of the whole-body read), then to deal them out
 *                   in chunks of at most -peri_read_chunk particles (default 65536: 2.6 MB of
 *                   positions, volumes and lines) to the ranks in turn;
 *   particles.mesh  Gmsh runs on rank 0 (it is serial), which holds the mesh and its particles
 *                   while reading, then deals them out as for a file; the mesh groups (positions:
 *                   O(group size)) are broadcast.
 * The box and the mean spacing of read particles are rank 0's, summed in the file's order, so
 * they round as the whole-body read does. Then the partition (PeriPartitionBlocks) names each
 * particle's rank and PeriParticlesMigrate moves it there, by sender and then in the sender's
 * order: rank r's particles, numbered from range[r] in arrival order, are exactly those the
 * whole-body path (PeriPartition, PeriParticlesPermute) gives it, in its order. */
#include "perilin/private/disc.h"

static PetscInt BlockStart(PetscInt N, PetscMPIInt size, PetscMPIInt r)
{
  return (PetscInt)((PetscInt64)N * r / size);
}

typedef struct {
  PetscErrorCode code;
  char           msg[4096];
} RootError;

/* Keeps the first error's message for OnRoot. */
static PetscErrorCode CaptureFirst(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *ctx)
{
  RootError *e = (RootError *)ctx;

  (void)comm, (void)line, (void)fun, (void)file;
  if (p == PETSC_ERROR_INITIAL && !e->msg[0]) (void)PetscSNPrintf(e->msg, sizeof(e->msg), "%s", mess ? mess : "error");
  return n;
}

/* Runs fn(ctx) on rank 0 alone; its failure becomes the same error (code and message) on every
 * rank, so that no rank waits in a collective call for a rank 0 that gave up. Collective. */
static PetscErrorCode OnRoot(MPI_Comm comm, PetscErrorCode (*fn)(void *), void *ctx)
{
  RootError   e = {PETSC_SUCCESS, ""};
  PetscMPIInt rank;
  int         code;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    PetscCall(PetscPushErrorHandler(CaptureFirst, &e));
    e.code = fn(ctx);
    PetscCall(PetscPopErrorHandler());
  }
  code = (int)e.code;
  PetscCallMPI(MPI_Bcast(&code, 1, MPI_INT, 0, comm));
  if (code) PetscCallMPI(MPI_Bcast(e.msg, (PetscMPIInt)sizeof(e.msg), MPI_CHAR, 0, comm));
  PetscCheck(!code, PETSC_COMM_SELF, (PetscErrorCode)code, "%s", e.msg);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rank 0 deals the body's particles, in order, to the ranks' blocks: its own block straight into
 * p, the others' in chunks of at most chunk particles (a chunk never spans two blocks). */
typedef struct {
  MPI_Comm       comm;
  PetscMPIInt    tag, size, dest; /* dest: the rank whose block particle k is in */
  PetscInt       N, k, end;       /* particles in all, dealt so far; the first past dest's block */
  PetscInt       chunk, nbuf;     /* the most particles per message; those waiting in the buffers */
  PetscReal     *rbuf;            /* 4 per particle: x, y, z, volume */
  PetscInt      *ibuf;            /* source lines */
  PeriParticles *p;               /* rank 0's block */
  PeriExtent     extent;          /* of all particles dealt */
} Dealer;

static PetscErrorCode DealerCreate(MPI_Comm comm, PetscMPIInt tag, PetscInt chunk, PetscInt N, PeriParticles *p, Dealer *d)
{
  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(d, sizeof(*d)));
  d->comm  = comm;
  d->tag   = tag;
  d->chunk = chunk;
  d->N     = N;
  d->p     = p;
  PetscCallMPI(MPI_Comm_size(comm, &d->size));
  d->end = BlockStart(N, d->size, 1);
  PetscCall(PetscMalloc2(4 * chunk, &d->rbuf, chunk, &d->ibuf));
  PeriExtentInit(&d->extent);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode DealerDestroy(Dealer *d)
{
  PetscFunctionBeginUser;
  PetscCheck(d->k == d->N, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "dealt %" PetscInt_FMT " of %" PetscInt_FMT " particles: did the file change while it was read?", d->k, d->N);
  PetscCall(PetscFree2(d->rbuf, d->ibuf));
  PeriExtentSet(&d->extent, d->p);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Particle k of the body: x (3), its volume and source line. */
static PetscErrorCode DealerPut(Dealer *d, const PetscReal x[], PetscReal vol, PetscInt line)
{
  PeriParticles *p = d->p;
  PetscReal      h = PeriParticleSpacing(p, vol);

  PetscFunctionBeginUser;
  PetscCheck(d->k < d->N, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "more than the %" PetscInt_FMT " particles counted: did the file change while it was read?", d->N);
  PeriExtentAdd(&d->extent, p->dim, x, h);
  while (d->k >= d->end) d->end = BlockStart(d->N, d->size, ++d->dest + 1);
  if (d->dest == 0) {
    for (PetscInt c = 0; c < 3; c++) p->x[3 * d->k + c] = x[c];
    p->volume[d->k]      = vol;
    p->spacing[d->k]     = h;
    p->source_line[d->k] = line;
  } else {
    for (PetscInt c = 0; c < 3; c++) d->rbuf[4 * d->nbuf + c] = x[c];
    d->rbuf[4 * d->nbuf + 3] = vol;
    d->ibuf[d->nbuf++]       = line;
    if (d->nbuf == d->chunk || d->k + 1 == d->end) {
      PetscCallMPI(MPI_Send(d->rbuf, (PetscMPIInt)(4 * d->nbuf), MPIU_REAL, d->dest, d->tag, d->comm));
      PetscCallMPI(MPI_Send(d->ibuf, (PetscMPIInt)d->nbuf, MPIU_INT, d->dest, d->tag, d->comm));
      d->nbuf = 0;
    }
  }
  d->k++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A rank other than 0: its block of p->n particles from rank 0, in the chunks DealerPut sends. */
static PetscErrorCode ReceiveBlock(MPI_Comm comm, PetscMPIInt tag, PetscInt chunk, PeriParticles *p)
{
  PetscReal *rbuf;
  PetscInt  *ibuf;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(4 * chunk, &rbuf, chunk, &ibuf));
  for (PetscInt off = 0; off < p->n; off += chunk) {
    PetscInt m = PetscMin(chunk, p->n - off);
    PetscCallMPI(MPI_Recv(rbuf, (PetscMPIInt)(4 * m), MPIU_REAL, 0, tag, comm, MPI_STATUS_IGNORE));
    PetscCallMPI(MPI_Recv(ibuf, (PetscMPIInt)m, MPIU_INT, 0, tag, comm, MPI_STATUS_IGNORE));
    for (PetscInt l = 0; l < m; l++) {
      for (PetscInt c = 0; c < 3; c++) p->x[3 * (off + l) + c] = rbuf[4 * l + c];
      p->volume[off + l]      = rbuf[4 * l + 3];
      p->spacing[off + l]     = PeriParticleSpacing(p, rbuf[4 * l + 3]);
      p->source_line[off + l] = ibuf[l];
    }
  }
  PetscCall(PetscFree2(rbuf, ibuf));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What rank 0 reads for the others: the scene's file or mesh, the count, and a mesh's particles. */
typedef struct {
  PeriScene      scene;
  PeriNode       node;
  PeriParticles *p;
  PetscInt       N;
  PetscReal     *x, *vol; /* a mesh's particles (rank 0, while reading) */
  PetscReal      box[6];  /* a mesh's nodes' bounding box */
} RootRead;

/* particles.file, first pass: every line checked, the particles counted. */
static PetscErrorCode CSVCount(void *ctx)
{
  RootRead   *r = (RootRead *)ctx;
  PeriCSV     csv;
  PetscBool   done = PETSC_FALSE;
  const char *problem;

  PetscFunctionBeginUser;
  PetscCall(PeriCSVOpen(r->scene, r->node, r->p->dim, &csv));
  while (!done) {
    PetscReal x[3], vol;
    PetscInt  line;
    PetscCall(PeriCSVNext(&csv, x, &vol, &line, &done, &problem));
    if (problem) PetscCall(PeriCSVFail(&csv, problem));
  }
  r->N = csv.n;
  PetscCall(PeriCSVClose(&csv));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles.file, second pass on rank 0: every particle dealt out. */
static PetscErrorCode CSVDeal(const RootRead *r, Dealer *d)
{
  PeriCSV     csv;
  PetscBool   done = PETSC_FALSE;
  const char *problem;

  PetscFunctionBeginUser;
  PetscCall(PeriCSVOpen(r->scene, r->node, r->p->dim, &csv));
  for (;;) {
    PetscReal x[3], vol;
    PetscInt  line;
    PetscCall(PeriCSVNext(&csv, x, &vol, &line, &done, &problem));
    if (problem) PetscCall(PeriCSVFail(&csv, problem));
    if (done) break;
    PetscCall(DealerPut(d, x, vol, line));
  }
  PetscCall(PeriCSVClose(&csv));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles.mesh on rank 0: the particles and the groups. */
static PetscErrorCode MeshReadRoot(void *ctx)
{
  RootRead *r = (RootRead *)ctx;

  PetscFunctionBeginUser;
  PetscCall(PeriMeshRead(r->scene, r->node, r->p->dim, r->p->thickness, &r->N, &r->x, &r->vol, &r->p->ngroups, &r->p->groups, r->box));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Rank 0's mesh groups to every rank. */
static PetscErrorCode GroupsBcast(MPI_Comm comm, PeriParticles *p)
{
  PetscMPIInt rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Bcast(&p->ngroups, 1, MPIU_INT, 0, comm));
  if (rank) PetscCall(PetscCalloc1(p->ngroups + 1, &p->groups));
  for (PetscInt k = 0; k < p->ngroups; k++) {
    PeriMeshGroup *g      = &p->groups[k];
    PetscInt       dc[2]  = {g->dim, g->count};
    PetscMPIInt    nbytes = (PetscMPIInt)sizeof(g->name);

    PetscCallMPI(MPI_Bcast(g->name, nbytes, MPI_CHAR, 0, comm));
    PetscCallMPI(MPI_Bcast(dc, 2, MPIU_INT, 0, comm));
    PetscCallMPI(MPI_Bcast(&g->measure, 1, MPIU_REAL, 0, comm));
    g->dim   = dc[0];
    g->count = dc[1];
    if (rank) PetscCall(PetscMalloc1(3 * PetscMax(g->count, 1), &g->x));
    PetscCallMPI(MPI_Bcast(g->x, (PetscMPIInt)(3 * g->count), MPIU_REAL, 0, comm));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A file's or a mesh's particles: read on rank 0 (mesh: r->x, r->vol; file: a second pass),
 * each rank receiving its block; then rank 0's box and mean spacing to all. */
static PetscErrorCode ReadBlock(MPI_Comm comm, PeriSource source, RootRead *r)
{
  PetscMPIInt rank, size, tag;
  MPI_Comm    inner;
  PetscReal   ext[7];
  PetscInt    chunk = 65536;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-peri_read_chunk", &chunk, NULL));
  PetscCheck(chunk > 0, comm, PETSC_ERR_USER_INPUT, "-peri_read_chunk %" PetscInt_FMT ": must be positive", chunk);
  PetscCall(OnRoot(comm, source == PERI_SOURCE_MESH ? MeshReadRoot : CSVCount, r));
  PetscCallMPI(MPI_Bcast(&r->N, 1, MPIU_INT, 0, comm));
  PetscCall(PeriParticlesAllocate(r->p, BlockStart(r->N, size, rank + 1) - BlockStart(r->N, size, rank)));
  PetscCall(PetscCommDuplicate(comm, &inner, &tag));
  if (rank == 0) {
    Dealer d;
    PetscCall(DealerCreate(inner, tag, chunk, r->N, r->p, &d));
    if (source == PERI_SOURCE_MESH)
      for (PetscInt k = 0; k < r->N; k++) PetscCall(DealerPut(&d, &r->x[3 * k], r->vol[k], 0));
    else
      PetscCall(CSVDeal(r, &d));
    PetscCall(DealerDestroy(&d));
    if (source == PERI_SOURCE_MESH) {
      PetscCall(PetscFree2(r->x, r->vol));
      PeriParticlesPeriodicBox(r->p, r->box); /* broadcast below with the extent */
    }
  } else
    PetscCall(ReceiveBlock(inner, tag, chunk, r->p));
  PetscCall(PetscCommDestroy(&inner));
  if (source == PERI_SOURCE_MESH) PetscCall(GroupsBcast(comm, r->p));
  for (PetscInt d = 0; d < 3; d++) ext[d] = r->p->lower[d], ext[3 + d] = r->p->upper[d];
  ext[6] = r->p->mean_spacing;
  PetscCallMPI(MPI_Bcast(ext, 7, MPIU_REAL, 0, comm));
  for (PetscInt d = 0; d < 3; d++) r->p->lower[d] = ext[d], r->p->upper[d] = ext[3 + d];
  r->p->mean_spacing = ext[6];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesCreateBlock - this rank's block of the body of PeriParticlesCreateFromScene: its
  particles floor(r N / P) .. floor((r + 1) N / P) - 1 in that order, with the body's box, periodic
  axes, mean spacing and (for a mesh) groups; *N the body's particles. No rank holds the whole
  body, except rank 0 while it reads a mesh. Input errors are those of the whole-body read, raised
  on every rank. Collective.
@*/
PetscErrorCode PeriParticlesCreateBlock(MPI_Comm comm, PeriScene scene, PetscInt dim, PetscReal thickness, PeriParticles *p, PetscInt *N)
{
  PeriSource  source;
  PeriNode    node;
  PetscMPIInt rank, size;
  RootRead    r;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PeriParticlesSource(scene, dim, thickness, p, &source, &node));
  if (source == PERI_SOURCE_GRID) {
    PetscCall(PeriGridCreate(scene, node, dim, rank, size, p, N));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscMemzero(&r, sizeof(r)));
  r.scene = scene;
  r.node  = node;
  r.p     = p;
  PetscCall(ReadBlock(comm, source, &r));
  *N = r.N;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesCreateOwned - creates this rank's owned particles, partitioned (-peri_partition)
  without the whole body on any rank: the block of PeriParticlesCreateBlock, then
  PeriPartitionBlocks and PeriParticlesMigrate. On return p holds rank r's particles, global
  numbers range[r] .. range[r + 1] - 1 (range: P + 1 entries, allocated here), in the order and
  with the numbering of the whole-body path (PeriParticlesCreateFromScene, PeriPartition,
  PeriParticlesPermute, then the slice range[r] .. range[r + 1]); *N is the body's count. Scenes
  with fictitious layers (boundary_layers) are refused: the system adds the layers to each rank's
  particles after the partition (PeriLayersAddParticles). Collective.
@*/
PetscErrorCode PeriParticlesCreateOwned(MPI_Comm comm, PeriScene scene, PetscInt dim, PetscReal thickness, PetscReal delta, PeriParticles *p, PetscInt *N, PetscInt **range)
{
  PeriNode    layers;
  PetscMPIInt size, *target;
  PetscInt   *count;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(scene->root, "boundary_layers", &layers));
  PetscCheck(!layers, comm, PETSC_ERR_SUP, "%s: fictitious layers (boundary_layers) are added after the partition by the system (PeriLayersAddParticles)", scene->file);
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PeriParticlesCreateBlock(comm, scene, dim, thickness, p, N));
  PetscCall(PeriPartitionBlocks(comm, p, delta, &target));
  if (size > 1) PetscCall(PeriParticlesMigrate(comm, p, target));
  PetscCall(PetscFree(target));
  PetscCall(PetscMalloc1(size + 1, range));
  count = *range + 1;
  PetscCallMPI(MPI_Allgather(&p->n, 1, MPIU_INT, count, 1, MPIU_INT, comm));
  (*range)[0] = 0;
  for (PetscMPIInt r = 0; r < size; r++) (*range)[r + 1] += (*range)[r];
  PetscFunctionReturn(PETSC_SUCCESS);
}
