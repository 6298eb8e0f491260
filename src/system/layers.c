/* Fictitious boundary layers (Oterkus & Madenci sec. 6) and torsion. A layer of particles outside
 * a face of a grid body copies the body's particles mirrored through the face:
 *   displacement u*:   u_f = 2 u* - u_m                     (eqs. 61-62)
 *   shear_stress tau:  u_f = u_m + (tau/mu) (a_f - a_m)      (eq. 63c, tau = sigma_az on the face)
 *   free:              u_f = u_m (+ the twist term)          (eqs. 64, 67)
 * With torsion (twist psi about (x0, y0)) the free and shear-stress faces carry the twist term
 * psi (y - y0)(x_f - x_m) on x faces and -psi (x - x0)(y_f - y_m) on y faces: the paper's eqs. 65-67
 * print a 1/mu (dimensionally wrong) and eq. 65b the opposite sign of eqs. 84/86; perilin follows
 * the traction-free conditions tau_xz = mu (u_z,x - psi (y - y0)) = 0, tau_yz = mu (u_z,y + psi (x - x0)) = 0.
 * The relations u = T u_body + g are eliminated from the static system: A = R K T (R keeps the
 * body's rows), which is symmetric for mirror images on a uniform grid (checked at run time). */
#include "perilin/private/system.h"

const char *const PeriLayerKinds[] = {"none", "displacement", "shear_stress", "free", NULL};

/* boundary_layers.<k> and torsion (cross-section models). */
static const char *const sides[]      = {"x-", "x+", "y-", "y+", NULL};
static const PeriKey     layer_keys[] = {
        {"side", PERI_KEY_CHOICE, "required", NULL, NULL, sides, "the face of the grid body the fictitious layer lies outside (each face at most once; not on a periodic axis)"},
        {"condition", PERI_KEY_CHOICE, "required", NULL, NULL, PeriLayerKinds + 1, "displacement (u_z = value on the face), shear_stress (sigma_nz = value), free (traction-free)"},
        {"value", PERI_KEY_REAL, NULL, NULL, "[length] or [stress]", NULL, "the prescribed displacement or shear stress; required for displacement and shear_stress, an error for free"},
        {NULL},
};
static const PeriKey torsion_keys[] = {
    {"twist", PERI_KEY_REAL, "required", NULL, "[1/length]", NULL, "angle of twist per unit length psi, not 0: the free layers carry it"},
    {"center", PERI_KEY_REALS, "the centre of the box", NULL, "[length]", NULL, "the axis of twist [x0, y0]"},
    {NULL},
};
const PeriSchema PeriLayersSchema[] = {
    {"boundary_layers.<k>", layer_keys},
    {"torsion", torsion_keys},
    {NULL},
};

static PetscErrorCode ReadTorsion(PeriSystem sys)
{
  PeriScene s = sys->scene;
  PeriNode  t;
  PetscInt  n;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "torsion", PETSC_FALSE, &t));
  if (!t) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneCheckSection(s, t, "torsion"));
  PeriInputCheck(PeriModelOutOfPlane(sys->model), s, t, NULL, "torsion needs a cross-section model (antiplane or antiplane_os), not %s", sys->model->type);
  PetscCall(PeriSceneGetReal(s, t, "twist", PETSC_TRUE, &sys->conditions.torsion.twist, NULL));
  PeriInputCheck(sys->conditions.torsion.twist != 0, s, t, "twist", "must not be zero (the angle of twist per unit length [1/length])");
  sys->conditions.torsion.center[0] = 0.5 * (sys->disc.particles.lower[0] + sys->disc.particles.upper[0]);
  sys->conditions.torsion.center[1] = 0.5 * (sys->disc.particles.lower[1] + sys->disc.particles.upper[1]);
  PetscCall(PeriSceneGetRealArray(s, t, "center", PETSC_FALSE, 2, 2, sys->conditions.torsion.center, &n));
  sys->conditions.torsion.active = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Fictitious cells beyond a face: those a body particle can bond to. A state-based particle's
 * force also involves its neighbours' shear angles, so there the layer is twice as deep: every
 * fictitious particle that a body particle bonds to has a complete family. */
static PetscInt LayerCells(PeriSystem sys, PetscReal h)
{
  PetscReal R = PeriSearchRadius(sys->disc.partial_volume, sys->disc.delta, h);
  return (PeriModelHasFamilies(sys->model) ? 2 : 1) * (PetscInt)PetscFloorReal(R * (1 - 1e-12) / h);
}

/* Reads one boundary_layers item into sys->conditions.layers and sets the depth nl of its face in lo or hi. */
static PetscErrorCode LayerRead(PeriSystem sys, PeriNode item, const PetscInt cells[], PetscInt nl, PetscInt lo[], PetscInt hi[])
{
  PeriScene   s    = sys->scene;
  PeriLayers *L    = &sys->conditions.layers;
  PetscInt    side = 0, kind = 0, face;
  PetscBool   hasv;

  PetscFunctionBeginUser;
  PeriInputCheck(item->kind == PERI_NODE_MAP, s, item, NULL, "a layer is a mapping {side: .., condition: .., value: ..}");
  PetscCall(PeriSceneCheckSection(s, item, "boundary_layers.<k>"));
  PetscCall(PeriSceneGetChoice(s, item, "side", sides, &side, NULL));
  PetscCall(PeriSceneGetChoice(s, item, "condition", PeriLayerKinds + 1, &kind, NULL));
  kind++;
  face = side;
  PeriInputCheck(!sys->disc.particles.periodic[face / 2], s, item, "side", "axis %c is periodic: it has no face", (char)('x' + face / 2));
  PeriInputCheck(L->kind[face] == PERI_LAYER_NONE, s, item, "side", "face %s already has a layer", sides[face]);
  L->kind[face] = (PeriLayerKind)kind;
  PetscCall(PeriSceneGetReal(s, item, "value", kind != PERI_LAYER_FREE, &L->value[face], &hasv));
  PeriInputCheck(kind != PERI_LAYER_FREE || !hasv, s, item, "value", "a free face takes no value");
  /* the mirror of the deepest fictitious cell must lie in the body */
  PeriInputCheck(cells[face / 2] >= nl, s, item, "side", "the body is %" PetscInt_FMT " particles across axis %c but the layer is %" PetscInt_FMT " deep (the horizon): the mirror images would fall outside the body; refine the grid or shorten the horizon", cells[face / 2], (char)('x' + face / 2), nl);
  if (face % 2)
    hi[face / 2] = nl;
  else
    lo[face / 2] = nl;
  L->nfaces++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The fictitious cells whose mirror image is the body cell m (cells[0] x cells[1] body, layers
 * lo/hi deep): per axis the cell itself or its mirror through each face within reach (both faces
 * on a body fewer than lo + hi cells across), every combination but m itself; c[] and mask[] get
 * them (at most 8), *n their number. */
static void MirrorCells(const PetscInt cells[], const PetscInt lo[], const PetscInt hi[], const PetscInt m[], PetscInt c[][2], unsigned char mask[], PetscInt *n)
{
  PetscInt      opt[2][3], nopt[2];
  unsigned char bit[2][3];

  for (PetscInt d = 0; d < 2; d++) {
    opt[d][0] = m[d];
    bit[d][0] = 0;
    nopt[d]   = 1;
    if (m[d] < lo[d]) {
      opt[d][nopt[d]]   = -1 - m[d];
      bit[d][nopt[d]++] = (unsigned char)(1 << (2 * d));
    }
    if (m[d] >= cells[d] - hi[d]) {
      opt[d][nopt[d]]   = 2 * cells[d] - 1 - m[d];
      bit[d][nopt[d]++] = (unsigned char)(1 << (2 * d + 1));
    }
  }
  *n = 0;
  for (PetscInt b = 0; b < nopt[1]; b++)
    for (PetscInt a = 0; a < nopt[0]; a++) {
      if (!a && !b) continue;
      c[*n][0]     = opt[0][a];
      c[*n][1]     = opt[1][b];
      mask[(*n)++] = (unsigned char)(bit[0][a] | bit[1][b]);
    }
}

/* Appends to this rank's particles (its owned body particles, partitioned) the fictitious cells
 * lo/hi deep beyond the faces of the cells[0] x cells[1] body whose mirror images they are, with
 * the faces they crossed: each fictitious particle lives on the rank of its image, which is then
 * never a ghost. The images are the body particles' global indices in the numbering of the
 * extended ranks (body particles first on each rank, then its fictitious ones). Collective. */
static PetscErrorCode LayersAppendParticles(PeriSystem sys, const PetscInt cells[], const PetscInt lo[], const PetscInt hi[])
{
  PeriParticles  *pt = &sys->disc.particles;
  const PetscReal h  = pt->mean_spacing;
  PetscInt        nb = pt->n, n = 0, N, rstart = 0, k;
  PetscReal      *x, *vol, *sp;
  PetscInt       *src, c[8][2], m[2], nc;
  unsigned char  *crossed, mask[8];

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < nb; i++) {
    for (PetscInt d = 0; d < 2; d++) m[d] = (PetscInt)PetscFloorReal((pt->x[3 * i + d] - pt->lower[d]) / h);
    MirrorCells(cells, lo, hi, m, c, mask, &nc);
    n += nc;
  }
  N = nb + n;
  PetscCallMPI(MPI_Exscan(&N, &rstart, 1, MPIU_INT, MPI_SUM, sys->comm));
  if (!sys->rank) rstart = 0; /* MPI_Exscan leaves rank 0's result undefined */
  PetscCall(PetscCalloc1(3 * N, &x));
  PetscCall(PetscMalloc3(N, &vol, N, &sp, N, &src));
  PetscCall(PetscMalloc2(N, &pt->image, N, &crossed));
  PetscCall(PetscArraycpy(x, pt->x, 3 * nb));
  PetscCall(PetscArraycpy(vol, pt->volume, nb));
  PetscCall(PetscArraycpy(sp, pt->spacing, nb));
  PetscCall(PetscArraycpy(src, pt->source_line, nb));
  for (k = 0; k < nb; k++) {
    pt->image[k] = -1;
    crossed[k]   = 0;
  }
  for (PetscInt i = 0; i < nb; i++) {
    for (PetscInt d = 0; d < 2; d++) m[d] = (PetscInt)PetscFloorReal((pt->x[3 * i + d] - pt->lower[d]) / h);
    MirrorCells(cells, lo, hi, m, c, mask, &nc);
    for (PetscInt t = 0; t < nc; t++, k++) {
      for (PetscInt d = 0; d < 2; d++) x[3 * k + d] = pt->lower[d] + (c[t][d] + 0.5) * h;
      vol[k]       = pt->volume[i];
      sp[k]        = h;
      src[k]       = 0;
      pt->image[k] = rstart + i;
      crossed[k]   = mask[t];
    }
  }
  PetscCall(PetscFree(pt->x));
  PetscCall(PetscFree3(pt->volume, pt->spacing, pt->source_line));
  pt->x           = x;
  pt->volume      = vol;
  pt->spacing     = sp;
  pt->source_line = src;
  pt->crossed     = crossed;
  pt->n           = N;
  PetscCallMPI(MPI_Allreduce(&n, &pt->nfictitious, 1, MPIU_INT, MPI_SUM, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriLayersAddParticles - reads boundary_layers and torsion and appends to each rank's particles
  (its body particles, partitioned) the fictitious particles whose mirror images they are. Call
  after the horizon, the corrections and the partition, before the ghosts. Collective.
@*/
PetscErrorCode PeriLayersAddParticles(PeriSystem sys)
{
  PeriScene      s  = sys->scene;
  PeriParticles *pt = &sys->disc.particles;
  PeriNode       list, grid;
  PetscInt       cells[2], lo[2] = {0, 0}, hi[2] = {0, 0}, nl;
  PetscReal      h;

  PetscFunctionBeginUser;
  PetscCall(ReadTorsion(sys));
  PetscCall(PeriSceneGetNode(s->root, "boundary_layers", &list));
  if (!list) PetscFunctionReturn(PETSC_SUCCESS);
  PeriInputCheck(list->kind == PERI_NODE_SEQ && list->n > 0, s, list, NULL, "must be a list of layers, each {side: x-|x+|y-|y+, condition: displacement|shear_stress|free, value: ..}");
  PeriInputCheck(PeriModelOutOfPlane(sys->model), s, list, NULL, "fictitious layers carry the conditions of the cross-section models (antiplane, antiplane_os); for model %s use bc and loads", sys->model->type);
  PetscCall(PeriSceneGetMap(s, s->root, "grid", PETSC_FALSE, &grid));
  PeriInputCheck(grid, s, list, NULL, "need a grid body (grid:), whose faces the layers mirror; particles.file is not supported");
  h = pt->mean_spacing;
  for (PetscInt d = 0; d < 2; d++) cells[d] = (PetscInt)PetscFloorReal((pt->upper[d] - pt->lower[d]) / h + 0.5);
  nl = LayerCells(sys, h);
  for (PetscInt i = 0; i < list->n; i++) PetscCall(LayerRead(sys, list->child[i], cells, nl, lo, hi));
  PetscCall(LayersAppendParticles(sys, cells, lo, hi));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The relation u(X) = sign u(Y) + offset across one face: Y is X mirrored through it. */
static void FaceRelation(PeriSystem sys, PetscInt face, const PetscReal X[], const PetscReal Y[], PetscReal mu, PetscReal *sign, PetscReal *offset)
{
  const PeriLayers *L    = &sys->conditions.layers;
  const PetscInt    a    = face / 2;
  PetscReal         grad = 0;

  if (L->kind[face] == PERI_LAYER_DISPLACEMENT) {
    *sign   = -1;
    *offset = 2 * L->value[face];
    return;
  }
  if (L->kind[face] == PERI_LAYER_SHEAR_STRESS) grad = L->value[face] / mu;
  if (sys->conditions.torsion.active) grad += a == 0 ? sys->conditions.torsion.twist * (X[1] - sys->conditions.torsion.center[1]) : -sys->conditions.torsion.twist * (X[0] - sys->conditions.torsion.center[0]);
  *sign   = 1;
  *offset = grad * (X[a] - Y[a]);
}

/*@C
  PeriLayersSetUp - the relation of every owned fictitious particle to its mirror image: the
  matrix T and the offsets g of u = T u_body + g. Call after calibration (the shear moduli).
  Collective.
@*/
PetscErrorCode PeriLayersSetUp(PeriSystem sys)
{
  const PeriParticles *pt     = &sys->disc.particles;
  PeriLayers          *L      = &sys->conditions.layers;
  const PetscInt       rstart = sys->disc.bonds.rstart, rend = sys->disc.bonds.rend;

  PetscFunctionBeginUser;
  if (!L->nfaces) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(MatCreateAIJ(sys->comm, rend - rstart, rend - rstart, sys->disc.N, sys->disc.N, 1, NULL, 1, NULL, &L->T));
  PetscCall(PeriSystemCreateVec(sys, &L->g));
  for (PetscInt i = rstart; i < rend; i++) {
    PetscInt    gi = pt->global[i], gm = pt->image[i], m, faces[2], nf = 0;
    PetscReal   sign = 1, offset = 0, mu;
    PetscScalar v;
    if (gm < 0) {
      PetscCall(MatSetValue(L->T, gi, gi, 1.0, INSERT_VALUES));
      continue;
    }
    m = PeriDiscLocal(&sys->disc, gm); /* the halo reaches every image (SetLocalView) */
    PetscCheck(m >= 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "the mirror image %" PetscInt_FMT " of fictitious particle %" PetscInt_FMT " is not in the local view", gm, gi);
    mu = sys->materials.mu ? sys->materials.mu[m] : sys->model->material.G;
    for (PetscInt f = 0; f < 4; f++)
      if (pt->crossed[i] & (1 << f)) faces[nf++] = f;
    if (nf == 1)
      FaceRelation(sys, faces[0], &pt->x[3 * i], &pt->x[3 * m], mu, &sign, &offset);
    else {
      /* a corner: through one face to an intermediate image, then through the other; the two
         orders differ in the twist term, so take their mean */
      for (PetscInt o = 0; o < 2; o++) {
        PetscInt  f1 = faces[o], f2 = faces[1 - o], a1 = f1 / 2;
        PetscReal Y[3], s1, o1, s2, o2;
        for (PetscInt d = 0; d < 3; d++) Y[d] = pt->x[3 * i + d];
        Y[a1] = pt->x[3 * m + a1];
        FaceRelation(sys, f1, &pt->x[3 * i], Y, mu, &s1, &o1);
        FaceRelation(sys, f2, Y, &pt->x[3 * m], mu, &s2, &o2);
        sign = s1 * s2;
        offset += 0.5 * (o1 + s1 * o2);
      }
    }
    v = sign;
    PetscCall(MatSetValue(L->T, gi, gm, v, INSERT_VALUES));
    PetscCall(VecSetValue(L->g, gi, offset, INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(L->T, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(L->T, MAT_FINAL_ASSEMBLY));
  PetscCall(VecAssemblyBegin(L->g));
  PetscCall(VecAssemblyEnd(L->g));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriLayersApply - eliminates the fictitious DOFs: *A = R K T with unit rows on the fictitious
  DOFs (scaled by the mean diagonal), f <- R (f - lambda K g) (lambda scales the conditions). Sets MAT_SYMMETRIC from a check of A.
  Collective.
@*/
PetscErrorCode PeriLayersApply(PeriSystem sys, PetscReal lambda, Mat *A, Vec f)
{
  const PeriParticles *pt = &sys->disc.particles;
  PeriLayers          *L  = &sys->conditions.layers;
  Mat                  K = sys->stiffness.K, Kaij = NULL;
  Vec                  w;
  PetscInt            *rows, nf = 0, N;
  PetscReal            diag, kmax;
  PetscBool            aij, sym;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompareAny((PetscObject)K, &aij, MATAIJ, MATSEQAIJ, MATMPIAIJ, ""));
  if (!aij) {
    PetscCall(MatConvert(K, MATAIJ, MAT_INITIAL_MATRIX, &Kaij));
    K = Kaij;
  }
  PetscCall(MatMatMult(K, L->T, MAT_INITIAL_MATRIX, PETSC_DEFAULT, A));
  PetscCall(MatCreateVecs(K, &w, NULL));
  PetscCall(MatMult(K, L->g, w));
  PetscCall(VecAXPY(f, -lambda, w));
  PetscCall(MatGetDiagonal(K, w));
  PetscCall(VecNorm(w, NORM_1, &diag));
  PetscCall(VecGetSize(w, &N));
  diag /= N;
  PetscCall(VecDestroy(&w));
  PetscCall(MatDestroy(&Kaij));
  PetscCall(PetscMalloc1(sys->disc.bonds.rend - sys->disc.bonds.rstart, &rows));
  for (PetscInt i = sys->disc.bonds.rstart; i < sys->disc.bonds.rend; i++)
    if (PeriParticleIsFictitious(pt, i)) rows[nf++] = pt->global[i];
  /* K T has no (i, i) for a fictitious i (T maps its column to its image's): MatZeroRows reuses a
   * slot of the row's diagonal block, and must allocate one where that part of the row is empty
   * (all of i's neighbours owned by other ranks, as a partition may give) */
  PetscCall(MatSetOption(*A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  PetscCall(MatZeroRows(*A, nf, rows, diag, NULL, NULL));
  for (PetscInt k = 0; k < nf; k++) PetscCall(VecSetValue(f, rows[k], 0.0, INSERT_VALUES));
  PetscCall(VecAssemblyBegin(f));
  PetscCall(VecAssemblyEnd(f));
  PetscCall(PetscFree(rows));
  PetscCall(MatNorm(*A, NORM_INFINITY, &kmax));
  PetscCall(MatIsSymmetric(*A, 1e-12 * kmax, &sym));
  PetscCall(MatSetOption(*A, MAT_SYMMETRIC, sym));
  sys->fields.solve.symmetric = sym;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* u <- T u + lambda g: the fictitious DOFs from their images. Collective. */
PetscErrorCode PeriLayersComplete(PeriSystem sys, PetscReal lambda, Vec u)
{
  Vec t;

  PetscFunctionBeginUser;
  if (!sys->conditions.layers.nfaces) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecDuplicate(u, &t));
  PetscCall(MatMult(sys->conditions.layers.T, u, t));
  PetscCall(VecWAXPY(u, lambda, sys->conditions.layers.g, t));
  PetscCall(VecDestroy(&t));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriLayersDestroy(PeriLayers *L)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&L->T));
  PetscCall(VecDestroy(&L->g));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The twist's load of one element: f_e = -K_e e with e_t = psi ((X_i - X0) x (X_t - X0))_z, the
 * rigid twist's relative displacement of particle t from the element's particle i (one DOF). */
static PetscErrorCode TorsionElementLoad(PeriSystem sys, const PeriElement *el, void *ctx)
{
  const PetscReal *x = sys->disc.particles.x, psi = sys->conditions.torsion.twist, *c = sys->conditions.torsion.center;
  const PetscInt   i = el->idx[0], n = el->n;
  PetscReal       *e = el->work, *fe = el->work + n;

  PetscFunctionBeginUser;
  e[0] = 0;
  for (PetscInt t = 1; t < n; t++) {
    PetscInt j = el->idx[t];
    e[t]       = psi * ((x[3 * i] - c[0]) * (x[3 * j + 1] - c[1]) - (x[3 * j] - c[0]) * (x[3 * i + 1] - c[1]));
  }
  for (PetscInt a = 0; a < n; a++) {
    fe[a] = 0;
    for (PetscInt b = 0; b < n; b++) fe[a] -= el->K[a * n + b] * e[b];
  }
  PetscCall(VecSetValues((Vec)ctx, n, el->gidx, fe, ADD_VALUES));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriTorsionLoads - without fictitious layers the twist enters every bond as a prescribed relative
  displacement e0 = psi ((X_i - X0) x (X_j - X0))_z (the rigid twist's contribution to the shear
  angle, so the pair energy is that of (u_j - u_i + e0)): f -= K_b (0, e0) per live bond, or per
  family for state-based models. Free faces and crack faces are then natural PD free surfaces,
  traction-free with the twist. Adds to f (owned rows, and others through the stash). Collective.
@*/
PetscErrorCode PeriTorsionLoads(PeriSystem sys, Vec f)
{
  PetscFunctionBeginUser;
  if (!sys->conditions.torsion.active || sys->conditions.layers.nfaces) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriElementsForEach(sys, TorsionElementLoad, f));
  PetscCall(VecAssemblyBegin(f));
  PetscCall(VecAssemblyEnd(f));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The torsion constant of a solid a x b rectangle (Saint-Venant, Prandtl's series). */
static PetscReal RectangleTorsionConstant(PetscReal A, PetscReal B)
{
  PetscReal a = 0.5 * PetscMin(A, B), b = 0.5 * PetscMax(A, B), sum = 0;
  for (PetscInt n = 1; n < 200; n += 2) sum += PetscTanhReal(n * PETSC_PI * b / (2 * a)) / PetscPowReal((PetscReal)n, 5);
  return 16.0 / 3.0 * a * a * a * b * (1 - 192 / PetscPowReal(PETSC_PI, 5) * a / b * sum);
}

/* The largest |tau| of the owned body particles and where (the first in global order on ties),
 * then over the ranks (the lowest rank on ties, so the first in global order). Collective. */
static PetscErrorCode TorsionMaxStress(PeriSystem sys, PeriTorsion *t)
{
  const PeriParticles *pt      = &sys->disc.particles;
  PetscReal            mine[3] = {0, 0, 0}, *all;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->disc.nowned; i++)
    if (!PeriParticleIsFictitious(pt, i) && sys->fields.tau[3 * i + 2] > mine[0]) {
      mine[0] = sys->fields.tau[3 * i + 2];
      mine[1] = pt->x[3 * i];
      mine[2] = pt->x[3 * i + 1];
    }
  PetscCall(PetscMalloc1(3 * sys->size, &all));
  PetscCallMPI(MPI_Allgather(mine, 3, MPIU_REAL, all, 3, MPIU_REAL, sys->comm));
  t->max_stress = 0;
  for (PetscMPIInt r = 0; r < sys->size; r++)
    if (all[3 * r] > t->max_stress) {
      t->max_stress = all[3 * r];
      t->max_at[0]  = all[3 * r + 1];
      t->max_at[1]  = all[3 * r + 2];
    }
  PetscCall(PetscFree(all));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriTorsionEvaluate - from the shear stresses sys->fields.tau of the owned particles: the torque per
  unit length T = sum (x tau_yz - y tau_xz) A over the body's particles (A = V / l), the torsion
  constant J = T / (mu psi), the largest stress |tau| and where. Collective.
@*/
PetscErrorCode PeriTorsionEvaluate(PeriSystem sys)
{
  const PeriParticles *pt = &sys->disc.particles;
  PeriTorsion         *t  = &sys->conditions.torsion;

  PetscFunctionBeginUser;
  if (!t->active) PetscFunctionReturn(PETSC_SUCCESS); /* the antiplane models' tau exists on every rank */
  t->torque = 0;
  for (PetscInt i = 0; i < sys->disc.nowned; i++) {
    PetscReal x = pt->x[3 * i] - t->center[0], y = pt->x[3 * i + 1] - t->center[1];
    if (!PeriParticleIsFictitious(pt, i)) t->torque += (x * sys->fields.tau[3 * i + 1] - y * sys->fields.tau[3 * i]) * pt->volume[i] / pt->thickness;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &t->torque, 1, MPIU_REAL, MPI_SUM, sys->comm));
  PetscCall(TorsionMaxStress(sys, t));
  t->J           = t->torque / (sys->model->material.G * t->twist);
  t->J_rectangle = RectangleTorsionConstant(pt->upper[0] - pt->lower[0], pt->upper[1] - pt->lower[1]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriTorsionSummary(PeriSystem sys, PeriJSON j)
{
  const PeriTorsion *t = &sys->conditions.torsion;

  PetscFunctionBeginUser;
  if (!t->active || !sys->fields.tau) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "torsion"));
  PetscCall(PeriJSONReal(j, "twist", t->twist));
  PetscCall(PeriJSONRealArray(j, "center", 2, t->center));
  PetscCall(PeriJSONReal(j, "torque", t->torque));
  PetscCall(PeriJSONReal(j, "J", t->J));
  PetscCall(PeriJSONReal(j, "J_rectangle_exact", t->J_rectangle));
  PetscCall(PeriJSONReal(j, "J_error_vs_rectangle", t->J / t->J_rectangle - 1));
  PetscCall(PeriJSONReal(j, "max_shear_stress", t->max_stress));
  PetscCall(PeriJSONRealArray(j, "max_shear_stress_at", 2, t->max_at));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* summary.json's boundary_layers: the fictitious particles and each face's kind. */
PetscErrorCode PeriLayersSummary(PeriSystem sys, PeriJSON j)
{
  static const char *const faces[] = {"x-", "x+", "y-", "y+"};

  PetscFunctionBeginUser;
  if (!sys->conditions.layers.nfaces) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "boundary_layers"));
  PetscCall(PeriJSONInt(j, "fictitious_particles", sys->disc.particles.nfictitious));
  for (PetscInt f = 0; f < 4; f++)
    if (sys->conditions.layers.kind[f]) PetscCall(PeriJSONString(j, faces[f], PeriLayerKinds[sys->conditions.layers.kind[f]]));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles.vtu's mirror_of: for each fictitious particle the body particle it mirrors (-1: a body
 * particle). */
PetscErrorCode PeriLayersAddFields(PeriSystem sys, PeriFieldList fl)
{
  PetscFunctionBeginUser;
  if (sys->disc.particles.image) PetscCall(PeriFieldListAddInt(fl, "mirror_of", sys->disc.particles.image)); /* the owned particles: the piece */
  PetscFunctionReturn(PETSC_SUCCESS);
}
