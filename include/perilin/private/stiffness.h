/* The stiffness operator of the system (src/system/assembly.c, operator.c, solve.c): K assembled or
 * applied bond by bond, the matrix that preconditions a matrix-free K, and the checked linear solve
 * K u = f with the prescribed DOFs eliminated. */
#pragma once

#include <petscksp.h>
#include "perilin/private/disc.h"

typedef struct _p_PeriSystem *PeriSystem;

/* How K is applied (solver.operator, src/system/operator.c), and the bodies small enough for
 * CG + Jacobi on a matrix-free K (PeriSystemAssemble). */
#define PERI_JACOBI_MAX_PARTICLES       500000
#define PERI_JACOBI_MAX_SPAN            200
#define PERI_JACOBI_MAX_SPAN_2D         64    /* 2D shear and micropolar bodies held at points, assembled or not (tests/perf/defaults.sh: the pinned mppd lamina at 61 spacings runs Jacobi in 0.046 s, the multigrid in 0.058 s) */
#define PERI_JACOBI_MAX_SPAN_2D_CLAMPED 48    /* the same clamped along an edge, where the multigrid applies (the clamped gerstle lamina, the default Jacobi over the fastest: 1.06 at 40 spacings, Jacobi the fastest; 1.18 at 50 and 1.35 at 60, the multigrid the fastest) */
#define PERI_JACOBI_MAX_SPAN_ANTIPLANE  100   /* 2D antiplane bodies (one DOF per particle) without bond failure, assembled (tests/perf/defaults.sh: bimaterial, square_bar, rect_bar, all at 100 spacings, fastest with Jacobi, GAMG 1.02-1.31x; torsion_edge_crack at 200 keeps GAMG) */
#define PERI_MG_MIN_PARTICLES_3D        30000 /* 3D grid bodies: the geometric multigrid from here on, Jacobi below */
#define PERI_JACOBI_BUDGET              400   /* iterations, about the cost of GAMG's set-up and solve */
typedef enum {
  PERI_OPERATOR_AUTO,
  PERI_OPERATOR_ASSEMBLED,
  PERI_OPERATOR_MATRIX_FREE
} PeriOperatorKind;
PETSC_EXTERN const char *const  PeriOperatorKinds[];
typedef struct _p_PeriOperator *PeriOperator;

/* The bonds of the short-range stiffness that preconditions a matrix-free K, chosen per particle
 * of the local view so that a graded body keeps every particle in it: a bond enters when it is no
 * longer than the larger reach of its ends (pc_radius times that end's 2 dim-th shortest bond), its block
 * scaled by the mean of its ends' scales (what the particle's whole family stores under a uniform
 * expansion over what its short bonds store). */
typedef struct {
  PetscReal *reach, *scale;
} PeriShortRange;

/* Whether bond k of particle i is in the short-range stiffness sr (NULL: every bond). */
static inline PetscBool PeriShortRangeHolds(const PeriShortRange *sr, const PeriDisc *d, PetscInt i, PetscInt k)
{
  return (PetscBool)(!sr || PeriDiscBondLength(d, i, k) <= PetscMax(sr->reach[i], sr->reach[d->bonds.j[k]]));
}

/* The factor of bond k of particle i in the short-range stiffness sr, 0 when it is not in it
 * (sr NULL: every bond, factor 1). */
static inline PetscReal PeriShortRangeFactor(const PeriShortRange *sr, const PeriDisc *d, PetscInt i, PetscInt k)
{
  if (!sr) return 1;
  return PeriShortRangeHolds(sr, d, i, k) ? 0.5 * (sr->scale[i] + sr->scale[d->bonds.j[k]]) : 0;
}

/* What an analysis asks of the stiffness, declared in its type (PeriAnalysisType.needs): the memory
 * estimate and K's defaults read it, so that no file of the system names an analysis. */
typedef struct {
  PetscBool matrix_free;         /* uses K through MatMult and PeriStiffnessScaleBond only: K may be matrix-free (solver.operator) */
  PetscBool static_solver;       /* solves with the static KSP, K of its default type (PeriStaticDefaultMatType); else K is AIJ */
  PetscReal matrix_copies;       /* copies of K it holds beside K (the quasi-static loop solves on one: 1) */
  PetscBool operator_only;       /* applies K only through its product (explicit dynamics): no matrix at all where the operator applies the model */
  PetscReal factor_fill;         /* a direct factorization of K, its fill in matrices per log2(particles) (nested dissection measured 0.45), or 0 */
  PetscReal iterative_dofs;      /* from this many DOFs on it solves iteratively by default (no factorization, K matrix-free where the operator applies), or 0 */
  PetscReal iterative_dofs_grid; /* the same for a grid body, where it takes the iterative solver sooner (0: as iterative_dofs) */
  PetscBool transient;           /* runs in time: loads may carry an amplitude (loads.<k>.amplitude) */
  PetscBool dry_run;             /* checks any analysis' scene (setup): what only time uses is read and checked, not refused */
} PeriSystemNeeds;

/* How the geometric multigrid (src/system/multigrid.c) gets the coarse levels of a system: the
 * system's own factory (src/system/system.c), so that the solver, below the system's set-up,
 * calls it without depending on it. */
typedef struct {
  PetscErrorCode (*create)(PeriSystem, PetscInt, PeriSystem *); /* level l of the scene, set up */
  PetscErrorCode (*destroy)(PeriSystem *);
} PeriLevelFactory;

/* An interaction term besides the model's bonds (contact today; docs/design.md, 'Interaction
 * terms'): its force, energy and Gershgorin row sums at a displacement, which the system's
 * PeriSystemInternalForce, PeriSystemStrainEnergy and PeriSystemStiffnessRowSums add to those of
 * the bonds. A term registers itself at the system's set-up (PeriSystemAddTerm) when the scene
 * turns it on; the analyses never call it by name. An op may be NULL. */
typedef struct {
  const char *name;
  PetscErrorCode (*add_force)(PeriSystem, Vec u, Vec f);     /* f += the term's internal force at u */
  PetscErrorCode (*energy)(PeriSystem, Vec u, PetscReal *E); /* its energy at u, summed over the ranks */
  PetscErrorCode (*add_row_sums)(PeriSystem, Vec rows);      /* rows += a bound of its Jacobian's absolute row sums */
} PeriTermOps;
#define PERI_MAX_TERMS 4

/* K and how it is applied and solved. */
typedef struct {
  Mat                K;                       /* stiffness: assembled, or a MATSHELL over op */
  Mat                Kpc;                     /* with op: the assembled short-range stiffness that preconditions K */
  PeriOperator       op;                      /* solver.operator: matrix_free, else NULL */
  PeriOperatorKind   operator_kind;           /* solver.operator */
  PetscReal          pc_radius;               /* solver.pc_radius */
  char               pc_default[16];          /* the static solve's PC unless -pc_type: gamg, or jacobi (matrix-free K on a small 3D body) */
  char               mat_type[PERI_NAME_LEN]; /* default type of K, before -mat_type */
  PeriSystemNeeds    needs;                   /* the analysis' (PeriSystemSetNeeds), before the set-up */
  PetscReal          residual_tol;            /* solver.residual_tol: the largest true relative residual accepted (0: the default) */
  PeriLevelFactory   levels;                  /* coarse versions of the system, for the geometric multigrid */
  const PeriTermOps *terms[PERI_MAX_TERMS];   /* the interaction terms besides the bonds */
  PetscInt           nterms;
} PeriStiffness;

PETSC_EXTERN PetscErrorCode PeriSystemAssemble(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriSystemGetJacobian(PeriSystem, Mat *);
PETSC_EXTERN PetscErrorCode PeriSystemInternalForce(PeriSystem, Vec, Vec);
PETSC_EXTERN PetscErrorCode PeriSystemInternalForceParts(PeriSystem, Vec, Vec, Vec);
PETSC_EXTERN PetscErrorCode PeriSystemStrainEnergy(PeriSystem, Vec, Vec, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriSystemStrainEnergyFromProduct(PeriSystem, Vec, Vec, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriSystemStiffnessRowSums(PeriSystem, Vec);
PETSC_EXTERN PetscErrorCode PeriSystemAddTerm(PeriSystem, const PeriTermOps *);
PETSC_EXTERN const char    *PeriMatrixFreeWhyNot(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriAssembleStiffness(PeriSystem, Mat *);
PETSC_EXTERN PetscErrorCode PeriBondStiffness(PeriSystem, PetscInt, PetscInt, PetscReal, PeriBondGeometry *, PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriRigidModes(PeriSystem, PetscInt *, Vec[], PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriSetNearNullSpace(PeriSystem, Mat, IS);
PETSC_EXTERN PetscErrorCode PeriMatrixMB(Mat, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriStiffnessRowSums(PeriSystem, Vec);
PETSC_EXTERN PetscErrorCode PeriAssembleShortRange(PeriSystem, const PeriShortRange *, PetscReal, Mat *);
PETSC_EXTERN PetscErrorCode PeriStiffnessScaleBond(PeriSystem, PetscInt, PetscInt, PetscReal, const PetscReal[], PetscReal *);
PETSC_EXTERN PetscErrorCode PeriStiffnessScaled(PeriSystem);
PETSC_EXTERN const char    *PeriOperatorWhyNotModel(PeriModel);
PETSC_EXTERN PetscErrorCode PeriOperatorCreate(PeriSystem, PetscReal, PeriOperator *);
PETSC_EXTERN PetscErrorCode PeriOperatorPreconditioner(PeriSystem);
PETSC_EXTERN PetscBool      PeriOperatorServesPC(const char[]);
PETSC_EXTERN PetscBool      PeriOperatorPCWithoutMatrix(const char[]);
PETSC_EXTERN PetscErrorCode PeriOperatorCreateMat(PeriSystem, Mat *);
PETSC_EXTERN PetscErrorCode PeriOperatorMatHeld(Mat, PetscReal *, PetscInt *, const PetscInt **);
PETSC_EXTERN PetscErrorCode PeriOperatorRowSums(PeriSystem, Vec);
PETSC_EXTERN PetscErrorCode PeriOperatorMemoryMB(PeriSystem, PeriOperator, PetscReal *);
PETSC_EXTERN PetscErrorCode PeriOperatorScaleBond(PeriSystem, PetscInt, PetscInt, PetscReal, const PetscReal[]);
PETSC_EXTERN PetscErrorCode PeriOperatorScaled(PeriSystem);
PETSC_EXTERN PetscErrorCode PeriOperatorDestroy(PeriOperator *);
PETSC_EXTERN PetscErrorCode PeriStaticKSPCreate(PeriSystem, PetscBool, KSP *);
PETSC_EXTERN PetscErrorCode PeriStaticSolve(PeriSystem, KSP *, PetscReal, PetscBool, PetscInt, const PetscInt[], const PetscReal[], KSPConvergedReason *);
PETSC_EXTERN PetscErrorCode PeriStaticPieces(PeriSystem, PetscInt *, PetscInt **, PetscReal **);
PETSC_EXTERN PetscErrorCode PeriStaticCheckConverged(PeriSystem, KSPConvergedReason);
PETSC_EXTERN PetscErrorCode PeriStaticConverged(PeriSystem, KSP, KSPConvergedReason, PetscBool *);
PETSC_EXTERN PetscErrorCode PeriStaticDefaultMatType(char[], size_t);
PETSC_EXTERN PetscReal      PeriResidualTolerance(PeriSystem, PetscReal);
PETSC_EXTERN PetscErrorCode PeriStiffnessDestroy(PeriStiffness *);
