/* Plain data shared by every layer: limits, particles, bonds, material, one bond as the kernels
 * see it. No PETSc objects beyond scalars. */
#pragma once

#include <petscsys.h>

#if PETSC_VERSION_LT(3, 19, 0)
#  define PETSC_SUCCESS 0
#endif

#define PERI_MAX_DOF     6 /* room for 3D micropolar (3 translations, 3 rotations); models declare their own count */
#define PERI_MAX_MODES   6
#define PERI_NAME_LEN    64
#define PERI_MAX_MEASURE 3

/* ------------------------------------------------------------------ particles (src/particles.c) */
typedef struct {
  PetscInt   dim;
  PetscInt   n;           /* particles held: the whole body, or a rank's local view (owned, then ghosts) */
  PetscInt  *global;      /* a local view (src/disc/halo.c): each particle's global index; NULL: the whole body */
  PetscReal *x;           /* 3 per particle (z = 0 in 2D) */
  PetscReal *volume;      /* includes the thickness in 2D */
  PetscReal *spacing;     /* the particle's own grid spacing, for partial volumes */
  PetscInt  *source_line; /* line in the CSV file (0 for grid particles), for messages */
  PetscReal  thickness;   /* 2D only */
  PetscReal  lower[3], upper[3];
  PetscBool  periodic[3];
  PetscReal  mean_spacing;
  /* fictitious boundary layers (src/system/layers.c): NULL when the scene has none */
  PetscInt      *image;   /* -1 for a particle of the body; else the body particle it mirrors */
  unsigned char *crossed; /* faces crossed to reach the particle: bit 2 axis + (upper face) */
  PetscInt       nfictitious;
  /* the named physical groups of particles.mesh (src/disc/mesh.c): NULL otherwise */
  PetscInt                 ngroups;
  struct _n_PeriMeshGroup *groups;
} PeriParticles;

#define PeriParticleIsFictitious(pt, k) ((pt)->image && (pt)->image[k] >= 0)

/* The global index of particle k of p (p may be a rank's local view). */
static inline PetscInt PeriParticleGlobal(const PeriParticles *p, PetscInt k)
{
  return p->global ? p->global[k] : k;
}

/* ------------------------------------------------------------------ bonds (src/neighbors.c, src/corrections.c) */
typedef enum {
  PERI_PARTIAL_VOLUME_NONE,
  PERI_PARTIAL_VOLUME_LINEAR,
  PERI_PARTIAL_VOLUME_LINEAR_CONTINUED
} PeriPartialVolume;
PETSC_EXTERN const char *const PeriPartialVolumes[];

typedef enum {
  PERI_SURFACE_NONE,
  PERI_SURFACE_VOLUME,
  PERI_SURFACE_ENERGY
} PeriSurfaceCorrection;
PETSC_EXTERN const char *const PeriSurfaceCorrections[];

/* Bonds are stored once per pair, in the row of the smaller global index (CSR over owned particles). */
typedef struct {
  PetscInt       rstart, rend; /* the rows: indices of the particles searched (a local view: its owned particles 0 .. nowned - 1) */
  PetscInt      *offset;       /* rend - rstart + 1 */
  PetscInt      *j;            /* the other particle, a local index of the particles searched (the pair's row is its smaller global index; j == i only for periodic self-images) */
  PetscReal     *xi;           /* 3 per bond: X_j - X_i, minimum image on periodic axes; NULL when not stored (no_geometry, PeriBondsReleaseGeometry) */
  PetscReal     *length;
  PetscReal     *alpha;       /* partial-volume factor */
  PetscReal     *lambda;      /* surface correction factor; NULL: all 1 (searches without geometry, surface: none) */
  unsigned char *live;        /* 1 intact, 0 broken */
  unsigned char *cause;       /* scenes with failure: why a dead bond broke (PeriFailureCause) */
  PetscReal     *intact;      /* softening bonds (Diana & Casolo eqs. 45-46): the remaining share of stiffness in (0, 1]; NULL otherwise */
  PetscInt       nbonds;      /* local */
  PetscBool      no_geometry; /* set before the search: xi, length and alpha are not stored (NULL), and readers recompute them from the coordinates (PeriDiscBondGeometry) */
} PeriBonds;

typedef struct {
  PetscReal E, nu, K, G; /* Young's modulus, Poisson ratio, 3D bulk and shear moduli */
  PetscReal rho;         /* density (0 when the scene gives none) */
  PetscReal thickness;   /* 2D */
} PeriMaterial;

/* One bond as the kernels see it: plain data, no PETSc objects. */
typedef struct {
  PetscInt  i, j;
  PetscReal xi[3], length;
  PetscReal Vi, Vj;
  PetscReal weight; /* alpha * lambda */
  PetscReal mu;     /* the bond's shear modulus across materials (Oterkus & Madenci eq. 60); 0: the material's */
  PetscInt  bond;   /* 1 + its index in the system's bond list; 0 for other geometry (families, unit cells): keys per-bond caches */
} PeriBondGeometry;
