/* The discretization (src/disc/): particles, regions, neighbour search and bonds, corrections,
 * partition. */
#pragma once

#include <perilin/scene.h>
#include "perilin/private/sys.h"
#include <petscsf.h>
#include <petscis.h>

PETSC_EXTERN PetscErrorCode PeriParticlesCreateFromScene(PeriScene, PetscInt, PetscReal, PeriParticles *);
PETSC_EXTERN PetscErrorCode PeriParticlesCreateBlock(MPI_Comm, PeriScene, PetscInt, PetscReal, PeriParticles *, PetscInt *);
PETSC_EXTERN PetscErrorCode PeriParticlesCreateOwned(MPI_Comm, PeriScene, PetscInt, PetscReal, PetscReal, PeriParticles *, PetscInt *, PetscInt **);
PETSC_EXTERN PetscErrorCode PeriParticlesAllocate(PeriParticles *, PetscInt);
PETSC_EXTERN PetscReal      PeriParticlesBytesPerParticle(PetscInt);
PETSC_EXTERN PetscErrorCode PeriParticlesPermute(PeriParticles *, const PetscInt[]);
PETSC_EXTERN PetscErrorCode PeriParticlesSlice(const PeriParticles *, PetscInt, PetscInt, PeriParticles *);
PETSC_EXTERN PetscErrorCode PeriParticlesDestroy(PeriParticles *);

/* ------------------------------------------------------------------ creation (particles.c, create.c) */
/* Where the body comes from: exactly one of grid, particles.file, particles.mesh. */
typedef enum {
  PERI_SOURCE_GRID,
  PERI_SOURCE_FILE,
  PERI_SOURCE_MESH
} PeriSource;
PETSC_EXTERN PetscErrorCode PeriParticlesSource(PeriScene, PetscInt, PetscReal, PeriParticles *, PeriSource *, PeriNode *);
PETSC_EXTERN PetscErrorCode PeriGridCreate(PeriScene, PeriNode, PetscInt, PetscMPIInt, PetscMPIInt, PeriParticles *, PetscInt *);

/* particles.file read particle by particle: by every rank (the whole body) or by rank 0, which
 * deals the particles out in chunks (src/disc/create.c). */
typedef struct {
  PeriScene scene;
  PeriNode  node;
  char      path[PETSC_MAX_PATH_LEN];
  FILE     *fp;
  PetscInt  dim, lineno, n; /* lines read, particles read */
  PetscBool header;
  char      stop[96]; /* the problem of a read stopped by a signal */
} PeriCSV;
PETSC_EXTERN PetscErrorCode PeriCSVOpen(PeriScene, PeriNode, PetscInt, PeriCSV *);
PETSC_EXTERN PetscErrorCode PeriCSVNext(PeriCSV *, PetscReal[], PetscReal *, PetscInt *, PetscBool *, const char **);
PETSC_EXTERN PetscErrorCode PeriCSVFail(PeriCSV *, const char[]);
PETSC_EXTERN PetscErrorCode PeriCSVClose(PeriCSV *);

/* The box and mean spacing of read particles (CSV, mesh), summed in the body's order. */
typedef struct {
  PetscReal lower[3], upper[3], sum;
  PetscInt  n;
} PeriExtent;
PETSC_EXTERN PetscReal PeriParticleSpacing(const PeriParticles *, PetscReal);
PETSC_EXTERN void      PeriExtentInit(PeriExtent *);
PETSC_EXTERN void      PeriExtentAdd(PeriExtent *, PetscInt, const PetscReal[], PetscReal);
PETSC_EXTERN void      PeriExtentSet(const PeriExtent *, PeriParticles *);

/* ------------------------------------------------------------------ Gmsh meshes (src/mesh.c) */
/* A named physical group: the positions of its particles, sorted lexicographically (positions,
 * not indices, so that the partition's renumbering leaves the set valid). */
typedef struct _n_PeriMeshGroup {
  char       name[PERI_NAME_LEN];
  PetscInt   dim;     /* the group's own dimension: the scene's, or lower for a boundary */
  PetscInt   count;   /* its particles */
  PetscReal *x;       /* 3 per particle, sorted */
  PetscReal  measure; /* a group of dimension dim - 1: its length x thickness (2D) or area (3D); else 0 */
} PeriMeshGroup;

PETSC_EXTERN void           PeriGmshLastError(char[], size_t);
PETSC_EXTERN PetscErrorCode PeriMeshGenerateIsolated(const char[], PetscInt, PetscReal, PetscBool *, char[], size_t);
PETSC_EXTERN PetscErrorCode PeriMeshRead(PeriScene, PeriNode, PetscInt, PetscReal, PetscInt *, PetscReal **, PetscReal **, PetscInt *, PeriMeshGroup **, PetscReal[6]);
PETSC_EXTERN PetscErrorCode PeriMeshSurfaceRead(PeriScene, PeriNode, const char[], const char[], PetscInt *, PetscReal **);
PETSC_EXTERN PetscErrorCode PeriParticlesReadPeriodic(PeriScene, PeriNode, PeriParticles *);
PETSC_EXTERN void           PeriParticlesPeriodicBox(PeriParticles *, const PetscReal[6]);
PETSC_EXTERN PetscErrorCode PeriMeshGroupsDestroy(PetscInt *, PeriMeshGroup **);
PETSC_EXTERN PetscErrorCode PeriMeshGroupsRestrict(PeriParticles *);

/* ------------------------------------------------------------------ regions (src/regions.c) */
typedef enum {
  PERI_REGION_ALL,
  PERI_REGION_BOX,
  PERI_REGION_LAYER,
  PERI_REGION_SET
} PeriRegionKind;

typedef struct {
  char           name[PERI_NAME_LEN];
  PeriRegionKind kind;
  PetscReal      lower[3], upper[3]; /* the box, or the layer's slab */
  PetscInt       axis, side;         /* layers: axis 0..2, side -1 (lower face) or +1 (upper face) */
  PetscReal      depth;              /* layers */
  PetscReal      face_area;          /* layers: area of the body's face the layer lies on; sets: the mesh boundary group's measure */
  PetscReal     *set;                /* sets: the sorted positions of a mesh group (owned by the particles) */
  PetscInt       nset;
  PetscInt       count;  /* particles inside */
  PetscReal      volume; /* their total volume */
  PeriNode       node;
} PeriRegion;

PETSC_EXTERN PetscErrorCode PeriRegionsCreateFromScene(MPI_Comm, PeriScene, const PeriParticles *, PetscInt, PetscReal, PetscInt *, PeriRegion **);
PETSC_EXTERN PetscErrorCode PeriRegionFind(PeriScene, PeriNode, const char[], PetscInt, PeriRegion *, PeriRegion **);
PETSC_EXTERN PetscBool      PeriRegionContains(const PeriRegion *, const PetscReal[]);
PETSC_EXTERN PetscReal      PeriRegionTolerance(const PeriParticles *);

PETSC_EXTERN PetscErrorCode PeriNeighborSearch(const PeriParticles *, PetscReal, const PetscReal[], PeriPartialVolume, PetscInt, PetscInt, PetscBool, PetscBool, PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriHorizonsByNeighbors(const PeriParticles *, PetscInt, PetscInt, PetscReal[], PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriNeighborSearchLevelsRows(const PeriParticles *, const PetscReal[], PeriPartialVolume, PetscInt, const PetscInt[], PetscInt, PetscBool, PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriNeighborSearchLevels(const PeriParticles *, const PetscReal[], PeriPartialVolume, PetscInt, PetscInt, PetscBool, PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriBondsAdd(const PeriParticles *, PetscInt, PetscInt, const PetscReal[], PetscReal, PeriPartialVolume, PeriBonds *, PetscInt *);
PETSC_EXTERN PetscErrorCode PeriBondsReserve(PeriBonds *, PetscInt, PetscInt *);
PETSC_EXTERN PetscReal      PeriBondsBallCount(PetscInt, PetscReal);
PETSC_EXTERN PetscReal      PeriBondsBytesPerParticle(PetscReal, PetscReal, PetscBool);
PETSC_EXTERN PetscErrorCode PeriBondsDestroy(PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriBondsReleaseGeometry(const PeriParticles *, PeriBonds *, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriBondsRestoreGeometry(const PeriParticles *, PetscReal, const PetscReal[], PeriPartialVolume, PeriBonds *);
PETSC_EXTERN PetscReal      PeriPartialVolumeFactor(PeriPartialVolume, PetscReal, PetscReal, PetscReal);
PETSC_EXTERN PetscReal      PeriSearchRadius(PeriPartialVolume, PetscReal, PetscReal);
PETSC_EXTERN PetscErrorCode PeriSurfaceCorrectionApply(PeriSurfaceCorrection, const PeriParticles *, PetscReal, const PetscReal[], const PetscReal[], PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriPartition(MPI_Comm, const PeriParticles *, PetscReal, PetscInt **, PetscInt **);
PETSC_EXTERN PetscErrorCode PeriPartitionBlocks(MPI_Comm, const PeriParticles *, PetscReal, PetscMPIInt **);

/* ------------------------------------------------------------------ exchange (src/disc/exchange.c) */
/* A sparse all-to-all: each rank sends each of its items to one rank and receives, ordered by the
 * sending rank and then by the sender's order, what is sent to it. One plan, any number of arrays. */
typedef struct {
  PetscSF      sf;        /* roots: the items sent, grouped by destination; leaves: those received */
  PetscInt     nsend;     /* items sent */
  PetscInt    *order;     /* nsend: the items in the order sent (by destination rank, stable) */
  PetscInt     nrecv;     /* items received */
  PetscMPIInt  nfrom;     /* ranks sending to this one */
  PetscMPIInt *from;      /* nfrom: those ranks, ascending */
  PetscInt    *fromstart; /* nfrom + 1: the items from from[i] are fromstart[i]..fromstart[i+1]-1 */
} PeriExchange;

PETSC_EXTERN PetscErrorCode PeriExchangeCreate(MPI_Comm, PetscInt, const PetscMPIInt[], PeriExchange *);
PETSC_EXTERN PetscErrorCode PeriExchangeSend(const PeriExchange *, MPI_Datatype, PetscInt, const void *, void *);
PETSC_EXTERN PetscErrorCode PeriExchangeDestroy(PeriExchange *);

PETSC_EXTERN PetscErrorCode PeriParticlesMigrate(MPI_Comm, PeriParticles *, const PetscMPIInt[]);
PETSC_EXTERN PetscErrorCode PeriParticlesGather(MPI_Comm, const PeriParticles *, PeriParticles *);
PETSC_EXTERN PetscErrorCode PeriParticlesNear(const PeriParticles *, PetscReal, PetscInt, const PetscReal[], PetscBool[]);

/* ------------------------------------------------------------------ ghosts (src/disc/halo.c) */
/* A rank's particles: the owned ones (global indices rstart..rstart+nowned-1), then nghost ghosts,
 * copies of other ranks' particles within the halo radius of an owned one. */
typedef struct {
  PetscInt  N;      /* particles of the whole body */
  PetscInt  rstart; /* global index of the first owned particle */
  PetscInt  nowned, nghost;
  PetscInt *global; /* nghost: each ghost's global index, ascending */
  PetscSF   sf;     /* roots: the owned particles; leaves: the ghosts */
} PeriHalo;

PETSC_EXTERN PetscErrorCode PeriHaloCreate(MPI_Comm, PeriParticles *, PetscReal, PeriHalo *);
PETSC_EXTERN PetscErrorCode PeriHaloUpdate(const PeriHalo *, MPI_Datatype, const void *, void *);
PETSC_EXTERN PetscErrorCode PeriHaloDestroy(PeriHalo *);

/* ------------------------------------------------------------------ pieces (src/disc/components.c) */
/* The connected pieces of a local view through its live links (labels: a piece's smallest global
 * index), and per-piece totals of owned values; no array of the whole body. */
PETSC_EXTERN PetscErrorCode PeriComponentsLabel(MPI_Comm, const PeriHalo *, const PetscInt[], const PetscInt[], const unsigned char[], PetscInt[], PetscInt *);
PETSC_EXTERN PetscErrorCode PeriComponentsReduce(MPI_Comm, const PeriHalo *, const PetscInt[], PetscInt, const MPI_Op[], PetscInt[], PetscInt *, PetscInt *);

/* grid, particles and regions.<name>, declared next to the code that reads them. */
PETSC_EXTERN const PeriSchema PeriParticlesSchema[], PeriRegionsSchema[];

/* The discretization of one body: every consumer reads particle data through this one owner.
 * Each rank holds its local view (docs/distributed.md): its owned particles, local indices
 * 0..nowned-1 (global rstart..rstart+nowned-1), then its ghosts (particles.global gives every
 * local particle's global index). Every per-particle array is sized to the local view; the bonds'
 * rows are the owned particles and their j are local indices. */
typedef struct {
  PeriParticles         particles;    /* the local view: owned, then ghosts */
  PetscInt              N;            /* particles of the whole body */
  PetscInt              nowned;       /* this rank's own particles */
  PetscInt              rstart;       /* the global index of local particle 0 */
  PetscMPIInt           size;         /* ranks */
  PetscInt             *range;        /* size + 1: rank r owns global indices range[r]..range[r+1]-1 */
  PeriHalo              halo;         /* the ghosts and the SF that refreshes them */
  PetscReal             ghost_radius; /* the ghosts are the other ranks' particles within this of an owned one */
  PetscInt              nregions;
  PeriRegion           *regions;
  PetscReal             delta;       /* the horizon: the body's one, or the largest of horizon[] */
  PetscReal             horizon_m;   /* horizon.spacing: own: delta_i = m h_i; 0: one delta */
  PetscInt              horizon_k;   /* horizon.neighbors: delta_i holds k neighbours (horizon_m its estimate before the search); 0: none */
  PetscReal            *horizon;     /* horizon.spacing: own: each local particle's delta_i; else NULL */
  PetscReal             horizon_min; /* horizon.spacing: own: the smallest delta_i of the body */
  PeriPartialVolume     partial_volume;
  PeriSurfaceCorrection surface;
  PeriBonds             bonds;          /* once per pair, in the row of the smaller global index (owned rows, local j) */
  PeriBonds             family;         /* state-based models: every bond of each owned particle (both directions) */
  PetscReal            *family_volume;  /* sum_j alpha_ij V_j over the family, per local particle (ghosts' from their owners) */
  PetscInt             *neighbor_count; /* per local particle (ghosts' from their owners) */
} PeriDisc;

PETSC_EXTERN PetscErrorCode PeriDiscDestroy(PeriDisc *);
PETSC_EXTERN PetscErrorCode PeriNeighborhoodVolumes(const PeriDisc *, PetscReal[], PetscInt[]);
PETSC_EXTERN void           PeriDiscBondGeometryFromCoordinates(const PeriDisc *, PetscInt, PetscInt, PetscReal[], PetscReal *, PetscReal *);

/* The vector X_j - X_i, length and partial-volume factor of stored bond k of owned particle i in
 * d's pair list: read where the list keeps them, else recomputed from the coordinates as
 * PeriBondsRestoreGeometry does (to the bit). Inline: the failure check calls it for every bond
 * at every step. Not collective. */
static inline void PeriDiscBondGeometry(const PeriDisc *d, PetscInt i, PetscInt k, PetscReal xi[], PetscReal *len, PetscReal *alpha)
{
  const PeriBonds *b = &d->bonds;

  if (!b->xi) {
    PeriDiscBondGeometryFromCoordinates(d, i, k, xi, len, alpha);
    return;
  }
  for (PetscInt e = 0; e < 3; e++) xi[e] = b->xi[3 * k + e];
  *len   = b->length[k];
  *alpha = b->alpha[k];
}

/* The length of stored bond k of owned particle i (PeriDiscBondGeometry). */
static inline PetscReal PeriDiscBondLength(const PeriDisc *d, PetscInt i, PetscInt k)
{
  PetscReal xi[3], len, alpha;

  if (d->bonds.length) return d->bonds.length[k];
  PeriDiscBondGeometryFromCoordinates(d, i, k, xi, &len, &alpha);
  return len;
}

/* The partial-volume factor of stored bond k of owned particle i (PeriDiscBondGeometry). */
static inline PetscReal PeriDiscBondAlpha(const PeriDisc *d, PetscInt i, PetscInt k)
{
  PetscReal xi[3], len, alpha;

  if (d->bonds.alpha) return d->bonds.alpha[k];
  PeriDiscBondGeometryFromCoordinates(d, i, k, xi, &len, &alpha);
  return alpha;
}
PETSC_EXTERN PetscErrorCode PeriDiscSetLocalView(MPI_Comm, PeriDisc *, PeriParticles *, PetscReal);
PETSC_EXTERN PetscMPIInt    PeriDiscOwner(const PeriDisc *, PetscInt);
PETSC_EXTERN PetscInt       PeriDiscLocal(const PeriDisc *, PetscInt);
PETSC_EXTERN PetscErrorCode PeriDiscGhostsToOwners(const PeriDisc *, MPI_Datatype, PetscInt, MPI_Op, void *);
PETSC_EXTERN PetscErrorCode PeriDiscOwnersToGhosts(const PeriDisc *, MPI_Datatype, PetscInt, void *);
