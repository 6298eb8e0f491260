/* Particles: a cell-centred grid in a box, or a CSV file of positions and volumes. */
#include "perilin/private/disc.h"
#include <errno.h>

static PetscErrorCode ParticlesAllocate(PeriParticles *p, PetscInt n)
{
  PetscFunctionBeginUser;
  p->n = n;
  PetscCall(PetscCalloc1(3 * n, &p->x));
  PetscCall(PetscMalloc3(n, &p->volume, n, &p->spacing, n, &p->source_line));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode GridCreate(PeriScene scene, PeriNode grid, PetscInt dim, PeriParticles *p)
{
  static const char *const keys[]   = {"lower", "upper", "spacing", "periodic", NULL};
  PetscReal                lower[3] = {0, 0, 0}, upper[3] = {0, 0, 0}, h, cellvol;
  PetscInt                 nl, nu, cells[3] = {1, 1, 1}, n = 1, k = 0;
  PeriNode                 per;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneCheckKeys(scene, grid, keys));
  PetscCall(PeriSceneGetRealArray(scene, grid, "lower", PETSC_TRUE, dim, dim, lower, &nl));
  PetscCall(PeriSceneGetRealArray(scene, grid, "upper", PETSC_TRUE, dim, dim, upper, &nu));
  PetscCall(PeriSceneGetReal(scene, grid, "spacing", PETSC_TRUE, &h, NULL));
  PeriInputCheck(h > 0, scene, grid, "spacing", "must be positive, got %g", (double)h);
  PetscCall(PeriSceneGetNode(grid, "periodic", &per));
  if (per) {
    PeriInputCheck(per->kind == PERI_NODE_SEQ && per->n == dim, scene, per, NULL, "must be a list of %" PetscInt_FMT " booleans, e.g. [false, true]", dim);
    for (PetscInt d = 0; d < dim; d++) PetscCall(PeriSceneParseBool(scene, per->child[d], &p->periodic[d]));
  }
  for (PetscInt d = 0; d < dim; d++) {
    PetscReal L = upper[d] - lower[d], c;
    /* 1e308 - (-1e308) is inf: say so rather than call inf "not a whole number of spacings" */
    PeriInputCheck(!PetscIsInfOrNanReal(L), scene, grid, "upper", "the box is too large for double precision: upper - lower = %g - (%g) overflows along axis %" PetscInt_FMT, (double)upper[d], (double)lower[d], d);
    PeriInputCheck(L > 0, scene, grid, "upper", "must exceed grid.lower in every axis (axis %" PetscInt_FMT ": %g <= %g)", d, (double)upper[d], (double)lower[d]);
    c        = L / h;
    cells[d] = (PetscInt)PetscFloorReal(c + 0.5);
    PeriInputCheck(cells[d] >= 1 && PetscAbsReal(c - cells[d]) < 1e-6 * PetscMax(c, 1), scene, grid, "spacing", "the box length %g along axis %" PetscInt_FMT " is not a whole number of spacings %g", (double)L, d, (double)h);
    PeriInputCheck(cells[d] <= 100000000 / n, scene, grid, "spacing", "gives too many particles");
    n *= cells[d];
    p->lower[d] = lower[d];
    p->upper[d] = upper[d];
  }
  PetscCall(ParticlesAllocate(p, n));
  cellvol = dim == 3 ? h * h * h : h * h * p->thickness;
  for (PetscInt c2 = 0; c2 < cells[2]; c2++)
    for (PetscInt c1 = 0; c1 < cells[1]; c1++)
      for (PetscInt c0 = 0; c0 < cells[0]; c0++, k++) {
        const PetscInt c[3] = {c0, c1, c2};
        for (PetscInt d = 0; d < dim; d++) p->x[3 * k + d] = lower[d] + (c[d] + 0.5) * h;
        p->volume[k]      = cellvol;
        p->spacing[k]     = h;
        p->source_line[k] = 0;
      }
  p->mean_spacing = h;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* x, y[, z], volume[, material]: one particle per line; '#' comments and a header line allowed. */
static PetscErrorCode CSVCreate(PeriScene scene, PeriNode node, PetscInt dim, PeriParticles *p)
{
  static const char *const keys[] = {"file", NULL};
  char                     name[PETSC_MAX_PATH_LEN], path[PETSC_MAX_PATH_LEN], line[1024];
  FILE                    *fp;
  PetscInt                 cap = 1024, n = 0, lineno = 0;
  PetscReal               *x, *vol, sum              = 0;
  PetscInt                *src;
  PetscBool                header = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneCheckKeys(scene, node, keys));
  PetscCall(PeriSceneGetString(scene, node, "file", PETSC_TRUE, name, sizeof(name), NULL));
  if (name[0] == '/')
    PetscCall(PetscStrncpy(path, name, sizeof(path)));
  else
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/%s", scene->dir, name));
  fp = fopen(path, "r");
  PeriInputCheck(fp, scene, node, "file", "cannot open %s: %s", path, strerror(errno));
  PetscCall(PetscMalloc3(3 * cap, &x, cap, &vol, cap, &src));
  while (fgets(line, sizeof(line), fp)) {
    double         v[5];
    int            nf   = 0;
    char          *s    = line, *end;
    PetscErrorCode ierr = PETSC_SUCCESS;

    lineno++;
    while (*s == ' ' || *s == '\t') s++;
    if (*s == '#' || *s == '\n' || *s == '\r' || !*s) continue;
    while (nf < 5) {
      v[nf] = strtod(s, &end);
      if (end == s) break;
      nf++;
      s = end;
      while (*s == ' ' || *s == '\t') s++;
      if (*s == ',') s++;
    }
    while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n') s++;
    if (nf == 0 && n == 0 && !header) { /* a header line before the first particle */
      header = PETSC_TRUE;
      continue;
    }
    if (nf < dim + 1 || nf > dim + 2 || *s)
      ierr = PETSC_ERR_USER_INPUT;
    else if (!(v[dim] > 0))
      ierr = PETSC_ERR_USER_INPUT + 1;
    for (int k = 0; k < nf; k++)
      if (!PetscIsNormalReal((PetscReal)v[k]) && v[k] != 0) ierr = PETSC_ERR_USER_INPUT + 2;
    if (ierr) {
      fclose(fp);
      PetscCall(PetscFree3(x, vol, src));
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s:%" PetscInt_FMT ": %s (particles.file, referenced from %s)", path, lineno, ierr == PETSC_ERR_USER_INPUT ? (dim == 2 ? "expected x, y, volume[, material]" : "expected x, y, z, volume[, material]") : (ierr == PETSC_ERR_USER_INPUT + 1 ? "the volume must be positive" : "every value must be a finite number"), scene->file);
    }
    if (n == cap) {
      PetscReal *x2, *v2;
      PetscInt  *s2;
      PetscCall(PetscMalloc3(6 * cap, &x2, 2 * cap, &v2, 2 * cap, &s2));
      PetscCall(PetscArraycpy(x2, x, 3 * cap));
      PetscCall(PetscArraycpy(v2, vol, cap));
      PetscCall(PetscArraycpy(s2, src, cap));
      PetscCall(PetscFree3(x, vol, src));
      x   = x2;
      vol = v2;
      src = s2;
      cap *= 2;
    }
    for (PetscInt d = 0; d < 3; d++) x[3 * n + d] = d < dim ? v[d] : 0;
    vol[n] = v[dim];
    src[n] = lineno;
    n++;
  }
  fclose(fp);
  if (!n) PetscCall(PetscFree3(x, vol, src));
  PeriInputCheck(n > 0, scene, node, "file", "%s holds no particles", path);
  PetscCall(ParticlesAllocate(p, n));
  for (PetscInt d = 0; d < 3; d++) {
    p->lower[d] = PETSC_MAX_REAL;
    p->upper[d] = PETSC_MIN_REAL;
  }
  for (PetscInt k = 0; k < n; k++) {
    PetscReal h = dim == 3 ? PetscCbrtReal(vol[k]) : PetscSqrtReal(vol[k] / p->thickness);
    for (PetscInt d = 0; d < 3; d++) p->x[3 * k + d] = x[3 * k + d];
    for (PetscInt d = 0; d < dim; d++) {
      p->lower[d] = PetscMin(p->lower[d], x[3 * k + d] - h / 2);
      p->upper[d] = PetscMax(p->upper[d], x[3 * k + d] + h / 2);
    }
    p->volume[k]      = vol[k];
    p->spacing[k]     = h;
    p->source_line[k] = src[k];
    sum += h;
  }
  for (PetscInt d = dim; d < 3; d++) p->lower[d] = p->upper[d] = 0;
  p->mean_spacing = sum / n;
  PetscCall(PetscFree3(x, vol, src));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriParticlesCreateFromScene - generates the particles from the scene's grid or particles
  section. Not collective: every rank builds the same set.
@*/
PetscErrorCode PeriParticlesCreateFromScene(PeriScene scene, PetscInt dim, PetscReal thickness, PeriParticles *p)
{
  PeriNode grid, csv;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(p, sizeof(*p)));
  p->dim       = dim;
  p->thickness = dim == 2 ? thickness : 1;
  PetscCall(PeriSceneGetMap(scene, scene->root, "grid", PETSC_FALSE, &grid));
  PetscCall(PeriSceneGetMap(scene, scene->root, "particles", PETSC_FALSE, &csv));
  PeriInputCheck(grid || csv, scene, scene->root, "grid", "is required (or give particles.file)");
  PeriInputCheck(!(grid && csv), scene, csv, NULL, "give either grid or particles, not both");
  if (grid)
    PetscCall(GridCreate(scene, grid, dim, p));
  else
    PetscCall(CSVCreate(scene, csv, dim, p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Renumbers the particles: new index k holds the old particle perm[k]. */
PetscErrorCode PeriParticlesPermute(PeriParticles *p, const PetscInt perm[])
{
  PeriParticles q = *p;

  PetscFunctionBeginUser;
  PetscCall(ParticlesAllocate(&q, p->n));
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
  PetscCall(PeriParticlesDestroy(p));
  *p = q;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriParticlesDestroy(PeriParticles *p)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(p->x));
  PetscCall(PetscFree3(p->volume, p->spacing, p->source_line));
  PetscCall(PetscFree2(p->image, p->crossed));
  PetscFunctionReturn(PETSC_SUCCESS);
}
