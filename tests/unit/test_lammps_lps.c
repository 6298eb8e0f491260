/* lps against LAMMPS's pair peri/lps, an independent implementation (Parks et al.'s PERI package),
 * on the identical lattice (tests/scenes/lammps_lps.yaml): the force density of every site under
 * the displacement u = eps (x y, y z, x^2) / L that tests/perf/lammps/lps_forces.in imposed, read
 * from its dump (tests/reference/lps_forces_lammps.dump: LAMMPS 20220106 of Debian; the command is
 * in docs/references/lammps_lps.md). perilin's internal force -K u of each site over its volume
 * must match LAMMPS's fx, fy, fz to 1e-6 of the largest (LAMMPS's bonds are geometrically
 * nonlinear: at eps = 1e-7 the difference is about 1.4e-7), on the surface sites too, with the
 * matrix-free and the assembled operator. usage: test_lammps_lps scene.yaml lammps.dump */
#include "testing.h"

#define NSITES 576

typedef struct {
  PetscReal x[3], u[3], f[3];
} Site;

/* The dump's sites by id (1-based): reference position, displacement, force density. */
static PetscErrorCode ReadDump(const char file[], Site sites[])
{
  FILE *fp;
  char  line[1024];
  int   n = 0;

  PetscFunctionBeginUser;
  fp = fopen(file, "r");
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot open %s", file);
  while (fgets(line, sizeof(line), fp))
    if (!strncmp(line, "ITEM: ATOMS", 11)) break;
  while (fgets(line, sizeof(line), fp)) {
    int    id;
    double v[10];
    if (sscanf(line, "%d %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", &id, &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9]) != 11) continue;
    PetscCheck(id >= 1 && id <= NSITES, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: atom id %d outside 1..%d", file, id, NSITES);
    for (int d = 0; d < 3; d++) {
      sites[id - 1].x[d] = v[d];
      sites[id - 1].u[d] = v[3 + d];
      sites[id - 1].f[d] = v[6 + d];
    }
    n++;
  }
  fclose(fp);
  PetscCheck(n == NSITES, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: %d sites, expected %d", file, n, NSITES);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The LAMMPS site at a particle's position (lattice constant a, 12 x 8 sites per layer). */
static PetscInt SiteOf(const PetscReal x[], PetscReal a)
{
  PetscInt i = (PetscInt)PetscFloorReal(x[0] / a + 0.5), j = (PetscInt)PetscFloorReal(x[1] / a + 0.5), k = (PetscInt)PetscFloorReal(x[2] / a + 0.5);
  return i + 12 * (j + 8 * k);
}

static PetscErrorCode Compare(const char scene[], const Site sites[], const char operator_kind[])
{
  PeriProblem        p;
  Vec                u, f;
  PetscScalar       *ua;
  const PetscScalar *fa;
  PetscReal          err = 0, fmax = 0, both[2];

  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-solver_operator", operator_kind));
  PetscCall(PeriProblemCreate(PETSC_COMM_WORLD, &p));
  PetscCall(PeriProblemLoad(p, scene));
  PetscCall(PeriProblemSetUp(p));
  p->sys->stiffness.needs.matrix_free = (PetscBool)!strcmp(operator_kind, "matrix_free");
  PetscCall(PeriSystemAssemble(p->sys));
  PetscCheck(p->sys->disc.N == NSITES, PETSC_COMM_WORLD, PETSC_ERR_PLIB, "%s: %" PetscInt_FMT " particles, LAMMPS's lattice has %d", scene, p->sys->disc.N, NSITES);
  PetscCall(MatCreateVecs(p->sys->stiffness.K, &u, &f));
  PetscCall(VecGetArray(u, &ua));
  for (PetscInt i = 0; i < p->sys->disc.nowned; i++) {
    const Site *s = &sites[SiteOf(&p->sys->disc.particles.x[3 * i], 1e-3)];
    for (PetscInt d = 0; d < 3; d++) {
      PetscCheck(PetscAbsReal(s->x[d] - p->sys->disc.particles.x[3 * i + d]) < 1e-9, PETSC_COMM_SELF, PETSC_ERR_PLIB, "particle %" PetscInt_FMT " is not at its LAMMPS site", i);
      ua[3 * i + d] = s->u[d];
    }
  }
  PetscCall(VecRestoreArray(u, &ua));
  PetscCall(MatMult(p->sys->stiffness.K, u, f));
  PetscCall(VecGetArrayRead(f, &fa));
  for (PetscInt i = 0; i < p->sys->disc.nowned; i++) {
    const Site *s = &sites[SiteOf(&p->sys->disc.particles.x[3 * i], 1e-3)];
    for (PetscInt d = 0; d < 3; d++) {
      err  = PetscMax(err, PetscAbsReal(-PetscRealPart(fa[3 * i + d]) / p->sys->disc.particles.volume[i] - s->f[d]));
      fmax = PetscMax(fmax, PetscAbsReal(s->f[d]));
    }
  }
  PetscCall(VecRestoreArrayRead(f, &fa));
  both[0] = err;
  both[1] = fmax;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, both, 2, MPIU_REAL, MPI_MAX, PETSC_COMM_WORLD));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "%s operator: largest LAMMPS force density %g\n", operator_kind, (double)both[1]));
  PeriTestClose("lps force density against LAMMPS peri/lps, every site (relative to the largest)", both[0] / both[1], 0.0, 1e-6);
  PetscCall(VecDestroy(&u));
  PetscCall(VecDestroy(&f));
  PetscCall(PeriProblemDestroy(&p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  Site *sites;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc == 3, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_lammps_lps scene.yaml lammps.dump");
  PetscCall(PetscMalloc1(NSITES, &sites));
  PetscCall(ReadDump(argv[2], sites));
  PetscCall(Compare(argv[1], sites, "matrix_free"));
  PetscCall(Compare(argv[1], sites, "assembled"));
  PetscCall(PetscFree(sites));
  PetscCall(PeriFinalize());
  return 0;
}
