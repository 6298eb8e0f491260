/* The geometry of pre-existing cracks (src/system/crack_surfaces.c): 2D segments, and in 3D planar
 * polygons (a surface file's triangles are polygons of three corners) and discs. Plain C on plain
 * arrays: no scene, no MPI. */
#pragma once

#include "perilin/types.h" /* petscsys.h, and PETSC_SUCCESS on older PETSc */

typedef enum {
  PERI_CRACK_SEGMENT,
  PERI_CRACK_POLYGON,
  PERI_CRACK_DISC
} PeriCrackKind;

/* One piece of a crack; item is the cracks.<k> it belongs to. */
typedef struct {
  PeriCrackKind kind;
  PetscInt      item;
  PetscInt      first, n;  /* polygon: its n corners, from points[3 first]; segment: its 2 ends */
  PetscReal     c[3];      /* polygon: its first corner; disc: the centre */
  PetscReal     normal[3]; /* unit (polygon, disc) */
  PetscReal     radius;    /* disc */
  PetscInt      drop;      /* polygon: the axis of the normal's largest component, dropped by the 2D test */
  PetscReal     lo[3], hi[3];
} PeriCrackFacet;

typedef struct _PeriCrackSet {
  PetscInt        nfacets, maxfacets, nitems;
  PeriCrackFacet *facet;
  PetscInt        npoints, maxpoints;
  PetscReal      *points; /* [x, y, z] each */
} PeriCrackSet;

PETSC_EXTERN PetscErrorCode PeriCrackAddSegment(PeriCrackSet *, PetscInt, const PetscReal[], const PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriCrackAddPolygon(PeriCrackSet *, PetscInt, PetscInt, const PetscReal[], const char **, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriCrackAddDisc(PeriCrackSet *, PetscInt, const PetscReal[], const PetscReal[], PetscReal, const char **);
PETSC_EXTERN PetscBool      PeriCrackCrosses(const PeriCrackSet *, const PeriCrackFacet *, const PetscReal[], const PetscReal[]);
PETSC_EXTERN void           PeriCrackItemBox(const PeriCrackSet *, PetscInt, PetscReal[], PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriCrackSetDestroy(PeriCrackSet *);
