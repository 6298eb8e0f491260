/* Particles created where they are owned (PeriParticlesCreateOwned, src/disc/create.c) against the
 * whole-body path computed here: every rank builds the whole body (PeriParticlesCreateFromScene),
 * partitions it (PeriPartition), permutes it and slices its range. For every scene given and each
 * partitioner (geometric, ptscotch, metis): the same particle count, the same ranges, and on every
 * rank the same positions, volumes, spacings and source lines in the same order, the same box,
 * periodic axes, mean spacing and mesh groups, all bitwise. The blocks of
 * PeriParticlesCreateBlock (before the partition) must be the whole body's slices
 * floor(r N / P) .. floor((r + 1) N / P): no rank receives more than its share plus the rounding.
 * A scene whose first line is "# expect: ..." (tests/bad_input) must fail in both paths with the
 * same message on every rank.
 *
 * test_create SCENE...: the comparison.
 * test_create SCENE -peak old|new [options]: no comparison; one path's creation and partition,
 * then each rank's peak resident memory (tests/perf/create.sh). */
#include "testing.h"
#include "perilin/private/disc.h"
#include <sys/resource.h>

static PetscErrorCode LoadScene(const char file[], PeriScene *scene, PetscInt *dim, PetscReal *thickness)
{
  PeriSchemaOwner owners[PERI_MAX_SCHEMA_OWNERS];
  PetscInt        n;
  PeriNode        mat;

  PetscFunctionBeginUser;
  PetscCall(PeriSchemaOwners(PERI_MAX_SCHEMA_OWNERS, owners, &n));
  PetscCall(PeriSceneCreateFromFile(file, n, owners, scene));
  PetscCall(PeriSceneGetInt(*scene, (*scene)->root, "dim", PETSC_TRUE, dim, NULL));
  PetscCall(PeriSceneGetMap(*scene, (*scene)->root, "material", PETSC_TRUE, &mat));
  *thickness = 1;
  PetscCall(PeriSceneGetReal(*scene, mat, "thickness", PETSC_FALSE, thickness, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The whole-body path: the whole body, its partition, and this rank's slice of the permuted body. */
static PetscErrorCode Reference(PeriScene scene, PetscInt dim, PetscReal thickness, PetscReal delta, PeriParticles *whole, PeriParticles *owned, PetscInt **range)
{
  PetscMPIInt rank, size;
  PetscInt   *perm;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PeriParticlesCreateFromScene(scene, dim, thickness, whole));
  PetscCall(PeriPartition(PETSC_COMM_WORLD, whole, delta, &perm, range));
  if (size > 1) PetscCall(PeriParticlesPermute(whole, perm));
  PetscCall(PeriParticlesSlice(whole, (*range)[rank], (*range)[rank + 1], owned));
  PetscCall(PetscFree(perm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscBool Same(const void *a, const void *b, size_t bytes)
{
  return (PetscBool)(bytes == 0 || memcmp(a, b, bytes) == 0);
}

/* Where a and b differ (bitwise; groups from g), else an empty msg. */
static void Differences(const PeriParticles *a, const PeriParticles *b, const PeriParticles *g, char msg[], size_t len)
{
  const size_t n = (size_t)a->n, R = sizeof(PetscReal);

  msg[0] = 0;
  if (a->n != b->n)
    (void)PetscSNPrintf(msg, len, "%" PetscInt_FMT " particles, expected %" PetscInt_FMT, b->n, a->n);
  else if (!Same(a->x, b->x, 3 * n * R))
    (void)PetscSNPrintf(msg, len, "positions differ");
  else if (!Same(a->volume, b->volume, n * R))
    (void)PetscSNPrintf(msg, len, "volumes differ");
  else if (!Same(a->spacing, b->spacing, n * R))
    (void)PetscSNPrintf(msg, len, "spacings differ");
  else if (!Same(a->source_line, b->source_line, n * sizeof(PetscInt)))
    (void)PetscSNPrintf(msg, len, "source lines differ");
  else if (!Same(a->lower, b->lower, 3 * R) || !Same(a->upper, b->upper, 3 * R))
    (void)PetscSNPrintf(msg, len, "boxes differ");
  else if (!Same(a->periodic, b->periodic, sizeof(a->periodic)))
    (void)PetscSNPrintf(msg, len, "periodic axes differ");
  else if (!Same(&a->mean_spacing, &b->mean_spacing, R) || !Same(&a->thickness, &b->thickness, R) || a->dim != b->dim)
    (void)PetscSNPrintf(msg, len, "mean spacing %.17g, expected %.17g (or thickness, dim)", (double)b->mean_spacing, (double)a->mean_spacing);
  else if (b->ngroups != g->ngroups)
    (void)PetscSNPrintf(msg, len, "%" PetscInt_FMT " mesh groups, expected %" PetscInt_FMT, b->ngroups, g->ngroups);
  for (PetscInt k = 0; !msg[0] && k < g->ngroups; k++) {
    const PeriMeshGroup *u = &g->groups[k], *v = &b->groups[k];
    if (strcmp(u->name, v->name) || u->dim != v->dim || u->count != v->count || !Same(&u->measure, &v->measure, R) || !Same(u->x, v->x, 3 * (size_t)u->count * R)) (void)PetscSNPrintf(msg, len, "mesh group %s differs", u->name);
  }
}

/* Fails on every rank when one found msg non-empty (each such rank prints its own). */
static PetscErrorCode Agree(const char what[], const char msg[])
{
  int bad = msg[0] != 0, any;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_LOR, PETSC_COMM_WORLD));
  if (bad) PetscCall(PetscPrintf(PETSC_COMM_SELF, "%s: %s\n", what, msg));
  PetscCheck(!any, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: the paths differ", what);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The blocks before the partition: the whole body's slices of floor or ceil(N / P) particles. */
static PetscErrorCode CheckBlocks(const char file[], PeriScene scene, PetscInt dim, PetscReal thickness)
{
  PetscMPIInt          rank, size;
  PeriParticles        b, s, w;
  const PeriParticles *whole = &w;
  PetscInt             N, r0, r1;
  char                 msg[256], what[PETSC_MAX_PATH_LEN + 64];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PeriParticlesCreateFromScene(scene, dim, thickness, &w));
  PetscCall(PeriParticlesCreateBlock(PETSC_COMM_WORLD, scene, dim, thickness, &b, &N));
  r0 = (PetscInt)((PetscInt64)rank * whole->n / size);
  r1 = (PetscInt)((PetscInt64)(rank + 1) * whole->n / size);
  PetscCall(PeriParticlesSlice(whole, r0, r1, &s));
  Differences(&s, &b, whole, msg, sizeof(msg));
  if (!msg[0] && N != whole->n) PetscCall(PetscSNPrintf(msg, sizeof(msg), "N %" PetscInt_FMT ", expected %" PetscInt_FMT, N, whole->n));
  if (!msg[0] && (b.n < whole->n / size || b.n > (whole->n + size - 1) / size)) PetscCall(PetscSNPrintf(msg, sizeof(msg), "a block of %" PetscInt_FMT " of %" PetscInt_FMT " particles", b.n, N));
  PetscCall(PetscSNPrintf(what, sizeof(what), "%s: blocks", file));
  PetscCall(Agree(what, msg));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s: the blocks of %" PetscInt_FMT " particles on %d ranks are the whole body's slices of floor or ceil(N/P), bitwise\n", file, N, size));
  PetscCall(PeriParticlesDestroy(&s));
  PetscCall(PeriParticlesDestroy(&b));
  PetscCall(PeriParticlesDestroy(&w));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One partitioner: PeriParticlesCreateOwned against the reference. */
static PetscErrorCode CheckOwned(const char file[], const char type[], PeriScene scene, PetscInt dim, PetscReal thickness)
{
  PetscMPIInt   size;
  PeriParticles whole, ref, own;
  PetscInt     *rref, *range, N;
  PetscReal     delta;
  char          msg[256], what[PETSC_MAX_PATH_LEN + 64];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(PeriTestSetOption("-peri_partition", type));
  PetscCall(PeriParticlesCreateFromScene(scene, dim, thickness, &whole));
  delta = 3.015 * whole.mean_spacing; /* the partition graph's radius is min(delta, 1.5 h) */
  PetscCall(PeriParticlesDestroy(&whole));
  PetscCall(Reference(scene, dim, thickness, delta, &whole, &ref, &rref));
  PetscCall(PeriParticlesCreateOwned(PETSC_COMM_WORLD, scene, dim, thickness, delta, &own, &N, &range));
  Differences(&ref, &own, &whole, msg, sizeof(msg));
  if (!msg[0] && N != whole.n) PetscCall(PetscSNPrintf(msg, sizeof(msg), "N %" PetscInt_FMT ", expected %" PetscInt_FMT, N, whole.n));
  if (!msg[0] && !Same(range, rref, (size + 1) * sizeof(PetscInt))) PetscCall(PetscSNPrintf(msg, sizeof(msg), "the ranges differ"));
  PetscCall(PetscSNPrintf(what, sizeof(what), "%s, %s", file, type));
  PetscCall(Agree(what, msg));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s, %s: %" PetscInt_FMT " particles on %d ranks (largest share %" PetscInt_FMT "): the same ranges and owned particles, bitwise\n", file, type, N, size, rref[1] - rref[0]));
  PetscCall(PetscFree(range));
  PetscCall(PetscFree(rref));
  PetscCall(PeriParticlesDestroy(&own));
  PetscCall(PeriParticlesDestroy(&ref));
  PetscCall(PeriParticlesDestroy(&whole));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode CaptureFirst(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *ctx)
{
  char *msg = (char *)ctx;

  (void)comm, (void)line, (void)fun, (void)file;
  if (p == PETSC_ERROR_INITIAL && !msg[0]) (void)PetscSNPrintf(msg, 1024, "%s", mess ? mess : "error");
  return n;
}

/* A bad scene: both paths fail, with one message. */
static PetscErrorCode CheckBad(const char file[], PeriScene scene, PetscInt dim, PetscReal thickness)
{
  char           old[1024] = "", new[1024] = "", msg[2200] = "", what[PETSC_MAX_PATH_LEN + 64];
  PeriParticles  p;
  PetscInt       N, *range = NULL;
  PetscErrorCode e1, e2;

  PetscFunctionBeginUser;
  PetscCall(PetscPushErrorHandler(CaptureFirst, old));
  e1 = PeriParticlesCreateFromScene(scene, dim, thickness, &p);
  PetscCall(PetscPopErrorHandler());
  PetscCall(PeriParticlesDestroy(&p));
  PetscCall(PetscPushErrorHandler(CaptureFirst, new));
  e2 = PeriParticlesCreateOwned(PETSC_COMM_WORLD, scene, dim, thickness, 1, &p, &N, &range);
  PetscCall(PetscPopErrorHandler());
  PetscCall(PeriParticlesDestroy(&p));
  PetscCall(PetscFree(range));
  if (!e1 || !e2 || strcmp(old, new)) PetscCall(PetscSNPrintf(msg, sizeof(msg), "the whole-body read says \"%s\" (%d), the owned one \"%s\" (%d)", old, (int)e1, new, (int)e2));
  PetscCall(PetscSNPrintf(what, sizeof(what), "%s (invalid)", file));
  PetscCall(Agree(what, msg));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s: both paths fail on every rank with: %s\n", file, new));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A scene with fictitious layers: refused by PeriParticlesCreateOwned on every rank. */
static PetscErrorCode CheckRefused(const char file[], PeriScene scene, PetscInt dim, PetscReal thickness)
{
  char           msg[1024] = "", what[PETSC_MAX_PATH_LEN + 64];
  PeriParticles  p;
  PetscInt       N, *range = NULL;
  PetscErrorCode e;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&p, sizeof(p)));
  PetscCall(PetscPushErrorHandler(CaptureFirst, msg));
  e = PeriParticlesCreateOwned(PETSC_COMM_WORLD, scene, dim, thickness, 1, &p, &N, &range);
  PetscCall(PetscPopErrorHandler());
  PetscCall(PeriParticlesDestroy(&p));
  PetscCall(PetscFree(range));
  PetscCall(PetscSNPrintf(what, sizeof(what), "%s (fictitious layers)", file));
  PetscCall(Agree(what, e == PETSC_ERR_SUP && strstr(msg, "fictitious layers") ? "" : "not refused, or another error"));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s: refused on every rank: %s\n", file, msg));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* -peak old|new: one path, then every rank's peak resident set and the time. The partition graph's
 * radius is 1.5 spacings (delta unbounded). */
static PetscErrorCode Peak(const char file[], const char mode[])
{
  PetscMPIInt    rank, size;
  PeriScene      scene;
  PetscInt       dim, N, *range;
  PetscReal      thickness;
  PeriParticles  whole, owned;
  PetscLogDouble t0, t1;
  struct rusage  ru;
  long          *peaks, mine;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCall(LoadScene(file, &scene, &dim, &thickness));
  PetscCall(PetscTime(&t0));
  if (!strcmp(mode, "old")) {
    PetscCall(Reference(scene, dim, thickness, PETSC_MAX_REAL, &whole, &owned, &range));
    N = whole.n;
    PetscCall(PeriParticlesDestroy(&whole));
  } else
    PetscCall(PeriParticlesCreateOwned(PETSC_COMM_WORLD, scene, dim, thickness, PETSC_MAX_REAL, &owned, &N, &range));
  PetscCall(PetscTime(&t1));
  PetscCheck(!getrusage(RUSAGE_SELF, &ru), PETSC_COMM_SELF, PETSC_ERR_SYS, "getrusage failed");
  mine = ru.ru_maxrss;
  PetscCall(PetscMalloc1(size, &peaks));
  PetscCallMPI(MPI_Gather(&mine, 1, MPI_LONG, peaks, 1, MPI_LONG, 0, PETSC_COMM_WORLD));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s %" PetscInt_FMT " particles, %d ranks, %.2f s, peak MB per rank:", mode, N, size, (double)(t1 - t0)));
  for (PetscMPIInt r = 0; r < size; r++) PetscCall(PetscPrintf(PETSC_COMM_WORLD, " %.0f", peaks[r] / 1024.0));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "\n"));
  PetscCall(PetscFree(peaks));
  PetscCall(PetscFree(range));
  PetscCall(PeriParticlesDestroy(&owned));
  PetscCall(PeriSceneDestroy(&scene));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the scene file starts with "# expect:", the mark of an invalid scene. */
static PetscErrorCode IsBad(const char file[], PetscBool *bad)
{
  char  line[16] = "";
  FILE *fp;

  PetscFunctionBeginUser;
  fp = fopen(file, "r");
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot open %s", file);
  if (!fgets(line, sizeof(line), fp)) line[0] = 0;
  fclose(fp);
  *bad = (PetscBool)!strncmp(line, "# expect:", 9);
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const char *const types[] = {"geometric", "ptscotch", "metis"};
  char              mode[8];
  PetscBool         peak;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2 && argv[1][0] != '-', PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_create SCENE... | SCENE -peak old|new [options]");
  PetscCall(PetscOptionsGetString(NULL, NULL, "-peak", mode, sizeof(mode), &peak));
  if (peak) PetscCall(Peak(argv[1], mode));
  for (int a = 1; a < argc && argv[a][0] != '-' && !peak; a++) {
    PeriScene scene;
    PetscInt  dim;
    PetscReal thickness;
    PetscBool bad;
    PeriNode  layers;

    PetscCall(IsBad(argv[a], &bad));
    PetscCall(LoadScene(argv[a], &scene, &dim, &thickness));
    PetscCall(PeriSceneGetNode(scene->root, "boundary_layers", &layers));
    if (bad)
      PetscCall(CheckBad(argv[a], scene, dim, thickness));
    else if (layers)
      PetscCall(CheckRefused(argv[a], scene, dim, thickness));
    else
      PetscCall(CheckBlocks(argv[a], scene, dim, thickness));
    for (int t = 0; t < 3 && !bad && !layers; t++) PetscCall(CheckOwned(argv[a], types[t], scene, dim, thickness));
    PetscCall(PeriSceneDestroy(&scene));
  }
  PetscCall(PeriFinalize());
  return 0;
}
