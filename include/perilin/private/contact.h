/* Contact (src/system/contact.c) and rigid impactors (src/system/impactors.c): interaction terms
 * that are not linear, added to the internal force of a transient analysis (PeriSystemInternalForce)
 * with their own energy (docs/contact.md).
 *
 * Contact between particles: every pair closer than d_ij = min(0.9 |X_j - X_i|, r_c) in the
 * deformed body repels with the short-range force of LAMMPS's peri pair styles and Peridigm's
 * short-range force, k V_i V_j (d_ij - r)/delta, from the energy k V_i V_j (d_ij - r)^2/(2 delta).
 * It acts between particles without a live bond: fragments, the faces of a crack, separate bodies
 * (a pair whose bond only the other rank holds is kept, and feels it only past 10 % compression). Candidate pairs
 * come from cells over the deformed positions with a skin, rebuilt when a particle has moved more
 * than half the skin since the last build.
 *
 * An impactor is a rigid body (sphere, cylinder, flat punch) of given mass and initial velocity in
 * penalty contact with the particles: a particle at depth p inside it is pushed out along the
 * surface's normal by k V_i^2 p/delta (the pair force against a particle of its own volume). It
 * moves with the body's time step by the same scheme (PETSc's velocity Verlet: drift half a step,
 * kick with the force there, drift half a step), so that momentum is conserved to round-off. */
#pragma once

#include <petscvec.h>
#include "perilin/scene.h"
#include "perilin/private/output.h"

typedef struct _p_PeriSystem *PeriSystem;

typedef enum {
  PERI_IMPACTOR_SPHERE,
  PERI_IMPACTOR_CYLINDER,
  PERI_IMPACTOR_PUNCH
} PeriImpactorShape;
PETSC_EXTERN const char *const PeriImpactorShapes[];

typedef struct {
  PeriImpactorShape shape;
  PetscReal         axis[3];       /* cylinder: its axis; punch: the face's normal, towards the body (unit) */
  PetscReal         radius;        /* sphere, cylinder; punch: the face's radius */
  PetscReal         length;        /* cylinder: its length along axis (2D: a disc, unused) */
  PetscReal         mass, k;       /* its mass; the penalty stiffness k (force k V_i^2 p / delta) */
  PetscReal         x[3], v[3], t; /* the centre and velocity at time t */
  PetscReal         force[3];      /* the particles' force on it in the last step */
  PetscReal         x0[3], v0[3];  /* at t = 0 */
} PeriImpactor;

typedef struct {
  PetscBool      on;                 /* contact: given */
  PetscReal      radius, k, skin;    /* r_c, the stiffness k, the skin of the candidate list */
  PetscReal      delta;              /* the horizon the force is scaled by */
  PetscInt       npairs, cap, *pair; /* candidates: (i owned, j local, the bond joining them or -1) */
  PetscReal     *ubuild;             /* the local translations at the last build (3 per particle) */
  PetscInt       builds;             /* candidate lists built */
  PetscReal      reach;              /* several ranks: the ghosts hold every pair while the spread of u stays below this */
  PetscReal      ghost_margin;       /* several ranks: contact.ghosts, how much farther than the bonds the ghosts reach */
  PetscReal      t;                  /* the time of the next evaluation (the impactors' positions) */
  PetscBool      record;             /* the next evaluation is the step's force: keep the impactors' */
  PetscReal      fstep[12];          /* this rank's share of each impactor's force in the step */
  PetscInt       nimpactors;
  PeriImpactor   impactors[4];
  PetscLogDouble seconds;                   /* spent in contact forces */
  PetscInt       tally_pairs, tally_builds; /* over the ranks, at the end (PeriContactTally) */
  PetscLogDouble tally_seconds;
} PeriContact;

PETSC_EXTERN const PeriSchema PeriContactSchema[];
PETSC_EXTERN PetscErrorCode   PeriContactSetUp(PeriSystem);
PETSC_EXTERN PetscBool        PeriContactActive(PeriSystem);
PETSC_EXTERN PetscErrorCode   PeriContactSetTime(PeriSystem, PetscReal, PetscBool);
PETSC_EXTERN PetscErrorCode   PeriContactCheckReach(PeriSystem, Vec);
PETSC_EXTERN PetscErrorCode   PeriContactGhostMargin(PeriSystem, PetscReal *);
PETSC_EXTERN PetscErrorCode   PeriContactTally(PeriSystem);
PETSC_EXTERN PetscErrorCode   PeriContactSummary(PeriSystem, PeriJSON);
PETSC_EXTERN PetscErrorCode   PeriContactDestroy(PeriContact *);
/* impactors (src/system/impactors.c) */
PETSC_EXTERN PetscErrorCode PeriImpactorsSetUp(PeriSystem);
PETSC_EXTERN void           PeriImpactorsAddForce(PeriSystem, const PetscScalar[], PetscScalar[], PetscReal[], PetscReal *);
PETSC_EXTERN PetscErrorCode PeriImpactorsAdvance(PeriSystem, PetscReal);
PETSC_EXTERN PetscReal      PeriImpactorsKinetic(PeriSystem);
PETSC_EXTERN void           PeriImpactorsAddRowSums(PeriSystem, PetscScalar[]);
