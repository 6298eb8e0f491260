/* The period error of PETSc's TSALPHA2 (generalized-alpha for second-order systems, Chung &
 * Hulbert, in PETSc's parametrization by the spectral radius rho at infinite frequency:
 * alpha_m = (2 - rho)/(1 + rho), alpha_f = 1/(1 + rho), gamma = 1/2 + alpha_m - alpha_f,
 * beta = (1 + alpha_m - alpha_f)^2 / 4) on one undamped mode u'' + w^2 u = 0 at the step h: the
 * discrete oscillation's angle per step, theta, from the amplification matrix's complex pair, and
 * the relative period error w h / theta - 1. rho = 1 is the trapezoidal rule, whose theta is
 * 2 atan(w h / 2) (tests/dynamics.sh checks the two agree). The dynamic analysis reports the
 * highest frequency its step resolves within 1 %. */
#include "perilin/private/analysis.h"

/* One step of the scheme on u'' + x^2 u = 0 with h = 1: (u, v, a) -> (u', v', a'). */
static void AlphaStep(PetscReal rho, PetscReal x, const PetscReal s[3], PetscReal t[3])
{
  const PetscReal am = (2 - rho) / (1 + rho), af = 1 / (1 + rho), g = 0.5 + am - af, b = 0.25 * PetscSqr(1 + am - af), x2 = x * x;
  const PetscReal u = s[0], v = s[1], a = s[2];

  t[2] = -((1 - am) * a + x2 * (u + af * (v + (0.5 - b) * a))) / (am + x2 * af * b);
  t[0] = u + v + (0.5 - b) * a + b * t[2];
  t[1] = v + (1 - g) * a + g * t[2];
}

/* The relative period error of a mode with w h = x (PETSC_INFINITY where the step does not
 * oscillate). */
PetscReal PeriAlpha2PeriodError(PetscReal rho, PetscReal x)
{
  PetscReal A[3][3], c2, c1, c0, lo, hi, r = 0, p, q, disc;

  for (int k = 0; k < 3; k++) {
    PetscReal s[3] = {k == 0, k == 1, k == 2}, t[3];
    AlphaStep(rho, x, s, t);
    for (int i = 0; i < 3; i++) A[i][k] = t[i];
  }
  /* characteristic polynomial l^3 + c2 l^2 + c1 l + c0 */
  c2 = -(A[0][0] + A[1][1] + A[2][2]);
  c1 = A[0][0] * A[1][1] - A[0][1] * A[1][0] + A[0][0] * A[2][2] - A[0][2] * A[2][0] + A[1][1] * A[2][2] - A[1][2] * A[2][1];
  c0 = -(A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]));
  /* the real (spurious) root by bisection within the Cauchy bound, then the quadratic left */
  hi = 1 + PetscMax(PetscAbsReal(c2), PetscMax(PetscAbsReal(c1), PetscAbsReal(c0)));
  lo = -hi;
  for (int it = 0; it < 200; it++) {
    r = 0.5 * (lo + hi);
    if (((r + c2) * r + c1) * r + c0 > 0)
      hi = r;
    else
      lo = r;
  }
  p    = c2 + r; /* l^2 + p l + q = the cubic / (l - r) */
  q    = c1 + r * p;
  disc = 4 * q - p * p;
  if (disc <= 0) return PETSC_INFINITY;
  return x / PetscAtan2Real(0.5 * PetscSqrtReal(disc), -0.5 * p) - 1; /* theta: the pair's angle */
}

/* The highest frequency (1/time) whose period error at the step h is at most tol. */
PetscReal PeriAlpha2ResolvedFrequency(PetscReal rho, PetscReal h, PetscReal tol)
{
  PetscReal lo = 0, hi = PETSC_PI;

  for (int it = 0; it < 100; it++) {
    const PetscReal mid = 0.5 * (lo + hi);
    if (PeriAlpha2PeriodError(rho, mid) > tol)
      hi = mid;
    else
      lo = mid;
  }
  return lo / (2 * PETSC_PI * h);
}
