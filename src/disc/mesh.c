/* Particles and regions from a Gmsh mesh, through Gmsh's own C API (gmshc.h): a .msh file of any
 * version Gmsh reads, or a .geo file meshed here; an Abaqus .inp or Exodus II file is converted
 * into a temporary .msh by mesh_import.py (meshio) in a child process first, since Gmsh reads
 * neither. One particle per element of the scene's dimension, at its centroid, with its exact
 * measure; named physical groups become particle sets (docs/mesh.md). Rank 0 reads: Gmsh is not
 * MPI-aware. */
#include "perilin/private/disc.h"
#include "perilin/private/gmsh_api.h"
#include <unistd.h>
#include <errno.h>
#include <stdlib.h>
#include <strings.h>

#define PERI_MESH_TIMEOUT 600 /* seconds for meshio to convert a mesh: about 5 s per million elements */
#ifndef PERI_MESH_PYTHON
#  define PERI_MESH_PYTHON "python3"
#endif
#ifndef PERI_MESH_SCRIPT
#  define PERI_MESH_SCRIPT ""
#endif
#ifndef PERI_MESH_SCRIPT_INSTALLED
#  define PERI_MESH_SCRIPT_INSTALLED ""
#endif

static PetscBool gmsh_started = PETSC_FALSE;

/* Gmsh holds global state: it is initialized once per process and finalized with PETSc. */
static PetscErrorCode GmshFinalizeOnce(void)
{
  int ierr = 0;

  PetscFunctionBeginUser;
  if (gmsh_started) gmshFinalize(&ierr);
  gmsh_started = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Starts Gmsh (once) with an empty model; silent unless verbose, and on one thread so that every
 * rank meshes a .geo into the very same elements. */
static PetscErrorCode GmshStart(PetscBool verbose)
{
  int ierr = 0;

  PetscFunctionBeginUser;
  if (!gmsh_started) {
    PetscCall(PeriGmshLoad());
    gmshInitialize(0, NULL, 0, &ierr);
    PetscCheck(!ierr, PETSC_COMM_SELF, PETSC_ERR_LIB, "Gmsh failed to initialize");
    gmsh_started = PETSC_TRUE;
    PetscCall(PetscRegisterFinalize(GmshFinalizeOnce));
  }
  gmshOptionSetNumber("General.Terminal", verbose ? 1 : 0, &ierr);
  gmshOptionSetNumber("General.Verbosity", verbose ? 5 : 0, &ierr);
  gmshOptionSetNumber("General.NumThreads", 1, &ierr);
  gmshOptionSetNumber("Mesh.MaxNumThreads2D", 1, &ierr);
  gmshOptionSetNumber("Mesh.MaxNumThreads3D", 1, &ierr);
  gmshClear(&ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

#define GmshCheck(ierr, what)                                                          \
  do {                                                                                 \
    if (PetscUnlikely(ierr)) {                                                         \
      char peri_msg_[256];                                                             \
      PeriGmshLastError(peri_msg_, sizeof(peri_msg_));                                 \
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_LIB, "Gmsh: %s failed: %s", what, peri_msg_); \
    }                                                                                  \
  } while (0)

/* The corners of Gmsh's linear elements: type -> (dimension, corners, simplex); 0 corners when
 * perilin does not read the type. */
static void ElementShape(int type, PetscInt *dim, PetscInt *corners, PetscBool *simplex)
{
  static const PetscInt  d[] = {0, 1, 2, 2, 3, 3}, c[] = {0, 2, 3, 4, 4, 8};
  static const PetscBool s[] = {PETSC_TRUE, PETSC_TRUE, PETSC_TRUE, PETSC_FALSE, PETSC_TRUE, PETSC_FALSE};

  if (type == 15) { /* a point */
    *dim = 0, *corners = 1, *simplex = PETSC_TRUE;
  } else if (type >= 1 && type <= 5) {
    *dim = d[type], *corners = c[type], *simplex = s[type];
  } else {
    *dim = -1, *corners = 0, *simplex = PETSC_FALSE;
  }
}

/* sqrt(det(J^T J)) of the k columns J (k <= 3) in 3D: length, area or volume scale, also for
 * lines and faces embedded in 3D. */
static PetscReal GramRoot(PetscInt k, PetscReal J[3][3])
{
  PetscReal G[3][3] = {{0}}, det;

  for (PetscInt a = 0; a < k; a++)
    for (PetscInt b = 0; b < k; b++)
      for (PetscInt r = 0; r < 3; r++) G[a][b] += J[r][a] * J[r][b];
  if (k == 0) return 1;
  if (k == 1)
    det = G[0][0];
  else if (k == 2)
    det = G[0][0] * G[1][1] - G[0][1] * G[1][0];
  else
    det = G[0][0] * (G[1][1] * G[2][2] - G[1][2] * G[2][1]) - G[0][1] * (G[1][0] * G[2][2] - G[1][2] * G[2][0]) + G[0][2] * (G[1][0] * G[2][1] - G[1][1] * G[2][0]);
  return PetscSqrtReal(PetscMax(det, 0));
}

/* The exact measure (length, area, volume) and centroid of a linear element from its corners X.
 * Simplices have a constant Jacobian; quadrangles and hexahedra are bi- and trilinear, whose
 * |det J| and x |det J| the 2-point Gauss rule per axis integrates exactly (valid elements). */
static void ElementMeasure(PetscInt dim, PetscInt corners, PetscBool simplex, const PetscReal X[][3], PetscReal *measure, PetscReal c[3])
{
  static const PetscReal ref[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
  PetscReal              J[3][3] = {{0}}, g = 1 / PetscSqrtReal(3);

  *measure = 0;
  c[0] = c[1] = c[2] = 0;
  if (simplex) {
    PetscReal fact = dim == 3 ? 6 : dim == 2 ? 2
                                             : 1;
    for (PetscInt k = 0; k < dim; k++)
      for (PetscInt r = 0; r < 3; r++) J[r][k] = X[k + 1][r] - X[0][r];
    *measure = GramRoot(dim, J) / fact;
    for (PetscInt a = 0; a < corners; a++)
      for (PetscInt r = 0; r < 3; r++) c[r] += X[a][r] / corners;
    return;
  }
  for (PetscInt q = 0; q < (1 << dim); q++) {
    PetscReal xi[3], x[3] = {0, 0, 0}, w;
    for (PetscInt k = 0; k < 3; k++) xi[k] = k < dim ? ((q >> k) & 1 ? g : -g) : 0;
    for (PetscInt r = 0; r < 3; r++)
      for (PetscInt k = 0; k < 3; k++) J[r][k] = 0;
    for (PetscInt a = 0; a < corners; a++) {
      PetscReal N = 1;
      for (PetscInt k = 0; k < dim; k++) N *= (1 + ref[a][k] * xi[k]) / 2;
      for (PetscInt k = 0; k < dim; k++) {
        PetscReal dN = ref[a][k] / 2;
        for (PetscInt l = 0; l < dim; l++)
          if (l != k) dN *= (1 + ref[a][l] * xi[l]) / 2;
        for (PetscInt r = 0; r < 3; r++) J[r][k] += dN * X[a][r];
      }
      for (PetscInt r = 0; r < 3; r++) x[r] += N * X[a][r];
    }
    w = GramRoot(dim, J);
    *measure += w;
    for (PetscInt r = 0; r < 3; r++) c[r] += w * x[r];
  }
  for (PetscInt r = 0; r < 3; r++) c[r] /= *measure;
}

/* The model's nodes: their coordinates by tag (index[tag] into xyz, -1 when absent). */
typedef struct {
  size_t    maxtag;
  PetscInt *index;
  double   *xyz;
  size_t   *tags, n;
} MeshNodes;

static PetscErrorCode NodesGet(MeshNodes *nodes)
{
  size_t  nc, np;
  double *param;
  int     ierr = 0;

  PetscFunctionBeginUser;
  gmshModelMeshGetNodes(&nodes->tags, &nodes->n, &nodes->xyz, &nc, &param, &np, -1, -1, 0, 0, &ierr);
  GmshCheck(ierr, "reading the nodes");
  gmshFree(param);
  nodes->maxtag = 0;
  for (size_t k = 0; k < nodes->n; k++) nodes->maxtag = PetscMax(nodes->maxtag, nodes->tags[k]);
  PetscCall(PetscMalloc1(nodes->maxtag + 1, &nodes->index));
  for (size_t t = 0; t <= nodes->maxtag; t++) nodes->index[t] = -1;
  for (size_t k = 0; k < nodes->n; k++) nodes->index[nodes->tags[k]] = (PetscInt)k;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode NodesDestroy(MeshNodes *nodes)
{
  PetscFunctionBeginUser;
  gmshFree(nodes->tags);
  gmshFree(nodes->xyz);
  PetscCall(PetscFree(nodes->index));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The corner coordinates of one element from its node tags. */
static void ElementCorners(const MeshNodes *nodes, const size_t tags[], PetscInt corners, PetscReal X[8][3])
{
  for (PetscInt a = 0; a < corners; a++)
    for (PetscInt r = 0; r < 3; r++) X[a][r] = nodes->xyz[3 * nodes->index[tags[a]] + r];
}

/* The elements of one dimension (all entities when tag < 0): Gmsh's arrays, freed by ElementsFree. */
typedef struct {
  int     *types;
  size_t   ntypes, **etags, *netags, nn, **ntags, *nntags, nn2;
  PetscInt count;
} MeshElements;

static PetscErrorCode ElementsGet(PetscInt dim, int tag, MeshElements *e)
{
  int ierr = 0;

  PetscFunctionBeginUser;
  gmshModelMeshGetElements(&e->types, &e->ntypes, &e->etags, &e->netags, &e->nn, &e->ntags, &e->nntags, &e->nn2, (int)dim, tag, &ierr);
  GmshCheck(ierr, "reading the elements");
  e->count = 0;
  for (size_t t = 0; t < e->ntypes; t++) e->count += (PetscInt)e->netags[t];
  PetscFunctionReturn(PETSC_SUCCESS);
}

static void ElementsFree(MeshElements *e)
{
  for (size_t t = 0; t < e->ntypes; t++) {
    gmshFree(e->etags[t]);
    gmshFree(e->ntags[t]);
  }
  gmshFree(e->types);
  gmshFree(e->etags);
  gmshFree(e->netags);
  gmshFree(e->ntags);
  gmshFree(e->nntags);
}

/* The format of a mesh Gmsh does not read, by its extension (any case), or NULL: Gmsh 4.8 writes
 * Abaqus .inp but reads neither it nor Exodus II, so src/disc/mesh_import.py (meshio) converts them. */
static const char *ImportedFormat(const char path[])
{
  static const char *const ext[] = {".inp", ".exo", ".e", ".ex2", ".exii", ".gen"};
  const char              *dot   = strrchr(path, '.');

  for (size_t k = 0; dot && k < sizeof(ext) / sizeof(ext[0]); k++)
    if (!strcasecmp(dot, ext[k])) return k ? "Exodus II" : "Abaqus";
  return NULL;
}

/* The mesh file's path (absolute, or relative to the scene file's folder), whether it is a .geo,
 * the characteristic length a .geo needs, and the format of a file to convert first (or NULL). */
static PetscErrorCode MeshSource(PeriScene scene, PeriNode node, char path[], size_t size, PetscBool *geo, PetscReal *lc, const char **format)
{
  size_t    len;
  PetscBool has;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetPath(scene, node, "mesh", PETSC_TRUE, path, size, NULL));
  PeriInputCheck(access(path, R_OK) == 0, scene, node, "mesh", "cannot read %s: %s", path, strerror(errno));
  PetscCall(PetscStrlen(path, &len));
  *geo    = len > 4 && !strcmp(path + len - 4, ".geo") ? PETSC_TRUE : PETSC_FALSE;
  *format = ImportedFormat(path);
  *lc     = 0;
  PetscCall(PeriSceneGetReal(scene, node, "size", PETSC_FALSE, lc, &has));
  PeriInputCheck(!*geo || has, scene, node, "mesh", "%s is a .geo file: give particles.size, the characteristic length Gmsh meshes it with", path);
  PeriInputCheck(*geo || !has, scene, node, "size", "applies to a .geo file only; %s is a mesh already", path);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Removes the conversion's scratch directory and what it holds (the .msh and the child's log). */
static void ImportRemove(const char dir[], const char msh[], const char log[])
{
  (void)unlink(msh);
  (void)unlink(log);
  (void)rmdir(dir);
}

/* Converts an Abaqus or Exodus mesh into dir/mesh.msh (dir: a new scratch directory under $TMPDIR or
 * /tmp) with meshio in a child process. A failed conversion is an input error quoting the child's
 * last line (meshio's message, or that meshio is missing) and leaves nothing behind. */
static PetscErrorCode MeshImport(PeriScene scene, PeriNode node, const char path[], const char format[], char dir[], size_t dsize, char msh[], size_t msize)
{
  const char *script = PeriChildScript("PERILIN_MESH_SCRIPT", PERI_MESH_SCRIPT, PERI_MESH_SCRIPT_INSTALLED), *tmp = getenv("TMPDIR");
  char        log[PETSC_MAX_PATH_LEN], reason[512]                                                                = "";
  char       *argv[5];
  int         failed;

  PetscFunctionBeginUser;
  PeriInputCheck(script, scene, node, "mesh", "%s is an %s mesh, converted by mesh_import.py, which is neither at %s nor at %s (set PERILIN_MESH_SCRIPT)", path, format, PERI_MESH_SCRIPT, PERI_MESH_SCRIPT_INSTALLED);
  PetscCall(PetscSNPrintf(dir, dsize, "%s/perilin-mesh-XXXXXX", tmp && tmp[0] ? tmp : "/tmp"));
  PetscCheck(mkdtemp(dir), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot create a scratch directory %s to convert %s: %s", dir, path, strerror(errno));
  PetscCall(PetscSNPrintf(msh, msize, "%s/mesh.msh", dir));
  PetscCall(PetscSNPrintf(log, sizeof(log), "%s/log", dir));
  argv[0] = (char *)PeriChildPython(PERI_MESH_PYTHON);
  argv[1] = (char *)script;
  argv[2] = (char *)path;
  argv[3] = msh;
  argv[4] = NULL;
  failed  = PeriChildRun(argv, log, PERI_MESH_TIMEOUT, reason, sizeof(reason));
  if (failed) ImportRemove(dir, msh, log);
  PeriInputCheck(!failed, scene, node, "mesh", "cannot read the %s mesh %s: %s", format, path, reason);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Opens the file (path, or the conversion of path in dir/mesh.msh, which is removed once read) in
 * Gmsh, meshing a .geo in the scene's dimension with the largest element size lc, and checks that
 * the mesh's highest element dimension is the scene's. */
static PetscErrorCode MeshOpen(PeriScene scene, PeriNode node, const char path[], const char dir[], const char msh[], PetscBool geo, PetscReal lc, PetscInt dim)
{
  char      msg[256], log[PETSC_MAX_PATH_LEN];
  int       ierr = 0, *types;
  size_t    ntypes;
  PetscInt  top = -1, ed, ec;
  PetscBool simplex;

  PetscFunctionBeginUser;
  gmshOpen(dir[0] ? msh : path, &ierr);
  if (ierr) PeriGmshLastError(msg, sizeof(msg));
  if (dir[0]) {
    PetscCall(PetscSNPrintf(log, sizeof(log), "%s/log", dir));
    ImportRemove(dir, msh, log);
  }
  PeriInputCheck(!ierr, scene, node, "mesh", "Gmsh cannot read %s: %s", path, msg);
  if (geo) {
    PetscBool ok;
    PetscCall(PeriMeshGenerateIsolated(path, dim, lc, &ok, msg, sizeof(msg)));
    PeriInputCheck(ok, scene, node, "mesh", "Gmsh cannot mesh %s in %" PetscInt_FMT "D: %s", path, dim, msg);
  }
  gmshModelMeshGetElementTypes(&types, &ntypes, -1, -1, &ierr);
  GmshCheck(ierr, "reading the element types");
  for (size_t t = 0; t < ntypes; t++) {
    ElementShape(types[t], &ed, &ec, &simplex);
    if (ec)
      top = PetscMax(top, ed);
    else {
      char   *name = NULL, errname[64];
      int     d, order, nn, np;
      double *lcoord;
      size_t  nl;
      gmshModelMeshGetElementProperties(types[t], &name, &d, &order, &nn, &lcoord, &nl, &np, &ierr);
      PetscCall(PetscStrncpy(errname, name ? name : "?", sizeof(errname)));
      gmshFree(name);
      gmshFree(lcoord);
      gmshFree(types);
      PeriInputCheck(PETSC_FALSE, scene, node, "mesh", "%s holds elements of type '%s', which perilin does not read: it reads linear points, lines, triangles, quadrangles, tetrahedra and hexahedra (Mesh.ElementOrder = 1, no prisms or pyramids)", path, errname);
    }
  }
  gmshFree(types);
  PeriInputCheck(top >= dim, scene, node, "mesh", "%s has no elements of dimension %" PetscInt_FMT " (the scene's dim; its highest is %" PetscInt_FMT ")", path, dim, top);
  PeriInputCheck(top == dim, scene, node, "mesh", "%s is a %" PetscInt_FMT "D mesh but the scene's dim is %" PetscInt_FMT, path, top, dim);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bytes per particle of the particles and their bonds (the counts src/system/memory.c's
 * Estimate uses, without the model's matrix and solver): a lower bound of what the run will hold.
 * m is the horizon in spacings; with horizon.delta (not known in spacings before the mesh is
 * refined) the default 3. */
static PetscErrorCode RefinedBytes(PeriScene scene, PetscInt dim, PetscReal *m, PetscReal *bytes)
{
  PeriNode       hz = NULL;
  PetscReal      r, ball;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  *m = 3;
  /* a bad horizon is reported later, by the reader of the horizon: quietly keep the default here */
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = PeriSceneGetMap(scene, scene->root, "horizon", PETSC_FALSE, &hz);
  if (!ierr && hz) ierr = PeriSceneGetReal(scene, hz, "m", PETSC_FALSE, m, NULL);
  PetscCall(PetscPopErrorHandler());
  if (ierr || !(*m >= 1)) *m = 1;
  r    = *m + 0.5; /* the continued partial-volume ramp's half spacing */
  ball = PeriBondsBallCount(dim, r);
  /* the particles' arrays and their bonds, every one found (faces not discounted: an upper bound
     of the bonds, but no matrix or solver is counted) */
  *bytes = PeriParticlesBytesPerParticle(dim) + PeriBondsBytesPerParticle(ball, 1, PETSC_FALSE);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles.refine splits every element into 2^dim per level: the particles and bonds that gives
 * are estimated before Gmsh refines, and refused above what the machine has (as a grid's are,
 * src/system/memory.c): refined into millions of particles, a run ended in a SIGSEGV or a raw
 * allocation error (issue 40, item 4). Every rank reads the mesh: the estimate is one rank's. */
static PetscErrorCode RefineFits(PeriScene scene, PeriNode node, const char path[], PetscInt dim, PetscInt refine)
{
  MeshElements e;
  PetscReal    m = 3, per = 0, n, need, have;
  PetscBool    check = PETSC_TRUE;
  size_t       count;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_memory_check", &check, NULL));
  if (!check || refine <= 0) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(ElementsGet(dim, -1, &e));
  count = e.count;
  ElementsFree(&e);
  PetscCall(RefinedBytes(scene, dim, &m, &per));
  n    = (PetscReal)count * PetscPowReal(dim == 2 ? 4 : 8, (PetscReal)refine);
  need = n * per;
  have = PeriMemoryAvailable();
  PetscCall(PetscInfo(NULL, "particles.refine %" PetscInt_FMT ": %g particles, at least %g bytes, %g available\n", refine, (double)n, (double)need, (double)have));
  PeriInputCheck(!(have > 0) || need <= have, scene, node, "refine", "%s's %zu elements split %" PetscInt_FMT " times give %.3g particles, whose particles and bonds alone (a horizon of %.3g spacings) need about %.3g GB, and this machine has %.3g GB available: give a smaller particles.refine, a coarser mesh or a smaller horizon (-peri_memory_check false skips this estimate)", path, count, refine, (double)n, (double)m, (double)(need / 1e9), (double)(have / 1e9));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles.refine: every element split uniformly that many times. */
static PetscErrorCode MeshRefine(PeriScene scene, PeriNode node, const char path[], PetscInt dim)
{
  PetscInt refine = 0;
  int      ierr   = 0;
  char     msg[256];

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetInt(scene, node, "refine", PETSC_FALSE, &refine, NULL));
  PetscCall(RefineFits(scene, node, path, dim, refine));
  for (PetscInt k = 0; k < refine && !ierr; k++) gmshModelMeshRefine(&ierr);
  if (ierr) PeriGmshLastError(msg, sizeof(msg));
  PeriInputCheck(!ierr, scene, node, "refine", "Gmsh cannot refine %s: %s", path, msg);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One particle per element of dimension dim: centroid, measure (x thickness in 2D); elem[tag] is
 * the particle of each element tag (-1 for none). */
static PetscErrorCode MeshParticles(PeriScene scene, PeriNode node, const char path[], const MeshNodes *nodes, PetscInt dim, PetscReal thickness, PetscInt *n, PetscReal **x, PetscReal **vol, PetscInt **elem, size_t *maxelem)
{
  MeshElements e;
  PetscInt     k = 0, ed, ec;
  PetscBool    simplex;

  PetscFunctionBeginUser;
  PetscCall(ElementsGet(dim, -1, &e));
  *n       = e.count;
  *maxelem = 0;
  for (size_t t = 0; t < e.ntypes; t++)
    for (size_t i = 0; i < e.netags[t]; i++) *maxelem = PetscMax(*maxelem, e.etags[t][i]);
  PetscCall(PetscMalloc2(3 * e.count, x, e.count, vol));
  PetscCall(PetscMalloc1(*maxelem + 1, elem));
  for (size_t t = 0; t <= *maxelem; t++) (*elem)[t] = -1;
  for (size_t t = 0; t < e.ntypes; t++) {
    ElementShape(e.types[t], &ed, &ec, &simplex);
    for (size_t i = 0; i < e.netags[t]; i++, k++) {
      PetscReal X[8][3], m;
      ElementCorners(nodes, &e.ntags[t][i * ec], ec, X);
      ElementMeasure(dim, ec, simplex, X, &m, &(*x)[3 * k]);
      (*vol)[k]              = dim == 2 ? m * thickness : m;
      (*elem)[e.etags[t][i]] = k;
      if (dim == 2 && (*x)[3 * k + 2] != 0) ElementsFree(&e);
      PeriInputCheck(dim == 3 || (*x)[3 * k + 2] == 0, scene, node, "mesh", "%s: a 2D mesh must lie in the plane z = 0 (element %zu is at z = %g)", path, e.etags[t][i], (double)(*x)[3 * k + 2]);
      if (!(m > 0)) ElementsFree(&e);
      PeriInputCheck(m > 0, scene, node, "mesh", "%s: element %zu is degenerate (measure %g)", path, e.etags[t][i], (double)m);
    }
  }
  ElementsFree(&e);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static int ComparePositions(const void *a, const void *b)
{
  const PetscReal *x = (const PetscReal *)a, *y = (const PetscReal *)b;
  for (int d = 0; d < 3; d++)
    if (x[d] != y[d]) return x[d] < y[d] ? -1 : 1;
  return 0;
}

/* The particles of the group's own elements (a group of the mesh's dimension), and the measure of
 * the elements of a lower-dimensional group (length x thickness of a 2D boundary curve, area of a
 * 3D boundary surface): the face area a traction on it acts on. */
static PetscErrorCode GroupEntities(PetscInt dim, PetscReal thickness, const MeshNodes *nodes, int gd, int gt, const PetscInt elem[], PetscInt *members, PetscInt *m, PetscReal *measure)
{
  int      *tags, ierr = 0;
  size_t    ntags;
  PetscInt  ed, ec;
  PetscBool simplex;

  PetscFunctionBeginUser;
  *measure = 0;
  gmshModelGetEntitiesForPhysicalGroup(gd, gt, &tags, &ntags, &ierr);
  GmshCheck(ierr, "reading a physical group's entities");
  for (size_t k = 0; k < ntags; k++) {
    MeshElements e;
    PetscCall(ElementsGet(gd, tags[k], &e));
    for (size_t t = 0; t < e.ntypes; t++) {
      ElementShape(e.types[t], &ed, &ec, &simplex);
      for (size_t i = 0; i < e.netags[t]; i++) {
        PetscReal X[8][3], c[3], w;
        if (gd == dim) {
          members[(*m)++] = elem[e.etags[t][i]];
          continue;
        }
        ElementCorners(nodes, &e.ntags[t][i * ec], ec, X);
        ElementMeasure(gd, ec, simplex, X, &w, c);
        *measure += gd == dim - 1 ? (dim == 2 ? w * thickness : w) : 0;
      }
    }
    ElementsFree(&e);
  }
  gmshFree(tags);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The group's particles: its own elements (a group of the mesh's dimension), or the elements with
 * at least gd + 1 corners on its nodes (a group of lower dimension gd: a side on a boundary curve or
 * surface, a corner at a point). Their positions are sorted so that membership is a binary search
 * that survives the renumbering of the partition. */
static PetscErrorCode GroupMembers(const MeshNodes *nodes, PetscInt dim, PetscReal thickness, int gd, int gt, const PetscInt elem[], PetscInt nparticles, const PetscReal x[], PeriMeshGroup *g)
{
  MeshElements e;
  size_t      *ntags, nn, nc;
  double      *coord;
  char        *on;
  PetscInt     ed, ec, *members, m = 0;
  PetscBool    simplex;
  int          ierr = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(nparticles, &members));
  PetscCall(GroupEntities(dim, thickness, nodes, gd, gt, elem, members, &m, &g->measure));
  if (gd < dim) {
    PetscCall(PetscCalloc1(nodes->maxtag + 1, &on));
    gmshModelMeshGetNodesForPhysicalGroup(gd, gt, &ntags, &nn, &coord, &nc, &ierr);
    GmshCheck(ierr, "reading a physical group's nodes");
    for (size_t k = 0; k < nn; k++) on[ntags[k]] = 1;
    gmshFree(ntags);
    gmshFree(coord);
    PetscCall(ElementsGet(dim, -1, &e));
    for (size_t t = 0; t < e.ntypes; t++) {
      ElementShape(e.types[t], &ed, &ec, &simplex);
      for (size_t i = 0; i < e.netags[t]; i++) {
        PetscInt hits = 0;
        for (PetscInt a = 0; a < ec; a++) hits += on[e.ntags[t][i * ec + a]];
        if (hits >= gd + 1) members[m++] = elem[e.etags[t][i]];
      }
    }
    ElementsFree(&e);
    PetscCall(PetscFree(on));
  }
  g->count = m;
  PetscCall(PetscMalloc1(3 * PetscMax(m, 1), &g->x));
  for (PetscInt k = 0; k < m; k++)
    for (PetscInt d = 0; d < 3; d++) g->x[3 * k + d] = x[3 * members[k] + d];
  qsort(g->x, (size_t)m, 3 * sizeof(PetscReal), ComparePositions);
  PetscCall(PetscFree(members));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every named physical group of dimension <= dim, as a particle set. */
static PetscErrorCode MeshGroups(PeriScene scene, PeriNode node, const char path[], const MeshNodes *nodes, PetscInt dim, PetscReal thickness, const PetscInt elem[], PetscInt n, const PetscReal x[], PetscInt *ngroups, PeriMeshGroup **groups)
{
  int   *dimtags, ierr = 0;
  size_t nd;

  PetscFunctionBeginUser;
  gmshModelGetPhysicalGroups(&dimtags, &nd, -1, &ierr);
  GmshCheck(ierr, "reading the physical groups");
  PetscCall(PetscCalloc1(nd / 2 + 1, groups));
  *ngroups = 0;
  for (size_t k = 0; k < nd / 2; k++) {
    PeriMeshGroup *g    = &(*groups)[*ngroups];
    char          *name = NULL;
    size_t         len;
    gmshModelGetPhysicalName(dimtags[2 * k], dimtags[2 * k + 1], &name, &ierr);
    len = name ? strlen(name) : 0;
    if (!len || dimtags[2 * k] > dim || len >= sizeof(g->name)) {
      if (len >= sizeof(g->name)) gmshFree(dimtags);
      PeriInputCheck(len < sizeof(g->name), scene, node, "mesh", "%s: the physical group name '%s' is too long (at most %d characters)", path, name, PERI_NAME_LEN - 1);
      gmshFree(name);
      continue; /* unnamed groups have no region name */
    }
    PetscCall(PetscStrncpy(g->name, name, sizeof(g->name)));
    gmshFree(name);
    g->dim = dimtags[2 * k];
    PetscCall(GroupMembers(nodes, dim, thickness, dimtags[2 * k], dimtags[2 * k + 1], elem, n, x, g));
    (*ngroups)++;
  }
  gmshFree(dimtags);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMeshRead - reads particles.mesh (a Gmsh mesh, or a .geo meshed with particles.size): one
  particle per element of dimension dim at its centroid with its exact volume (area x thickness in
  2D), the named physical groups, and box (lower, then upper corner) the nodes' bounding box: the
  exact box of a body meshed periodically. x, vol are allocated with PetscMalloc2; groups with
  PetscCalloc1 (free with PeriMeshGroupsDestroy). Not collective: every rank reads the same file.
@*/
PetscErrorCode PeriMeshRead(PeriScene scene, PeriNode node, PetscInt dim, PetscReal thickness, PetscInt *n, PetscReal **x, PetscReal **vol, PetscInt *ngroups, PeriMeshGroup **groups, PetscReal box[6])
{
  char        path[PETSC_MAX_PATH_LEN], dir[PETSC_MAX_PATH_LEN] = "", msh[PETSC_MAX_PATH_LEN] = "";
  PetscBool   geo = PETSC_FALSE, verbose;
  PetscReal   lc  = 0;
  MeshNodes   nodes;
  PetscInt   *elem;
  size_t      maxelem;
  int         ierr   = 0;
  const char *format = NULL;

  PetscFunctionBeginUser;
  PetscCall(MeshSource(scene, node, path, sizeof(path), &geo, &lc, &format));
  PetscCall(PeriSceneGetBool(scene, node, "verbose", &verbose, NULL));
  PetscCall(GmshStart(verbose));
  if (format) PetscCall(MeshImport(scene, node, path, format, dir, sizeof(dir), msh, sizeof(msh)));
  PetscCall(MeshOpen(scene, node, path, dir, msh, geo, lc, dim));
  PetscCall(MeshRefine(scene, node, path, dim));
  PetscCall(NodesGet(&nodes));
  for (PetscInt d = 0; d < 3; d++) {
    box[d]     = d < dim ? PETSC_MAX_REAL : 0;
    box[3 + d] = d < dim ? PETSC_MIN_REAL : 0;
    for (size_t k = 0; k < nodes.n && d < dim; k++) {
      box[d]     = PetscMin(box[d], nodes.xyz[3 * k + d]);
      box[3 + d] = PetscMax(box[3 + d], nodes.xyz[3 * k + d]);
    }
  }
  PetscCall(MeshParticles(scene, node, path, &nodes, dim, thickness, n, x, vol, &elem, &maxelem));
  PetscCall(MeshGroups(scene, node, path, &nodes, dim, thickness, elem, *n, *x, ngroups, groups));
  PetscCall(PetscFree(elem));
  PetscCall(NodesDestroy(&nodes));
  gmshClear(&ierr); /* the model is not needed any more: free its memory now */
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMeshGroupsRestrict - keeps of each group of p the positions of p's own particles: once p is a
  rank's local view, the rest of the body's group is never asked for (a group may be the whole
  body). The positions stay sorted. Not collective.
@*/
PetscErrorCode PeriMeshGroupsRestrict(PeriParticles *p)
{
  PetscFunctionBeginUser;
  for (PetscInt g = 0; g < p->ngroups; g++) {
    PeriMeshGroup *grp = &p->groups[g];
    PetscBool     *keep;
    PetscInt       m = 0;
    PetscCall(PetscCalloc1(grp->count, &keep));
    for (PetscInt i = 0; i < p->n; i++) {
      const PetscReal *hit = (const PetscReal *)bsearch(&p->x[3 * i], grp->x, (size_t)grp->count, 3 * sizeof(PetscReal), ComparePositions);
      if (hit) keep[(hit - grp->x) / 3] = PETSC_TRUE;
    }
    for (PetscInt k = 0; k < grp->count; k++)
      if (keep[k]) PetscCall(PetscArraymove(&grp->x[3 * m++], &grp->x[3 * k], 3));
    grp->count = m;
    PetscCall(PetscFree(keep));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriMeshGroupsDestroy(PetscInt *ngroups, PeriMeshGroup **groups)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < *ngroups; k++) PetscCall(PetscFree((*groups)[k].x));
  PetscCall(PetscFree(*groups));
  *ngroups = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The corners of the surface elements e holds (triangles; a quadrangle gives two) into tri[9 k ..]. */
static PetscErrorCode SurfaceCorners(const MeshNodes *nodes, const MeshElements *e, PetscInt *ntri, PetscReal **tri)
{
  PetscInt  ed, ec, n = 0;
  PetscBool simplex;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(18 * e->count + 1, tri));
  for (size_t t = 0; t < e->ntypes; t++) {
    ElementShape(e->types[t], &ed, &ec, &simplex);
    if (ed != 2 || !ec) continue;
    for (size_t k = 0; k < e->netags[t]; k++) {
      PetscReal X[8][3];
      ElementCorners(nodes, &e->ntags[t][k * (e->nntags[t] / e->netags[t])], ec, X);
      for (PetscInt h = 0; h + 2 < ec; h++) { /* a fan about the first corner */
        for (PetscInt r = 0; r < 3; r++) {
          (*tri)[9 * n + r]     = X[0][r];
          (*tri)[9 * n + 3 + r] = X[h + 1][r];
          (*tri)[9 * n + 6 + r] = X[h + 2][r];
        }
        n++;
      }
    }
  }
  *ntri = n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMeshSurfaceRead - the triangles of a surface file (path, already resolved; map.key names it in
  errors) that Gmsh reads: a .msh surface mesh, or an STL file (ASCII or binary). tri gets 9
  coordinates per triangle (PetscFree); a quadrangle gives two. Not collective: every rank reads it.
@*/
PetscErrorCode PeriMeshSurfaceRead(PeriScene scene, PeriNode map, const char key[], const char path[], PetscInt *ntri, PetscReal **tri)
{
  char         msg[256] = "";
  int          ierr     = 0;
  MeshNodes    nodes;
  MeshElements e;

  PetscFunctionBeginUser;
  PeriInputCheck(access(path, R_OK) == 0, scene, map, key, "cannot read %s: %s", path, strerror(errno));
  PetscCall(GmshStart(PETSC_FALSE));
  gmshOpen(path, &ierr);
  if (ierr) PeriGmshLastError(msg, sizeof(msg));
  PeriInputCheck(!ierr, scene, map, key, "Gmsh cannot read %s: %s", path, msg);
  PetscCall(NodesGet(&nodes));
  PetscCall(ElementsGet(2, -1, &e));
  PetscCall(SurfaceCorners(&nodes, &e, ntri, tri));
  ElementsFree(&e);
  PetscCall(NodesDestroy(&nodes));
  gmshClear(&ierr);
  if (!*ntri) PetscCall(PetscFree(*tri));
  PeriInputCheck(*ntri > 0, scene, map, key, "%s holds no triangles", path);
  PetscFunctionReturn(PETSC_SUCCESS);
}
