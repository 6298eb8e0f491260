/* The geometry of pre-existing cracks (cracks:, docs/failure.md): a bond is removed when its
 * segment crosses a crack properly, a touch at an end point or a bond in the crack's plane does
 * not count, so a crack through a row of particles removes nothing along that row. 2D: segments;
 * 3D: planar polygons (a surface file's triangles among them) and discs. */
#include "perilin/private/crack_surfaces.h"

/* Room for one more facet and n more points. */
static PetscErrorCode Grow(PeriCrackSet *s, PetscInt n)
{
  PetscFunctionBeginUser;
  if (s->nfacets == s->maxfacets) {
    s->maxfacets = 2 * s->maxfacets + 4;
    PetscCall(PetscRealloc(sizeof(PeriCrackFacet) * (size_t)s->maxfacets, &s->facet));
  }
  if (s->npoints + n > s->maxpoints) {
    s->maxpoints = 2 * s->maxpoints + n;
    PetscCall(PetscRealloc(sizeof(PetscReal) * 3 * (size_t)s->maxpoints, &s->points));
  }
  PetscCall(PetscMemzero(&s->facet[s->nfacets], sizeof(PeriCrackFacet)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A new facet of item holding the n points x (z = 0 where dim is 2), its box theirs. */
static PetscErrorCode AddFacet(PeriCrackSet *s, PeriCrackKind kind, PetscInt item, PetscInt n, const PetscReal x[], PeriCrackFacet **f)
{
  PetscFunctionBeginUser;
  PetscCall(Grow(s, n));
  *f          = &s->facet[s->nfacets++];
  (*f)->kind  = kind;
  (*f)->item  = item;
  (*f)->first = s->npoints;
  (*f)->n     = n;
  s->nitems   = PetscMax(s->nitems, item + 1);
  PetscCall(PetscArraycpy(&s->points[3 * s->npoints], x, 3 * n));
  s->npoints += n;
  for (PetscInt d = 0; d < 3; d++) {
    (*f)->lo[d] = PETSC_MAX_REAL;
    (*f)->hi[d] = PETSC_MIN_REAL;
    for (PetscInt k = 0; k < n; k++) {
      (*f)->lo[d] = PetscMin((*f)->lo[d], x[3 * k + d]);
      (*f)->hi[d] = PetscMax((*f)->hi[d], x[3 * k + d]);
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCrackAddSegment - adds the 2D segment from a to b ([x, y, 0] each) as a facet of item. Not
  collective.
@*/
PetscErrorCode PeriCrackAddSegment(PeriCrackSet *s, PetscInt item, const PetscReal a[], const PetscReal b[])
{
  PetscReal       x[6] = {a[0], a[1], 0, b[0], b[1], 0};
  PeriCrackFacet *f    = NULL;

  PetscFunctionBeginUser;
  PetscCall(AddFacet(s, PERI_CRACK_SEGMENT, item, 2, x, &f));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static void Cross(const PetscReal a[], const PetscReal b[], PetscReal c[])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static PetscReal Dot(const PetscReal a[], const PetscReal b[])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Newell's normal of the polygon x (twice its area times the unit normal, for any planar
 * polygon, convex or not) and the polygon's size (its box's diagonal). */
static void PolygonNormal(PetscInt n, const PetscReal x[], PetscReal N[], PetscReal *size)
{
  PetscReal lo[3], hi[3];

  N[0] = N[1] = N[2] = 0;
  for (PetscInt d = 0; d < 3; d++) lo[d] = hi[d] = x[d];
  for (PetscInt k = 0; k < n; k++) {
    const PetscReal *p = &x[3 * k], *q = &x[3 * ((k + 1) % n)];
    PetscReal        c[3];
    Cross(p, q, c);
    for (PetscInt d = 0; d < 3; d++) {
      N[d] += c[d];
      lo[d] = PetscMin(lo[d], p[d]);
      hi[d] = PetscMax(hi[d], p[d]);
    }
  }
  *size = PetscSqrtReal(PetscSqr(hi[0] - lo[0]) + PetscSqr(hi[1] - lo[1]) + PetscSqr(hi[2] - lo[2]));
}

/* The axis of v's largest component. */
static PetscInt LargestAxis(const PetscReal v[])
{
  PetscInt a = 0;
  for (PetscInt d = 1; d < 3; d++)
    if (PetscAbsReal(v[d]) > PetscAbsReal(v[a])) a = d;
  return a;
}

/*@C
  PeriCrackAddPolygon - adds the planar polygon of n corners x as a facet of item; *problem (else
  NULL) says why it is refused: zero area (collinear or repeated corners) or corners off its plane
  by more than 1e-6 of its size (*off, relative). Not collective.
@*/
PetscErrorCode PeriCrackAddPolygon(PeriCrackSet *s, PetscInt item, PetscInt n, const PetscReal x[], const char **problem, PetscReal *off)
{
  PetscReal       N[3], size, area;
  PeriCrackFacet *f = NULL;

  PetscFunctionBeginUser;
  *problem = NULL;
  *off     = 0;
  PolygonNormal(n, x, N, &size);
  area = 0.5 * PetscSqrtReal(Dot(N, N));
  if (!(size > 0) || !(area > 1e-12 * size * size)) {
    *problem = "its corners enclose no area (collinear or repeated)";
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  for (PetscInt d = 0; d < 3; d++) N[d] /= 2 * area;
  for (PetscInt k = 0; k < n; k++) {
    PetscReal v[3] = {x[3 * k] - x[0], x[3 * k + 1] - x[1], x[3 * k + 2] - x[2]};
    *off           = PetscMax(*off, PetscAbsReal(Dot(N, v)) / size);
  }
  if (*off > 1e-6) {
    *problem = "its corners do not lie in one plane";
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(AddFacet(s, PERI_CRACK_POLYGON, item, n, x, &f));
  PetscCall(PetscArraycpy(f->c, x, 3));
  PetscCall(PetscArraycpy(f->normal, N, 3));
  f->drop = LargestAxis(N);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCrackAddDisc - adds the disc of centre c, normal nrm (any length) and radius r as a facet of
  item; *problem (else NULL) says why it is refused: a zero normal, or r not positive. Not
  collective.
@*/
PetscErrorCode PeriCrackAddDisc(PeriCrackSet *s, PetscInt item, const PetscReal c[], const PetscReal nrm[], PetscReal r, const char **problem)
{
  PetscReal       len = PetscSqrtReal(Dot(nrm, nrm));
  PeriCrackFacet *f   = NULL;

  PetscFunctionBeginUser;
  *problem = !(len > 0) ? "the normal is zero" : !(r > 0) ? "the radius must be positive"
                                                          : NULL;
  if (*problem) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(AddFacet(s, PERI_CRACK_DISC, item, 1, c, &f));
  PetscCall(PetscArraycpy(f->c, c, 3));
  f->radius = r;
  for (PetscInt d = 0; d < 3; d++) f->normal[d] = nrm[d] / len;
  for (PetscInt d = 0; d < 3; d++) { /* the disc's extent along axis d: r sin(angle of the normal to d) */
    PetscReal e = r * PetscSqrtReal(PetscMax(0, 1 - PetscSqr(f->normal[d])));
    f->lo[d]    = c[d] - e;
    f->hi[d]    = c[d] + e;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Do the open 2D segments P0P1 and Q0Q1 cross (a touch at an end point does not count)? */
static PetscBool SegmentsCross(const PetscReal P0[], const PetscReal P1[], const PetscReal Q0[], const PetscReal Q1[])
{
  PetscReal d1 = (P1[0] - P0[0]) * (Q0[1] - P0[1]) - (P1[1] - P0[1]) * (Q0[0] - P0[0]);
  PetscReal d2 = (P1[0] - P0[0]) * (Q1[1] - P0[1]) - (P1[1] - P0[1]) * (Q1[0] - P0[0]);
  PetscReal d3 = (Q1[0] - Q0[0]) * (P0[1] - Q0[1]) - (Q1[1] - Q0[1]) * (P0[0] - Q0[0]);
  PetscReal d4 = (Q1[0] - Q0[0]) * (P1[1] - Q0[1]) - (Q1[1] - Q0[1]) * (P1[0] - Q0[0]);
  return (PetscBool)(d1 * d2 < 0 && d3 * d4 < 0);
}

/* Whether X, a point of the polygon's plane, lies inside it (crossing number in the plane of the
 * two axes other than drop: the projection keeps insideness since the normal is not along them). */
static PetscBool InPolygon(const PetscReal p[], PetscInt n, PetscInt drop, const PetscReal X[])
{
  const PetscInt u = (drop + 1) % 3, v = (drop + 2) % 3;
  PetscBool      in = PETSC_FALSE;

  for (PetscInt i = 0, j = n - 1; i < n; j = i++) {
    const PetscReal *A = &p[3 * i], *B = &p[3 * j];
    if ((A[v] > X[v]) != (B[v] > X[v]) && X[u] < (B[u] - A[u]) * (X[v] - A[v]) / (B[v] - A[v]) + A[u]) in = (PetscBool)!in;
  }
  return in;
}

/* Whether the segment ab crosses the plane of f strictly (its ends on either side), and where. */
static PetscBool PlaneCrossing(const PeriCrackFacet *f, const PetscReal a[], const PetscReal b[], PetscReal X[])
{
  PetscReal da = 0, db = 0, t;

  for (PetscInt d = 0; d < 3; d++) {
    da += f->normal[d] * (a[d] - f->c[d]);
    db += f->normal[d] * (b[d] - f->c[d]);
  }
  if (!(da * db < 0)) return PETSC_FALSE;
  t = da / (da - db);
  for (PetscInt d = 0; d < 3; d++) X[d] = a[d] + t * (b[d] - a[d]);
  return PETSC_TRUE;
}

/*@C
  PeriCrackCrosses - whether the bond from a to b ([x, y, z], z = 0 in 2D) crosses the facet f of
  s. Not collective.
@*/
PetscBool PeriCrackCrosses(const PeriCrackSet *s, const PeriCrackFacet *f, const PetscReal a[], const PetscReal b[])
{
  PetscReal X[3], r2 = 0;

  for (PetscInt d = 0; d < 3; d++)
    if (PetscMax(a[d], b[d]) < f->lo[d] || PetscMin(a[d], b[d]) > f->hi[d]) return PETSC_FALSE;
  if (f->kind == PERI_CRACK_SEGMENT) return SegmentsCross(a, b, &s->points[3 * f->first], &s->points[3 * f->first + 3]);
  if (!PlaneCrossing(f, a, b, X)) return PETSC_FALSE;
  if (f->kind == PERI_CRACK_POLYGON) return InPolygon(&s->points[3 * f->first], f->n, f->drop, X);
  for (PetscInt d = 0; d < 3; d++) r2 += PetscSqr(X[d] - f->c[d]);
  return (PetscBool)(r2 < PetscSqr(f->radius));
}

/*@C
  PeriCrackItemBox - the box [lo, hi] of every facet of item. Not collective.
@*/
void PeriCrackItemBox(const PeriCrackSet *s, PetscInt item, PetscReal lo[], PetscReal hi[])
{
  for (PetscInt d = 0; d < 3; d++) {
    lo[d] = PETSC_MAX_REAL;
    hi[d] = PETSC_MIN_REAL;
  }
  for (PetscInt k = 0; k < s->nfacets; k++)
    for (PetscInt d = 0; d < 3 && s->facet[k].item == item; d++) {
      lo[d] = PetscMin(lo[d], s->facet[k].lo[d]);
      hi[d] = PetscMax(hi[d], s->facet[k].hi[d]);
    }
}

PetscErrorCode PeriCrackSetDestroy(PeriCrackSet *s)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(s->facet));
  PetscCall(PetscFree(s->points));
  PetscCall(PetscMemzero(s, sizeof(*s)));
  PetscFunctionReturn(PETSC_SUCCESS);
}
