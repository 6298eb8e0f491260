/* Ganzenmueller et al. sec. 3.1.1 (Fig. 3): energy density of u = s X at the centre of a cubic
 * lattice for m = 2, 2.5, 3, 4, 5, 6. npmb must give 9 K s^2 / 2 to round-off; pmb's error must equal the
 * lattice sum sum_j |xi_j| V_j / (pi delta^4) - 1, computed here independently by brute force.
 * cpmb (conical influence 1 - |xi|/delta) must equal sum_j (1 - |xi_j|/delta) |xi_j| V_j /
 * (pi delta^4 / 5), the same brute-force sum with the weight.
 * The paper's neighbour counts (32 at m = 2, 924 at m = 6) are checked too, and its "errors
 * exceed 30 %" for pmb: the lattice sum at m = 2.5 (+31.4 %). */
#include "testing.h"
#include <slepcsys.h>

/* sum over lattice points 0 < |xi| <= m of |xi|^p, and their number */
static void LatticeSum(PetscReal m, PetscInt p, PetscReal *sum, PetscInt *count)
{
  const PetscInt n = (PetscInt)PetscFloorReal(m);
  *sum             = 0;
  *count           = 0;
  for (PetscInt i = -n; i <= n; i++)
    for (PetscInt j = -n; j <= n; j++)
      for (PetscInt k = -n; k <= n; k++) {
        PetscInt r2 = i * i + j * j + k * k;
        if (r2 == 0 || r2 > m * m) continue;
        *sum += PetscPowReal(PetscSqrtReal((PetscReal)r2), (PetscReal)p);
        (*count)++;
      }
}

int main(int argc, char **argv)
{
  const PetscReal K = 1e9, s = 0.01, Wexact = 4.5 * K * s * s;

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_energy_density examples/pmb/energy_density.yaml");
  const PetscReal ms[] = {2, 2.5, 3, 4, 5, 6};
  for (size_t im = 0; im < sizeof(ms) / sizeof(ms[0]); im++) {
    const PetscReal m = ms[im];
    char            val[16], what[128];
    PetscReal       sum1, sum2;
    PetscInt        count;
    PeriProblem     p;
    PeriProbe      *c;

    LatticeSum(m, 1, &sum1, &count);
    LatticeSum(m, 2, &sum2, &count);
    PetscCall(PetscSNPrintf(val, sizeof(val), "%g", (double)m));
    PetscCall(PeriTestSetOption("-horizon_m", val));

    PetscCall(PeriTestSetOption("-model_type", "npmb"));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
    if (p->rank == 0) {
      PetscCall(PeriSystemFindProbe(p->sys, "center", &c));
      PetscCall(PetscSNPrintf(what, sizeof(what), "npmb m=%g: centre W / (9 K s^2/2)", m));
      PeriTestClose(what, c->W / Wexact, 1.0, 1e-10);
      PetscCall(PetscSNPrintf(what, sizeof(what), "m=%g: neighbours of the centre (lattice count)", (double)m));
      PeriTestClose(what, (PetscReal)p->sys->disc.neighbor_count[c->particle], (PetscReal)count, 0);
      if (m == 2.0) PeriTestClose("m=2: neighbours of the centre (paper: 32)", (PetscReal)count, 32, 0);
      if (m == 6.0) PeriTestClose("m=6: neighbours of the centre (paper: 924)", (PetscReal)count, 924, 0);
    }
    PetscCall(PeriProblemDestroy(&p));

    PetscCall(PeriTestSetOption("-model_type", "pmb"));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
    if (p->rank == 0) {
      PetscReal predicted = sum1 / (PETSC_PI * PetscPowReal(m, 4));
      PetscCall(PeriSystemFindProbe(p->sys, "center", &c));
      PetscCall(PetscSNPrintf(what, sizeof(what), "pmb m=%g: centre W / (9 K s^2/2), error %+.2f %%", (double)m, (double)(100 * (c->W / Wexact - 1))));
      PeriTestClose(what, c->W / Wexact, predicted, 1e-10 * predicted);
      /* Ganzenmueller's text: pmb's errors exceed 30 % (at fractional m, as here) */
      if (m == 2.5) {
        PetscCheck(c->W / Wexact - 1 > 0.30, PETSC_COMM_SELF, PETSC_ERR_PLIB, "pmb m=2.5: error %+.2f %% is not above the paper's 30 %%", (double)(100 * (c->W / Wexact - 1)));
        PetscCall(PetscPrintf(PETSC_COMM_SELF, "ok: pmb m=2.5: error %+.2f %% exceeds the paper's 30 %%\n", (double)(100 * (c->W / Wexact - 1))));
      }
    }
    PetscCall(PeriProblemDestroy(&p));

    PetscCall(PeriTestSetOption("-model_type", "cpmb"));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
    if (p->rank == 0) {
      PetscReal predicted = (sum1 - sum2 / m) / (PETSC_PI * PetscPowReal(m, 4) / 5);
      PetscCall(PeriSystemFindProbe(p->sys, "center", &c));
      PetscCall(PetscSNPrintf(what, sizeof(what), "cpmb m=%g: centre W / (9 K s^2/2), error %+.2f %%", (double)m, (double)(100 * (c->W / Wexact - 1))));
      PeriTestClose(what, c->W / Wexact, predicted, 1e-10 * predicted);
    }
    PetscCall(PeriProblemDestroy(&p));
  }
  PetscCall(PeriFinalize());
  return 0;
}
