/* Lattice-consistent calibration (model.calibration: lattice), shared by the bond models.
 *
 * A model calibrated on the continuous horizon gets the energy of a homogeneous strain right only
 * where its discrete family sums equal the horizon integrals. Every energy of a homogeneous strain
 * is a moment of the family: the sum over the bonds of w = alpha lambda V_j p(|xi|) times a
 * polynomial of the bond direction e, of degree 4 for displacement vectors (stretch^2 and
 * sliding^2 are quartic in e) and of degree 2 for one antiplane component. p is the spring's
 * length profile (pmb: |xi|). The continuum's moments are isotropic, S times the mean of the
 * monomial over the unit circle or sphere, with S = int_H p dV. A grid's are not: they miss S by a
 * few per cent and carry the grid's anisotropy (5 % in the fourth moments at m = 3 in 2D).
 *
 * So each particle i gets a multiplier for its bonds, scale_i mu_i(e): mu_i is the polynomial of
 * that degree in e closest to 1 (least squares with the weights w) that makes the family's moments
 * isotropic with the family's own sum S_i, and scale_i = S / S_i. A bond's factor is the mean of
 * its two ends' multipliers (the bond stays symmetric). The family's moments then equal the
 * continuum's, so the continuum micromoduli reproduce the target elasticity exactly for every
 * homogeneous strain wherever a particle and its neighbours share a family shape, at surfaces,
 * corners and cracks too (docs/models/lattice.md). Where no polynomial of the degree makes the
 * family isotropic (too few directions), the particle keeps mu = 1, its scale only, as npmb; where
 * the polynomial would turn a bond's multiplier below a tenth (a lopsided family, as at a corner),
 * the particle takes the largest part of it that keeps them all at a tenth. The calibration warns
 * how many did either. */
#include <perilin/model.h>
#include <petscblaslapack.h>

#define LATTICE_MAX_BASIS 15 /* degree-4 monomials in 3D */
#define LATTICE_MAX_MOM   45 /* degree-8 monomials in 3D */
#define LATTICE_MIN_MU    0.1
#define LATTICE_DEGREE    4 /* the largest degree */

struct _n_PeriLattice {
  PetscInt   n, dim, degree, nbasis;
  PetscInt   a[LATTICE_MAX_BASIS][3];                    /* the basis's exponents */
  PetscInt   gram[LATTICE_MAX_BASIS][LATTICE_MAX_BASIS]; /* the moment of a_k + a_l */
  PetscReal  iso[LATTICE_MAX_BASIS];                     /* <e^a_k> */
  PetscReal  unit[LATTICE_MAX_MOM];                      /* (e.e)^degree in the moments' monomials */
  PetscReal *scale;                                      /* per particle (global index) */
  PetscReal *coef;                                       /* per particle: nbasis coefficients of mu_i */
  PetscInt   kept;                                       /* particles that kept mu = 1: no polynomial of the degree makes them isotropic */
  PetscInt   damped;                                     /* particles that took part of their polynomial */
  PeriPatch  patch;                                      /* model.calibration: patch, the global correction on top (models/patch.c); else NULL */
};

/* monomials of total degree D in dim variables, in a fixed order: exponents of the k-th */
static PetscInt NumMonomials(PetscInt dim, PetscInt D)
{
  return dim == 2 ? D + 1 : (D + 1) * (D + 2) / 2;
}

static void Exponents(PetscInt dim, PetscInt D, PetscInt k, PetscInt a[3])
{
  PetscInt idx = 0;
  a[0] = a[1] = a[2] = 0;
  if (dim == 2) {
    a[0] = D - k;
    a[1] = k;
    return;
  }
  for (PetscInt x = D; x >= 0; x--)
    for (PetscInt y = D - x; y >= 0; y--, idx++)
      if (idx == k) {
        a[0] = x;
        a[1] = y;
        a[2] = D - x - y;
        return;
      }
}

static PetscInt MonomialIndex(PetscInt dim, PetscInt D, const PetscInt a[3])
{
  if (dim == 2) return a[1];
  /* rows x = D, D-1, ... hold D - x + 1 monomials each */
  return (D - a[0]) * (D - a[0] + 1) / 2 + (D - a[0] - a[1]);
}

/* pw[d][p] = e_d^p for p <= D */
static void Powers(const PetscReal e[3], PetscInt D, PetscReal pw[3][2 * LATTICE_DEGREE + 1])
{
  for (PetscInt d = 0; d < 3; d++) {
    pw[d][0] = 1;
    for (PetscInt p = 1; p <= D; p++) pw[d][p] = pw[d][p - 1] * e[d];
  }
}

static PetscReal DoubleFactorial(PetscInt n)
{
  PetscReal r = 1;
  for (PetscInt k = n; k > 1; k -= 2) r *= k;
  return r;
}

/* the mean of e^a over the unit circle (dim 2) or sphere (dim 3): (a-1)!!(b-1)!!(c-1)!!/(|a|+dim-2)!! */
static PetscReal IsotropicMean(PetscInt dim, const PetscInt a[3])
{
  if (a[0] % 2 || a[1] % 2 || a[2] % 2) return 0;
  return DoubleFactorial(a[0] - 1) * DoubleFactorial(a[1] - 1) * DoubleFactorial(a[2] - 1) / DoubleFactorial(a[0] + a[1] + a[2] + dim - 2);
}

/* the multinomial coefficient of e^a in (e.e)^(D/2): sum_a coef e^a = 1 on the unit sphere */
static PetscReal UnitCoefficient(const PetscInt a[3])
{
  PetscInt  h[3] = {a[0] / 2, a[1] / 2, a[2] / 2};
  PetscReal r    = 1;
  if (a[0] % 2 || a[1] % 2 || a[2] % 2) return 0;
  for (PetscInt k = 1; k <= h[0] + h[1] + h[2]; k++) r *= k;
  for (PetscInt d = 0; d < 3; d++)
    for (PetscInt k = 1; k <= h[d]; k++) r /= k;
  return r;
}

/* int_H p(|xi|) dV by 8-point Gauss-Legendre on [0, delta] (exact for the polynomial profiles times
 * the radial measure r dr or r^2 dr; 1/|xi| times r is constant) */
static PetscReal HorizonIntegral(PeriModel m, PetscReal (*profile)(PeriModel, PetscReal))
{
  static const PetscReal x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
  static const PetscReal w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  PetscReal              s = 0, h = 0.5 * m->delta;
  for (PetscInt k = 0; k < 8; k++) {
    PetscReal r = h * (1 + (k < 4 ? -x[k] : x[k - 4])), wk = w[k % 4] * h;
    s += wk * profile(m, r) * (m->dim == 2 ? 2 * PETSC_PI * r * m->material.thickness : 4 * PETSC_PI * r * r);
  }
  return s;
}

/* the degree-2D moments of every particle's family, summed over both ends of this rank's bonds and
 * then over the ranks holding the particle; mom is n x nmom */
static PetscErrorCode FamilyMoments(PeriModel m, const PeriCalibrationData *data, PetscInt D2, PetscReal (*profile)(PeriModel, PetscReal), PetscReal mom[])
{
  const PeriBonds     *b    = data->bonds;
  const PeriParticles *pt   = data->particles;
  const PetscInt       nmom = NumMonomials(m->dim, D2);
  PetscInt             a[LATTICE_MAX_MOM][3];

  PetscFunctionBeginUser;
  for (PetscInt q = 0; q < nmom; q++) Exponents(m->dim, D2, q, a[q]);
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      const PetscInt  j = b->j[k];
      const PetscReal L = b->length[k], w = b->alpha[k] * b->lambda[k] * profile(m, L);
      PetscReal       e[3] = {b->xi[3 * k] / L, b->xi[3 * k + 1] / L, m->dim == 3 ? b->xi[3 * k + 2] / L : 0}, pw[3][2 * LATTICE_DEGREE + 1];
      if (j == i) continue; /* a periodic self-image: no energy in a periodic field */
      Powers(e, D2, pw);
      for (PetscInt q = 0; q < nmom; q++) {
        PetscReal v = pw[0][a[q][0]] * pw[1][a[q][1]] * pw[2][a[q][2]];
        mom[i * nmom + q] += w * pt->volume[j] * v;
        mom[j * nmom + q] += w * pt->volume[i] * v;
      }
    }
  PetscCall(data->combine(data, MPIU_REAL, nmom, MPI_SUM, mom));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The minimum-norm least-squares solution of the nb x nb system G c = r (LAPACK's SVD solver; G
 * is singular where the family has fewer directions than the basis has monomials, a small horizon,
 * and the system may still be consistent). False when it is not: no polynomial of the basis makes
 * this family isotropic. */
static PetscBool SolveSmall(PetscInt nb, const PetscReal G[], PetscReal r[])
{
  PetscReal    A[LATTICE_MAX_BASIS * LATTICE_MAX_BASIS], x[LATTICE_MAX_BASIS], sv[LATTICE_MAX_BASIS], work[64 * LATTICE_MAX_BASIS], rcond = 1e-12, res = 0, rn = 0;
  PetscBLASInt n = (PetscBLASInt)nb, one = 1, rank, lwork = 64 * LATTICE_MAX_BASIS, info;

  for (PetscInt k = 0; k < nb * nb; k++) A[k] = G[k];
  for (PetscInt k = 0; k < nb; k++) x[k] = r[k];
  LAPACKgelss_(&n, &n, &one, A, &n, x, &n, sv, &rcond, &rank, work, &lwork, &info);
  if (info) return PETSC_FALSE;
  for (PetscInt k = 0; k < nb; k++) {
    PetscReal t = -r[k];
    for (PetscInt l = 0; l < nb; l++) t += G[k * nb + l] * x[l];
    res += t * t;
    rn += r[k] * r[k];
  }
  if (res > 1e-16 * rn) return PETSC_FALSE;
  for (PetscInt k = 0; k < nb; k++) r[k] = x[k];
  return PETSC_TRUE;
}

/* mu = 1 written in the basis: the coefficients of (e.e)^(D/2) */
static void UnitPolynomial(PeriLattice lat, PetscReal coef[])
{
  PetscInt a[3];
  for (PetscInt k = 0; k < lat->nbasis; k++) {
    Exponents(lat->dim, lat->degree, k, a);
    coef[k] = UnitCoefficient(a);
  }
}

/* the tables ParticlePolynomial uses: exponents, Gram indices, isotropic means, unit polynomial */
static void Tables(PeriLattice lat)
{
  const PetscInt D2 = 2 * lat->degree;
  PetscInt       a[3], s[3];
  for (PetscInt k = 0; k < lat->nbasis; k++) {
    Exponents(lat->dim, lat->degree, k, lat->a[k]);
    lat->iso[k] = IsotropicMean(lat->dim, lat->a[k]);
  }
  for (PetscInt k = 0; k < lat->nbasis; k++)
    for (PetscInt l = 0; l < lat->nbasis; l++) {
      for (PetscInt d = 0; d < 3; d++) s[d] = lat->a[k][d] + lat->a[l][d];
      lat->gram[k][l] = MonomialIndex(lat->dim, D2, s);
    }
  for (PetscInt q = 0; q < NumMonomials(lat->dim, D2); q++) {
    Exponents(lat->dim, D2, q, a);
    lat->unit[q] = UnitCoefficient(a);
  }
}

/* Cholesky, the fast path for a well-conditioned G (LAPACK dpotrf/dpotrs); false when G is not
 * safely positive definite */
static PetscBool SolveCholesky(PetscInt nb, const PetscReal G[], PetscReal r[])
{
  PetscReal    A[LATTICE_MAX_BASIS * LATTICE_MAX_BASIS], x[LATTICE_MAX_BASIS], dmin = PETSC_MAX_REAL, gmax = 0;
  PetscBLASInt n = (PetscBLASInt)nb, one = 1, info;

  for (PetscInt k = 0; k < nb * nb; k++) A[k] = G[k];
  for (PetscInt k = 0; k < nb; k++) x[k] = r[k];
  LAPACKpotrf_("L", &n, A, &n, &info);
  if (info) return PETSC_FALSE;
  for (PetscInt k = 0; k < nb; k++) {
    dmin = PetscMin(dmin, A[k * nb + k] * A[k * nb + k]);
    gmax = PetscMax(gmax, G[k * nb + k]);
  }
  if (dmin <= 1e-10 * gmax) return PETSC_FALSE;
  LAPACKpotrs_("L", &n, &one, A, &n, x, &n, &info);
  if (info) return PETSC_FALSE;
  for (PetscInt k = 0; k < nb; k++) r[k] = x[k];
  return PETSC_TRUE;
}

/* particle i's polynomial from its moments: the weighted least-squares fit
 * sum_l G_kl c_l = S_i <e^a_k>, G_kl = sum_j w_j e^(a_k + a_l) */
static PetscBool ParticlePolynomial(PeriLattice lat, const PetscReal mom[], PetscReal coef[], PetscReal *S)
{
  const PetscInt nb = lat->nbasis;
  PetscReal      G[LATTICE_MAX_BASIS * LATTICE_MAX_BASIS];

  *S = 0;
  for (PetscInt q = 0; q < NumMonomials(lat->dim, 2 * lat->degree); q++) *S += lat->unit[q] * mom[q];
  for (PetscInt k = 0; k < nb; k++) {
    coef[k] = *S * lat->iso[k];
    for (PetscInt l = 0; l < nb; l++) G[k * nb + l] = mom[lat->gram[k][l]];
  }
  if (SolveCholesky(nb, G, coef) || SolveSmall(nb, G, coef)) return PETSC_TRUE;
  UnitPolynomial(lat, coef);
  return PETSC_FALSE;
}

static PetscReal Multiplier(PeriLattice lat, PetscInt i, const PetscReal pw[3][2 * LATTICE_DEGREE + 1])
{
  const PetscReal *c  = lat->coef + i * lat->nbasis;
  PetscReal        mu = 0;
  for (PetscInt k = 0; k < lat->nbasis; k++) mu += c[k] * pw[0][lat->a[k][0]] * pw[1][lat->a[k][1]] * pw[2][lat->a[k][2]];
  return mu;
}

/* A particle some of whose bonds the polynomial would nearly switch off takes only part of it:
 * mu_t = 1 + t (mu - 1) with the largest t that keeps every bond's multiplier at LATTICE_MIN_MU
 * (mu is linear in its coefficients, and both 1 and mu keep the family's sum S_i). */
static PetscErrorCode DampLopsided(PeriLattice lat, const PeriCalibrationData *data)
{
  const PeriBonds *b = data->bonds;
  PetscReal       *low, unit[LATTICE_MAX_BASIS];

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(lat->n, &low));
  for (PetscInt i = 0; i < lat->n; i++) low[i] = 1;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      const PetscInt  j = b->j[k];
      const PetscReal L = b->length[k], e[3] = {b->xi[3 * k] / L, b->xi[3 * k + 1] / L, lat->dim == 3 ? b->xi[3 * k + 2] / L : 0};
      PetscReal       pw[3][2 * LATTICE_DEGREE + 1];
      if (j == i) continue;
      Powers(e, lat->degree, pw);
      low[i] = PetscMin(low[i], Multiplier(lat, i, pw));
      low[j] = PetscMin(low[j], Multiplier(lat, j, pw));
    }
  PetscCall(data->combine(data, MPIU_REAL, 1, MPI_MIN, low));
  UnitPolynomial(lat, unit);
  for (PetscInt i = 0; i < lat->n; i++)
    if (low[i] < LATTICE_MIN_MU) {
      const PetscReal t = (1 - LATTICE_MIN_MU) / (1 - low[i]);
      PetscReal      *c = lat->coef + i * lat->nbasis;
      for (PetscInt k = 0; k < lat->nbasis; k++) c[k] = unit[k] + t * (c[k] - unit[k]);
      if (i < data->nowned) lat->damped++;
    }
  PetscCall(PetscFree(low));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* model.calibration: patch: the lattice's factors of the rank's bonds, then their global
 * correction (models/patch.c); warns with the smallest factor when one is below LATTICE_MIN_MU. */
static PetscErrorCode Patch(PeriLattice lat, PeriModel m, const PeriCalibrationData *data, PetscReal (*profile)(PeriModel, PetscReal), PetscReal Scont)
{
  const PeriBonds *b = data->bonds;
  PetscReal       *f0, fmin = PETSC_MAX_REAL;

  PetscFunctionBeginUser;
  PetscCheck(m->central_force && lat->degree == LATTICE_DEGREE, PETSC_COMM_SELF, PETSC_ERR_SUP, "%s: the patch calibration is for central-force models", m->type);
  PetscCall(PetscMalloc1(b->nbonds, &f0));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PeriBondGeometry g = {.i = i, .j = b->j[k], .length = b->length[k], .Vi = data->particles->volume[i], .Vj = data->particles->volume[b->j[k]], .weight = b->alpha[k] * b->lambda[k], .bond = k + 1};
      for (PetscInt d = 0; d < 3; d++) g.xi[d] = b->xi[3 * k + d];
      f0[k] = PeriLatticeFactor(lat, &g);
    }
  PetscCall(PeriPatchCreate(m, data, profile, f0, Scont, &lat->patch));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PeriBondGeometry g = {.bond = k + 1};
      if (b->j[k] != i && b->live[k]) fmin = PetscMin(fmin, f0[k] + PeriPatchCorrection(lat->patch, &g));
    }
  PetscCall(PetscFree(f0));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &fmin, 1, MPIU_REAL, MPI_MIN, data->comm));
  if (fmin < LATTICE_MIN_MU) PetscCall(PetscSNPrintf(m->warning, sizeof(m->warning), "patch calibration: the smallest bond factor is %g (below %g): the corrections of a few irregular families are large; check the mesh's quality near them, or use model.calibration: lattice", (double)fmin, (double)LATTICE_MIN_MU));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriLatticeCreate - the lattice calibration of one spring family: for every particle the scale
  and the angular polynomial (of degree 4, or 2 for a scalar field) that make the discrete moments
  of the weights alpha lambda V_j profile(|xi|) equal the continuum's. Frees *lattice first; leaves
  it NULL (factor 1) unless model.calibration is lattice. Collective on data->comm.
@*/
PetscErrorCode PeriLatticeCreate(PeriModel m, const PeriCalibrationData *data, PetscInt degree, PetscReal (*profile)(PeriModel, PetscReal), PeriLattice *lattice)
{
  PeriLattice lat;
  PetscReal  *mom, Scont = HorizonIntegral(m, profile);
  PetscInt    nmom = NumMonomials(m->dim, 2 * degree);

  PetscFunctionBeginUser;
  PetscCall(PeriLatticeDestroy(lattice));
  if (m->calibration == PERI_CALIBRATION_CONTINUUM) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCheck(degree == 2 || degree == LATTICE_DEGREE, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "lattice calibration: degree %" PetscInt_FMT " (2 or 4)", degree);
  PetscCall(PetscNew(&lat));
  lat->n      = data->n;
  lat->dim    = m->dim;
  lat->degree = degree;
  lat->nbasis = NumMonomials(m->dim, degree);
  Tables(lat);
  PetscCall(PetscMalloc2(lat->n, &lat->scale, lat->n * lat->nbasis, &lat->coef));
  PetscCall(PetscCalloc1(lat->n * nmom, &mom));
  PetscCall(FamilyMoments(m, data, 2 * degree, profile, mom));
  for (PetscInt i = 0; i < lat->n; i++) {
    PetscReal S;
    if (!ParticlePolynomial(lat, mom + i * nmom, lat->coef + i * lat->nbasis, &S) && i < data->nowned) lat->kept++;
    PetscCheck(S > 0, PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: the particle at (%g, %g) has no bonds, so its lattice calibration is undefined (is the horizon smaller than the spacing?)", m->type, (double)data->particles->x[3 * i], (double)data->particles->x[3 * i + 1]);
    lat->scale[i] = Scont / S;
  }
  PetscCall(PetscFree(mom));
  PetscCall(DampLopsided(lat, data));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &lat->kept, 1, MPIU_INT, MPI_SUM, data->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &lat->damped, 1, MPIU_INT, MPI_SUM, data->comm));
  if (m->calibration == PERI_CALIBRATION_PATCH)
    PetscCall(Patch(lat, m, data, profile, Scont));
  else if (lat->kept || lat->damped)
    PetscCall(PetscSNPrintf(m->warning, sizeof(m->warning), "lattice calibration: %" PetscInt_FMT " of %" PetscInt_FMT " particles (at corners and edges) are not made exactly isotropic: %" PetscInt_FMT " have too few bond directions (scale only, as npmb), %" PetscInt_FMT " take part of the correction so that no bond's multiplier falls below %g", lat->kept + lat->damped, data->N, lat->kept, lat->damped, (double)LATTICE_MIN_MU));
  *lattice = lat;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The multipliers of a bond in its two ends' families, scale_i mu_i(e) and scale_j mu_j(e); 1
 * without a lattice calibration (lat NULL). State-based models weigh each family with its own
 * (models/lps.c). */
void PeriLatticeMultipliers(PeriLattice lat, const PeriBondGeometry *b, PetscReal *fi, PetscReal *fj)
{
  PetscReal e[3], pw[3][2 * LATTICE_DEGREE + 1];
  *fi = *fj = 1;
  if (!lat) return;
  for (PetscInt d = 0; d < 3; d++) e[d] = d < lat->dim ? b->xi[d] / b->length : 0;
  Powers(e, lat->degree, pw);
  *fi = lat->scale[b->i] * Multiplier(lat, b->i, pw);
  *fj = lat->scale[b->j] * Multiplier(lat, b->j, pw);
}

/* The factor of a bond's continuum stiffness: the mean of its two ends' multipliers; 1 without a
 * lattice calibration (lat NULL). */
PetscReal PeriLatticeFactor(PeriLattice lat, const PeriBondGeometry *b)
{
  PetscReal fi, fj;
  if (!lat) return 1;
  PeriLatticeMultipliers(lat, b, &fi, &fj);
  return 0.5 * (fi + fj) + PeriPatchCorrection(lat->patch, b);
}

PetscErrorCode PeriLatticeDestroy(PeriLattice *lat)
{
  PetscFunctionBeginUser;
  if (!*lat) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscFree2((*lat)->scale, (*lat)->coef));
  PetscCall(PeriPatchDestroy(&(*lat)->patch));
  PetscCall(PetscFree(*lat));
  PetscFunctionReturn(PETSC_SUCCESS);
}
