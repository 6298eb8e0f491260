/* The scene's pre-existing cracks (cracks:, docs/failure.md): each item is read into facets of a
 * PeriCrackSet (src/system/crack_surfaces.c) and the bonds crossing them are removed. 2D scenes
 * give segments {from, to}; 3D scenes a polygon, a disc or a surface file per item. */
#include "perilin/private/system.h"
#include "perilin/private/crack_surfaces.h"

const PeriKey PeriCrackKeys[] = {
    {"from", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "2D: a pre-existing crack, a segment: its first end [x, y]; bonds crossing it are removed before the first step"},
    {"to", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "2D: its other end"},
    {"polygon", PERI_KEY_LIST, NULL, NULL, "[length]", NULL, "3D: a planar polygon [[x, y, z], ..] (3 corners or more, in order)"},
    {"disc", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "3D: a disc {center: [x, y, z], normal: [nx, ny, nz], radius: r}"},
    {"surface", PERI_KEY_STRING, NULL, NULL, NULL, NULL, "3D: a triangulated surface: STL (ASCII or binary) or a Gmsh .msh surface mesh, relative to the scene file"},
    {NULL},
};
const PeriKey PeriCrackDiscKeys[] = {
    {"center", PERI_KEY_REALS, "required", NULL, "[length]", NULL, "the disc's centre [x, y, z]"},
    {"normal", PERI_KEY_REALS, "required", NULL, NULL, NULL, "its normal [nx, ny, nz] (any length but zero)"},
    {"radius", PERI_KEY_REAL, "required", NULL, "[length]", NULL, "its radius (positive)"},
    {NULL},
};

static const char *const kinds[] = {"from", "polygon", "disc", "surface"};

/* Whether the 2D segment s = (x0, y0, x1, y1) meets the box [lo, hi] (Liang-Barsky clipping). */
static PetscBool SegmentMeetsBox(const PetscReal s[], const PetscReal lo[], const PetscReal hi[])
{
  PetscReal t0 = 0, t1 = 1;
  for (PetscInt d = 0; d < 2; d++) {
    PetscReal dx = s[2 + d] - s[d], tol = 1e-9 * (hi[d] - lo[d]);
    PetscReal pq[2][2] = {
        {-dx, s[d] - (lo[d] - tol)},
        {dx, (hi[d] + tol) - s[d]}};
    for (PetscInt k = 0; k < 2; k++) {
      if (pq[k][0] == 0) {
        if (pq[k][1] < 0) return PETSC_FALSE;
      } else if (pq[k][0] < 0)
        t0 = PetscMax(t0, pq[k][1] / pq[k][0]);
      else
        t1 = PetscMin(t1, pq[k][1] / pq[k][0]);
    }
  }
  return t0 <= t1 ? PETSC_TRUE : PETSC_FALSE;
}

/* A 2D segment {from: [x, y], to: [x, y]}. A crack that misses the body entirely cuts nothing,
   which is almost always a mistake of units or coordinates, so it is reported. */
static PetscErrorCode ReadSegment(PeriSystem sys, PeriNode item, PetscInt k, PeriCrackSet *set)
{
  PeriScene        s  = sys->scene;
  const PetscReal *lo = sys->disc.particles.lower, *hi = sys->disc.particles.upper;
  PetscReal        seg[4];
  PetscInt         n;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetRealArray(s, item, "from", PETSC_TRUE, 2, 2, &seg[0], &n));
  PetscCall(PeriSceneGetRealArray(s, item, "to", PETSC_TRUE, 2, 2, &seg[2], &n));
  PeriInputCheck(seg[0] != seg[2] || seg[1] != seg[3], s, item, "to", "the segment has zero length");
  PeriInputCheck(SegmentMeetsBox(seg, lo, hi), s, item, NULL, "the segment from (%g, %g) to (%g, %g) lies outside the body [%g, %g] x [%g, %g]: it would cut no bond", (double)seg[0], (double)seg[1], (double)seg[2], (double)seg[3], (double)lo[0], (double)hi[0], (double)lo[1], (double)hi[1]);
  PetscCall(PeriCrackAddSegment(set, k, &seg[0], &seg[2]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* polygon: [[x, y, z], ..], three corners or more in one plane. */
static PetscErrorCode ReadPolygon(PeriSystem sys, PeriNode item, PetscInt k, PeriCrackSet *set)
{
  PeriScene   s = sys->scene;
  PeriNode    p;
  PetscReal  *x, off;
  PetscInt    n;
  const char *problem;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(item, "polygon", &p));
  PeriInputCheck(p->kind == PERI_NODE_SEQ && p->n >= 3, s, item, "polygon", "must be a list of 3 corners or more, each [x, y, z]");
  PetscCall(PetscMalloc1(3 * p->n, &x));
  for (PetscInt c = 0; c < p->n; c++) {
    PetscErrorCode ierr = PeriSceneParseRealArray(s, p->child[c], 3, 3, &x[3 * c], &n);
    if (ierr) PetscCall(PetscFree(x)); /* an input error frees the corners before it is passed on */
    PetscCall(ierr);
  }
  PetscCall(PeriCrackAddPolygon(set, k, p->n, x, &problem, &off));
  PetscCall(PetscFree(x));
  PeriInputCheck(!problem, s, item, "polygon", "%s (off the plane by %g of its size)", problem, (double)off);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* disc: {center, normal, radius}. */
static PetscErrorCode ReadDisc(PeriSystem sys, PeriNode item, PetscInt k, PeriCrackSet *set)
{
  PeriScene   s = sys->scene;
  PeriNode    d;
  PetscReal   c[3], nrm[3], r;
  PetscInt    n;
  const char *problem;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(item, "disc", &d));
  PeriInputCheck(d->kind == PERI_NODE_MAP, s, item, "disc", "must be {center: [x, y, z], normal: [nx, ny, nz], radius: r}");
  PetscCall(PeriSceneCheckSection(s, d, "cracks.<k>.disc"));
  PetscCall(PeriSceneGetRealArray(s, d, "center", PETSC_TRUE, 3, 3, c, &n));
  PetscCall(PeriSceneGetRealArray(s, d, "normal", PETSC_TRUE, 3, 3, nrm, &n));
  PetscCall(PeriSceneGetReal(s, d, "radius", PETSC_TRUE, &r, NULL));
  PetscCall(PeriCrackAddDisc(set, k, c, nrm, r, &problem));
  PeriInputCheck(!problem, s, d, r > 0 ? "normal" : "radius", "%s", problem);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* surface: FILE, its triangles as polygons; slivers of zero area cut nothing and are skipped. */
static PetscErrorCode ReadSurface(PeriSystem sys, PeriNode item, PetscInt k, PeriCrackSet *set)
{
  PeriScene   s = sys->scene;
  char        path[PETSC_MAX_PATH_LEN];
  PetscReal  *tri, off;
  PetscInt    ntri, added = 0;
  const char *problem;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetPath(s, item, "surface", PETSC_TRUE, path, sizeof(path), NULL));
  PetscCall(PeriMeshSurfaceRead(s, item, "surface", path, &ntri, &tri));
  for (PetscInt t = 0; t < ntri; t++) {
    PetscCall(PeriCrackAddPolygon(set, k, 3, &tri[9 * t], &problem, &off));
    added += !problem;
  }
  PetscCall(PetscFree(tri));
  PeriInputCheck(added, s, item, "surface", "%s holds no triangle of nonzero area", path);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The kind of crack item is (its one key of kinds), checked against the scene's dimension. */
static PetscErrorCode ItemKind(PeriSystem sys, PeriNode item, PetscInt *kind)
{
  PeriScene s   = sys->scene;
  PetscInt  dim = sys->disc.particles.dim, given = 0;

  PetscFunctionBeginUser;
  *kind = -1;
  for (PetscInt i = 0; i < 4; i++) {
    PeriNode v;
    PetscCall(PeriSceneGetNode(item, kinds[i], &v));
    if (!v) continue;
    PeriInputCheck(!given, s, item, kinds[i], "give one of from/to, polygon, disc and surface per crack, not %s and %s", kinds[*kind], kinds[i]);
    given = 1;
    *kind = i;
  }
  PeriInputCheck(given, s, item, NULL, "%s", dim == 2 ? "a crack of a 2D scene is a segment {from: [x, y], to: [x, y]}" : "a crack of a 3D scene is one of polygon: [[x, y, z], ..], disc: {center, normal, radius} or surface: FILE");
  PeriInputCheck(dim == 3 || *kind == 0, s, item, kinds[*kind], "is a crack of a 3D scene; a 2D scene's crack is a segment {from: [x, y], to: [x, y]}");
  PeriInputCheck(dim == 2 || *kind != 0, s, item, "from", "a segment is a crack of a 2D scene; a 3D scene's crack is a polygon, a disc or a surface");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the boxes [lo, hi] and [a, b] meet, to a round-off of the body's size. */
static PetscBool BoxesMeet(const PetscReal lo[], const PetscReal hi[], const PetscReal a[], const PetscReal b[])
{
  for (PetscInt d = 0; d < 3; d++) {
    PetscReal tol = 1e-9 * (hi[d] - lo[d]);
    if (b[d] < lo[d] - tol || a[d] > hi[d] + tol) return PETSC_FALSE;
  }
  return PETSC_TRUE;
}

/* Crack item k of cracks: into set. */
static PetscErrorCode ReadItem(PeriSystem sys, PeriNode item, PetscInt k, PeriCrackSet *set)
{
  static PetscErrorCode (*const read[])(PeriSystem, PeriNode, PetscInt, PeriCrackSet *) = {ReadSegment, ReadPolygon, ReadDisc, ReadSurface};
  PeriScene        s                                                                    = sys->scene;
  const PetscReal *lo = sys->disc.particles.lower, *hi = sys->disc.particles.upper;
  PetscReal        a[3], b[3];
  PetscInt         kind;

  PetscFunctionBeginUser;
  PeriInputCheck(item->kind == PERI_NODE_MAP, s, item, NULL, "a crack is a segment {from: [x, y], to: [x, y]} (2D), or one of polygon, disc and surface (3D)");
  PetscCall(PeriSceneCheckSection(s, item, "cracks.<k>"));
  PetscCall(ItemKind(sys, item, &kind));
  PetscCall(read[kind](sys, item, k, set));
  PeriCrackItemBox(set, k, a, b);
  PeriInputCheck(BoxesMeet(lo, hi, a, b), s, item, kinds[kind], "the crack's box [%g, %g] x [%g, %g] x [%g, %g] lies outside the body [%g, %g] x [%g, %g] x [%g, %g]: it would cut no bond", (double)a[0], (double)b[0], (double)a[1], (double)b[1], (double)a[2], (double)b[2], (double)lo[0], (double)hi[0], (double)lo[1], (double)hi[1], (double)lo[2], (double)hi[2]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCracksRead - the cracks of the list cracks: into set (empty on entry; destroyed on an input
  error). Not collective: every rank reads every crack.
@*/
PetscErrorCode PeriCracksRead(PeriSystem sys, PeriNode list, PeriCrackSet *set)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < list->n; k++) {
    /* an input error frees the set before it is passed on (LeakSanitizer) */
    PetscErrorCode ierr = ReadItem(sys, list->child[k], k, set);
    if (ierr) PetscCall(PeriCrackSetDestroy(set));
    PetscCall(ierr);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the bonds of the particle at x (none longer than reach) may reach the facet's box. */
static PetscBool MayReach(const PeriCrackFacet *f, const PetscReal x[], PetscReal reach)
{
  for (PetscInt d = 0; d < 3; d++)
    if (x[d] < f->lo[d] - reach || x[d] > f->hi[d] + reach) return PETSC_FALSE;
  return PETSC_TRUE;
}

/*@C
  PeriCracksCut - removes every bond of b that crosses a facet of set; hits (may be NULL) gets, per
  item, the crossings found (a bond crossing two items counts for both, so that an item hidden
  behind another is still seen to cut). Returns the bonds removed here. Not collective.
@*/
PetscInt PeriCracksCut(const PeriParticles *pt, PeriBonds *b, const PeriCrackSet *set, PetscInt hits[])
{
  PetscReal reach = 0;
  PetscInt  cut   = 0;

  for (PetscInt k = 0; k < b->nbonds; k++) reach = PetscMax(reach, PetscSqrtReal(PetscSqr(b->xi[3 * k]) + PetscSqr(b->xi[3 * k + 1]) + PetscSqr(b->xi[3 * k + 2])));
  for (PetscInt f = 0; f < set->nfacets; f++)
    for (PetscInt i = b->rstart; i < b->rend; i++) {
      const PetscReal *x = &pt->x[3 * i];
      if (!MayReach(&set->facet[f], x, reach)) continue;
      for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
        PetscReal X1[3] = {x[0] + b->xi[3 * k], x[1] + b->xi[3 * k + 1], x[2] + b->xi[3 * k + 2]};
        if (!PeriCrackCrosses(set, &set->facet[f], x, X1)) continue;
        if (hits) hits[set->facet[f].item]++;
        cut += b->live[k];
        b->live[k] = 0;
      }
    }
  return cut;
}
