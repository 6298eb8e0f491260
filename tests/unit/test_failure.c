/* Failure criteria on single bonds, against the formulas (docs/failure.md): the index of tension,
 * compression, sliding and frictional sliding, the critical stretch from G of pmb (Silling &
 * Askari / Ha & Bobaru, plane stress sqrt(4 pi G / (9 E delta))) and of the antiplane shear angle
 * (Oterkus & Madenci eq. 78); and a plate with a crack that cuts off an unloaded piece solves,
 * the piece held, the damage of the cut particles positive.
 * usage: test_failure tests/scenes/fragment.yaml */
#include "testing.h"
#include <slepcsys.h>

int main(int argc, char **argv)
{
  PeriProblem      p;
  PeriBondGeometry g = {0};
  PetscReal        meas[PERI_MAX_MEASURE];

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_failure fragment.yaml");
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
  /* the scene: s_c = 0.01, compressive 0.02 */
  meas[0] = 0.005;
  PeriTestClose("tension index s/s_c", PeriBondFailureIndex(p->sys, &g, meas, NULL), 0.5, 1e-14);
  meas[0] = 0.012;
  PeriTestClose("tension index past s_c", PeriBondFailureIndex(p->sys, &g, meas, NULL), 1.2, 1e-14);
  meas[0] = -0.03;
  PeriTestClose("compression index -s/s_cc", PeriBondFailureIndex(p->sys, &g, meas, NULL), 1.5, 1e-14);
  /* the cut-off piece: held, the rest loaded and solved */
  PeriTestClose("static solve converged with a held piece", (PetscReal)(p->sys->fields.solve.residual_norm < 1e-8), 1, 0);
  PetscCall(PeriDamage(p->sys, &p->sys->bond_state.damage));
  {
    PetscReal dmax = 0;
    for (PetscInt i = 0; i < p->sys->disc.nowned; i++) dmax = PetscMax(dmax, p->sys->bond_state.damage[(PERI_NCAUSES + 1) * i]);
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &dmax, 1, MPIU_REAL, MPI_MAX, PETSC_COMM_WORLD));
    PeriTestClose("largest damage of the cut particles in (0, 1)", (PetscReal)(dmax > 0.2 && dmax < 1), 1, 0);
  }
  PeriTestClose("pre-cracked bonds > 0", (PetscReal)(p->sys->bond_state.failure.precracked_bonds > 0), 1, 0);
  /* G: pmb, plane stress: s_c = sqrt(4 pi G / (9 E delta)) */
  PetscCall(PeriFailureSetValue(&p->sys->bond_state.failure, "critical_stretch", 0));
  PetscCall(PeriFailureSetValue(&p->sys->bond_state.failure, "G", 100));
  meas[0] = PetscSqrtReal(4 * PETSC_PI * 100 / (9 * 1e9 * p->sys->disc.delta));
  PeriTestClose("pmb plane stress: s at s_c from G gives index 1", PeriBondFailureIndex(p->sys, &g, meas, NULL), 1, 1e-12);
  PetscCall(PeriProblemDestroy(&p));

  /* sliding and friction (pds): gamma_0 = 0.01; friction 30 degrees, cohesion 0.005 */
  PetscCall(PeriTestSetOption("-model_type", "pds"));
  PetscCall(PeriTestSetOption("-material_nu", "0.2"));
  PetscCall(PeriTestSetOption("-failure_sliding", "0.01"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
  meas[0] = 0;
  meas[1] = -0.008;
  PeriTestClose("pds sliding index |gamma|/gamma_0", PeriBondFailureIndex(p->sys, &g, meas, NULL), 0.8, 1e-14);
  PetscCall(PeriFailureSetValue(&p->sys->bond_state.failure, "sliding", 0));
  PetscCall(PeriFailureSetValue(&p->sys->bond_state.failure, "friction_angle", 30));
  PetscCall(PeriFailureSetValue(&p->sys->bond_state.failure, "cohesion", 0.005));
  meas[0] = -0.004; /* compression raises the limit to a - s tan(beta) */
  meas[1] = 0.006;
  PeriTestClose("frictional sliding index", PeriBondFailureIndex(p->sys, &g, meas, NULL), 0.006 / (0.005 + 0.004 * PetscTanReal(PETSC_PI / 6)), 1e-14);
  meas[0] = 0.01; /* tension beyond a / tan(beta): no sliding strength left */
  PeriTestClose("frictional sliding in tension breaks", (PetscReal)(PeriBondFailureIndex(p->sys, &g, meas, NULL) >= 1), 1, 0);
  PetscCall(PeriProblemDestroy(&p));
  PetscCall(PeriTestSetOption("-model_type", NULL));
  PetscCall(PeriTestSetOption("-material_nu", NULL));
  PetscCall(PeriTestSetOption("-failure_sliding", NULL));
  /* softening (eqs. 45-46): halfway between the critical and the ultimate stretch a bond keeps
     half its stiffness; the strip's energy falls below the linear one once its strain passes s_0 */
  if (argc >= 3) {
    PetscReal E1, E2, dmax = 0;
    PetscCall(PeriTestSetOption("-quiet", "true"));
    PetscCall(PeriTestSetOption("-analysis_load_factor_max", "0.5"));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[2], &p));
    meas[0] = 2e-3;
    PeriTestClose("softening share at (s_0 + s_u)/2", PeriBondSoftening(p->sys, meas), 0.5, 1e-14);
    E1 = p->sys->fields.strain_energy;
    PetscCall(PeriProblemDestroy(&p));
    PetscCall(PeriTestSetOption("-analysis_load_factor_max", "4"));
    PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[2], &p));
    E2 = p->sys->fields.strain_energy;
    for (PetscInt i = 0; i < p->sys->disc.nowned; i++) dmax = PetscMax(dmax, p->sys->bond_state.damage[(PERI_NCAUSES + 1) * i]);
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &dmax, 1, MPIU_REAL, MPI_MAX, PETSC_COMM_WORLD));
    PeriTestClose("strip below s_0 at load 0.5: nothing softened", (PetscReal)(E1 > 0), 1, 0);
    PeriTestClose("softened strip: energy at load 4 / (64 x energy at load 0.5) below 0.95", (PetscReal)(E2 / (64 * E1) < 0.95), 1, 0);
    PeriTestClose("softened strip: largest damage in (0, 1)", (PetscReal)(dmax > 0 && dmax < 1), 1, 0);
    PetscCall(PeriProblemDestroy(&p));
    PetscCall(PeriTestSetOption("-analysis_load_factor_max", NULL));
    PetscCall(PeriTestSetOption("-quiet", NULL));
  }
  PetscCall(PeriFinalize());
  return 0;
}
