/* Particles from Gmsh meshes (docs/mesh.md).
 *   test_mesh read SCENE MESH VOLUME FACE: one particle per element of the scene's dimension (counted
 *     here through Gmsh's API), total volume VOLUME to 1e-12, the group "left" (a boundary on x = 0)
 *     holding the elements with a side on x = 0 and the face area FACE to 1e-12.
 *   test_mesh uniform SCENE TOL: a bar pulled along x by a traction s = 1 MPa, E = 1 GPa, nu = 1/3
 *     (bond-based): the least-squares slopes of ux along x and of uy along y over the particles one
 *     horizon inside the body match s/E and -nu s/E within TOL (relative). On this unstructured mesh
 *     (size 0.025, m = 3) npmb gives -2.8 % (xx) and +5.1 % (yy), pmb with the volume correction
 *     -6.4 % (xx): the PD discretization error of irregular particles, not exactness.
 *   test_mesh same SCENE MSH OTHER [ALIAS=GROUP ...]: SCENE read with particles.mesh MSH (a Gmsh
 *     mesh) and with OTHER (the same mesh as Abaqus .inp or Exodus, tests/mesh/make_imports.sh) gives
 *     the same particles (each of one matched to one of the other within 1e-9 of the body's size,
 *     with the same volume to 1e-9) and every group of MSH the same particles (count, volume, face
 *     area to 1e-9) under its name in OTHER; ALIAS=GROUP: OTHER's ALIAS also equals MSH's GROUP. One
 *     rank (the reader is rank 0's). */
#include "testing.h"
#include <gmshc.h>

/* Elements of dimension dim in MESH, and those with dim corners on the plane x = 0. */
static PetscErrorCode CountElements(const char mesh[], PetscInt dim, PetscInt *n, PetscInt *left)
{
  int     ierr = 0, *types;
  size_t  ntypes, **et, *net, nn, **nt, *nnt, nn2, *tags, ntags, nc, np;
  double *xyz, *par;

  PetscFunctionBeginUser;
  gmshInitialize(0, NULL, 0, &ierr);
  gmshOptionSetNumber("General.Terminal", 0, &ierr);
  gmshOpen(mesh, &ierr);
  PetscCheck(!ierr, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "Gmsh cannot read %s", mesh);
  gmshModelMeshGetNodes(&tags, &ntags, &xyz, &nc, &par, &np, -1, -1, 0, 0, &ierr);
  gmshModelMeshGetElements(&types, &ntypes, &et, &net, &nn, &nt, &nnt, &nn2, (int)dim, -1, &ierr);
  *n = *left = 0;
  for (size_t t = 0; t < ntypes; t++) {
    size_t per = nnt[t] / net[t];
    *n += (PetscInt)net[t];
    for (size_t e = 0; e < net[t]; e++) {
      PetscInt on = 0;
      for (size_t a = 0; a < per; a++)
        for (size_t k = 0; k < ntags; k++)
          if (tags[k] == nt[t][e * per + a] && xyz[3 * k] == 0) on++;
      if (on >= dim) (*left)++;
    }
  }
  /* the arrays Gmsh's C API returns are the caller's */
  for (size_t t = 0; t < ntypes; t++) {
    gmshFree(et[t]);
    gmshFree(nt[t]);
  }
  gmshFree(types);
  gmshFree(et);
  gmshFree(net);
  gmshFree(nt);
  gmshFree(nnt);
  gmshFree(tags);
  gmshFree(xyz);
  gmshFree(par);
  gmshFinalize(&ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode TestRead(const char scene[], const char mesh[], PetscReal volume, PetscReal face)
{
  PeriProblem    p;
  PetscInt       n, left;
  PetscReal      sum = 0;
  PeriParticles *pt;
  PeriRegion    *r = NULL;

  PetscFunctionBeginUser;
  /* Gmsh once here, before perilin's own session (which lasts until PeriFinalize) */
  PetscCall(CountElements(mesh, strstr(mesh, "tet") ? 3 : 2, &n, &left));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, scene, &p));
  pt = &p->sys->disc.particles;
  PeriTestClose("particles = elements", (PetscReal)p->sys->disc.N, (PetscReal)n, 0);
  for (PetscInt k = 0; k < p->sys->disc.nowned; k++) sum += pt->volume[k];
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPIU_REAL, MPI_SUM, PETSC_COMM_WORLD));
  PeriTestClose("total volume", sum, volume, 1e-12 * volume);
  for (PetscInt k = 0; k < p->sys->disc.nregions; k++)
    if (!strcmp(p->sys->disc.regions[k].name, "left")) r = &p->sys->disc.regions[k];
  PetscCheck(r, PETSC_COMM_SELF, PETSC_ERR_PLIB, "no region 'left'");
  PeriTestClose("particles of group 'left'", (PetscReal)r->count, (PetscReal)left, 0);
  PeriTestClose("face area of group 'left'", r->face_area, face, 1e-12 * face);
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode TestUniform(const char scene[], PetscReal tol)
{
  PeriProblem    p;
  PeriParticles *pt;
  PetscBool     *in;
  PetscReal      delta, eps = 1e6 / 1e9, sx, sy;
  PetscInt       bs, no;

  PetscFunctionBeginUser;
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, scene, &p));
  pt    = &p->sys->disc.particles;
  delta = p->sys->disc.delta;
  bs    = p->sys->model->dofs;
  no    = p->sys->disc.nowned;
  PetscCall(PetscMalloc1(no, &in));
  for (PetscInt k = 0; k < no; k++) {
    in[k] = PETSC_TRUE;
    for (PetscInt d = 0; d < pt->dim; d++)
      if (pt->x[3 * k + d] < pt->lower[d] + delta || pt->x[3 * k + d] > pt->upper[d] - delta) in[k] = PETSC_FALSE;
  }
  PetscCall(PeriTestSlope(PETSC_COMM_WORLD, no, &pt->x[0], 3, &p->sys->fields.u_owned[0], bs, in, &sx));
  PetscCall(PeriTestSlope(PETSC_COMM_WORLD, no, &pt->x[1], 3, &p->sys->fields.u_owned[1], bs, in, &sy));
  PeriTestClose("interior strain xx (ux slope along x)", sx, eps, tol * eps);
  PeriTestClose("interior strain yy (uy slope along y)", sy, -eps / 3, tol * eps / 3);
  PetscCall(PetscFree(in));
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The particles of SCENE read with -particles_mesh mesh: on one rank, the problem itself. */
static PetscErrorCode ReadWith(const char scene[], const char mesh[], PeriProblem *p)
{
  PetscFunctionBeginUser;
  PetscCall(PetscOptionsSetValue(NULL, "-particles_mesh", mesh));
  PetscCall(PeriTestRunScene(PETSC_COMM_SELF, scene, p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every particle of a matched to a distinct one of b at the same place, with the same volume. */
static PetscErrorCode SameParticles(const PeriParticles *a, const PeriParticles *b, PetscReal size)
{
  PetscBool *used;
  PetscInt   matched = 0;

  PetscFunctionBeginUser;
  PeriTestClose("particles", (PetscReal)b->n, (PetscReal)a->n, 0);
  PetscCall(PetscCalloc1(b->n, &used));
  for (PetscInt i = 0; i < a->n; i++) {
    PetscInt  best = -1;
    PetscReal d2, bd = PETSC_MAX_REAL;
    for (PetscInt j = 0; j < b->n; j++) {
      d2 = 0;
      for (PetscInt d = 0; d < 3; d++) d2 += PetscSqr(a->x[3 * i + d] - b->x[3 * j + d]);
      if (d2 < bd) bd = d2, best = j;
    }
    if (best >= 0 && !used[best] && PetscSqrtReal(bd) <= 1e-9 * size && PetscAbsReal(a->volume[i] - b->volume[best]) <= 1e-9 * a->volume[i]) {
      used[best] = PETSC_TRUE;
      matched++;
    }
  }
  PeriTestClose("particles at the same place with the same volume", (PetscReal)matched, (PetscReal)a->n, 0);
  PetscCall(PetscFree(used));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static const PeriRegion *FindRegion(PeriProblem p, const char name[])
{
  for (PetscInt k = 0; k < p->sys->disc.nregions; k++)
    if (!strcmp(p->sys->disc.regions[k].name, name)) return &p->sys->disc.regions[k];
  return NULL;
}

/* OTHER's group name holds what MSH's group ref does. */
static PetscErrorCode SameGroup(PeriProblem a, PeriProblem b, const char ref[], const char name[])
{
  const PeriRegion *ra = FindRegion(a, ref), *rb = FindRegion(b, name);
  char              what[128];

  PetscFunctionBeginUser;
  PetscCheck(ra && rb, PETSC_COMM_SELF, PETSC_ERR_PLIB, "FAIL: group '%s' is missing", ra ? name : ref);
  PetscCall(PetscSNPrintf(what, sizeof(what), "group '%s' (as '%s'): particles", name, ref));
  PeriTestClose(what, (PetscReal)rb->count, (PetscReal)ra->count, 0);
  PetscCall(PetscSNPrintf(what, sizeof(what), "group '%s' (as '%s'): volume", name, ref));
  PeriTestClose(what, rb->volume, ra->volume, 1e-9 * ra->volume);
  PetscCall(PetscSNPrintf(what, sizeof(what), "group '%s' (as '%s'): face area", name, ref));
  PeriTestClose(what, rb->face_area, ra->face_area, 1e-9 * PetscMax(ra->face_area, 1e-300));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode TestSame(const char scene[], const char msh[], const char other[], PetscInt nalias, char **alias)
{
  PeriProblem    a, b;
  PeriParticles *pa;
  PetscReal      size = 0;

  PetscFunctionBeginUser;
  PetscCall(ReadWith(scene, msh, &a));
  PetscCall(ReadWith(scene, other, &b));
  pa = &a->sys->disc.particles;
  for (PetscInt d = 0; d < 3; d++) size = PetscMax(size, pa->upper[d] - pa->lower[d]);
  PetscCall(SameParticles(pa, &b->sys->disc.particles, size));
  for (PetscInt g = 0; g < pa->ngroups; g++) PetscCall(SameGroup(a, b, pa->groups[g].name, pa->groups[g].name));
  for (PetscInt k = 0; k < nalias; k++) {
    char *eq = strchr(alias[k], '=');
    PetscCheck(eq, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "ALIAS=GROUP expected, not %s", alias[k]);
    *eq = 0;
    PetscCall(SameGroup(a, b, eq + 1, alias[k]));
  }
  PetscCall(PeriProblemDestroy(&a));
  PetscCall(PeriProblemDestroy(&b));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 4, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_mesh read SCENE MESH VOLUME FACE | uniform SCENE TOL");
  if (!strcmp(argv[1], "same")) {
    PetscCheck(argc >= 5, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_mesh same SCENE MSH OTHER [ALIAS=GROUP ...]");
    PetscCall(TestSame(argv[2], argv[3], argv[4], argc - 5, argv + 5));
  } else if (!strcmp(argv[1], "read")) {
    PetscCheck(argc >= 6, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_mesh read SCENE MESH VOLUME FACE");
    PetscCall(TestRead(argv[2], argv[3], atof(argv[4]), atof(argv[5])));
  } else {
    PetscCall(TestUniform(argv[2], atof(argv[3])));
  }
  PetscCall(PeriFinalize());
  return 0;
}
