/* examples/pmb/plate_traction.yaml: the far-field strain of a plane-stress PMB plate under uniaxial
 * traction. The exact elastic answer is e_xx = sigma/E, nu = 1/3; a bond-based lattice at m = 3
 * has its own homogenized stiffness, computed here independently from the lattice sums
 * C_ijkl = (c/2) sum_j alpha_j V_j |xi_j| e_i e_j e_k e_l (a few percent off the continuum:
 * see docs/theory.md). The plate must match that lattice value to 2 % (what is left is the finite
 * plate and the probe sampling) and so the elastic value to |lattice error| + 2 %, with and without
 * the surface correction. On several ranks the result must equal a one-rank run to solver tolerance. */
#include "testing.h"
#include <slepcsys.h>

/* alpha of the continued linear ramp, as in docs/theory.md */
static PetscReal Alpha(PetscReal r, PetscReal m)
{
  if (r >= m + 0.5) return 0;
  if (r <= m - 0.5) return 1;
  return m + 0.5 - r;
}

static void LatticeUniaxial(PetscReal m, PetscReal *exx, PetscReal *nu)
{
  PetscReal c11 = 0, c12 = 0, c22 = 0, c = 9 / (PETSC_PI * m * m * m), det;
  PetscInt  R = (PetscInt)m + 2;
  for (PetscInt i = -R; i <= R; i++)
    for (PetscInt j = -R; j <= R; j++) {
      PetscReal r = PetscSqrtReal((PetscReal)(i * i + j * j)), a, ex, ey;
      if (!i && !j) continue;
      a = Alpha(r, m);
      if (a <= 0) continue;
      ex = i / r;
      ey = j / r;
      c11 += 0.5 * c * a * r * ex * ex * ex * ex;
      c12 += 0.5 * c * a * r * ex * ex * ey * ey;
      c22 += 0.5 * c * a * r * ey * ey * ey * ey;
    }
  det  = c11 * c22 - c12 * c12; /* strain for unit stress and unit E */
  *exx = c22 / det;
  *nu  = c12 / c22;
}

static PetscErrorCode FarField(PeriProblem p, PetscReal sigma, PetscReal *exx, PetscReal *nu)
{
  PeriProbe *a, *b, *c, *d;

  PetscFunctionBeginUser;
  PetscCall(PeriSystemFindProbe(p->sys, "a", &a));
  PetscCall(PeriSystemFindProbe(p->sys, "b", &b));
  PetscCall(PeriSystemFindProbe(p->sys, "c", &c));
  PetscCall(PeriSystemFindProbe(p->sys, "d", &d));
  *exx = (b->u[0] - a->u[0]) / (b->x[0] - a->x[0]) / (sigma / p->sys->model->material.E);
  *nu  = -((d->u[1] - c->u[1]) / (d->x[1] - c->x[1])) / (*exx * sigma / p->sys->model->material.E);
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const char *const surfaces[] = {"none", "volume"};
  const PetscReal   sigma      = 1e6;
  PetscReal         lat_exx, lat_nu;
  PetscMPIInt       size, rank;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_plate_traction examples/pmb/plate_traction.yaml");
  PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  LatticeUniaxial(3, &lat_exx, &lat_nu);
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "lattice homogenization, m = 3: e_xx E / sigma = %.4f, nu = %.4f\n", (double)lat_exx, (double)lat_nu));
  for (int k = 0; k < 2; k++) {
    PeriProblem p;
    PetscReal   exx, nu;
    char        what[128];

    PetscCall(PeriTestSetOption("-corrections_surface", surfaces[k]));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
    if (rank == 0) {
      PetscCall(FarField(p, sigma, &exx, &nu));
      PetscCall(PetscSNPrintf(what, sizeof(what), "surface %s: e_xx E / sigma vs lattice", surfaces[k]));
      PeriTestClose(what, exx, lat_exx, 0.02);
      PetscCall(PetscSNPrintf(what, sizeof(what), "surface %s: e_xx E / sigma vs elasticity", surfaces[k]));
      PeriTestClose(what, exx, 1.0, PetscAbsReal(lat_exx - 1) + 0.02);
      PetscCall(PetscSNPrintf(what, sizeof(what), "surface %s: nu vs lattice", surfaces[k]));
      PeriTestClose(what, nu, lat_nu, 0.01);
    }
    if (size > 1) {
      /* every rank solves the same scene alone: the reference for the distributed run */
      PeriProblem q;
      PetscCall(PeriTestRunScene(PETSC_COMM_SELF, argv[1], &q));
      if (rank == 0) {
        for (PetscInt i = 0; i < p->sys->fields.nprobes; i++)
          for (PetscInt c = 0; c < 2; c++) {
            PetscCall(PetscSNPrintf(what, sizeof(what), "surface %s: probe %s u[%" PetscInt_FMT "], %d ranks vs 1", surfaces[k], p->sys->fields.probes[i].name, c, size));
            PeriTestClose(what, p->sys->fields.probes[i].u[c], q->sys->fields.probes[i].u[c], 1e-7 * p->sys->fields.max_abs_u[c]);
          }
        PeriTestClose("strain energy, ranks vs 1", p->sys->fields.strain_energy, q->sys->fields.strain_energy, 1e-8 * q->sys->fields.strain_energy);
      }
      PetscCall(PeriProblemDestroy(&q));
    }
    PetscCall(PeriProblemDestroy(&p));
  }
  PetscCall(PeriFinalize());
  return 0;
}
