/* Particles from Gmsh meshes (docs/mesh.md).
 *   test_mesh read SCENE MESH VOLUME FACE: one particle per element of the scene's dimension (counted
 *     here through Gmsh's API), total volume VOLUME to 1e-12, the group "left" (a boundary on x = 0)
 *     holding the elements with a side on x = 0 and the face area FACE to 1e-12.
 *   test_mesh uniform SCENE TOL: a bar pulled along x by a traction s = 1 MPa, E = 1 GPa, nu = 1/3
 *     (bond-based): the least-squares slopes of ux along x and of uy along y over the particles one
 *     horizon inside the body match s/E and -nu s/E within TOL (relative). On this unstructured mesh
 *     (size 0.025, m = 3) npmb gives -2.8 % (xx) and +5.1 % (yy), pmb with the volume correction
 *     -6.4 % (xx): the PD discretization error of irregular particles, not exactness. */
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

int main(int argc, char **argv)
{
  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 4, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_mesh read SCENE MESH VOLUME FACE | uniform SCENE TOL");
  if (!strcmp(argv[1], "read")) {
    PetscCheck(argc >= 6, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_mesh read SCENE MESH VOLUME FACE");
    PetscCall(TestRead(argv[2], argv[3], atof(argv[4]), atof(argv[5])));
  } else {
    PetscCall(TestUniform(argv[2], atof(argv[3])));
  }
  PetscCall(PeriFinalize());
  return 0;
}
