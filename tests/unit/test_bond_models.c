/* The shear-bond and micropolar bond models against exact statements:
 *  - pds has no shear springs at the bond-based Poisson ratio: its K equals pmb's to round-off
 *    (nu = 1/3 plane stress, 1/4 plane strain);
 *  - a rigid rotation u = w x X (theta = w) stores no energy in mppd and gerstle;
 *  - in pds it slides every bond by gamma = w, storing sum_bonds (1/2) alpha lambda V_i V_j g |xi| w^2,
 *    g of Diana & Casolo eq. (21), computed here from the bond list, not from the assembly. */
#include "testing.h"
#include <slepcsys.h>

static PetscErrorCode Setup(const char file[], const char model[], const char nu[], const char plane[], PeriProblem *p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-model_type", model));
  PetscCall(PeriTestSetOption("-material_nu", nu));
  PetscCall(PeriTestSetOption("-model_plane", plane));
  /* the statements are about the continuum constants of eqs. 7, 21, 43 */
  PetscCall(PeriTestSetOption("-model_calibration", "continuum"));
  PetscCall(PeriProblemCreate(PETSC_COMM_WORLD, p));
  PetscCall(PeriProblemLoad(*p, file));
  PetscCall(PeriProblemSetUp(*p));
  (*p)->sys->stiffness.needs.matrix_free = PETSC_FALSE; /* the test reads K's entries: assembled */
  PetscCall(PeriSystemAssemble((*p)->sys));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* u = A (X - centre) on the displacements, theta = th: returns (1/2) u^T K u */
static PetscErrorCode Energy(PeriProblem p, const PetscReal A[2][2], PetscReal th, PetscReal *E)
{
  Vec          u, Ku;
  PetscScalar *a, e;
  PetscInt     bs = p->sys->model->dofs;

  PetscFunctionBeginUser;
  PetscCall(MatCreateVecs(p->sys->stiffness.K, &u, &Ku));
  PetscCall(VecGetArray(u, &a));
  for (PetscInt i = p->sys->disc.bonds.rstart; i < p->sys->disc.bonds.rend; i++) {
    PetscReal x                                 = p->sys->disc.particles.x[3 * i] - 0.5 * (p->sys->disc.particles.lower[0] + p->sys->disc.particles.upper[0]);
    PetscReal y                                 = p->sys->disc.particles.x[3 * i + 1] - 0.5 * (p->sys->disc.particles.lower[1] + p->sys->disc.particles.upper[1]);
    a[(i - p->sys->disc.bonds.rstart) * bs + 0] = A[0][0] * x + A[0][1] * y;
    a[(i - p->sys->disc.bonds.rstart) * bs + 1] = A[1][0] * x + A[1][1] * y;
    if (bs == 3) a[(i - p->sys->disc.bonds.rstart) * bs + 2] = th;
  }
  PetscCall(VecRestoreArray(u, &a));
  PetscCall(MatMult(p->sys->stiffness.K, u, Ku));
  PetscCall(VecDot(u, Ku, &e));
  *E = 0.5 * PetscRealPart(e);
  PetscCall(VecDestroy(&u));
  PetscCall(VecDestroy(&Ku));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const PetscReal w = 1e-3, rot[2][2] = {{0, -1e-3}, {1e-3, 0}}, dil[2][2] = {{1e-3, 0}, {0, 1e-3}};
  const char     *planes[] = {"stress", "strain"}, *nus[] = {"1/3", "1/4"};
  PeriProblem     p, q;
  char            what[160];

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_bond_models tests/scenes/affine_2d.yaml");

  for (int k = 0; k < 2; k++) {
    PetscReal diff, norm;
    PetscCall(Setup(argv[1], "pds", nus[k], planes[k], &p));
    PetscCall(Setup(argv[1], "pmb", nus[k], planes[k], &q));
    PetscCall(MatNorm(q->sys->stiffness.K, NORM_FROBENIUS, &norm));
    PetscCall(MatAXPY(p->sys->stiffness.K, -1, q->sys->stiffness.K, SAME_NONZERO_PATTERN));
    PetscCall(MatNorm(p->sys->stiffness.K, NORM_FROBENIUS, &diff));
    PetscCall(PetscSNPrintf(what, sizeof(what), "plane %s, nu = %s: |K_pds - K_pmb| / |K_pmb|", planes[k], nus[k]));
    PeriTestClose(what, diff / norm, 0, 1e-13);
    PetscCall(PeriProblemDestroy(&p));
    PetscCall(PeriProblemDestroy(&q));
  }

  for (int mo = 0; mo < 3; mo++) {
    const char *models[] = {"mppd", "gerstle", "pds"}, *nuv[] = {"-0.5", "0", "0.25"};
    for (int k = 0; k < 3; k++) {
      PetscReal Erot, Edil, nu = (PetscReal)atof(nuv[k]);
      PetscCall(Setup(argv[1], models[mo], nuv[k], "stress", &p));
      PetscCall(Energy(p, rot, w, &Erot));
      PetscCall(Energy(p, dil, 0, &Edil));
      if (mo < 2) {
        PetscCall(PetscSNPrintf(what, sizeof(what), "%s nu = %s: rigid rotation energy / dilatation energy", models[mo], nuv[k]));
        PeriTestClose(what, Erot / Edil, 0, 1e-12);
      } else {
        const PeriParticles *pt = &p->sys->disc.particles;
        const PetscReal      E = p->sys->model->material.E, t = pt->thickness, d3 = PetscPowReal(p->sys->disc.delta, 3);
        const PetscReal      g      = 6 * E * (1 - 3 * nu) / (PETSC_PI * t * d3 * (1 - nu * nu));
        PetscReal            expect = 0;
        for (PetscInt i = p->sys->disc.bonds.rstart; i < p->sys->disc.bonds.rend; i++)
          for (PetscInt b = p->sys->disc.bonds.offset[i - p->sys->disc.bonds.rstart]; b < p->sys->disc.bonds.offset[i - p->sys->disc.bonds.rstart + 1]; b++) {
            PetscInt j = p->sys->disc.bonds.j[b];
            expect += 0.5 * p->sys->disc.bonds.alpha[b] * p->sys->disc.bonds.lambda[b] * pt->volume[i] * pt->volume[j] * g * p->sys->disc.bonds.length[b] * w * w;
          }
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &expect, 1, MPIU_REAL, MPI_SUM, p->comm));
        PetscCall(PetscSNPrintf(what, sizeof(what), "pds nu = %s: rigid rotation energy / sum of (1/2) W g |xi| w^2 (nonzero: the defect)", nuv[k]));
        PeriTestClose(what, Erot / expect, 1, 1e-10);
      }
      PetscCall(PeriProblemDestroy(&p));
    }
  }
  PetscCall(PeriFinalize());
  return 0;
}
