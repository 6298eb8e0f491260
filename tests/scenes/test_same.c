/* Two scenes that describe the same body must give the same answer: the strain energy and the
 * largest displacement of every component, to the solver tolerance. */
#include "testing.h"
#include <slepcsys.h>

int main(int argc, char **argv)
{
  PeriProblem p, q;
  char        what[256];

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 3, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_same A.yaml B.yaml [options]");
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[1], &p));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, argv[2], &q));
  PetscCall(PetscSNPrintf(what, sizeof(what), "strain energy, %s vs %s", argv[2], argv[1]));
  PeriTestClose(what, q->sys->fields.strain_energy, p->sys->fields.strain_energy, 1e-8 * p->sys->fields.strain_energy);
  for (PetscInt c = 0; c < p->sys->model->dofs; c++) {
    PetscCall(PetscSNPrintf(what, sizeof(what), "max |%s|", p->sys->model->components[c]));
    PeriTestClose(what, q->sys->fields.max_abs_u[c], p->sys->fields.max_abs_u[c], 1e-7 * p->sys->fields.max_abs_u[c]);
  }
  PetscCall(PeriProblemDestroy(&p));
  PetscCall(PeriProblemDestroy(&q));
  PetscCall(PeriFinalize());
  return 0;
}
