/* Helpers for perilin's tests: run a scene through the library and assert numbers. */
#pragma once
#include "perilin/private/problem.h"

/* Fails the test with the expected value, the tolerance and what was measured. */
#define PeriTestClose(what, got, expected, tol)                                                                                                                                                                                   \
  do {                                                                                                                                                                                                                            \
    PetscReal got_ = (got), exp_ = (expected), tol_ = (tol);                                                                                                                                                                      \
    PetscCheck(PetscAbsReal(got_ - exp_) <= tol_, PETSC_COMM_SELF, PETSC_ERR_PLIB, "%s: got %.12g, expected %.12g within %.3g (off by %.3g)", what, (double)got_, (double)exp_, (double)tol_, (double)PetscAbsReal(got_ - exp_)); \
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "ok: %s = %.10g (expected %.10g, tolerance %.2g)\n", what, (double)got_, (double)exp_, (double)tol_));                                                                                \
  } while (0)

PetscErrorCode PeriTestRunScene(MPI_Comm, const char[], PeriProblem *);
PetscErrorCode PeriTestSetOption(const char[], const char[]);
PetscErrorCode PeriTestSlope(MPI_Comm, PetscInt, const PetscReal[], PetscInt, const PetscReal[], PetscInt, const PetscBool[], PetscReal *);

/* The analysis' results (its data) when the problem ran an analysis of that type, else NULL. */
static inline PeriModal *PeriTestModal(PeriProblem p)
{
  return p->analysis && !strcmp(p->analysis->type->name, "modal") ? (PeriModal *)p->analysis->data : NULL;
}
static inline PeriQuasistatic *PeriTestQuasistatic(PeriProblem p)
{
  return p->analysis && !strcmp(p->analysis->type->name, "quasistatic") ? (PeriQuasistatic *)p->analysis->data : NULL;
}

/* Local views in unit tests (issue 17): a grid of cells[0] x cells[1] x cells[2] particles spaced
 * 0.1 apart, owned by contiguous blocks of the x-fastest cell index or scattered (cell k on rank
 * k mod P), every rank holding the whole grid to check against. */
typedef struct {
  PetscInt  dim, cells[3];
  PetscBool periodic[3];
  PetscBool scattered;
} PeriTestGrid;

PetscErrorCode PeriTestGridCreate(const PeriTestGrid *, PetscMPIInt, PetscInt *, PetscReal **, PetscMPIInt **, PetscInt **);
PetscErrorCode PeriTestGridOwned(const PeriTestGrid *, PetscMPIInt, PetscInt, const PetscReal[], const PetscMPIInt[], PeriParticles *);
PetscReal      PeriTestGridDistance(const PeriTestGrid *, const PetscReal[], const PetscReal[]);
