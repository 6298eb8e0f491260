/* Quasi-static failure and cracked sections (docs/failure.md):
 * - Ganzenmueller's edge-crack patch (npmb, plane stress, G = 1): the critical traction within 5 %
 *   of LEFM's 130.6 Pa (K_I = sqrt(G E), eq. 23) at dx = 0.04 and 0.02;
 * - Oterkus & Madenci 8.3, both antiplane models: the central crack grows along its own line:
 *   every damaged particle within one horizon of y = 0, the damage beyond the initial tips and
 *   symmetric to one spacing;
 * - a micropolar block sheared by displacement breaks bonds by frictional sliding;
 * - 8.5: torsion of an edge-cracked bar (a/b = 0.25, 0.5, 0.75): on the crack faces the stress
 *   is along the crack (mean |tau_yz| below 10 % of the uncracked peak and of mean |tau_xz|), the
 *   largest stress sits at the tip, and J falls as the crack deepens.
 * usage: test_fracture edge_crack.yaml cracked_bar.yaml micropolar_shear.yaml torsion/torsion_edge_crack.yaml */
#include "testing.h"
#include <slepcsys.h>

static PetscErrorCode Run(const char scene[], const char spacing[], PeriProblem *p)
{
  PetscFunctionBeginUser;
  PetscCall(PeriTestSetOption("-grid_spacing", spacing));
  PetscCall(PeriTestSetOption("-quiet", "true"));
  PetscCall(PeriTestRunScene(PETSC_COMM_WORLD, scene, p));
  PetscCall(PeriTestSetOption("-grid_spacing", NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

int main(int argc, char **argv)
{
  const PetscReal    a8 = 0.125, F = 1.12 - 0.23 * a8 + 10.6 * a8 * a8 - 21.7 * a8 * a8 * a8 + 30.4 * a8 * a8 * a8 * a8;
  const PetscReal    lefm       = PetscSqrtReal(1.0 * 1e4) / PetscSqrtReal(PETSC_PI * a8) / F; /* plane stress */
  static const char *spacings[] = {"0.04", "0.02"};
  PeriProblem        p;
  char               what[256];

  PetscCall(PeriInitialize(&argc, &argv, NULL));
  PetscCheck(argc >= 5, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "usage: test_fracture edge_crack.yaml cracked_bar.yaml micropolar_shear.yaml torsion_edge_crack.yaml");
  PeriTestClose("LEFM sigma_F plane stress [Pa]", lefm, 130.6, 0.05);
  for (PetscInt k = 0; k < 2; k++) {
    PetscCall(Run(argv[1], spacings[k], &p));
    PetscCall(PetscSNPrintf(what, sizeof(what), "edge crack dx = %s: critical traction / LEFM", spacings[k]));
    PeriTestClose(what, PeriTestQuasistatic(p)->critical_load_factor / lefm, 1, 0.05);
    PeriTestClose("edge crack: failed, and the bracket is min_step wide", PeriTestQuasistatic(p)->critical_load_factor - PeriTestQuasistatic(p)->peak_load_factor, 0.25, 1e-9);
    PetscCall(PeriProblemDestroy(&p));
  }

  for (PetscInt k = 0; k < 2; k++) {
    /* both antiplane models; the state-based one at the coarser grid (its K is reassembled each round) */
    PetscCall(PeriTestSetOption("-model_type", k ? "antiplane_os" : "antiplane"));
    PetscCall(Run(argv[2], k ? "0.04" : "0.02", &p));
    PetscCall(PeriTestSetOption("-model_type", NULL));
    /* in stable steps, or in the failed trial only (the state-based model's crack runs away at once) */
    PeriTestClose("cracked bar: the crack grew (bonds broken)", (PetscReal)(PeriTestQuasistatic(p)->broken_bonds + PeriTestQuasistatic(p)->failed_trial_broken > 0), 1, 0);
    /* one state: the results are those of the last equilibrium, steps.csv's last row */
    PeriTestClose("cracked bar: broken bonds = the last step's broken_total", (PetscReal)PeriTestQuasistatic(p)->broken_bonds, (PetscReal)PeriTestQuasistatic(p)->steps[PeriTestQuasistatic(p)->nsteps - 1].broken_total, 0);
    if (p->rank == 0) {
      /* the stable growth at the last equilibrium, then the failed trial's run-away crack */
      for (PetscInt t = 0; t < 2; t++) {
        const PetscReal *damage = t ? PeriTestQuasistatic(p)->trial_damage : p->sys->bond_state.damage;
        PetscReal        ymax = 0, xmin = 0, xmax = 0;
        for (PetscInt i = 0; i < p->sys->disc.particles.n; i++) {
          const PetscReal *X = &p->sys->disc.particles.x[3 * i];
          if (damage[(PERI_NCAUSES + 1) * i] <= 0.01) continue;
          ymax = PetscMax(ymax, PetscAbsReal(X[1]));
          xmin = PetscMin(xmin, X[0]);
          xmax = PetscMax(xmax, X[0]);
        }
        PeriTestClose(t ? "cracked bar, failed trial: damaged particles within a horizon of y = 0" : "cracked bar: damaged particles within a horizon of y = 0", ymax, 0, p->sys->disc.delta);
        if (t) PeriTestClose("cracked bar, failed trial: damage beyond the initial tips (x = 0.1 + delta)", (PetscReal)(xmax > 0.1 + p->sys->disc.delta && xmin < -0.1 - p->sys->disc.delta), 1, 0);
        PeriTestClose(t ? "cracked bar, failed trial: the growth is symmetric" : "cracked bar: the growth is symmetric", xmax + xmin, 0, 1.01 * p->sys->disc.particles.mean_spacing);
      }
    }
    PetscCall(PeriProblemDestroy(&p));
  }

  PetscCall(Run(argv[3], "0.005", &p));
  PeriTestClose("micropolar shear: bonds broke by sliding before the last load", (PetscReal)(PeriTestQuasistatic(p)->broken_bonds > 0 && PeriTestQuasistatic(p)->peak_load_factor > 0), 1, 0);
  PetscCall(PeriProblemDestroy(&p));

  {
    static const char *tips[] = {"-0.25", "0", "0.25"};
    /* the uncracked bar: J = 0.45733 from the exact warping series (test_antiplane's quadrature,
       Timoshenko's beta = 0.229 gives 0.458) and the peak stress mu psi (2a) k = 1.1161e7 psi with
       k = 1 - (8/pi^2) sum_n odd 1/(n^2 cosh(n pi b/(2a))) = 0.93007 for b/a = 2 */
    PetscReal Jprev = 0.4573300474, tau0 = 1.1161e7;
    for (PetscInt k = 0; k < 3; k++) {
      PetscReal tip = atof(tips[k]);
      PetscCall(PeriTestSetOption("-cracks_0_to_0", tips[k]));
      PetscCall(Run(argv[4], "0.02", &p));
      if (p->rank == 0) {
        const PeriParticles *pt  = &p->sys->disc.particles;
        PetscReal            syz = 0, sxz = 0, n = 0, best = 0, bx = 0, by = 0;
        for (PetscInt i = 0; i < pt->n; i++) {
          const PetscReal *X = &pt->x[3 * i];
          if (p->sys->fields.tau[3 * i + 2] > best) {
            best = p->sys->fields.tau[3 * i + 2];
            bx   = X[0];
            by   = X[1];
          }
          if (PetscAbsReal(PetscAbsReal(X[1]) - 0.5 * pt->mean_spacing) > 1e-9 || X[0] > tip - p->sys->disc.delta) continue;
          syz += PetscAbsReal(p->sys->fields.tau[3 * i + 1]);
          sxz += PetscAbsReal(p->sys->fields.tau[3 * i]);
          n += 1;
        }
        PetscCall(PetscSNPrintf(what, sizeof(what), "torsion crack tip %s: mean |tau_yz| on the faces / uncracked peak", tips[k]));
        PeriTestClose(what, syz / n / tau0, 0, 0.1);
        PetscCall(PetscSNPrintf(what, sizeof(what), "torsion crack tip %s: mean |tau_yz| / mean |tau_xz| on the faces", tips[k]));
        PeriTestClose(what, syz / sxz, 0, 0.2);
        PetscCall(PetscSNPrintf(what, sizeof(what), "torsion crack tip %s: distance of the peak stress from the tip", tips[k]));
        PeriTestClose(what, PetscSqrtReal(PetscSqr(bx - tip) + by * by), 0, 2 * p->sys->disc.delta);
      }
      PetscCall(PetscSNPrintf(what, sizeof(what), "torsion crack tip %s: J below the shallower crack's", tips[k]));
      PeriTestClose(what, (PetscReal)(p->sys->conditions.torsion.J < Jprev), 1, 0);
      Jprev = p->sys->conditions.torsion.J;
      PetscCall(PeriProblemDestroy(&p));
    }
    PetscCall(PeriTestSetOption("-cracks_0_to_0", NULL));
  }
  PetscCall(PeriTestSetOption("-quiet", NULL));
  PetscCall(PeriFinalize());
  return 0;
}
