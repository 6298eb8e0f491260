/* The discretization (src/disc/): particles, regions, neighbour search and bonds, corrections,
 * partition. */
#pragma once

#include <perilin/scene.h>
#include "perilin/private/sys.h"

PETSC_EXTERN PetscErrorCode PeriParticlesCreateFromScene(PeriScene, PetscInt, PetscReal, PeriParticles *);
PETSC_EXTERN PetscErrorCode PeriParticlesPermute(PeriParticles *, const PetscInt[]);
PETSC_EXTERN PetscErrorCode PeriParticlesDestroy(PeriParticles *);

/* ------------------------------------------------------------------ regions (src/regions.c) */
typedef enum {
  PERI_REGION_ALL,
  PERI_REGION_BOX,
  PERI_REGION_LAYER
} PeriRegionKind;

typedef struct {
  char           name[PERI_NAME_LEN];
  PeriRegionKind kind;
  PetscReal      lower[3], upper[3]; /* the box, or the layer's slab */
  PetscInt       axis, side;         /* layers: axis 0..2, side -1 (lower face) or +1 (upper face) */
  PetscReal      depth;              /* layers */
  PetscReal      face_area;          /* layers: area of the body's face the layer lies on */
  PetscInt       count;              /* particles inside */
  PetscReal      volume;             /* their total volume */
  PeriNode       node;
} PeriRegion;

PETSC_EXTERN PetscErrorCode PeriRegionsCreateFromScene(PeriScene, const PeriParticles *, PetscReal, PetscInt *, PeriRegion **);
PETSC_EXTERN PetscErrorCode PeriRegionFind(PeriScene, PeriNode, const char[], PetscInt, PeriRegion *, PeriRegion **);
PETSC_EXTERN PetscBool      PeriRegionContains(const PeriRegion *, const PetscReal[]);

PETSC_EXTERN PetscErrorCode PeriNeighborSearch(const PeriParticles *, PetscReal, PeriPartialVolume, PetscInt, PetscInt, PetscBool, PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriBondsDestroy(PeriBonds *);
PETSC_EXTERN PetscReal      PeriPartialVolumeFactor(PeriPartialVolume, PetscReal, PetscReal, PetscReal);
PETSC_EXTERN PetscReal      PeriSearchRadius(PeriPartialVolume, PetscReal, PetscReal);
PETSC_EXTERN PetscErrorCode PeriNeighborhoodVolumes(MPI_Comm, const PeriParticles *, const PeriBonds *, PetscReal[], PetscInt[]);
PETSC_EXTERN PetscErrorCode PeriSurfaceCorrectionApply(PeriSurfaceCorrection, const PeriParticles *, PetscReal, const PetscReal[], PeriBonds *);
PETSC_EXTERN PetscErrorCode PeriPartition(MPI_Comm, const PeriParticles *, PetscReal, PetscInt **, PetscInt **);

/* grid, particles and regions.<name>, declared next to the code that reads them. */
PETSC_EXTERN const PeriSchema PeriParticlesSchema[], PeriRegionsSchema[];
