/* Named regions: boxes, boundary layers of a given depth along a face of the body, and the particle
 * sets of a mesh's physical groups. */
#include "perilin/private/disc.h"

static const char *const sides[]       = {"x-", "x+", "y-", "y+", "z-", "z+", NULL};
static const PeriKey     region_keys[] = {
        {"lower", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "a box region: its lower corner, with upper"},
        {"upper", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "a box region: its upper corner, at least lower"},
        {"side", PERI_KEY_CHOICE, NULL, NULL, NULL, sides, "a boundary layer instead: the face it lies along (z- and z+ in 3D only)"},
        {"depth", PERI_KEY_REAL, "horizon delta", "(0, inf)", "[length]", NULL, "a boundary layer's depth"},
        {"group", PERI_KEY_STRING, NULL, NULL, NULL, NULL, "a physical group of particles.mesh under another name (every named group is a region already; docs/mesh.md)"},
        {NULL},
};
const PeriSchema PeriRegionsSchema[] = {{"regions.<name>", region_keys}, {NULL}};

/* Points on a region's boundary belong to it: every box is widened by this tolerance, relative to
 * the body size. */
PetscReal PeriRegionTolerance(const PeriParticles *p)
{
  PetscReal L = 0;
  for (PetscInt d = 0; d < p->dim; d++) L = PetscMax(L, p->upper[d] - p->lower[d]);
  return 1e-9 * L;
}

PetscBool PeriRegionContains(const PeriRegion *r, const PetscReal x[])
{
  PetscInt lo = 0, hi;

  /* "all" is the body's box too: fictitious layer particles lie outside it */
  for (PetscInt d = 0; d < 3; d++)
    if (x[d] < r->lower[d] || x[d] > r->upper[d]) return PETSC_FALSE;
  if (r->kind != PERI_REGION_SET) return PETSC_TRUE;
  /* a mesh group: positions are copied, never recomputed, so equality is exact */
  for (hi = r->nset; lo < hi;) {
    PetscInt         mid = (lo + hi) / 2, c = 0;
    const PetscReal *y = &r->set[3 * mid];
    for (PetscInt d = 0; d < 3 && !c; d++) c = x[d] < y[d] ? -1 : x[d] > y[d] ? 1
                                                                              : 0;
    if (!c) return PETSC_TRUE;
    if (c < 0)
      hi = mid;
    else
      lo = mid + 1;
  }
  return PETSC_FALSE;
}

/* A region of the particles of a mesh's physical group, bounded by their box for a quick reject. */
static void RegionFromGroup(const PeriMeshGroup *g, PetscReal tol, PeriRegion *r)
{
  r->kind      = PERI_REGION_SET;
  r->set       = g->x; /* read only */
  r->nset      = g->count;
  r->face_area = g->measure;
  for (PetscInt d = 0; d < 3; d++) {
    r->lower[d] = PETSC_MAX_REAL;
    r->upper[d] = -PETSC_MAX_REAL;
  }
  for (PetscInt k = 0; k < g->count; k++)
    for (PetscInt d = 0; d < 3; d++) {
      r->lower[d] = PetscMin(r->lower[d], g->x[3 * k + d] - tol);
      r->upper[d] = PetscMax(r->upper[d], g->x[3 * k + d] + tol);
    }
}

/* regions.<name>.group: the named physical group, or an error that lists them. */
static PetscErrorCode RegionGroup(PeriScene scene, PeriNode node, const PeriParticles *p, PeriRegion *r)
{
  char name[PERI_NAME_LEN], list[512] = "";

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetString(scene, node, "group", PETSC_TRUE, name, sizeof(name), NULL));
  PeriInputCheck(p->groups, scene, node, "group", "names a physical group, but the particles come from no mesh (particles.mesh)");
  for (PetscInt k = 0; k < p->ngroups; k++) {
    if (!strcmp(p->groups[k].name, name)) {
      RegionFromGroup(&p->groups[k], PeriRegionTolerance(p), r);
      PetscFunctionReturn(PETSC_SUCCESS);
    }
    PeriListAppend(list, sizeof(list), p->groups[k].name);
  }
  PeriInputCheck(PETSC_FALSE, scene, node, "group", "no physical group named '%s' in particles.mesh; its named groups are: %s", name, list);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode RegionFromScene(PeriScene scene, PeriNode node, const PeriParticles *p, PetscReal delta, PeriRegion *r)
{
  PetscReal tol = PeriRegionTolerance(p);
  PetscInt  n, dim = p->dim, side = -1;
  PeriNode  lower, sidenode, group;

  PetscFunctionBeginUser;
  PeriInputCheck(node->kind == PERI_NODE_MAP, scene, node, NULL, "a region is a box {lower: [..], upper: [..]} or a layer {side: x-, depth: d}");
  PetscCall(PeriSceneCheckSection(scene, node, "regions.<name>"));
  PetscCall(PetscStrncpy(r->name, node->key, sizeof(r->name)));
  r->node = node;
  PetscCall(PeriSceneGetNode(node, "lower", &lower));
  PetscCall(PeriSceneGetNode(node, "side", &sidenode));
  PetscCall(PeriSceneGetNode(node, "group", &group));
  PeriInputCheck(lower || sidenode || group, scene, node, NULL, "give lower and upper (a box), side (a boundary layer) or group (a mesh's physical group)");
  PeriInputCheck((lower ? 1 : 0) + (sidenode ? 1 : 0) + (group ? 1 : 0) == 1, scene, node, NULL, "give one of lower/upper (a box), side (a layer) or group (a mesh's physical group)");
  for (PetscInt d = 0; d < 3; d++) {
    r->lower[d] = d < dim ? p->lower[d] - tol : -PETSC_MAX_REAL;
    r->upper[d] = d < dim ? p->upper[d] + tol : PETSC_MAX_REAL;
  }
  if (group) {
    PetscCall(RegionGroup(scene, node, p, r));
  } else if (lower) {
    PetscReal lo[3], hi[3];
    r->kind = PERI_REGION_BOX;
    PetscCall(PeriSceneGetRealArray(scene, node, "lower", PETSC_TRUE, dim, dim, lo, &n));
    PetscCall(PeriSceneGetRealArray(scene, node, "upper", PETSC_TRUE, dim, dim, hi, &n));
    for (PetscInt d = 0; d < dim; d++) {
      PeriInputCheck(hi[d] >= lo[d], scene, node, "upper", "must not be below lower (axis %" PetscInt_FMT ")", d);
      r->lower[d] = lo[d] - tol;
      r->upper[d] = hi[d] + tol;
    }
  } else {
    r->kind  = PERI_REGION_LAYER;
    r->depth = delta;
    PetscCall(PeriSceneGetChoice(scene, node, "side", sides, &side, NULL));
    PetscCall(PeriSceneGetReal(scene, node, "depth", PETSC_FALSE, &r->depth, NULL));
    r->axis = side / 2;
    r->side = side % 2 ? 1 : -1;
    PeriInputCheck(r->axis < dim, scene, node, "side", "axis %c does not exist in %" PetscInt_FMT "D", (char)('x' + r->axis), dim);
    if (r->side < 0)
      r->upper[r->axis] = p->lower[r->axis] + r->depth + tol;
    else
      r->lower[r->axis] = p->upper[r->axis] - r->depth - tol;
    r->face_area = dim == 2 ? p->thickness : 1;
    for (PetscInt d = 0; d < dim; d++)
      if (d != r->axis) r->face_area *= p->upper[d] - p->lower[d];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every named physical group of the mesh is a region of its name, r[1 .. ngroups]. */
static PetscErrorCode RegionsFromGroups(PeriScene scene, const PeriParticles *p, PeriRegion r[])
{
  PetscFunctionBeginUser;
  for (PetscInt g = 0; g < p->ngroups; g++) {
    PeriRegion *rg = &r[1 + g];
    PeriInputCheck(strcmp(p->groups[g].name, "all"), scene, scene->root, "particles", "the mesh's physical group 'all' clashes with the region 'all' (every particle): rename it");
    PetscCall(PetscStrncpy(rg->name, p->groups[g].name, sizeof(rg->name)));
    rg->node = scene->root;
    RegionFromGroup(&p->groups[g], PeriRegionTolerance(p), rg);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The particles and volume of every region: the owned particles 0..nowned-1 of p, summed over the
 * ranks ("all": the body's, not the fictitious layers'). A region of the scene must hold one. */
static PetscErrorCode RegionsCount(MPI_Comm comm, PeriScene scene, const PeriParticles *p, PetscInt nowned, PetscInt n, PeriRegion r[], PetscInt first)
{
  PetscReal *sums;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(2 * n, &sums));
  for (PetscInt k = 0; k < nowned; k++)
    for (PetscInt g = 0; g < n; g++)
      if (g ? PeriRegionContains(&r[g], &p->x[3 * k]) : !PeriParticleIsFictitious(p, k)) {
        sums[2 * g] += 1;
        sums[2 * g + 1] += p->volume[k];
      }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, sums, (PetscMPIInt)(2 * n), MPIU_REAL, MPI_SUM, comm));
  for (PetscInt g = 0; g < n; g++) {
    r[g].count  = (PetscInt)sums[2 * g];
    r[g].volume = sums[2 * g + 1];
  }
  PetscCall(PetscFree(sums)); /* before a refusal: the Python module lives on after it */
  for (PetscInt g = first; g < n; g++) PeriInputCheck(r[g].count > 0, scene, r[g].node, NULL, "the region holds no particle");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriRegionsCreateFromScene - reads the regions map; region "all" always exists. p is a rank's
  local view, whose owned particles 0..nowned-1 the counts sum. Collective.
@*/
PetscErrorCode PeriRegionsCreateFromScene(MPI_Comm comm, PeriScene scene, const PeriParticles *p, PetscInt nowned, PetscReal delta, PetscInt *nregions, PeriRegion **regions)
{
  PeriNode    map;
  PetscInt    n;
  PeriRegion *r;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(scene, scene->root, "regions", PETSC_FALSE, &map));
  n = 1 + p->ngroups + (map ? map->n : 0);
  PetscCall(PetscCalloc1(n, &r));
  /* the caller's from here: an input error below leaves the array to its destroy (no leak) */
  *nregions = n;
  *regions  = r;
  PetscCall(PetscStrncpy(r[0].name, "all", sizeof(r[0].name)));
  r[0].kind = PERI_REGION_ALL;
  for (PetscInt d = 0; d < 3; d++) {
    r[0].lower[d] = p->lower[d] - PeriRegionTolerance(p);
    r[0].upper[d] = p->upper[d] + PeriRegionTolerance(p);
  }
  PetscCall(RegionsFromGroups(scene, p, r));
  for (PetscInt k = 1 + p->ngroups; k < n; k++) {
    PeriNode node = map->child[k - 1 - p->ngroups];
    PeriInputCheck(strcmp(node->key, "all"), scene, node, NULL, "'all' is reserved: it always names every particle");
    for (PetscInt g = 0; g < p->ngroups; g++) PeriInputCheck(strcmp(node->key, p->groups[g].name), scene, node, NULL, "'%s' is a physical group of particles.mesh already, and so a region: name this one otherwise", node->key);
    PetscCall(RegionFromScene(scene, node, p, delta, &r[k]));
  }
  PetscCall(RegionsCount(comm, scene, p, nowned, n, r, 1 + p->ngroups));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The region named by the scalar key of map (e.g. bc.0.region). */
PetscErrorCode PeriRegionFind(PeriScene scene, PeriNode map, const char key[], PetscInt nregions, PeriRegion *regions, PeriRegion **region)
{
  char name[PERI_NAME_LEN], list[512] = "";

  PetscFunctionBeginUser;
  if (key)
    PetscCall(PeriSceneGetString(scene, map, key, PETSC_TRUE, name, sizeof(name), NULL));
  else
    PetscCall(PetscStrncpy(name, map->key, sizeof(name))); /* a map entry keyed by the region's name */
  for (PetscInt k = 0; k < nregions; k++) {
    if (!strcmp(regions[k].name, name)) {
      *region = &regions[k];
      PetscFunctionReturn(PETSC_SUCCESS);
    }
    PeriListAppend(list, sizeof(list), regions[k].name);
  }
  PeriInputCheck(PETSC_FALSE, scene, map, key, "no region named '%s'; the regions are: %s", name, list);
  PetscFunctionReturn(PETSC_SUCCESS);
}
