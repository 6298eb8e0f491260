/* Particles: a cell-centred grid in a box, a CSV file of positions and volumes, or the elements of
 * a Gmsh mesh (src/disc/mesh.c). */
#include "perilin/private/disc.h"
#include <errno.h>

/* Room for n particles: positions (zeroed: z = 0 in 2D), volumes, spacings, source lines. */
PetscErrorCode PeriParticlesAllocate(PeriParticles *p, PetscInt n)
{
  PetscFunctionBeginUser;
  p->n = n;
  PetscCall(PetscCalloc1(3 * n, &p->x));
  PetscCall(PetscMalloc3(n, &p->volume, n, &p->spacing, n, &p->source_line));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* grid.* and particles.*: a body is one or the other. */
static const PeriKey grid_keys[] = {
    {"lower", PERI_KEY_REALS, "required", NULL, "[length]", NULL, "the box's lower corner, dim numbers"},
    {"upper", PERI_KEY_REALS, "required", NULL, "[length]", NULL, "the box's upper corner, dim numbers, above lower on every axis"},
    {"spacing", PERI_KEY_REAL, "required", "(0, inf)", "[length]", NULL, "particle spacing dx: every box length a whole number of spacings"},
    {"periodic", PERI_KEY_BOOLS, "all false", NULL, NULL, NULL, "dim booleans: the periodic axes (minimum image)"},
    {"holes", PERI_KEY_LIST, NULL, NULL, NULL, NULL, "holes cut out of the grid: the cells whose centre lies inside a circle (2D), a cylinder or a sphere (3D), or a box, are left out"},
    {NULL},
};
static const char *const hole_axes[] = {"x", "y", "z", "none", NULL};
static const PeriKey     hole_keys[] = {
        {"center", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "a round hole: a point on its axis (its centre), dim numbers; with radius"},
        {"radius", PERI_KEY_REAL, NULL, "(0, inf)", "[length]", NULL, "a round hole's radius: cells closer to the axis (to the centre for a sphere) are left out"},
        {"axis", PERI_KEY_CHOICE, "z", NULL, NULL, hole_axes, "3D, a round hole: the cylinder's axis, or none for a sphere"},
        {"lower", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "a box hole instead: its lower corner, dim numbers; with upper (cells whose centre lies in the closed box are left out)"},
        {"upper", PERI_KEY_REALS, NULL, NULL, "[length]", NULL, "a box hole's upper corner, above lower on every axis"},
        {NULL},
};
static const PeriKey particles_keys[] = {
    {"file", PERI_KEY_STRING, NULL, NULL, NULL, NULL, "CSV file of x, y[, z], volume[, material] (relative to the scene file), instead of grid; give file or mesh"},
    {"mesh", PERI_KEY_STRING, NULL, NULL, NULL, NULL, "Gmsh mesh (.msh, any version Gmsh reads), geometry (.geo, meshed with size), Abaqus .inp or Exodus II (.exo, .e: converted with meshio), relative to the scene file: one particle per element of dimension dim, named physical groups, element and node sets and Exodus blocks as regions (docs/mesh.md)"},
    {"size", PERI_KEY_REAL, "required for a .geo", "(0, inf)", "[length]", NULL, "the largest element size Gmsh meshes a .geo with (Mesh.MeshSizeMax; smaller sizes in the .geo still refine)"},
    {"verbose", PERI_KEY_BOOL, "false", NULL, NULL, NULL, "let Gmsh print its messages while it reads or meshes particles.mesh"},
    {"refine", PERI_KEY_INT, "0", "[0, 4]", NULL, NULL, "particles.mesh: split every element uniformly this many times (Gmsh's RefineMesh: a triangle into 4, a tetrahedron into 8), the same mesh finer, as a convergence study refines (docs/mesh.md)"},
    {"periodic", PERI_KEY_BOOLS, "all false", NULL, NULL, NULL, "particles.mesh: dim booleans, the periodic axes (minimum image); the period is the mesh nodes' extent along the axis (docs/mesh.md)"},
    {NULL},
};
const PeriSchema PeriParticlesSchema[] = {
    {"grid", grid_keys},
    {"grid.holes.<k>", hole_keys},
    {"particles", particles_keys},
    {NULL},
};

/*@C
  PeriParticlesReadPeriodic - node.periodic (grid or particles) into p->periodic. Not collective.
@*/
PetscErrorCode PeriParticlesReadPeriodic(PeriScene scene, PeriNode node, PeriParticles *p)
{
  PeriNode per;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(node, "periodic", &per));
  if (!per) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(per->kind == PERI_NODE_SEQ && per->n == p->dim, scene, per, NULL, "must be a list of %" PetscInt_FMT " booleans, e.g. [false, true]", p->dim);
  for (PetscInt d = 0; d < p->dim; d++) PetscCall(PeriSceneParseBool(scene, per->child[d], &p->periodic[d]));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesPeriodicBox - a mesh's body on its periodic axes spans the nodes' bounding box
  (lower, then upper corner), not the particles' cells: the period is the mesh's length.
@*/
void PeriParticlesPeriodicBox(PeriParticles *p, const PetscReal box[6])
{
  for (PetscInt d = 0; d < p->dim; d++)
    if (p->periodic[d]) {
      p->lower[d] = box[d];
      p->upper[d] = box[3 + d];
    }
}

#define PERI_MAX_HOLES 64

/* grid.holes: the cells left out of the grid */
typedef struct {
  PetscInt  n;
  PetscReal c[PERI_MAX_HOLES][3], r2[PERI_MAX_HOLES], hi[PERI_MAX_HOLES][3]; /* a box: c is its lower corner */
  PetscInt  axis[PERI_MAX_HOLES];                                            /* 0, 1, 2, -1 for a sphere, -2 for a box */
} GridHoles;

/* A box hole's corners (lower, upper). */
static PetscErrorCode BoxHoleParse(PeriScene scene, PeriNode item, PetscInt dim, PetscReal lo[], PetscReal hi[])
{
  PeriNode round;
  PetscInt n;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(item, "center", &round));
  PeriInputCheck(!round, scene, item, "center", "a hole is a box (lower, upper) or round (center, radius), not both");
  PetscCall(PeriSceneGetRealArray(scene, item, "lower", PETSC_TRUE, dim, dim, lo, &n));
  PetscCall(PeriSceneGetRealArray(scene, item, "upper", PETSC_TRUE, dim, dim, hi, &n));
  for (PetscInt d = 0; d < dim; d++) PeriInputCheck(hi[d] >= lo[d], scene, item, "upper", "must be at least lower on every axis (axis %" PetscInt_FMT ": %g < %g)", d, (double)hi[d], (double)lo[d]);
  for (PetscInt d = dim; d < 3; d++) lo[d] = hi[d] = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Reads grid.holes into holes. */
static PetscErrorCode HolesParse(PeriScene scene, PeriNode grid, PetscInt dim, GridHoles *holes)
{
  PeriNode list;

  PetscFunctionBeginUser;
  holes->n = 0;
  PetscCall(PeriSceneGetNode(grid, "holes", &list));
  if (!list) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(list->kind == PERI_NODE_SEQ && list->n <= PERI_MAX_HOLES, scene, grid, "holes", "a list of at most %d holes [{center: [..], radius: r}, ..]", PERI_MAX_HOLES);
  for (PetscInt k = 0; k < list->n; k++) {
    PeriNode  item = list->child[k];
    PeriNode  given;
    PetscReal r;
    PetscInt  n, axis = 2;
    PeriInputCheck(item->kind == PERI_NODE_MAP, scene, item, NULL, "a hole is {center: [..], radius: r(, axis: x|y|z|none)} or {lower: [..], upper: [..]}");
    PetscCall(PeriSceneCheckSection(scene, item, "grid.holes.<k>"));
    for (PetscInt d = 0; d < 3; d++) holes->c[k][d] = holes->hi[k][d] = 0;
    PetscCall(PeriSceneGetNode(item, "lower", &given));
    if (given) {
      PetscCall(BoxHoleParse(scene, item, dim, holes->c[k], holes->hi[k]));
      holes->axis[k] = -2;
      continue;
    }
    PetscCall(PeriSceneGetRealArray(scene, item, "center", PETSC_TRUE, dim, dim, holes->c[k], &n));
    PetscCall(PeriSceneGetReal(scene, item, "radius", PETSC_TRUE, &r, NULL));
    PetscCall(PeriSceneGetNode(item, "axis", &given));
    PeriInputCheck(dim == 3 || !given, scene, item, "axis", "is for 3D grids only (a 2D hole is a circle)");
    PetscCall(PeriSceneGetChoice(scene, item, "axis", hole_axes, &axis, NULL));
    holes->r2[k]   = r * r;
    holes->axis[k] = dim == 2 ? 2 : axis == 3 ? -1
                                              : axis;
  }
  holes->n = list->n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The hole that holds x, or -1. */
static PetscInt HoleAt(const GridHoles *holes, const PetscReal x[])
{
  for (PetscInt k = 0; k < holes->n; k++) {
    PetscReal d2 = 0;
    if (holes->axis[k] == -2) {
      PetscBool in = PETSC_TRUE;
      for (PetscInt d = 0; d < 3; d++) in = (PetscBool)(in && x[d] >= holes->c[k][d] && x[d] <= holes->hi[k][d]);
      if (in) return k;
      continue;
    }
    for (PetscInt d = 0; d < 3; d++)
      if (d != holes->axis[k]) d2 += PetscSqr(x[d] - holes->c[k][d]);
    if (d2 < holes->r2[k]) return k;
  }
  return -1;
}

/* Reads grid.*: the box into p, the cells per axis and the spacing. */
static PetscErrorCode GridParse(PeriScene scene, PeriNode grid, PetscInt dim, PeriParticles *p, PetscInt cells[3], PetscReal *h)
{
  PetscReal lower[3] = {0, 0, 0}, upper[3] = {0, 0, 0};
  PetscInt  nl, nu, n = 1;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneCheckSection(scene, grid, "grid"));
  PetscCall(PeriSceneGetRealArray(scene, grid, "lower", PETSC_TRUE, dim, dim, lower, &nl));
  PetscCall(PeriSceneGetRealArray(scene, grid, "upper", PETSC_TRUE, dim, dim, upper, &nu));
  PetscCall(PeriSceneGetReal(scene, grid, "spacing", PETSC_TRUE, h, NULL));
  PetscCall(PeriParticlesReadPeriodic(scene, grid, p));
  for (PetscInt d = 0; d < 3; d++) cells[d] = 1;
  for (PetscInt d = 0; d < dim; d++) {
    PetscReal L = upper[d] - lower[d], c;
    /* 1e308 - (-1e308) is inf: say so rather than call inf "not a whole number of spacings" */
    PeriInputCheck(!PetscIsInfOrNanReal(L), scene, grid, "upper", "the box is too large for double precision: upper - lower = %g - (%g) overflows along axis %" PetscInt_FMT, (double)upper[d], (double)lower[d], d);
    PeriInputCheck(L > 0, scene, grid, "upper", "must exceed grid.lower in every axis (axis %" PetscInt_FMT ": %g <= %g)", d, (double)upper[d], (double)lower[d]);
    c        = L / *h;
    cells[d] = (PetscInt)PetscFloorReal(c + 0.5);
    PeriInputCheck(cells[d] >= 1 && PetscAbsReal(c - cells[d]) < 1e-6 * PetscMax(c, 1), scene, grid, "spacing", "the box length %g along axis %" PetscInt_FMT " is not a whole number of spacings %g", (double)L, d, (double)*h);
    PeriInputCheck(cells[d] <= 100000000 / n, scene, grid, "spacing", "gives too many particles");
    n *= cells[d];
    p->lower[d] = lower[d];
    p->upper[d] = upper[d];
  }
  for (PetscInt l = 0; l < scene->coarsen; l++) { /* a multigrid level: the same box, centred */
    *h *= 2;
    for (PetscInt d = 0; d < dim; d++) {
      const PetscReal mid = 0.5 * (lower[d] + upper[d]);
      cells[d]            = (cells[d] + 1) / 2;
      p->lower[d]         = mid - 0.5 * cells[d] * *h;
      p->upper[d]         = mid + 0.5 * cells[d] * *h;
    }
  }
  p->mean_spacing = *h;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The centre of cell k (x fastest). */
static inline void CellCentre(const PeriParticles *p, const PetscInt cells[3], PetscReal h, PetscInt k, PetscReal x[3])
{
  const PetscInt c[3] = {k % cells[0], (k / cells[0]) % cells[1], k / (cells[0] * cells[1])};
  for (PetscInt d = 0; d < 3; d++) x[d] = d < p->dim ? p->lower[d] + (c[d] + 0.5) * h : 0;
}

/* The grid's cells kstart..kend-1 (x fastest) outside the holes, one particle at each centre. */
static PetscErrorCode GridFill(PeriParticles *p, const PetscInt cells[3], PetscReal h, const GridHoles *holes, PetscInt kstart, PetscInt kend)
{
  const PetscReal cellvol = p->dim == 3 ? h * h * h : h * h * p->thickness;
  PetscInt        n = 0, l = 0;
  PetscReal       x[3];

  PetscFunctionBeginUser;
  for (PetscInt k = kstart; k < kend; k++) {
    CellCentre(p, cells, h, k, x);
    n += HoleAt(holes, x) < 0;
  }
  PetscCall(PeriParticlesAllocate(p, n));
  for (PetscInt k = kstart; k < kend; k++) {
    CellCentre(p, cells, h, k, x);
    if (HoleAt(holes, x) >= 0) continue;
    for (PetscInt d = 0; d < p->dim; d++) p->x[3 * l + d] = x[d];
    p->volume[l]      = cellvol;
    p->spacing[l]     = h;
    p->source_line[l] = 0;
    l++;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The grid's count of particles, N cells less those in the holes; an input error for a hole that
 * takes no cell or every one. */
static PetscErrorCode GridCount(PeriScene scene, PeriNode grid, const PeriParticles *p, const PetscInt cells[3], PetscReal h, const GridHoles *holes, PetscInt *N)
{
  PetscInt  taken[PERI_MAX_HOLES] = {0}, left = 0;
  PetscReal x[3];
  PeriNode  list;

  PetscFunctionBeginUser;
  if (!holes->n) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; k < *N; k++) {
    PetscInt hole;
    CellCentre(p, cells, h, k, x);
    hole = HoleAt(holes, x);
    if (hole >= 0)
      taken[hole]++;
    else
      left++;
  }
  PetscCall(PeriSceneGetNode(grid, "holes", &list));
  for (PetscInt k = 0; k < holes->n; k++) PeriInputCheck(taken[k] > 0, scene, list->child[k], holes->axis[k] == -2 ? "lower" : "radius", "the hole takes no particle: no cell centre lies inside it that an earlier hole did not take (outside the body, smaller than a cell, or inside another hole)");
  PeriInputCheck(left > 0, scene, grid, "holes", "the holes take every particle of the grid");
  *N = left;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriGridCreate - the grid's particles (grid.*): of its N cells in x-fastest order, those of the
  share floor(rank N / size) .. floor((rank + 1) N / size) - 1 that lie outside grid.holes; *N is
  the whole body's count (every rank counts the holes' cells); p's box, periodic axes and spacing
  are the whole grid's. Not collective.
@*/
PetscErrorCode PeriGridCreate(PeriScene scene, PeriNode grid, PetscInt dim, PetscMPIInt rank, PetscMPIInt size, PeriParticles *p, PetscInt *N)
{
  PetscInt  cells[3], ncells;
  PetscReal h;
  GridHoles holes;

  PetscFunctionBeginUser;
  PetscCall(GridParse(scene, grid, dim, p, cells, &h));
  PetscCall(HolesParse(scene, grid, dim, &holes));
  *N = ncells = cells[0] * cells[1] * cells[2];
  PetscCall(GridCount(scene, grid, p, cells, h, &holes, N));
  PetscCall(GridFill(p, cells, h, &holes, (PetscInt)((PetscInt64)ncells * rank / size), (PetscInt)((PetscInt64)ncells * (rank + 1) / size)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Splits one line into up to 5 numbers; *skip for comments and blank lines, *rest when text follows the numbers. */
static PetscErrorCode CSVLineSplit(char line[], double v[5], int *nf, PetscBool *skip, PetscBool *rest)
{
  char *s = line, *end;

  PetscFunctionBeginUser;
  *nf   = 0;
  *skip = PETSC_FALSE;
  *rest = PETSC_FALSE;
  while (*s == ' ' || *s == '\t') s++;
  if (*s == '#' || *s == '\n' || *s == '\r' || !*s) {
    *skip = PETSC_TRUE;
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  while (*nf < 5) {
    v[*nf] = strtod(s, &end);
    if (end == s) break;
    (*nf)++;
    s = end;
    while (*s == ' ' || *s == '\t') s++;
    if (*s == ',') s++;
  }
  while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n') s++;
  *rest = *s ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What is wrong with a particle line (NULL if nothing): its fields, then its volume; a non-finite value overrides both. */
static PetscErrorCode CSVLineProblem(PetscInt dim, const double v[], int nf, PetscBool rest, const char **problem)
{
  PetscFunctionBeginUser;
  *problem = NULL;
  if (nf < dim + 1 || nf > dim + 2 || rest)
    *problem = dim == 2 ? "expected x, y, volume[, material]" : "expected x, y, z, volume[, material]";
  else if (!(v[dim] > 0))
    *problem = "the volume must be positive";
  for (int k = 0; k < nf; k++)
    if (!PetscIsNormalReal((PetscReal)v[k]) && v[k] != 0) *problem = "every value must be a finite number";
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Doubles the capacity of the positions (3 per particle), volumes and source lines read so far. */
static PetscErrorCode CSVGrow(PetscInt *cap, PetscReal **x, PetscReal **vol, PetscInt **src)
{
  PetscReal *x2, *v2;
  PetscInt  *s2;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc3(6 * *cap, &x2, 2 * *cap, &v2, 2 * *cap, &s2));
  PetscCall(PetscArraycpy(x2, *x, 3 * *cap));
  PetscCall(PetscArraycpy(v2, *vol, *cap));
  PetscCall(PetscArraycpy(s2, *src, *cap));
  PetscCall(PetscFree3(*x, *vol, *src));
  *x   = x2;
  *vol = v2;
  *src = s2;
  *cap *= 2;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCSVOpen - opens particles.file (section node) for reading particle by particle with
  PeriCSVNext. Not collective.
@*/
PetscErrorCode PeriCSVOpen(PeriScene scene, PeriNode node, PetscInt dim, PeriCSV *csv)
{
  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(csv, sizeof(*csv)));
  csv->scene = scene;
  csv->node  = node;
  csv->dim   = dim;
  PetscCall(PeriSceneGetPath(scene, node, "file", PETSC_TRUE, csv->path, sizeof(csv->path), NULL));
  csv->fp = fopen(csv->path, "r");
  PeriInputCheck(csv->fp, scene, node, "file", "cannot open %s: %s", csv->path, strerror(errno));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCSVNext - the file's next particle: position (z = 0 in 2D), volume and line number; *done
  at the end of the file. *problem (else NULL) says what is wrong with the line just read: the
  caller frees what it holds, then raises the error with PeriCSVFail. Not collective.
@*/
PetscErrorCode PeriCSVNext(PeriCSV *csv, PetscReal x[], PetscReal *vol, PetscInt *line, PetscBool *done, const char **problem)
{
  char line_text[1024];

  PetscFunctionBeginUser;
  *done    = PETSC_TRUE;
  *problem = NULL;
  while (fgets(line_text, sizeof(line_text), csv->fp)) {
    double    v[5];
    int       nf;
    PetscBool skip, rest;

    if (PeriSignalPending()) { /* a file of millions of lines takes seconds: SIGTERM ends it */
      PetscCall(PetscSNPrintf(csv->stop, sizeof(csv->stop), "interrupted by %s while reading: nothing was written", PeriSignalName(PeriSignalPending())));
      *problem = csv->stop;
      break;
    }
    csv->lineno++;
    PetscCall(CSVLineSplit(line_text, v, &nf, &skip, &rest));
    if (skip) continue;
    if (nf == 0 && csv->n == 0 && !csv->header) { /* a header line before the first particle */
      csv->header = PETSC_TRUE;
      continue;
    }
    PetscCall(CSVLineProblem(csv->dim, v, nf, rest, problem));
    if (*problem) break;
    for (PetscInt d = 0; d < 3; d++) x[d] = d < csv->dim ? v[d] : 0;
    *vol  = v[csv->dim];
    *line = csv->lineno;
    *done = PETSC_FALSE;
    csv->n++;
    break;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriCSVFail - closes the file and raises the error of its last line read (file:line: problem).
@*/
PetscErrorCode PeriCSVFail(PeriCSV *csv, const char problem[])
{
  PetscFunctionBeginUser;
  fclose(csv->fp);
  csv->fp = NULL;
  SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%" PetscInt_FMT ": %s (particles.file, referenced from %s)", csv->path, csv->lineno, problem, csv->scene->file);
}

/*@C
  PeriCSVClose - closes the file; a file without particles is an error. Not collective.
@*/
PetscErrorCode PeriCSVClose(PeriCSV *csv)
{
  PetscFunctionBeginUser;
  fclose(csv->fp);
  csv->fp = NULL;
  PeriInputCheck(csv->n > 0, csv->scene, csv->node, "file", "%s holds no particles", csv->path);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Reads the file's n particles into x, vol, src (allocated here, freed by the caller); stops at the first bad line. */
static PetscErrorCode CSVRead(PeriScene scene, PeriNode node, PetscInt dim, PetscInt *n, PetscReal **x, PetscReal **vol, PetscInt **src)
{
  PeriCSV     csv;
  PetscInt    cap = 1024;
  PetscBool   done;
  const char *problem;

  PetscFunctionBeginUser;
  *n = 0;
  PetscCall(PeriCSVOpen(scene, node, dim, &csv));
  PetscCall(PetscMalloc3(3 * cap, x, cap, vol, cap, src));
  for (;;) {
    PetscReal xk[3], vk;
    PetscInt  lk;

    PetscCall(PeriCSVNext(&csv, xk, &vk, &lk, &done, &problem));
    if (problem || (done && !*n)) PetscCall(PetscFree3(*x, *vol, *src));
    if (problem) PetscCall(PeriCSVFail(&csv, problem));
    if (done) break;
    if (*n == cap) PetscCall(CSVGrow(&cap, x, vol, src));
    for (PetscInt d = 0; d < 3; d++) (*x)[3 * *n + d] = xk[d];
    (*vol)[*n] = vk;
    (*src)[*n] = lk;
    (*n)++;
  }
  PetscCall(PeriCSVClose(&csv));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticleSpacing - a read particle's spacing from its volume: cbrt(V) in 3D, sqrt(V /
  thickness) in 2D.
@*/
PetscReal PeriParticleSpacing(const PeriParticles *p, PetscReal vol)
{
  return p->dim == 3 ? PetscCbrtReal(vol) : PetscSqrtReal(vol / p->thickness);
}

/*@C
  PeriExtentInit, PeriExtentAdd, PeriExtentSet - the box of read particles (each one's cell of its
  own spacing) and their mean spacing, accumulated particle by particle in the body's order:
  every creation path sums the spacings in that order, so the mean rounds alike on all of them.
@*/
void PeriExtentInit(PeriExtent *e)
{
  for (PetscInt d = 0; d < 3; d++) {
    e->lower[d] = PETSC_MAX_REAL;
    e->upper[d] = PETSC_MIN_REAL;
  }
  e->sum = 0;
  e->n   = 0;
}

void PeriExtentAdd(PeriExtent *e, PetscInt dim, const PetscReal x[], PetscReal h)
{
  for (PetscInt d = 0; d < dim; d++) {
    e->lower[d] = PetscMin(e->lower[d], x[d] - h / 2);
    e->upper[d] = PetscMax(e->upper[d], x[d] + h / 2);
  }
  e->sum += h;
  e->n++;
}

void PeriExtentSet(const PeriExtent *e, PeriParticles *p)
{
  for (PetscInt d = 0; d < 3; d++) {
    p->lower[d] = d < p->dim ? e->lower[d] : 0;
    p->upper[d] = d < p->dim ? e->upper[d] : 0;
  }
  p->mean_spacing = e->sum / e->n;
}

/* Fills p with the n particles read: each one's spacing from its volume, the bounding box from those spacings. */
static PetscErrorCode CSVFill(PeriParticles *p, PetscInt n, const PetscReal x[], const PetscReal vol[], const PetscInt src[])
{
  PeriExtent e;

  PetscFunctionBeginUser;
  PetscCall(PeriParticlesAllocate(p, n));
  PeriExtentInit(&e);
  for (PetscInt k = 0; k < n; k++) {
    PetscReal h = PeriParticleSpacing(p, vol[k]);
    for (PetscInt d = 0; d < 3; d++) p->x[3 * k + d] = x[3 * k + d];
    PeriExtentAdd(&e, p->dim, &x[3 * k], h);
    p->volume[k]      = vol[k];
    p->spacing[k]     = h;
    p->source_line[k] = src[k];
  }
  PeriExtentSet(&e, p);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* x, y[, z], volume[, material]: one particle per line; '#' comments and a header line allowed. */
static PetscErrorCode CSVCreate(PeriScene scene, PeriNode node, PetscInt dim, PeriParticles *p)
{
  PetscInt   n;
  PetscReal *x, *vol;
  PetscInt  *src;

  PetscFunctionBeginUser;
  PetscCall(CSVRead(scene, node, dim, &n, &x, &vol, &src));
  PetscCall(CSVFill(p, n, x, vol, src));
  PetscCall(PetscFree3(x, vol, src));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One particle per element of a Gmsh mesh; the spacing of each is sqrt(area) or cbrt(volume), as
 * for the CSV particles. */
static PetscErrorCode MeshCreate(PeriScene scene, PeriNode node, PetscInt dim, PeriParticles *p)
{
  PetscInt   n, *src;
  PetscReal *x, *vol, box[6];

  PetscFunctionBeginUser;
  PetscCall(PeriMeshRead(scene, node, dim, p->thickness, &n, &x, &vol, &p->ngroups, &p->groups, box));
  PetscCall(PetscCalloc1(n, &src));
  PetscCall(CSVFill(p, n, x, vol, src));
  PeriParticlesPeriodicBox(p, box);
  PetscCall(PetscFree2(x, vol));
  PetscCall(PetscFree(src));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesSource - starts p (no particles; its dimension and thickness) and finds where the
  scene's body comes from: grid, particles.file or particles.mesh, exactly one of them. *node is
  the grid or the particles section. Not collective.
@*/
PetscErrorCode PeriParticlesSource(PeriScene scene, PetscInt dim, PetscReal thickness, PeriParticles *p, PeriSource *source, PeriNode *node)
{
  PeriNode grid, csv, file, mesh;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(p, sizeof(*p)));
  p->dim       = dim;
  p->thickness = dim == 2 ? thickness : 1;
  PetscCall(PeriSceneGetMap(scene, scene->root, "grid", PETSC_FALSE, &grid));
  PetscCall(PeriSceneGetMap(scene, scene->root, "particles", PETSC_FALSE, &csv));
  PeriInputCheck(grid || csv, scene, scene->root, "grid", "is required (or give particles.file or particles.mesh)");
  PeriInputCheck(!(grid && csv), scene, csv, NULL, "give either grid or particles, not both");
  *node   = grid ? grid : csv;
  *source = PERI_SOURCE_GRID;
  if (grid) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneCheckSection(scene, csv, "particles"));
  PetscCall(PeriSceneGetNode(csv, "file", &file));
  PetscCall(PeriSceneGetNode(csv, "mesh", &mesh));
  PeriInputCheck(file || mesh, scene, csv, "file", "is required (or give particles.mesh)");
  PeriInputCheck(!(file && mesh), scene, csv, "mesh", "give either particles.file or particles.mesh, not both");
  *source = mesh ? PERI_SOURCE_MESH : PERI_SOURCE_FILE;
  PetscCall(PeriSceneGetNode(csv, "periodic", &grid));
  PeriInputCheck(mesh || !grid, scene, csv, "periodic", "applies to particles.mesh (whose nodes give the period); a particles.file has no box");
  PetscCall(PeriParticlesReadPeriodic(scene, csv, p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesCreateFromScene - generates the particles from the scene's grid or particles
  section. Not collective: every rank builds the same set, the whole body (PeriParticlesCreateOwned
  builds only a rank's share).
@*/
PetscErrorCode PeriParticlesCreateFromScene(PeriScene scene, PetscInt dim, PetscReal thickness, PeriParticles *p)
{
  PeriSource source;
  PeriNode   node;
  PetscInt   N;

  PetscFunctionBeginUser;
  PetscCall(PeriParticlesSource(scene, dim, thickness, p, &source, &node));
  if (source == PERI_SOURCE_GRID)
    PetscCall(PeriGridCreate(scene, node, dim, 0, 1, p, &N));
  else if (source == PERI_SOURCE_MESH)
    PetscCall(MeshCreate(scene, node, dim, p));
  else
    PetscCall(CSVCreate(scene, node, dim, p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Renumbers the particles: new index k holds the old particle perm[k]. */
PetscErrorCode PeriParticlesPermute(PeriParticles *p, const PetscInt perm[])
{
  PeriParticles q = *p;

  PetscFunctionBeginUser;
  PetscCall(PeriParticlesAllocate(&q, p->n));
  for (PetscInt k = 0; k < p->n; k++) {
    PetscInt o = perm[k];
    for (PetscInt d = 0; d < 3; d++) q.x[3 * k + d] = p->x[3 * o + d];
    q.volume[k]      = p->volume[o];
    q.spacing[k]     = p->spacing[o];
    q.source_line[k] = p->source_line[o];
  }
  if (p->image) {
    PetscInt *inv;
    PetscCall(PetscMalloc1(p->n, &inv));
    for (PetscInt k = 0; k < p->n; k++) inv[perm[k]] = k;
    PetscCall(PetscMalloc2(p->n, &q.image, p->n, &q.crossed));
    for (PetscInt k = 0; k < p->n; k++) {
      PetscInt o   = perm[k];
      q.image[k]   = p->image[o] < 0 ? -1 : inv[p->image[o]];
      q.crossed[k] = p->crossed[o];
    }
    PetscCall(PetscFree(inv));
  }
  p->ngroups = 0; /* the groups hold positions, not indices: q keeps them as they are */
  p->groups  = NULL;
  PetscCall(PeriParticlesDestroy(p));
  *p = q;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesSlice - q holds copies of particles rstart..rend-1 of p and p's description of the
  body (box, periodic axes, thickness, mean spacing), with their layer images (global indices) but
  no mesh groups: the owned part of a rank's local view. Not collective.
@*/
PetscErrorCode PeriParticlesSlice(const PeriParticles *p, PetscInt rstart, PetscInt rend, PeriParticles *q)
{
  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(q, sizeof(*q)));
  q->dim          = p->dim;
  q->thickness    = p->thickness;
  q->mean_spacing = p->mean_spacing;
  for (PetscInt d = 0; d < 3; d++) {
    q->lower[d]    = p->lower[d];
    q->upper[d]    = p->upper[d];
    q->periodic[d] = p->periodic[d];
  }
  PetscCall(PeriParticlesAllocate(q, rend - rstart));
  PetscCall(PetscArraycpy(q->x, &p->x[3 * rstart], 3 * (rend - rstart)));
  PetscCall(PetscArraycpy(q->volume, &p->volume[rstart], rend - rstart));
  PetscCall(PetscArraycpy(q->spacing, &p->spacing[rstart], rend - rstart));
  PetscCall(PetscArraycpy(q->source_line, &p->source_line[rstart], rend - rstart));
  if (p->image) { /* the images stay global indices */
    PetscCall(PetscMalloc2(rend - rstart, &q->image, rend - rstart, &q->crossed));
    PetscCall(PetscArraycpy(q->image, &p->image[rstart], rend - rstart));
    PetscCall(PetscArraycpy(q->crossed, &p->crossed[rstart], rend - rstart));
    q->nfictitious = p->nfictitious;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriParticlesDestroy(PeriParticles *p)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(p->global));
  PetscCall(PetscFree(p->x));
  PetscCall(PetscFree3(p->volume, p->spacing, p->source_line));
  PetscCall(PetscFree2(p->image, p->crossed));
  PetscCall(PeriMeshGroupsDestroy(&p->ngroups, &p->groups));
  PetscFunctionReturn(PETSC_SUCCESS);
}
