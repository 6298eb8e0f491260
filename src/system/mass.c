/* The mass service (include/perilin/private/mass.h): densities, lumped mass, total mass. Any
 * analysis with inertia (modal, transient) asks for it; it is built once, on the first request,
 * and lives with the system. */
#include "perilin/private/system.h"

/* The density of each owned particle: material.rho, or material.rho_by_region {region: rho}
 * (later regions win where they overlap). */
/*@C
  PeriMassSetFromScene - material.rho_by_region into the mass's settings (its regions and
  densities, each checked positive), read once at the set-up, and the node that locates a missing
  density; the mass itself is built on first request. Not collective.
@*/
PetscErrorCode PeriMassSetFromScene(PeriSystem sys)
{
  PeriScene s = sys->scene;
  PeriMass *m = &sys->mass;
  PeriNode  map;

  PetscFunctionBeginUser;
  PetscCall(PetscFree2(m->by_region, m->by_value));
  m->nby = 0;
  PetscCall(PeriSceneGetNode(s->root, "material", &m->where));
  PetscCall(PeriSceneGetMap(s, m->where, "rho_by_region", PETSC_FALSE, &map));
  if (!map) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc2(map->n, &m->by_region, map->n, &m->by_value));
  for (PetscInt k = 0; k < map->n; k++) {
    PetscCall(PeriRegionFind(s, map->child[k], NULL, sys->disc.nregions, sys->disc.regions, &m->by_region[k]));
    PetscCall(PeriSceneGetReal(s, map, map->child[k]->key, PETSC_TRUE, &m->by_value[k], NULL));
    PeriInputCheck(m->by_value[k] > 0, s, map, map->child[k]->key, "must be positive");
    m->nby = k + 1;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The density of each owned particle: material.rho, or the last rho_by_region that holds it. */
static PetscErrorCode Densities(PeriSystem sys, PetscReal rho[])
{
  const PeriMass *m    = &sys->mass;
  const PetscInt  nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < nloc; i++) rho[i] = sys->model->material.rho;
  /* the node only locates the message: nothing is read from the scene here */
  PeriInputCheck(sys->model->material.rho > 0, sys->scene, m->where, "rho", "an analysis with inertia needs the density (material.rho > 0)");
  for (PetscInt k = 0; k < m->nby; k++)
    for (PetscInt i = 0; i < nloc; i++)
      if (PeriRegionContains(m->by_region[k], &sys->disc.particles.x[3 * (sys->disc.bonds.rstart + i)])) rho[i] = m->by_value[k];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMassSetUp - the densities, the lumped mass per DOF and the total mass of the owned particles;
  does nothing when already built. Reads material.rho and material.rho_by_region (an input error
  when a density is not positive). Collective.
@*/
PetscErrorCode PeriMassSetUp(PeriSystem sys)
{
  PeriMass      *m  = &sys->mass;
  const PetscInt bs = sys->model->dofs, nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart;
  PetscScalar   *a;

  PetscFunctionBeginUser;
  if (m->set) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc1(nloc, &m->rho));
  PetscCall(Densities(sys, m->rho));
  PetscCall(PeriSystemCreateVec(sys, &m->diag));
  PetscCall(VecGetArray(m->diag, &a));
  m->total = 0;
  for (PetscInt i = 0; i < nloc; i++) {
    PetscReal V = sys->disc.particles.volume[sys->disc.bonds.rstart + i], h = sys->disc.particles.spacing[sys->disc.bonds.rstart + i];
    for (PetscInt c = 0; c < bs; c++) a[i * bs + c] = sys->model->rotational[c] ? m->rho[i] * V * (h * h + h * h) / 12 : m->rho[i] * V;
    m->total += m->rho[i] * V;
  }
  PetscCall(VecRestoreArray(m->diag, &a));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &m->total, 1, MPIU_REAL, MPI_SUM, sys->comm));
  m->set = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMassGetDiagonal - the lumped mass per DOF (borrowed: do not destroy), built on first use. Collective.
@*/
PetscErrorCode PeriMassGetDiagonal(PeriSystem sys, Vec *d)
{
  PetscFunctionBeginUser;
  PetscCall(PeriMassSetUp(sys));
  *d = sys->mass.diag;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMassGetTotal - the body's total mass (translational), built on first use. Collective.
@*/
PetscErrorCode PeriMassGetTotal(PeriSystem sys, PetscReal *total)
{
  PetscFunctionBeginUser;
  PetscCall(PeriMassSetUp(sys));
  *total = sys->mass.total;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriMassGetMatrix - the lumped mass as a diagonal AIJ matrix in the layout of K (borrowed: do
  not destroy), for solvers that take a matrix (SLEPc's GHEP, TS's I2Jacobian). Collective.
@*/
PetscErrorCode PeriMassGetMatrix(PeriSystem sys, Mat *M)
{
  PeriMass      *m  = &sys->mass;
  const PetscInt bs = sys->model->dofs, nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart;

  PetscFunctionBeginUser;
  PetscCall(PeriMassSetUp(sys));
  if (!m->M) {
    PetscCall(MatCreate(sys->comm, &m->M));
    PetscCall(MatSetSizes(m->M, nloc * bs, nloc * bs, PETSC_DETERMINE, PETSC_DETERMINE));
    PetscCall(MatSetBlockSize(m->M, bs));
    PetscCall(MatSetType(m->M, MATAIJ));
    PetscCall(MatXAIJSetPreallocation(m->M, 1, NULL, NULL, NULL, NULL));
    PetscCall(MatSeqAIJSetPreallocation(m->M, 1, NULL));
    PetscCall(MatMPIAIJSetPreallocation(m->M, 1, NULL, 0, NULL));
    PetscCall(MatDiagonalSet(m->M, m->diag, INSERT_VALUES));
    PetscCall(MatAssemblyBegin(m->M, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(m->M, MAT_FINAL_ASSEMBLY));
  }
  *M = m->M;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriMassDestroy(PeriMass *m)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(m->rho));
  PetscCall(VecDestroy(&m->diag));
  PetscCall(MatDestroy(&m->M));
  PetscCall(PetscFree2(m->by_region, m->by_value));
  m->nby = 0;
  m->set = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}
