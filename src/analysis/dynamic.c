/* Transient dynamics, M a + K u = f(t), on PETSc's TS with the system's stiffness, mass and bond
 * state (issue 26, first part; docs/dynamics.md). Explicit: velocity Verlet (TSBASICSYMPLECTIC,
 * kick-drift-kick, RegisterKDK; PETSc's drift-kick-drift type 2 with impactors and bc velocities)
 * on the lumped mass, one product with K per step, the energy balance included (CachedForce), the
 * step checked against the stability
 * limit 2/omega_max, omega_max^2 bounded from above by Gershgorin's theorem on M^-1 K. Implicit:
 * generalized-alpha for second-order systems (TSALPHA2; spectral radius 1 by default, which is
 * Newmark's average acceleration, beta = 1/4, gamma = 1/2), each step a linear solve with the
 * static solver's KSP/PC. Any -ts_* option applies after these defaults. Bonds break after each
 * step by the scene's failure criteria (all bonds past them, irreversibly), and the energy they
 * held is counted as dissipated; the energy balance (kinetic + strain + dissipated - work of the
 * loads) must close to analysis.energy_tolerance, or the run fails. */
#include "perilin/private/analysis.h"
#include <petscts.h>
#include <signal.h>

static const char *const dyn_integrators[] = {"explicit", "implicit", NULL};
static const char *const dyn_profiles[]    = {"gaussian", "cosine", NULL};
static const char *const dyn_directions[]  = {"both", "positive", "negative", NULL};

#define PERI_DYN_MAX_TERMS   16 /* load terms with amplitudes of their own, plus one */
#define DYN_FRAMES           25 /* snapshots over t_end by default (output.every 0) */
#define DYN_JACOBI_RATIO     20 /* implicit: CG with Jacobi up to dt = 20 explicit limits, GAMG beyond (ChooseImplicitPC) */
#define DYN_HISTORY_COLUMNS  11 /* t, kinetic, strain, dissipated, work, balance, broken, pulse position, probe, wave front, damage front */
#define DYN_IMPACTOR_COLUMNS 9  /* per impactor: its centre, velocity and the particles' force on it */
#define DYN_ROW(d)           (DYN_HISTORY_COLUMNS + DYN_IMPACTOR_COLUMNS * (d)->nimpactors)
#define DYN_KDK              "kdk" /* perilin's kick-drift-kick velocity Verlet (RegisterKDK) */

typedef struct {
  /* analysis.* */
  PetscBool      implicit;
  PetscReal      t_end, dt, energy_tol, rho_inf;
  PetscInt       energy_every;                                                   /* the energies, the balance and a history row every k steps */
  PetscBool      pulse;                                                          /* analysis.pulse given */
  char           initial_file[PETSC_MAX_PATH_LEN], initial_array[PERI_NAME_LEN]; /* analysis.initial: "" when not given */
  PetscReal      initial_scale;
  PetscReal      pulse_A, pulse_x0, pulse_w; /* u = A exp(-((x - x0)/w)^2), or A cos(pi (x - x0)/w), along the pulse axis */
  PetscInt       profile;                    /* 0 gaussian, 1 cosine */
  PetscReal      velocity[3];                /* analysis.velocity.value, on the particles of region */
  PeriNode       vnode;                      /* analysis.velocity, or NULL */
  PeriNode       unode;                      /* analysis.displacement, or NULL */
  PeriRegion    *vregion, *uregion;          /* their regions, found at the set-up (NULL: none) */
  PetscReal      displacement[3];            /* analysis.displacement.value, on the particles of region */
  PetscInt       pulse_axis;                 /* the pulse's axis */
  PetscInt       pulse_dir;                  /* the axis it displaces along: pulse_axis (a longitudinal wave) or across it (a shear wave) */
  PeriAmplitude  amp;                        /* analysis.amplitude: of every load without one of its own */
  PetscInt       nloads;                     /* loads.<k> in the scene */
  PeriAmplitude *load_amp;                   /* loads.<k>.amplitude (shape step where absent) */
  PetscBool     *own_amp;                    /* loads.<k> has an amplitude of its own */
  /* the load in time, f(t) = sum of a_k(t) f_k over the terms: the loads without an amplitude of
     their own under analysis.amplitude, then one term per load with its own */
  PetscInt              nterms;
  const PeriAmplitude **term_amp;
  Vec                  *term_f;
  PetscReal            *term_prev; /* a_k at the last step, for the work */
  PetscReal            *term_fv;   /* kick-drift-kick: f_k . p at the last step, for the work */
  /* the run */
  PetscBool          started;
  PetscReal          omega2_max, dt_limit; /* Gershgorin's bound of M^-1 K, and 2/omega_max */
  PetscInt           nsteps, broken, snes_its, ksp_its;
  PetscInt           damage_broken;                                              /* d->broken when Fronts last computed the damage; -1: never */
  PetscReal          worst;                                                      /* implicit: the largest relative residual a step ended with */
  PetscReal          kinetic, strain, dissipated, work, E0, scale, error, drift; /* drift: the largest |balance - E0| over the largest energy */
  PetscReal          work_bc;                                                    /* this rank's work of the moving boundaries since the last Work */
  PetscReal         *reaction, ke_held;                                          /* implicit, moving boundaries: K u - f on this rank's held DOFs at t_prev (NULL until known), and their kinetic energy */
  PetscBool          fronts;                                                     /* analysis.fronts given */
  PetscInt           front_axis, front_dir;                                      /* front_dir: 0 both sides of the origin, 1 only beyond it (+axis), 2 only before it */
  PetscReal          front_origin, front_speed, front_damage;                    /* origin along the axis; the thresholds of speed and damage */
  PetscReal          wave_front, damage_front;                                   /* the farthest distance from the origin along the axis of a particle past them */
  PetscReal          t_prev, pulse_pos, probe_u;                                 /* probe_u: the first probe's displacement along the pulse axis (x without a pulse) */
  PetscInt           nhist, cap, nsnap, nimpactors;                              /* history rows (DYN_ROW reals each), their room, snapshots; impactors */
  PetscInt           every;                                                      /* a snapshot every k steps: output.every, or DYN_FRAMES over the run */
  PetscReal         *hist, *snap_time;                                           /* rank 0 keeps them; every rank counts */
  PetscInt          *snap_idx, next_frame;                                       /* each frame's NNNN (particles_NNNN), and the next one's */
  PetscInt           checkpoints, restart_step;                                  /* checkpoints written; the step -restart continued from (0: none) */
  PetscInt           stop_after;                                                 /* -peri_stop_after_step: stop after this step as a SIGINT would (0: never) */
  PetscBool          resumed;                                                    /* -restart: the first monitor call is the checkpoint's step, recorded already */
  Vec                minv, uprev, tmp;                                           /* 1/m per DOF (0 on held DOFs), the last step's u, work */
  Mat                J;                                                          /* implicit: K + shift M with the held rows and columns eliminated */
  Mat                Kh, Pa;                                                     /* implicit, matrix-free K: K's view with the held rows and columns eliminated (J's part); the assembled preconditioning matrix (short range + shift M) for a PC that needs entries, or NULL */
  Vec                jshift, jwork;                                              /* implicit, matrix-free K: shift M on the free DOFs, 0 on the held ones; J's own work vector */
  const PeriContact *contact;                                                    /* the system's, for the impactors' history */
  IS                 isq, isp;                                                   /* explicit: positions and velocities in the state [q; p] */
  PetscBool          kdk;                                                        /* explicit, kick-drift-kick: the force at q_(n+1) serves the next step and the balance (CachedForce) */
  PetscBool          fvalid;                                                     /* fq, fkq and ff hold a force evaluation that the bonds since have not changed */
  Vec                fq, fkq, ff;                                                /* where it was evaluated, K q there, and the whole internal force */
  TS                 ts;
} Dynamic;

static inline Dynamic *DYN(PeriAnalysis an)
{
  return (Dynamic *)an->data;
}

/* Velocity Verlet as kick-drift-kick (LAMMPS's fix nve): in TSBASICSYMPLECTIC's terms (p += c h
 * a(q), then q += d h p) c = {1/2, 1/2}, d = {1, 0}, so each step evaluates the force at q_n and
 * q_(n+1), the latter again at the next step's start, and CachedForce makes that one product.
 * PETSc's own type 2 (velverlet) is drift-kick-drift, its force at q_(n+1/2), which the balance at
 * q_(n+1) cannot reuse. Registered once per PETSc session (PetscFinalize frees the list). */
static PetscBool kdk_registered;

static PetscErrorCode ForgetKDK(void)
{
  kdk_registered = PETSC_FALSE;
  return PETSC_SUCCESS;
}

static PetscErrorCode RegisterKDK(void)
{
  PetscReal c[2] = {0.5, 0.5}, d[2] = {1, 0};

  PetscFunctionBeginUser;
  if (kdk_registered) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(TSBasicSymplecticRegister(DYN_KDK, 2, 2, c, d));
  PetscCall(PetscRegisterFinalize(ForgetKDK));
  kdk_registered = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static const PeriKey dyn_keys[] = {
    {"integrator", PERI_KEY_CHOICE, "explicit", NULL, NULL, dyn_integrators, "explicit: velocity Verlet on the lumped mass (TSBASICSYMPLECTIC), dt held below 2/omega_max; implicit: generalized-alpha (TSALPHA2), a linear solve per step"},
    {"t_end", PERI_KEY_REAL, "required", "(0, inf)", "[time]", NULL, "the end time"},
    {"dt", PERI_KEY_REAL, "0.8 of the explicit limit (explicit); required (implicit)", "(0, inf)", "[time]", NULL, "the time step (-ts_dt overrides it); an explicit dt above the stability limit is an input error"},
    {"energy_tolerance", PERI_KEY_REAL, "0.01", "(0, inf)", NULL, NULL, "the largest drift of the energy balance (kinetic + strain + dissipated - work of the loads) over the run, relative to the largest energy: above it the run fails"},
    {"energy_every", PERI_KEY_INT, "1", "[1, inf)", NULL, NULL, "the energies, the balance check and a history.csv row every k steps and at the last (the loads' work is summed every step): the explicit step's own force evaluation gives the strain energy, so k above 1 saves a product with K per step only with impactors or bc velocities (drift-kick-drift) and on the implicit integrator"},
    {"rho_infinity", PERI_KEY_REAL, "1", "[0, 1]", NULL, NULL, "implicit: the spectral radius at infinite frequency (1: no numerical damping, Newmark's average acceleration)"},
    {"pulse", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "an initial displacement u = amplitude exp(-((x - center)/width)^2) along axis (Ganzenmueller sec. 3.1.2)"},
    {"amplitude", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "the loads' amplitude in time (default: a step, constant from t = 0)"},
    {"velocity", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "an initial velocity of the particles of a region (a projectile, an impactor)"},
    {"displacement", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "an initial displacement of the particles of a region, at rest, added to the pulse and analysis.initial"},
    {"fronts", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "the wave front and the damage front along an axis, in history.csv and (fitted speeds) summary.json"},
    {"initial", PERI_KEY_MAP, NULL, NULL, NULL, NULL, "an initial displacement read from a particles file perilin wrote of the same body (a modal run's mode_NN.vtu, an earlier state), added to the pulse"},
    {NULL},
};
static const PeriKey dyn_initial_keys[] = {
    {"file", PERI_KEY_STRING, "required", NULL, NULL, NULL, "the .vtu or .pvtu, relative to the scene file; particles are matched by position"},
    {"array", PERI_KEY_STRING, "displacement", NULL, NULL, NULL, "the vector array of the translations; the other DOFs from ARRAY_<component> (plain <component> for displacement: theta)"},
    {"scale", PERI_KEY_REAL, "1", NULL, NULL, NULL, "a factor on the field (a mode shape is written with max |u| = 1)"},
    {NULL},
};
static const PeriKey dyn_pulse_keys[] = {
    {"amplitude", PERI_KEY_REAL, "required", NULL, "[length]", NULL, "the pulse's peak displacement"},
    {"center", PERI_KEY_REAL, "required", NULL, "[length]", NULL, "its position along axis"},
    {"width", PERI_KEY_REAL, "required", "(0, inf)", "[length]", NULL, "its width w"},
    {"axis", PERI_KEY_STRING, "x", NULL, NULL, NULL, "the axis along which the pulse lies and displaces: x, y or z"},
    {"direction", PERI_KEY_STRING, NULL, NULL, NULL, NULL, "the displacement's direction x, y or z when not along axis (absent: along axis): across it, a shear wave"},
    {"profile", PERI_KEY_CHOICE, "gaussian", NULL, NULL, dyn_profiles, "gaussian: amplitude exp(-((x - center)/width)^2); cosine: amplitude cos(pi (x - center)/width), a standing wave (with center 0 and width the bar's length, a free bar's lowest longitudinal mode)"},
    {NULL},
};
static const PeriKey dyn_velocity_keys[] = {
    {"region", PERI_KEY_STRING, "required", NULL, NULL, NULL, "the region whose particles move at t = 0"},
    {"value", PERI_KEY_REALS, "required", NULL, "[length/time]", NULL, "their velocity, one number per dimension"},
    {NULL},
};
static const PeriKey dyn_displacement_keys[] = {
    {"region", PERI_KEY_STRING, "required", NULL, NULL, NULL, "the region whose particles start displaced"},
    {"value", PERI_KEY_REALS, "required", NULL, "[length]", NULL, "their displacement, one number per dimension"},
    {NULL},
};
static const PeriKey dyn_fronts_keys[] = {
    {"axis", PERI_KEY_STRING, "x", NULL, NULL, NULL, "the axis along which the fronts run: x, y or z"},
    {"origin", PERI_KEY_REAL, "0", NULL, "[length]", NULL, "where they start along it: a front is the farthest distance from here"},
    {"speed", PERI_KEY_REAL, "required", "(0, inf)", "[length/time]", NULL, "the wave front: particles moving faster than this"},
    {"damage", PERI_KEY_REAL, "0.5", "(0, 1)", NULL, NULL, "the damage front: particles damaged more than this (scenes with failure)"},
    {"direction", PERI_KEY_CHOICE, "both", NULL, NULL, dyn_directions, "both: the distance |x - origin| on either side; positive: only particles at or beyond origin along +axis (a pre-crack's damage behind its tip is not counted); negative: only those before it"},
    {NULL},
};
/* output.every, which the snapshots follow (problem.c reads it with output.*) */
static const PeriKey dyn_output_keys[] = {
    {"every", PERI_KEY_INT, "0", "[0, inf)", NULL, NULL, "with output.vtk, also write particles_NNNN.vtu every k time steps and at the last, indexed by particles.pvd with the time (0: about 25 frames over t_end)"},
    {NULL},
};
static const PeriSchema dyn_schema[] = {
    {"analysis", dyn_keys},
    {"analysis.pulse", dyn_pulse_keys},
    {"analysis.amplitude", PeriAmplitudeKeys},
    {"analysis.velocity", dyn_velocity_keys},
    {"analysis.displacement", dyn_displacement_keys},
    {"analysis.fronts", dyn_fronts_keys},
    {"analysis.initial", dyn_initial_keys},
    {"output", dyn_output_keys},
    {NULL},
};
/* Checks the keys of map (a sub-map of this analysis' section) against those this analysis
 * declares there: an unknown key names the allowed ones. */
static PetscErrorCode CheckOwnSection(PeriScene s, PeriNode map, const char section[])
{
  const char *names[16];
  PetscInt    n = 0;

  PetscFunctionBeginUser;
  for (const PeriSchema *sec = dyn_schema; sec->section; sec++)
    for (const PeriKey *key = sec->keys; !strcmp(sec->section, section) && key->name && n + 1 < (PetscInt)PETSC_STATIC_ARRAY_LENGTH(names); key++) names[n++] = key->name;
  names[n] = NULL;
  PetscCall(PeriSceneCheckKeys(s, map, names));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.fronts. */
static PetscErrorCode ReadFronts(Dynamic *d, PeriScene s, PeriNode a)
{
  PeriNode f;
  char     axis[8] = "x";

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, a, "fronts", PETSC_FALSE, &f));
  if (!f) PetscFunctionReturn(PETSC_SUCCESS);
  d->fronts = PETSC_TRUE;
  PetscCall(CheckOwnSection(s, f, "analysis.fronts"));
  PetscCall(PeriSceneGetString(s, f, "axis", PETSC_FALSE, axis, sizeof(axis), NULL));
  PeriInputCheck(!strcmp(axis, "x") || !strcmp(axis, "y") || !strcmp(axis, "z"), s, f, "axis", "must be x, y or z, got '%s'", axis);
  d->front_axis = axis[0] - 'x';
  PetscCall(PeriSceneGetReal(s, f, "origin", PETSC_FALSE, &d->front_origin, NULL));
  PetscCall(PeriSceneGetReal(s, f, "speed", PETSC_TRUE, &d->front_speed, NULL));
  PetscCall(PeriSceneGetReal(s, f, "damage", PETSC_FALSE, &d->front_damage, NULL));
  PetscCall(PeriSceneGetChoice(s, f, "direction", dyn_directions, &d->front_dir, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.<key>: {region, value} (velocity, displacement), the region found at set-up. */
static PetscErrorCode ReadRegionValue(PeriScene s, PeriNode a, const char key[], PeriNode *node, PetscReal value[3])
{
  char     section[64];
  PetscInt n;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, a, key, PETSC_FALSE, node));
  if (!*node) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscSNPrintf(section, sizeof(section), "analysis.%s", key));
  PetscCall(CheckOwnSection(s, *node, section));
  PetscCall(PeriSceneGetRealArray(s, *node, "value", PETSC_TRUE, 1, 3, value, &n));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.initial: the file must exist now, before any particle does. */
static PetscErrorCode ReadInitial(Dynamic *d, PeriScene s, PeriNode a)
{
  PeriNode  f;
  PetscBool exists;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, a, "initial", PETSC_FALSE, &f));
  if (!f) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(CheckOwnSection(s, f, "analysis.initial"));
  PetscCall(PeriSceneGetPath(s, f, "file", PETSC_TRUE, d->initial_file, sizeof(d->initial_file), NULL));
  PetscCall(PetscTestFile(d->initial_file, 'r', &exists));
  PeriInputCheck(exists, s, f, "file", "cannot read %s", d->initial_file);
  PetscCall(PeriSceneGetString(s, f, "array", PETSC_FALSE, d->initial_array, sizeof(d->initial_array), NULL));
  PetscCall(PeriSceneGetReal(s, f, "scale", PETSC_FALSE, &d->initial_scale, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* loads.<k>.amplitude, before any particle exists (the loads themselves are read at set-up). */
static PetscErrorCode ReadLoadAmplitudes(Dynamic *d, PeriScene s)
{
  PeriNode loads, amp;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "loads", &loads));
  if (!loads || loads->kind != PERI_NODE_SEQ || !loads->n) PetscFunctionReturn(PETSC_SUCCESS);
  d->nloads = loads->n;
  PetscCall(PetscCalloc2(d->nloads, &d->load_amp, d->nloads, &d->own_amp));
  for (PetscInt k = 0; k < d->nloads; k++) {
    if (loads->child[k]->kind != PERI_NODE_MAP) continue; /* the loads' reader says what is wrong */
    PetscCall(PeriSceneGetNode(loads->child[k], "amplitude", &amp));
    if (!amp) continue;
    PetscCall(PeriSceneCheckSection(s, amp, "loads.<k>.amplitude"));
    PetscCall(PeriAmplitudeFromScene(s, amp, &d->load_amp[k]));
    d->own_amp[k] = PETSC_TRUE;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.* before any particle exists. */
static PetscErrorCode SetFromScene_Dynamic(PeriAnalysis an, PeriScene s, PeriNode a)
{
  Dynamic  *d;
  PeriNode  p, amp;
  PetscInt  kind    = 0;
  char      axis[8] = "x";
  PetscBool found;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&d));
  an->data         = d;
  d->damage_broken = -1;
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_TRUE, &a));
  PetscCall(PeriSceneGetChoice(s, a, "integrator", dyn_integrators, &kind, NULL));
  d->implicit = (PetscBool)(kind == 1);
  if (!d->implicit) { /* the explicit step applies K only through its product: no matrix, no copy (the memory estimate) */
    an->needs.operator_only = PETSC_TRUE;
    an->needs.matrix_copies = 0;
  }
  PetscCall(PeriSceneGetReal(s, a, "t_end", PETSC_TRUE, &d->t_end, NULL));
  PetscCall(PeriSceneGetReal(s, a, "dt", (PetscBool)d->implicit, &d->dt, NULL));
  PeriInputCheck(d->dt <= d->t_end, s, a, "dt", "must not exceed t_end = %g, got %g", (double)d->t_end, (double)d->dt);
  PetscCall(PeriSceneGetReal(s, a, "energy_tolerance", PETSC_FALSE, &d->energy_tol, NULL));
  PetscCall(PeriSceneGetInt(s, a, "energy_every", PETSC_FALSE, &d->energy_every, NULL));
  PetscCall(PeriSceneGetReal(s, a, "rho_infinity", PETSC_FALSE, &d->rho_inf, NULL));
  PetscCall(PeriSceneGetMap(s, a, "pulse", PETSC_FALSE, &p));
  if (p) {
    d->pulse = PETSC_TRUE;
    PetscCall(CheckOwnSection(s, p, "analysis.pulse"));
    PetscCall(PeriSceneGetReal(s, p, "amplitude", PETSC_TRUE, &d->pulse_A, NULL));
    PetscCall(PeriSceneGetReal(s, p, "center", PETSC_TRUE, &d->pulse_x0, NULL));
    PetscCall(PeriSceneGetReal(s, p, "width", PETSC_TRUE, &d->pulse_w, NULL));
    PetscCall(PeriSceneGetString(s, p, "axis", PETSC_FALSE, axis, sizeof(axis), NULL));
    PeriInputCheck(!strcmp(axis, "x") || !strcmp(axis, "y") || !strcmp(axis, "z"), s, p, "axis", "must be x, y or z, got '%s'", axis);
    d->pulse_axis = axis[0] - 'x';
    PetscCall(PeriSceneGetString(s, p, "direction", PETSC_FALSE, axis, sizeof(axis), &found));
    PeriInputCheck(!found || !strcmp(axis, "x") || !strcmp(axis, "y") || !strcmp(axis, "z"), s, p, "direction", "must be x, y or z, got '%s'", axis);
    d->pulse_dir = found ? axis[0] - 'x' : d->pulse_axis;
    PetscCall(PeriSceneGetChoice(s, p, "profile", dyn_profiles, &d->profile, NULL));
  }
  PetscCall(ReadRegionValue(s, a, "velocity", &d->vnode, d->velocity));
  PetscCall(ReadRegionValue(s, a, "displacement", &d->unode, d->displacement));
  PetscCall(ReadFronts(d, s, a));
  PetscCall(ReadInitial(d, s, a));
  PetscCall(PeriSceneGetMap(s, a, "amplitude", PETSC_FALSE, &amp));
  if (amp) PetscCall(CheckOwnSection(s, amp, "analysis.amplitude"));
  PetscCall(PeriAmplitudeFromScene(s, amp, &d->amp));
  PetscCall(ReadLoadAmplitudes(d, s));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-peri_stop_after_step", &d->stop_after, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode LoadTerms(PeriAnalysis);

/* What needs the system: a density (the mass service checks it), bc and loads only. */
static PetscErrorCode SetUp_Dynamic(PeriAnalysis an)
{
  PeriScene s = an->sys->scene;
  Dynamic  *d = DYN(an);

  PetscFunctionBeginUser;
  PeriInputCheck(!an->sys->conditions.layers.nfaces, s, s->root, "boundary_layers", "the fictitious layers carry static conditions; a dynamic analysis takes bc only");
  PeriInputCheck(!d->pulse || d->pulse_axis < an->sys->disc.particles.dim, s, s->root, "analysis.pulse.axis", "the body is %" PetscInt_FMT "D", an->sys->disc.particles.dim);
  PeriInputCheck(!d->pulse || PeriModelTranslation(an->sys->model, d->pulse_dir) >= 0, s, s->root, d->pulse_dir == d->pulse_axis ? "analysis.pulse.axis" : "analysis.pulse.direction", "model %s does not translate along this axis", an->sys->model->type);
  PetscCall(PeriMassSetUp(an->sys));
  PeriInputCheck(!d->implicit || !an->sys->contact.nimpactors, s, s->root, "impactors", "impactors move with the explicit integrator (analysis.integrator: explicit)");
  /* what the run takes from the scene, read now: the regions of the initial values, the loads */
  if (d->vnode) PetscCall(PeriRegionFind(s, d->vnode, "region", an->sys->disc.nregions, an->sys->disc.regions, &d->vregion));
  if (d->unode) PetscCall(PeriRegionFind(s, d->unode, "region", an->sys->disc.nregions, an->sys->disc.regions, &d->uregion));
  PetscCall(LoadTerms(an));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* omega_max^2 of M^-1 K from above (Gershgorin: every eigenvalue of M^-1 K lies within
 * max_i sum_j |K_ij| / m_i), and the explicit step's limit 2/omega_max. Collective. */
static PetscErrorCode StabilityBound(PeriAnalysis an)
{
  Dynamic           *d = DYN(an);
  Vec                m, rows;
  const PetscScalar *ma, *ra;
  PetscInt           n;
  PetscReal          worst = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriMassGetDiagonal(an->sys, &m));
  PetscCall(VecDuplicate(m, &rows));
  PetscCall(PeriSystemStiffnessRowSums(an->sys, rows));
  PetscCall(VecGetLocalSize(m, &n));
  PetscCall(VecGetArrayRead(m, &ma));
  PetscCall(VecGetArrayRead(rows, &ra));
  for (PetscInt r = 0; r < n; r++) worst = PetscMax(worst, PetscRealPart(ra[r]) / PetscRealPart(ma[r]));
  PetscCall(VecRestoreArrayRead(rows, &ra));
  PetscCall(VecRestoreArrayRead(m, &ma));
  PetscCall(VecDestroy(&rows));
  PetscCallMPI(MPI_Allreduce(&worst, &d->omega2_max, 1, MPIU_REAL, MPI_MAX, an->comm));
  d->dt_limit = d->omega2_max > 0 ? 2 / PetscSqrtReal(d->omega2_max) : PETSC_MAX_REAL;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The explicit step's default: 0.8 of the limit, shortened so that whole steps end at t_end (the
 * limit itself is checked once the TS has read -ts_dt, SetUpTS). */
static void ChooseStep(Dynamic *d)
{
  if (!d->implicit && d->dt <= 0) d->dt = d->t_end / PetscCeilReal(d->t_end / (0.8 * d->dt_limit));
}

/* Adds value (one number per dimension) to the translations of the particles of region r
 * (analysis.velocity's or analysis.displacement's; nothing when NULL). */
static PetscErrorCode AddRegionValue(PeriAnalysis an, const PeriRegion *r, const PetscReal value[], Vec v)
{
  PeriSystem     sys = an->sys;
  const PetscInt bs = sys->model->dofs, nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart, dim = sys->disc.particles.dim;
  PetscScalar   *a;

  PetscFunctionBeginUser;
  if (!r) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecGetArray(v, &a));
  for (PetscInt i = 0; i < nloc; i++)
    if (PeriRegionContains(r, &sys->disc.particles.x[3 * i]))
      for (PetscInt k = 0; k < dim; k++) {
        const PetscInt c = PeriModelTranslation(sys->model, k);
        if (c >= 0) a[i * bs + c] += value[k];
      }
  PetscCall(VecRestoreArray(v, &a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The initial displacements: analysis.initial's field, the pulse and analysis.displacement added,
 * and the prescribed values on the held DOFs. */
static PetscErrorCode InitialDisplacement(PeriAnalysis an, Vec u)
{
  Dynamic       *d   = DYN(an);
  PeriSystem     sys = an->sys;
  const PetscInt bs = sys->model->dofs, nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart;
  PetscScalar   *a;

  PetscFunctionBeginUser;
  PetscCall(VecSet(u, 0));
  if (d->initial_file[0]) PetscCall(PeriSystemReadDOFs(sys, d->initial_file, d->initial_array, d->initial_scale, u));
  if (d->pulse) {
    const PetscInt c = PeriModelTranslation(sys->model, d->pulse_dir);
    PetscCall(VecGetArray(u, &a));
    for (PetscInt i = 0; i < nloc; i++) {
      const PetscReal x = sys->disc.particles.x[3 * i + d->pulse_axis];
      a[i * bs + c] += d->pulse_A * (d->profile ? PetscCosReal(PETSC_PI * (x - d->pulse_x0) / d->pulse_w) : PetscExpReal(-PetscSqr((x - d->pulse_x0) / d->pulse_w)));
    }
    PetscCall(VecRestoreArray(u, &a));
  }
  PetscCall(AddRegionValue(an, d->uregion, d->displacement, u));
  PetscCall(VecSetValues(u, sys->conditions.nconstrained, sys->conditions.constrained, sys->conditions.constrained_value, INSERT_VALUES));
  PetscCall(VecAssemblyBegin(u));
  PetscCall(VecAssemblyEnd(u));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* 0 on the held DOFs (their velocity, their inverse mass). */
static PetscErrorCode ZeroHeld(PeriAnalysis an, Vec v)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < an->sys->conditions.nconstrained; k++) PetscCall(VecSetValue(v, an->sys->conditions.constrained[k], 0, INSERT_VALUES));
  PetscCall(VecAssemblyBegin(v));
  PetscCall(VecAssemblyEnd(v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The initial velocities: analysis.velocity on its region's particles (translations only), 0
 * elsewhere and on the held DOFs but the moving ones (w a(0)). */
static PetscErrorCode InitialVelocity(PeriAnalysis an, Vec v)
{
  PetscFunctionBeginUser;
  PetscCall(VecSet(v, 0));
  PetscCall(AddRegionValue(an, DYN(an)->vregion, DYN(an)->velocity, v));
  PetscCall(ZeroHeld(an, v));
  if (an->sys->conditions.constrained_velocity) { /* the moving boundaries: held, at their velocity (owned rows) */
    const PeriConditions *C = &an->sys->conditions;
    PetscScalar          *a;
    PetscInt              r0;
    PetscCall(VecGetOwnershipRange(v, &r0, NULL));
    PetscCall(VecGetArray(v, &a));
    for (PetscInt k = 0; k < C->nconstrained; k++) PeriConditionsMotion(C, k, 0, NULL, &a[C->constrained[k] - r0], NULL);
    PetscCall(VecRestoreArray(v, &a));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* 1/m per DOF, 0 on the held DOFs: a = minv (f - K u) leaves them where they are. */
static PetscErrorCode InverseMass(PeriAnalysis an)
{
  Dynamic *d = DYN(an);
  Vec      m;

  PetscFunctionBeginUser;
  PetscCall(PeriMassGetDiagonal(an->sys, &m));
  PetscCall(VecDuplicate(m, &d->minv));
  PetscCall(VecCopy(m, d->minv));
  PetscCall(VecReciprocal(d->minv));
  PetscCall(ZeroHeld(an, d->minv));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Explicit, position split: dq/dt = p (p: the velocities). */
static PetscErrorCode RHSPosition(TS ts, PetscReal t, Vec p, Vec dq, void *ctx)
{
  PetscFunctionBeginUser;
  (void)ts;
  (void)t;
  (void)ctx;
  PetscCall(VecCopy(p, dq));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* y = alpha y + sign f(t), f(t) the sum of the load terms under their amplitudes. */
static PetscErrorCode LoadAt(PeriAnalysis an, PetscReal t, PetscReal sign, PetscReal alpha, Vec y)
{
  Dynamic    *d = DYN(an);
  PetscScalar a[PERI_DYN_MAX_TERMS];

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < d->nterms; k++) a[k] = sign * PeriAmplitudeValue(d->term_amp[k], t);
  PetscCall(VecAXPBY(y, a[0], alpha, d->term_f[0])); /* one pass over y when every load shares one amplitude */
  if (d->nterms > 1) PetscCall(VecMAXPY(y, d->nterms - 1, a + 1, d->term_f + 1));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The work of the moving boundaries (bc.<k>.velocity) in the step whose one force evaluation (at
 * t, half a step in: PETSc's velocity Verlet) left r = f - K q: the supports push the held DOFs
 * with m w a'(t) - r (what accelerates them, less what the body pulls) while they move by
 * w a(t) dt. This rank's share, summed in Work. */
static PetscErrorCode BoundaryWork(PeriAnalysis an, Vec r, PetscReal t)
{
  const PeriConditions *C = &an->sys->conditions;
  const PetscScalar    *a, *m;
  PetscInt              r0;
  Vec                   mass;

  PetscFunctionBeginUser;
  if (!C->constrained_velocity) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriMassGetDiagonal(an->sys, &mass));
  PetscCall(VecGetOwnershipRange(r, &r0, NULL));
  PetscCall(VecGetArrayRead(r, &a));
  PetscCall(VecGetArrayRead(mass, &m));
  for (PetscInt k = 0; k < C->nconstrained; k++) {
    const PetscInt row = C->constrained[k] - r0;
    PetscReal      v, acc;
    PeriConditionsMotion(C, k, t, NULL, &v, &acc);
    DYN(an)->work_bc += (PetscRealPart(m[row]) * acc - PetscRealPart(a[row])) * v * DYN(an)->dt;
  }
  PetscCall(VecRestoreArrayRead(mass, &m));
  PetscCall(VecRestoreArrayRead(r, &a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The moving boundaries' acceleration w a'(t) on their rows of dp (0 there from 1/m = 0): the kick
 * of velocity Verlet then gives them their velocity w a(t), to second order in dt (exactly for a
 * ramp or a step). */
static PetscErrorCode BoundaryAcceleration(PeriAnalysis an, Vec dp, PetscReal t)
{
  const PeriConditions *C = &an->sys->conditions;
  PetscScalar          *a;
  PetscInt              r0;

  PetscFunctionBeginUser;
  if (!C->constrained_velocity) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecGetOwnershipRange(dp, &r0, NULL));
  PetscCall(VecGetArray(dp, &a));
  for (PetscInt k = 0; k < C->nconstrained; k++) PeriConditionsMotion(C, k, t, NULL, NULL, &a[C->constrained[k] - r0]);
  PetscCall(VecRestoreArray(dp, &a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* f = the interactions' force at q (K q and the terms'). Kick-drift-kick evaluates it at q_(n+1)
 * at the end of step n, the energy balance wants K q_(n+1) after the step, and the next step
 * starts with the same force: one product serves the three. A bond that breaks in between clears
 * it (AfterStep), and it is used only for the very q it was evaluated at. f may be NULL. */
static PetscErrorCode CachedForce(PeriAnalysis an, Vec q, Vec f)
{
  Dynamic  *d    = DYN(an);
  PetscBool same = PETSC_FALSE;

  PetscFunctionBeginUser;
  if (!d->kdk) {
    if (f) PetscCall(PeriSystemInternalForce(an->sys, q, f));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  if (!d->fq) {
    PetscBool terms = PETSC_FALSE; /* without nonlinear terms the whole force is K q */
    for (PetscInt k = 0; k < an->sys->stiffness.nterms; k++) terms = (PetscBool)(terms || an->sys->stiffness.terms[k]->add_force);
    PetscCall(VecDuplicate(q, &d->fq));
    PetscCall(VecDuplicate(q, &d->fkq));
    if (terms)
      PetscCall(VecDuplicate(q, &d->ff));
    else
      PetscCall(PetscObjectReference((PetscObject)(d->ff = d->fkq)));
  }
  if (d->fvalid) PetscCall(VecEqual(q, d->fq, &same));
  if (!same) {
    PetscCall(PeriSystemInternalForceParts(an->sys, q, d->fkq, d->ff));
    PetscCall(VecCopy(q, d->fq));
    d->fvalid = PETSC_TRUE;
  }
  if (f) PetscCall(VecCopy(d->ff, f));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Explicit, momentum split: dp/dt = M^-1 (a(t) f - K q), 0 on the held DOFs. */
static PetscErrorCode RHSMomentum(TS ts, PetscReal t, Vec q, Vec dp, void *ctx)
{
  PeriAnalysis an = (PeriAnalysis)ctx;

  PetscFunctionBeginUser;
  (void)ts;
  PetscCall(PeriContactSetTime(an->sys, t, PETSC_TRUE)); /* the step's one force: the impactors' kick */
  PetscCall(CachedForce(an, q, dp));
  PetscCall(LoadAt(an, t, 1, -1, dp));
  PetscCall(BoundaryWork(an, dp, t));
  PetscCall(VecPointwiseMult(dp, dp, DYN(an)->minv));
  PetscCall(BoundaryAcceleration(an, dp, t));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Explicit, the whole right-hand side [p; M^-1 (f - K q)], for any explicit TS (-ts_type rk). */
static PetscErrorCode RHSWhole(TS ts, PetscReal t, Vec U, Vec F, void *ctx)
{
  Dynamic *d = DYN((PeriAnalysis)ctx);
  Vec      q, p, fq, fp;

  PetscFunctionBeginUser;
  PetscCall(VecGetSubVector(U, d->isq, &q));
  PetscCall(VecGetSubVector(U, d->isp, &p));
  PetscCall(VecGetSubVector(F, d->isq, &fq));
  PetscCall(VecGetSubVector(F, d->isp, &fp));
  PetscCall(RHSPosition(ts, t, p, fq, ctx));
  PetscCall(RHSMomentum(ts, t, q, fp, ctx));
  PetscCall(VecRestoreSubVector(F, d->isp, &fp));
  PetscCall(VecRestoreSubVector(F, d->isq, &fq));
  PetscCall(VecRestoreSubVector(U, d->isp, &p));
  PetscCall(VecRestoreSubVector(U, d->isq, &q));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The held DOFs' reactions from the body, K q - f(t), on this rank into R, and this rank's
 * kinetic energy of the held DOFs, ke. One product with K. */
static PetscErrorCode Reactions(PeriAnalysis an, Vec q, Vec p, PetscReal t, PetscReal R[], PetscReal *ke)
{
  const PeriConditions *C = &an->sys->conditions;
  const PetscScalar    *a, *m, *v;
  PetscInt              r0;
  Vec                   mass;

  PetscFunctionBeginUser;
  PetscCall(PeriMassGetDiagonal(an->sys, &mass));
  PetscCall(PeriSystemInternalForce(an->sys, q, DYN(an)->tmp));
  PetscCall(LoadAt(an, t, -1, 1, DYN(an)->tmp));
  PetscCall(VecGetOwnershipRange(q, &r0, NULL));
  PetscCall(VecGetArrayRead(DYN(an)->tmp, &a));
  PetscCall(VecGetArrayRead(mass, &m));
  PetscCall(VecGetArrayRead(p, &v));
  *ke = 0;
  for (PetscInt k = 0; k < C->nconstrained; k++) {
    const PetscInt row = C->constrained[k] - r0;
    R[k]               = PetscRealPart(a[row]);
    *ke += 0.5 * PetscRealPart(m[row] * v[row] * v[row]);
  }
  PetscCall(VecRestoreArrayRead(p, &v));
  PetscCall(VecRestoreArrayRead(mass, &m));
  PetscCall(VecRestoreArrayRead(DYN(an)->tmp, &a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit: the moving boundaries' work from t_prev to t (this rank's share, into work_bc): what
 * accelerated the held DOFs, the change of their kinetic energy (with Newmark's trapezoidal rule,
 * m (a_n + a_n+1)/2 . du is exactly that), plus the trapezoid of the body's pull on them,
 * (R_n + R_n+1)/2 . du, du = w (I(t) - I(t_prev)). With average acceleration the balance then
 * closes to round-off on a linear body. The first call (step 0, or the step -restart resumed)
 * only records R and the kinetic energy. Collective. */
static PetscErrorCode ImplicitBoundaryWork(PeriAnalysis an, Vec q, Vec p, PetscReal t)
{
  Dynamic              *d = DYN(an);
  const PeriConditions *C = &an->sys->conditions;
  PetscReal            *R, ke = 0;

  PetscFunctionBeginUser;
  if (!d->implicit || !C->moving) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc1(C->nconstrained + 1, &R));
  PetscCall(Reactions(an, q, p, t, R, &ke));
  if (d->reaction) {
    d->work_bc += ke - d->ke_held;
    for (PetscInt k = 0; k < C->nconstrained; k++) {
      PetscReal u, u0;
      PeriConditionsMotion(C, k, t, &u, NULL, NULL);
      PeriConditionsMotion(C, k, d->t_prev, &u0, NULL, NULL);
      d->work_bc += 0.5 * (R[k] + d->reaction[k]) * (u - u0);
    }
  }
  PetscCall(PetscFree(d->reaction));
  d->reaction = R;
  d->ke_held  = ke;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit: U - g on the held DOFs' rows of F, g = value + w I(t) (bc.<k>.velocity). The
 * generalized-alpha residual comes at t_n + alpha_f dt with U interpolated linearly over the step,
 * so g is too: then U_n+1 = g(t_n+1) exactly, and the scheme's velocities follow the prescribed
 * motion (exactly for a ramp whose rise is a whole number of steps) instead of oscillating about
 * it, as U_af = g(t_af) would make them for a motion not linear in time. */
static PetscErrorCode HeldResidual(PeriAnalysis an, TS ts, PetscReal t, Vec U, Vec F)
{
  const PeriConditions *C = &an->sys->conditions;
  const PetscScalar    *u;
  PetscScalar          *f;
  PetscReal             tn, h, th;
  PetscInt              r0;

  PetscFunctionBeginUser;
  PetscCall(TSGetTime(ts, &tn)); /* the step's start during the step's solve */
  PetscCall(TSGetTimeStep(ts, &h));
  th = h > 0 ? (t - tn) / h : 0;
  PetscCall(VecGetOwnershipRange(F, &r0, NULL));
  PetscCall(VecGetArrayRead(U, &u));
  PetscCall(VecGetArray(F, &f));
  for (PetscInt k = 0; k < C->nconstrained; k++) {
    PetscReal g0, g1;
    PeriConditionsMotion(C, k, tn, &g0, NULL, NULL);
    PeriConditionsMotion(C, k, tn + h, &g1, NULL, NULL);
    f[C->constrained[k] - r0] = u[C->constrained[k] - r0] - (C->constrained_value[k] + g0 + th * (g1 - g0));
  }
  PetscCall(VecRestoreArray(F, &f));
  PetscCall(VecRestoreArrayRead(U, &u));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit: F = M A + K U - a(t) f, and U - g(t) on the held DOFs (HeldResidual). */
static PetscErrorCode I2Function(TS ts, PetscReal t, Vec U, Vec V, Vec A, Vec F, void *ctx)
{
  PeriAnalysis an  = (PeriAnalysis)ctx;
  PeriSystem   sys = an->sys;
  Vec          m;

  PetscFunctionBeginUser;
  (void)V;
  PetscCall(PeriMassGetDiagonal(sys, &m));
  PetscCall(PeriContactSetTime(sys, t, PETSC_FALSE));
  PetscCall(PeriSystemInternalForce(sys, U, F));
  PetscCall(VecPointwiseMult(DYN(an)->tmp, m, A));
  PetscCall(VecAXPY(F, 1, DYN(an)->tmp));
  PetscCall(LoadAt(an, t, -1, 1, F));
  PetscCall(HeldResidual(an, ts, t, U, F));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit, matrix-free K: y = K_h x + (shift M) x, K_h the operator with the held DOFs' rows and
 * columns replaced by the identity, shift M zero on them. */
static PetscErrorCode JacobianMult(Mat J, Vec x, Vec y)
{
  PeriAnalysis an;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(J, &an));
  PetscCall(MatMult(DYN(an)->Kh, x, y));
  PetscCall(VecPointwiseMult(DYN(an)->jwork, DYN(an)->jshift, x));
  PetscCall(VecAXPY(y, 1, DYN(an)->jwork));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode JacobianDiagonal(Mat J, Vec diag)
{
  PeriAnalysis an;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(J, &an));
  PetscCall(MatGetDiagonal(DYN(an)->Kh, diag));
  PetscCall(VecAXPY(diag, 1, DYN(an)->jshift));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit, matrix-free K: J as a shell over the operator's bond data (no copy of K). */
static PetscErrorCode CreateJacobianShell(PeriAnalysis an)
{
  Dynamic              *d = DYN(an);
  const PeriConditions *C = &an->sys->conditions;
  PetscInt              n;

  PetscFunctionBeginUser;
  PetscCall(PeriOperatorCreateMat(an->sys, &d->Kh));
  PetscCall(MatZeroRowsColumns(d->Kh, C->nconstrained, C->constrained, 1.0, NULL, NULL));
  PetscCall(VecDuplicate(an->sys->fields.u, &d->jshift));
  PetscCall(VecSet(d->jshift, 0));
  PetscCall(VecDuplicate(d->jshift, &d->jwork));
  PetscCall(VecGetLocalSize(d->jshift, &n));
  PetscCall(MatCreateShell(an->comm, n, n, PETSC_DETERMINE, PETSC_DETERMINE, an, &d->J));
  PetscCall(MatSetBlockSize(d->J, an->sys->model->dofs));
  PetscCall(MatShellSetOperation(d->J, MATOP_MULT, (void (*)(void))JacobianMult));
  PetscCall(MatShellSetOperation(d->J, MATOP_MULT_TRANSPOSE, (void (*)(void))JacobianMult));
  PetscCall(MatShellSetOperation(d->J, MATOP_GET_DIAGONAL, (void (*)(void))JacobianDiagonal));
  PetscCall(MatSetOption(d->J, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(d->J, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode I2Jacobian(TS, PetscReal, Vec, Vec, Vec, PetscReal, PetscReal, Mat, Mat, void *);

/* Implicit, matrix-free K: a PC that reads entries (GAMG, by default beyond 20 explicit limits, or
 * any -pc_type but jacobi and none) gets the assembled short range plus shift M, as the static
 * solve's GAMG gets the short range alone. After the PC's type is known. Collective. */
static PetscErrorCode AssembledPreconditioningMatrix(PeriAnalysis an)
{
  Dynamic  *d = DYN(an);
  SNES      snes;
  KSP       ksp;
  PC        pc;
  PetscBool shell;

  PetscFunctionBeginUser;
  if (!d->Kh) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(TSGetSNES(d->ts, &snes));
  PetscCall(SNESGetKSP(snes, &ksp));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &shell, PCJACOBI, PCNONE, ""));
  if (shell) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriOperatorPreconditioner(an->sys));
  PetscCall(MatDuplicate(an->sys->stiffness.Kpc, MAT_COPY_VALUES, &d->Pa));
  PetscCall(PeriSetNearNullSpace(an->sys, d->Pa, NULL));
  PetscCall(TSSetI2Jacobian(d->ts, d->J, d->Pa, I2Jacobian, an));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit, matrix-free K: the step's shift into J's diagonal part and the assembled P (if any). */
static PetscErrorCode ShiftMatrixFree(PeriAnalysis an, Vec m, PetscReal shiftA)
{
  Dynamic              *d = DYN(an);
  const PeriConditions *C = &an->sys->conditions;

  PetscFunctionBeginUser;
  PetscCall(VecCopy(m, d->jshift));
  PetscCall(VecScale(d->jshift, shiftA));
  PetscCall(ZeroHeld(an, d->jshift));
  /* K or the shift changed: the assembly marks J so, and SNES's lag decides whether the PC follows */
  PetscCall(MatAssemblyBegin(d->J, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(d->J, MAT_FINAL_ASSEMBLY));
  if (!d->Pa) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(MatCopy(an->sys->stiffness.Kpc, d->Pa, SAME_NONZERO_PATTERN));
  PetscCall(MatDiagonalSet(d->Pa, d->jshift, ADD_VALUES));
  PetscCall(MatZeroRowsColumns(d->Pa, C->nconstrained, C->constrained, 1.0, NULL, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit: J = K + shiftA M, the held rows and columns replaced by the identity. */
static PetscErrorCode I2Jacobian(TS ts, PetscReal t, Vec U, Vec V, Vec A, PetscReal shiftV, PetscReal shiftA, Mat J, Mat P, void *ctx)
{
  PeriAnalysis an  = (PeriAnalysis)ctx;
  PeriSystem   sys = an->sys;
  Vec          m;
  Mat          K;

  PetscFunctionBeginUser;
  (void)ts, (void)t, (void)U, (void)V, (void)A, (void)shiftV;
  PetscCall(PeriMassGetDiagonal(sys, &m));
  if (DYN(an)->Kh) {
    PetscCall(ShiftMatrixFree(an, m, shiftA));
    if (J != DYN(an)->J) { /* J applied by differences (contact): it takes the new state from its assembly */
      PetscCall(MatAssemblyBegin(J, MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(J, MAT_FINAL_ASSEMBLY));
    }
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PeriSystemGetJacobian(sys, &K));
  PetscCall(MatCopy(K, P, SAME_NONZERO_PATTERN));
  PetscCall(VecCopy(m, DYN(an)->tmp));
  PetscCall(VecScale(DYN(an)->tmp, shiftA));
  PetscCall(MatDiagonalSet(P, DYN(an)->tmp, ADD_VALUES));
  PetscCall(MatZeroRowsColumns(P, sys->conditions.nconstrained, sys->conditions.constrained, 1.0, NULL, NULL));
  if (J != P) { /* J matrix-free (-snes_mf_operator, or contact: JacobianFree): it takes the new state from its assembly */
    PetscCall(MatAssemblyBegin(J, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(J, MAT_FINAL_ASSEMBLY));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The displacements and velocities of the state (views: restore with RestoreState). */
static PetscErrorCode GetState(PeriAnalysis an, Vec U, Vec *q, Vec *p)
{
  Dynamic *d = DYN(an);

  PetscFunctionBeginUser;
  if (d->implicit) {
    *q = U;
    PetscCall(TS2GetSolution(d->ts, NULL, p));
  } else {
    PetscCall(VecGetSubVector(U, d->isq, q));
    PetscCall(VecGetSubVector(U, d->isp, p));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode RestoreState(PeriAnalysis an, Vec U, Vec *q, Vec *p)
{
  Dynamic *d = DYN(an);

  PetscFunctionBeginUser;
  if (!d->implicit) {
    PetscCall(VecRestoreSubVector(U, d->isp, p));
    PetscCall(VecRestoreSubVector(U, d->isq, q));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* 1/2 q^T K q with the present bonds, and the energy of contact (kick-drift-kick: from the
 * step's force evaluation, CachedForce). */
static PetscErrorCode StrainEnergy(PeriAnalysis an, Vec q, PetscReal *E)
{
  PetscFunctionBeginUser;
  if (DYN(an)->kdk) {
    PetscCall(CachedForce(an, q, NULL));
    PetscCall(PeriSystemStrainEnergyFromProduct(an->sys, q, DYN(an)->fkq, E));
  } else
    PetscCall(PeriSystemStrainEnergy(an->sys, q, DYN(an)->tmp, E));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit: the step's final residual over its first (the SNES history of this step). */
static PetscErrorCode WorstResidual(Dynamic *d, SNES snes)
{
  PetscReal *a;
  PetscInt   n;

  PetscFunctionBeginUser;
  PetscCall(SNESGetConvergenceHistory(snes, &a, NULL, &n));
  if (n > 1 && a[0] > 0) d->worst = PetscMax(d->worst, a[n - 1] / a[0]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* After each step: the bonds past the criteria break; the energy they held is dissipated. */
/* After a step to t at the displacements q: the impactors moved, the contact reach checked, the
 * bonds past their criteria broken (their number in nb) and their energy counted. */
static PetscErrorCode AfterStep(PeriAnalysis an, Vec q, PetscReal t, PetscInt *nb)
{
  Dynamic  *d = DYN(an);
  PetscReal before, after = 0, released;
  /* the broken bonds' energy from their own blocks; a model with states (lps) also releases the
     share of each state the bond carried, which is measured as K's energy before and after */
  const PetscBool bybond = (PetscBool)(an->sys->model->ops.bond_stiffness && !an->sys->model->ops.bond_state);

  PetscFunctionBeginUser;
  PetscCall(PeriImpactorsAdvance(an->sys, t));
  PetscCall(PeriContactCheckReach(an->sys, q));
  if (!an->sys->bond_state.failure.active) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecCopy(q, an->sys->fields.u));
  if (bybond) {
    PetscCall(PeriBondsBreak(an->sys, an->sys->fields.u, PETSC_TRUE, 1, nb, &released));
    if (*nb) d->fvalid = PETSC_FALSE; /* K changed: the kept force is not K's */
  } else {
    /* K changed in more than the broken bonds' blocks: the energy it held before and after */
    PetscCall(StrainEnergy(an, q, &before));
    PetscCall(PeriBondsBreak(an->sys, an->sys->fields.u, PETSC_TRUE, 1, nb, NULL));
    if (*nb) d->fvalid = PETSC_FALSE;
    if (*nb) PetscCall(StrainEnergy(an, q, &after));
    released = *nb ? before - after : 0;
  }
  d->dissipated += released;
  d->broken += *nb;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PostStep(TS ts)
{
  PeriAnalysis   an;
  Dynamic       *d;
  Vec            U, q, p;
  PetscInt       nb = 0, step;
  PetscReal      t;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(TSGetApplicationContext(ts, &an));
  d = DYN(an);
  PetscCall(TSGetSolution(ts, &U));
  PetscCall(TSGetTime(ts, &t));
  PetscCall(GetState(an, U, &q, &p));
  ierr = AfterStep(an, q, t, &nb); /* a refusal (the contact reach) gives the state back first */
  PetscCall(RestoreState(an, U, &q, &p));
  PetscCall(ierr);
  /* a signal ends the run after this step (TSStep resets the reason, so a monitor could not) */
  PetscCall(TSGetStepNumber(ts, &step));
  if (step == d->stop_after) PeriSignalSimulate(SIGINT);
  PetscCall(PeriSignalReceived(an->comm, &an->sys->run.interrupted));
  if (an->sys->run.interrupted) PetscCall(TSSetConvergedReason(ts, TS_CONVERGED_USER));
  if (d->implicit) {
    SNES snes;
    /* K changed: the next step sets up a new preconditioner, later steps keep it */
    PetscCall(TSGetSNES(ts, &snes));
    if (nb) PetscCall(SNESSetLagPreconditioner(snes, -2));
    PetscCall(WorstResidual(d, snes));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles_NNNN.vtu of the present state (q, p), through the problem's snapshot callback. */
static PetscErrorCode WriteSnapshot(PeriAnalysis an, Vec q, Vec p, PetscReal t)
{
  Dynamic *d = DYN(an);
  char     name[64];

  PetscFunctionBeginUser;
  if (!an->vtk || !an->snapshot) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecCopy(q, an->sys->fields.u));
  PetscCall(PeriSystemEvaluateEnergy(an->sys));
  PetscCall(PeriSystemKeepVelocity(an->sys, p));
  if (an->sys->bond_state.failure.active) PetscCall(PeriDamage(an->sys, &an->sys->bond_state.damage));
  PetscCall(PetscRealloc(sizeof(PetscReal) * (d->nsnap + 1), &d->snap_time));
  PetscCall(PetscRealloc(sizeof(PetscInt) * (d->nsnap + 1), &d->snap_idx));
  d->snap_time[d->nsnap]  = t;
  d->snap_idx[d->nsnap++] = d->next_frame;
  PetscCall(PetscSNPrintf(name, sizeof(name), "particles_%04" PetscInt_FMT, d->next_frame++));
  PetscCall(an->snapshot(an->snapshotctx, name));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Appends a row of history.csv. */
static PetscErrorCode RecordHistory(Dynamic *d, PetscReal t, PetscReal balance)
{
  const PetscReal row[DYN_HISTORY_COLUMNS] = {t, d->kinetic, d->strain, d->dissipated, d->work, balance, (PetscReal)d->broken, d->pulse_pos, d->probe_u, d->wave_front, d->damage_front};
  PetscReal      *r;

  PetscFunctionBeginUser;
  if (d->nhist == d->cap) {
    d->cap = PetscMax(256, 2 * d->cap);
    PetscCall(PetscRealloc(sizeof(PetscReal) * DYN_ROW(d) * d->cap, &d->hist));
  }
  r = &d->hist[DYN_ROW(d) * d->nhist++];
  PetscCall(PetscArraycpy(r, row, DYN_HISTORY_COLUMNS));
  for (PetscInt k = 0; k < d->nimpactors; k++) {
    const PeriImpactor *imp = &d->contact->impactors[k];
    PetscCall(PetscArraycpy(&r[DYN_HISTORY_COLUMNS + DYN_IMPACTOR_COLUMNS * k], imp->x, 3));
    PetscCall(PetscArraycpy(&r[DYN_HISTORY_COLUMNS + DYN_IMPACTOR_COLUMNS * k + 3], imp->v, 3));
    PetscCall(PetscArraycpy(&r[DYN_HISTORY_COLUMNS + DYN_IMPACTOR_COLUMNS * k + 6], imp->force, 3));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The kinetic and strain energy of the state. */
static PetscErrorCode Energies(PeriAnalysis an, Vec q, Vec p)
{
  Dynamic    *d = DYN(an);
  Vec         m;
  PetscScalar e;

  PetscFunctionBeginUser;
  PetscCall(PeriMassGetDiagonal(an->sys, &m));
  PetscCall(VecPointwiseMult(d->tmp, p, p));
  PetscCall(VecDot(d->tmp, m, &e));
  d->kinetic = 0.5 * PetscRealPart(e) + PeriImpactorsKinetic(an->sys);
  PetscCall(StrainEnergy(an, q, &d->strain));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Kick-drift-kick: f_k . p for each load term, kept for the next step's work. */
static PetscErrorCode LoadPower(PeriAnalysis an, Vec p)
{
  Dynamic    *d = DYN(an);
  PetscScalar fv[PERI_DYN_MAX_TERMS];

  PetscFunctionBeginUser;
  if (!d->kdk) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecMDot(p, d->nterms, d->term_f, fv));
  for (PetscInt k = 0; k < d->nterms; k++) d->term_fv[k] = PetscRealPart(fv[k]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The loads' work since the last step: every step, dot products. Drift-kick-drift: trapezoidal in
 * time over the step's displacement, exact for a free body under loads linear in t. Kick-drift-
 * kick: each half kick's force times the mean velocity over it, (1/4)(a_n + a_(n+1)) f.(q_(n+1) -
 * q_n) + (h/4)(a_n f.p_n + a_(n+1) f.p_(n+1)), the kinetic energy the loads give a free body
 * under any amplitude, exactly. */
static PetscErrorCode Work(PeriAnalysis an, Vec q, Vec p, PetscReal t)
{
  Dynamic        *d = DYN(an);
  PetscScalar     w[PERI_DYN_MAX_TERMS];
  PetscReal       fv_prev[PERI_DYN_MAX_TERMS];
  const PetscReal h = t - d->t_prev;

  PetscFunctionBeginUser;
  PetscCall(ImplicitBoundaryWork(an, q, p, t));
  PetscCall(VecWAXPY(d->tmp, -1, d->uprev, q));
  PetscCall(VecMDot(d->tmp, d->nterms, d->term_f, w));
  PetscCall(PetscArraycpy(fv_prev, d->term_fv, d->nterms));
  PetscCall(LoadPower(an, p));
  for (PetscInt k = 0; k < d->nterms; k++) {
    const PetscReal a = PeriAmplitudeValue(d->term_amp[k], t);
    if (d->kdk)
      d->work += 0.25 * (a + d->term_prev[k]) * PetscRealPart(w[k]) + 0.25 * h * (d->term_prev[k] * fv_prev[k] + a * d->term_fv[k]);
    else
      d->work += 0.5 * (a + d->term_prev[k]) * PetscRealPart(w[k]);
    d->term_prev[k] = a;
  }
  PetscCall(VecCopy(q, d->uprev));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &d->work_bc, 1, MPIU_REAL, MPI_SUM, an->comm));
  d->work += d->work_bc; /* the moving boundaries' */
  d->work_bc = 0;
  d->t_prev  = t;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Where the pulse is: the centroid along its axis of u^2 over the particles displaced by more than
 * half the largest displacement (a symmetric pulse's centre, to a fraction of the spacing). */
static PetscErrorCode PulsePosition(PeriAnalysis an, Vec q)
{
  Dynamic           *d   = DYN(an);
  PeriSystem         sys = an->sys;
  const PetscInt     bs = sys->model->dofs, c = PeriModelTranslation(sys->model, d->pulse_dir), nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart;
  const PetscScalar *u;
  PetscReal          umax = 0, sum[2] = {0, 0};

  PetscFunctionBeginUser;
  if (!d->pulse) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecGetArrayRead(q, &u));
  for (PetscInt i = 0; i < nloc; i++) umax = PetscMax(umax, PetscAbsScalar(u[i * bs + c]));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &umax, 1, MPIU_REAL, MPI_MAX, an->comm));
  for (PetscInt i = 0; i < nloc; i++) {
    const PetscReal v = PetscAbsScalar(u[i * bs + c]);
    if (v <= 0.5 * umax) continue;
    sum[0] += v * v * sys->disc.particles.x[3 * i + d->pulse_axis];
    sum[1] += v * v;
  }
  PetscCall(VecRestoreArrayRead(q, &u));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, sum, 2, MPIU_REAL, MPI_SUM, an->comm));
  d->pulse_pos = sum[1] > 0 ? sum[0] / sum[1] : 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The wave front (the farthest particle from the origin along the axis moving faster than the
 * threshold) and the damage front (damaged more than its threshold), as distances. Collective. */
static PetscErrorCode Fronts(PeriAnalysis an, Vec p)
{
  Dynamic           *d   = DYN(an);
  PeriSystem         sys = an->sys;
  const PetscInt     bs = sys->model->dofs, nloc = sys->disc.bonds.rend - sys->disc.bonds.rstart;
  const PetscScalar *v;
  PetscReal          far[2] = {0, 0};

  PetscFunctionBeginUser;
  if (!d->fronts) PetscFunctionReturn(PETSC_SUCCESS);
  /* the damage changes only where bonds broke (softening ones change it by any amount): a bond
     loop every step costs as much as the step's product on the EOI */
  if (sys->bond_state.failure.active && (sys->disc.bonds.intact || !sys->bond_state.damage || d->broken != d->damage_broken)) {
    PetscCall(PeriDamage(sys, &sys->bond_state.damage));
    d->damage_broken = d->broken;
  }
  PetscCall(VecGetArrayRead(p, &v));
  for (PetscInt i = 0; i < nloc; i++) {
    const PetscReal dx     = sys->disc.particles.x[3 * i + d->front_axis] - d->front_origin;
    const PetscReal x      = PetscAbsReal(dx);
    PetscReal       speed2 = 0;
    if ((d->front_dir == 1 && dx < 0) || (d->front_dir == 2 && dx > 0)) continue;
    for (PetscInt c = 0; c < bs; c++)
      if (sys->model->axis[c] >= 0) speed2 += PetscSqr(PetscRealPart(v[i * bs + c]));
    if (speed2 > PetscSqr(d->front_speed)) far[0] = PetscMax(far[0], x);
    if (sys->bond_state.damage && sys->bond_state.damage[(PERI_NCAUSES + 1) * i] > d->front_damage) far[1] = PetscMax(far[1], x);
  }
  PetscCall(VecRestoreArrayRead(p, &v));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, far, 2, MPIU_REAL, MPI_MAX, an->comm));
  d->wave_front   = far[0];
  d->damage_front = far[1];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The first probe's displacement along the pulse axis (x without a pulse), from its owner. */
static PetscErrorCode ProbeDisplacement(PeriAnalysis an, Vec q)
{
  Dynamic         *d  = DYN(an);
  const PeriProbe *pr = an->sys->fields.nprobes ? &an->sys->fields.probes[0] : NULL;
  PetscReal        v  = 0;

  PetscFunctionBeginUser;
  if (!pr) PetscFunctionReturn(PETSC_SUCCESS);
  if (pr->rank == an->rank) {
    const PetscScalar *u;
    const PetscInt     c = PeriModelTranslation(an->sys->model, d->pulse_axis);
    PetscCall(VecGetArrayRead(q, &u));
    if (c >= 0) v = PetscRealPart(u[pr->particle * an->sys->model->dofs + c]);
    PetscCall(VecRestoreArrayRead(q, &u));
  }
  PetscCallMPI(MPI_Allreduce(&v, &d->probe_u, 1, MPIU_REAL, MPI_SUM, an->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Refuses a checkpoint whose counts or step do not fit this run, before they size anything. */
static PetscErrorCode CheckState(PeriAnalysis an, PetscViewer v, const PetscInt n[], const PetscReal r[])
{
  Dynamic *d = DYN(an);

  PetscFunctionBeginUser;
  PetscCheck(n[4] == DYN_ROW(d) && n[5] == d->nterms && n[6] == d->nimpactors, an->comm, PETSC_ERR_USER_INPUT, "-restart: the checkpoint's history, loads or impactors do not fit this scene: restart with the scene of the run that wrote it");
  PetscCheck(r[9] == d->dt, an->comm, PETSC_ERR_USER_INPUT, "-restart: the checkpoint's run stepped by dt = %g and this one by %g: restart with the options of the run that wrote it", (double)r[9], (double)d->dt);
  PetscCheck(n[0] >= 0 && n[1] >= 0 && n[3] >= 0 && r[0] >= 0 && r[0] <= d->t_end && PetscIsNormalReal(r[4] + r[1] + 1), an->comm, PETSC_ERR_USER_INPUT, "-restart: the checkpoint is damaged (its step, time %g or energies out of range): restart from an undamaged checkpoint, or run the scene from the start", (double)r[0]);
  PetscCall(PeriAnalysisCheckpointFits(an, v, n[2], DYN_ROW(d) * sizeof(PetscReal)));
  PetscCall(PeriAnalysisCheckpointFits(an, v, n[3], sizeof(PetscReal) + sizeof(PetscInt)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The run's state at a step, besides the bonds and u (PeriCheckpointView) and the velocities: the
 * step and time, the energies and counters, history.csv's rows, the frames written, the loads'
 * last amplitudes and the impactors. write: into v, else from v. Collective. */
static PetscErrorCode StateBinary(PeriAnalysis an, PetscViewer v, PetscReal *t, PetscBool write)
{
  Dynamic     *d     = DYN(an);
  PeriContact *C     = &an->sys->contact;
  PetscInt     n[8]  = {d->nsteps, d->broken, d->nhist, d->nsnap, DYN_ROW(d), d->nterms, d->nimpactors, d->next_frame};
  PetscReal    r[10] = {*t, d->kinetic, d->strain, d->dissipated, d->work, d->E0, d->scale, d->error, d->drift, d->dt}, imp[40];

  PetscFunctionBeginUser;
  for (PetscInt k = 0; write && k < PetscMin(d->nimpactors, 4); k++) {
    PetscCall(PetscArraycpy(&imp[10 * k], C->impactors[k].x, 3));
    PetscCall(PetscArraycpy(&imp[10 * k + 3], C->impactors[k].v, 3));
    PetscCall(PetscArraycpy(&imp[10 * k + 6], C->impactors[k].force, 3));
    imp[10 * k + 9] = C->impactors[k].t;
  }
  if (write) {
    PetscCall(PetscViewerBinaryWrite(v, n, 8, PETSC_INT));
    PetscCall(PetscViewerBinaryWrite(v, r, 10, PETSC_REAL));
  } else {
    PetscCall(PetscViewerBinaryRead(v, n, 8, NULL, PETSC_INT));
    PetscCall(PetscViewerBinaryRead(v, r, 10, NULL, PETSC_REAL));
    PetscCall(PeriAnalysisCheckpointFinite(an, r, 10, NULL, "time, energies and time step"));
    PetscCall(CheckState(an, v, n, r));
    d->nsteps = n[0], d->broken = n[1], d->nhist = d->cap = n[2], d->nsnap = n[3], d->next_frame = n[7];
    *t = r[0], d->kinetic = r[1], d->strain = r[2], d->dissipated = r[3], d->work = r[4], d->E0 = r[5], d->scale = r[6], d->error = r[7], d->drift = r[8];
    PetscCall(PetscMalloc1(DYN_ROW(d) * PetscMax(1, d->nhist), &d->hist));
    PetscCall(PetscMalloc1(PetscMax(1, d->nsnap), &d->snap_time)); /* apart: WriteSnapshot grows each */
    PetscCall(PetscMalloc1(PetscMax(1, d->nsnap), &d->snap_idx));
  }
  if (write) {
    PetscCall(PetscViewerBinaryWrite(v, d->term_prev, d->nterms, PETSC_REAL));
    PetscCall(PetscViewerBinaryWrite(v, imp, 10 * d->nimpactors, PETSC_REAL));
    PetscCall(PetscViewerBinaryWrite(v, d->hist, DYN_ROW(d) * d->nhist, PETSC_REAL));
    PetscCall(PetscViewerBinaryWrite(v, d->snap_time, d->nsnap, PETSC_REAL));
    PetscCall(PetscViewerBinaryWrite(v, d->snap_idx, d->nsnap, PETSC_INT));
  } else {
    PetscCall(PetscViewerBinaryRead(v, d->term_prev, d->nterms, NULL, PETSC_REAL));
    PetscCall(PetscViewerBinaryRead(v, imp, 10 * d->nimpactors, NULL, PETSC_REAL));
    PetscCall(PetscViewerBinaryRead(v, d->hist, DYN_ROW(d) * d->nhist, NULL, PETSC_REAL));
    PetscCall(PetscViewerBinaryRead(v, d->snap_time, d->nsnap, NULL, PETSC_REAL));
    PetscCall(PetscViewerBinaryRead(v, d->snap_idx, d->nsnap, NULL, PETSC_INT));
    PetscCall(PeriAnalysisCheckpointFinite(an, d->term_prev, d->nterms, NULL, "loads' amplitudes"));
    PetscCall(PeriAnalysisCheckpointFinite(an, imp, 10 * d->nimpactors, NULL, "impactors' positions, velocities and forces"));
    PetscCall(PeriAnalysisCheckpointFinite(an, d->hist, DYN_ROW(d) * d->nhist, NULL, "history.csv rows"));
    PetscCall(PeriAnalysisCheckpointFinite(an, d->snap_time, d->nsnap, NULL, "snapshot times"));
  }
  for (PetscInt k = 0; !write && k < PetscMin(d->nimpactors, 4); k++) {
    PetscCall(PetscArraycpy(C->impactors[k].x, &imp[10 * k], 3));
    PetscCall(PetscArraycpy(C->impactors[k].v, &imp[10 * k + 3], 3));
    PetscCall(PetscArraycpy(C->impactors[k].force, &imp[10 * k + 6], 3));
    C->impactors[k].t = imp[10 * k + 9];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What a checkpoint holds of the state (q, p) after the step to t. */
typedef struct {
  Vec       q, p;
  PetscReal t;
} CheckpointState;

static PetscErrorCode CheckpointBody(PeriAnalysis an, PetscViewer v, void *ctx)
{
  CheckpointState *c   = (CheckpointState *)ctx;
  PeriSystem       sys = an->sys;
  PeriCheckpoint   eq  = {c->q, sys->disc.bonds.live, sys->disc.bonds.intact, sys->fields.solve};

  PetscFunctionBeginUser;
  PetscCall(StateBinary(an, v, &c->t, PETSC_TRUE));
  PetscCall(PeriCheckpointView(sys, &eq, v));
  PetscCall(VecView(c->p, v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* checkpoint/state.bin of the state (q, p) after the step to t: the run's state, the bonds and u,
 * then the velocities (src/analysis/checkpoint.c). Collective. */
static PetscErrorCode WriteCheckpoint(PeriAnalysis an, Vec q, Vec p, PetscReal t)
{
  CheckpointState c = {q, p, t};

  PetscFunctionBeginUser;
  PetscCall(PeriAnalysisCheckpointWrite(an, CheckpointBody, &c));
  DYN(an)->checkpoints++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* -restart: the run's state, the bonds, u and the velocities of the checkpoint into the TS's state
 * U, K for those bonds, and the frames of the stopped run adopted. The step goes on from there
 * as the stopped run's did: the same dt (from the same pristine body), the same operations. */
static PetscErrorCode Restart(PeriAnalysis an, Vec U, Vec V)
{
  Dynamic       *d = DYN(an);
  PeriCheckpoint eq;
  PetscViewer    v;
  char           file[PETSC_MAX_PATH_LEN + 32];
  Vec            q, p;
  PetscReal      t = 0;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PetscFree(d->hist));
  PetscCall(PeriAnalysisRestartBegin(an, &v, file, sizeof(file))); /* a refused header: nothing to free */
  PetscCall(PeriCheckpointCreate(an->sys, &eq));
  PetscCall(GetState(an, U, &q, &p));
  /* PETSc's refusals of a damaged file are said by PeriAnalysisRestartEnd, naming the file */
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = StateBinary(an, v, &t, PETSC_FALSE);
  if (!ierr) ierr = PeriCheckpointLoad(an->sys, &eq, v, file);
  if (!ierr) ierr = VecLoad(d->implicit ? V : p, v);
  if (!ierr) ierr = PeriAnalysisCheckpointFinite(an, NULL, 0, d->implicit ? V : p, "velocities");
  PetscCall(PetscPopErrorHandler());
  ierr = PeriAnalysisRestartEnd(an, &v, file, ierr); /* a refused checkpoint is closed too */
  if (!ierr) ierr = VecCopy(eq.u, q);
  if (!ierr) ierr = VecCopy(eq.u, d->uprev);
  PetscCall(RestoreState(an, U, &q, &p));
  if (!ierr) ierr = PeriCheckpointRestore(an->sys, &eq, PETSC_TRUE, PETSC_TRUE);
  PetscCall(PeriCheckpointDestroy(&eq));
  PetscCall(ierr);
  PetscCall(TSSetTime(d->ts, t));
  PetscCall(TSSetStepNumber(d->ts, d->nsteps));
  PetscCall(PeriAnalysisAdoptSnapshots(an, &d->nsnap, d->snap_idx, d->snap_time));
  d->restart_step = d->nsteps;
  d->resumed      = PETSC_TRUE;
  d->t_prev       = t;
  PetscCall(PetscPrintf(an->comm, "perilin: restarted from %s: step %" PetscInt_FMT " at t = %g, %" PetscInt_FMT " bonds broken\n", file, d->nsteps, (double)t, d->broken));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* After each step (and at t = 0): energies, the balance, history, snapshots, signals. */
static PetscErrorCode Monitor(TS ts, PetscInt step, PetscReal t, Vec U, void *ctx)
{
  PeriAnalysis an = (PeriAnalysis)ctx;
  Dynamic     *d  = DYN(an);
  Vec          q, p;
  PetscReal    balance;
  PetscInt     last;
  PetscBool    snap, ckpt;

  PetscFunctionBeginUser;
  if (d->resumed) { /* -restart: this step's row, frame and checkpoint are the stopped run's */
    d->resumed = PETSC_FALSE;
    PetscCall(GetState(an, U, &q, &p));
    PetscCall(ImplicitBoundaryWork(an, q, p, t)); /* its reactions, for the next step's work */
    PetscCall(LoadPower(an, p));
    PetscCall(RestoreState(an, U, &q, &p));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(GetState(an, U, &q, &p));
  PetscCall(Work(an, q, p, t));
  PetscCall(TSGetMaxSteps(ts, &last));
  d->nsteps = step;
  snap      = (PetscBool)(step % d->every == 0 || step >= last);
  ckpt      = (PetscBool)(an->sys->run.interrupted || (an->checkpoint_every && step % an->checkpoint_every == 0 && step < last && step > 0));
  if (step % d->energy_every && step < last && !snap && !ckpt) { /* not a step that checks the balance */
    PetscCall(RestoreState(an, U, &q, &p));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PeriContactSetTime(an->sys, t, PETSC_FALSE)); /* the impactors where they are at t */
  PetscCall(Energies(an, q, p));
  PetscCall(PulsePosition(an, q));
  PetscCall(ProbeDisplacement(an, q));
  PetscCall(Fronts(an, p));
  balance = d->kinetic + d->strain + d->dissipated - d->work;
  if (step == 0) d->E0 = balance;
  /* the largest error of the balance over the run, relative to the largest energy of the run */
  d->scale = PetscMax(d->scale, PetscMax(d->kinetic + d->strain + d->dissipated, PetscAbsReal(d->work)));
  d->error = PetscMax(d->error, PetscAbsReal(balance - d->E0));
  d->drift = d->scale > 0 ? d->error / d->scale : 0;
  PetscCall(RecordHistory(d, t, balance));
  if (snap) PetscCall(WriteSnapshot(an, q, p, t));
  if (ckpt) PetscCall(WriteCheckpoint(an, q, p, t));
  PetscCall(PeriProgressUpdate(an->sys->run.progress, PERI_PROGRESS_ANALYSIS, "step %" PetscInt_FMT ", t = %g of %g, %" PetscInt_FMT " bonds broken", step, (double)t, (double)d->t_end, d->broken));
  PetscCall(RestoreState(an, U, &q, &p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Explicit: the state [q; p] of the owned DOFs, split for TSBASICSYMPLECTIC. */
static PetscErrorCode CreateExplicit(PeriAnalysis an, Vec *U)
{
  Dynamic       *d = DYN(an);
  Vec            q;
  PetscInt       n, r0;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(an->sys->fields.u, &n));
  PetscCall(VecCreateMPI(an->comm, 2 * n, PETSC_DETERMINE, U));
  PetscCall(VecGetOwnershipRange(*U, &r0, NULL));
  PetscCall(ISCreateStride(an->comm, n, r0, 1, &d->isq));
  PetscCall(ISCreateStride(an->comm, n, r0 + n, 1, &d->isp));
  /* the parts go back to U even when the initial state is refused (analysis.initial): no leak */
  PetscCall(VecGetSubVector(*U, d->isq, &q));
  ierr = InitialDisplacement(an, q);
  PetscCall(VecRestoreSubVector(*U, d->isq, &q));
  PetscCall(ierr);
  PetscCall(VecGetSubVector(*U, d->isp, &q));
  ierr = InitialVelocity(an, q);
  PetscCall(VecRestoreSubVector(*U, d->isp, &q));
  PetscCall(ierr);
  PetscCall(TSSetType(d->ts, TSBASICSYMPLECTIC));
  PetscCall(RegisterKDK());
  /* impactors and moving boundaries are integrated with PETSc's drift-kick-drift (CheckImpactorScheme) */
  PetscCall(TSBasicSymplecticSetType(d->ts, an->sys->contact.nimpactors || an->sys->conditions.moving ? TSBASICSYMPLECTICVELVERLET : DYN_KDK));
  PetscCall(TSSetRHSFunction(d->ts, NULL, RHSWhole, an));
  PetscCall(TSRHSSplitSetIS(d->ts, "position", d->isq));
  PetscCall(TSRHSSplitSetIS(d->ts, "momentum", d->isp));
  PetscCall(TSRHSSplitSetRHSFunction(d->ts, "position", NULL, RHSPosition, an));
  PetscCall(TSRHSSplitSetRHSFunction(d->ts, "momentum", NULL, RHSMomentum, an));
  PetscCall(TSSetSolution(d->ts, *U));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Implicit: u and v apart (TS2), generalized-alpha with the static solver's KSP/PC defaults. */
static PetscErrorCode CreateImplicit(PeriAnalysis an, Vec *U, Vec *V)
{
  Dynamic *d = DYN(an);
  SNES     snes;
  KSP      ksp;
  PC       pc;
  Mat      K;

  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(an->sys->fields.u, U));
  PetscCall(VecDuplicate(an->sys->fields.u, V));
  PetscCall(InitialDisplacement(an, *U));
  PetscCall(InitialVelocity(an, *V));
  PetscCall(PeriSystemGetJacobian(an->sys, &K));
  if (an->sys->stiffness.op)
    PetscCall(CreateJacobianShell(an)); /* no copy of K */
  else {
    PetscCall(MatDuplicate(K, MAT_COPY_VALUES, &d->J));
    PetscCall(PeriSetNearNullSpace(an->sys, d->J, NULL));
  }
  PetscCall(TSSetType(d->ts, TSALPHA2));
  PetscCall(TSAlpha2SetRadius(d->ts, d->rho_inf));
  PetscCall(TSSetI2Function(d->ts, NULL, I2Function, an));
  PetscCall(TSSetI2Jacobian(d->ts, d->J, d->J, I2Jacobian, an));
  PetscCall(TS2SetSolution(d->ts, *U, *V));
  PetscCall(TSGetSNES(d->ts, &snes));
  /* Newton, not KSPONLY: each step's residual must fall by 1e-8 (a true-residual check) */
  PetscCall(SNESSetType(snes, SNESNEWTONLS));
  PetscCall(SNESSetTolerances(snes, PETSC_DEFAULT, 1e-8, PETSC_DEFAULT, 10, PETSC_DEFAULT));
  PetscCall(SNESSetConvergenceHistory(snes, NULL, NULL, 16, PETSC_TRUE));
  PetscCall(SNESGetKSP(snes, &ksp));
  /* J follows K and the step's shift: its preconditioner is built once and kept until bonds break
     (PostStep); SNES's lag decides, since SNES resets KSP's reuse flag at each Jacobian */
  PetscCall(SNESSetLagPreconditioner(snes, -2));
  PetscCall(KSPSetType(ksp, KSPCG));
  if (an->sys->stiffness.nterms) {
    /* a term besides the bonds (contact) has no Jacobian op: J applied matrix-free, by differences
       of the residual, preconditioned by the bonds' (Jacobian-free Newton-Krylov, as
       -snes_mf_operator); J is then not exactly symmetric, hence GMRES. Modified Newton with the
       bonds' J alone stalls on the steps where contact acts (DIVERGED_MAX_IT at dt 1 on the
       bars of tests/scenes/contact_bars.yaml) */
    PetscCall(SNESSetUseMatrixFree(snes, PETSC_TRUE, PETSC_FALSE));
    PetscCall(KSPSetType(ksp, KSPGMRES));
  }
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCGAMG)); /* ChooseImplicitPC may take Jacobi once dt is known */
  PetscCall(KSPSetTolerances(ksp, 1e-10, PETSC_DEFAULT, PETSC_DEFAULT, 10000));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The implicit step's preconditioner when no -pc_type names one. Its matrix K + M/(beta dt^2) is
 * dominated by the mass term up to dt of some 20 explicit limits (Jacobi's condition number is about
 * 1 + (dt/dt_limit)^2): there CG with Jacobi costs fewer operator products than GAMG's set-up and
 * V-cycles; beyond, GAMG. The ratio 20 is measured on the pulse (docs/dynamics.md, 'The implicit
 * step's preconditioner'). */
static PetscErrorCode ChooseImplicitPC(PeriAnalysis an)
{
  Dynamic  *d = DYN(an);
  PetscBool given;
  SNES      snes;
  KSP       ksp;
  PC        pc;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsHasName(NULL, NULL, "-pc_type", &given));
  if (given || d->dt > DYN_JACOBI_RATIO * d->dt_limit) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(TSGetSNES(d->ts, &snes));
  PetscCall(SNESGetKSP(snes, &ksp));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCJACOBI));
  PetscCall(PCSetFromOptions(pc)); /* -pc_jacobi_* */
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Impactors move by PETSc's velocity Verlet of the particles (PeriImpactorsAdvance): another -ts_type
 * or -ts_basicsymplectic_type would integrate the two differently. */
static PetscErrorCode CheckImpactorScheme(PeriAnalysis an)
{
  TSType    type;
  PetscBool ok;

  PetscFunctionBeginUser;
  if (DYN(an)->implicit || (!an->sys->contact.nimpactors && !an->sys->conditions.moving)) PetscFunctionReturn(PETSC_SUCCESS); /* implicit: g(t) in the residual */
  PetscCall(TSGetType(DYN(an)->ts, &type));
  PetscCall(PetscStrcmp(type, TSBASICSYMPLECTIC, &ok));
  if (ok) {
    TSBasicSymplecticType bt;
    PetscCall(TSBasicSymplecticGetType(DYN(an)->ts, &bt));
    PetscCall(PetscStrcmp(bt, TSBASICSYMPLECTICVELVERLET, &ok));
  }
  PetscCheck(ok, an->comm, PETSC_ERR_USER_INPUT, "%s: impactors and bc velocities move with the particles' velocity Verlet (-ts_type basicsymplectic -ts_basicsymplectic_type velverlet, the default): drop the -ts_type or -ts_basicsymplectic_type option", an->sys->scene->file);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the TS is perilin's kick-drift-kick (its force kept for the next step and the balance). */
static PetscErrorCode IsKDK(Dynamic *d)
{
  TSType                type;
  TSBasicSymplecticType bt;

  PetscFunctionBeginUser;
  PetscCall(TSGetType(d->ts, &type));
  PetscCall(PetscStrcmp(type, TSBASICSYMPLECTIC, &d->kdk));
  if (!d->kdk) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(TSBasicSymplecticGetType(d->ts, &bt));
  PetscCall(PetscStrcmp(bt, DYN_KDK, &d->kdk));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The TS of the run, set from the options after perilin's defaults. */
static PetscErrorCode SetUpTS(PeriAnalysis an, Vec *U, Vec *V)
{
  Dynamic  *d = DYN(an);
  PeriNode  a;
  PetscBool given;

  PetscFunctionBeginUser;
  PetscCall(TSCreate(an->comm, &d->ts));
  PetscCall(TSSetApplicationContext(d->ts, an));
  PetscCall(TSSetProblemType(d->ts, TS_NONLINEAR)); /* so that SNES checks each step's residual */
  if (d->implicit)
    PetscCall(CreateImplicit(an, U, V));
  else
    PetscCall(CreateExplicit(an, U));
  PetscCall(TSSetTime(d->ts, 0));
  PetscCall(TSSetTimeStep(d->ts, d->dt));
  /* a fixed step (no TSAdapt clips the last one): as many steps as reach t_end, and the time
     limit half a step beyond, so that round-off in the sum of the steps adds no step */
  PetscCall(TSSetMaxTime(d->ts, d->t_end + 0.5 * d->dt));
  PetscCall(TSSetExactFinalTime(d->ts, TS_EXACTFINALTIME_STEPOVER));
  PetscCall(TSMonitorSet(d->ts, Monitor, an, NULL));
  PetscCall(TSSetPostStep(d->ts, PostStep));
  PetscCall(TSSetErrorIfStepFails(d->ts, PETSC_FALSE)); /* a failed step is perilin's message (CheckSteps) */
  PetscCall(TSSetFromOptions(d->ts));
  PetscCall(CheckImpactorScheme(an));
  PetscCall(IsKDK(d));
  PetscCall(TSGetTimeStep(d->ts, &d->dt));
  if (d->implicit) PetscCall(ChooseImplicitPC(an));
  if (d->implicit) PetscCall(AssembledPreconditioningMatrix(an));
  PetscCall(PetscOptionsHasName(NULL, NULL, "-ts_max_steps", &given));
  if (!given) PetscCall(TSSetMaxSteps(d->ts, (PetscInt)PetscCeilReal(d->t_end / d->dt - 1e-9)));
  PetscCall(TSGetMaxSteps(d->ts, &d->every));
  d->every = an->every ? an->every : PetscMax(1, (d->every + DYN_FRAMES - 1) / DYN_FRAMES);
  PetscCall(PeriSceneGetNode(an->sys->scene->root, "analysis", &a));
  /* analysis.dt or -ts_dt, held to the limit before any step */
  PeriInputCheck(d->implicit || d->dt <= d->dt_limit, an->sys->scene, a, "dt", "%g (or -ts_dt) is above the explicit stability limit 2/omega_max = %g (omega_max^2 <= %g by Gershgorin's bound on M^-1 K): use dt <= %g, or integrator: implicit", (double)d->dt, (double)d->dt_limit, (double)d->omega2_max, (double)d->dt_limit);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What summary.json's solver section reports: the TS, and for the implicit one its KSP/PC. */
static PetscErrorCode RecordSolver(PeriAnalysis an)
{
  Dynamic *d = DYN(an);
  TSType   type;

  PetscFunctionBeginUser;
  PetscCall(TSGetType(d->ts, &type));
  PetscCall(PetscStrncpy(an->sys->fields.solve.ksp_type, type, sizeof(an->sys->fields.solve.ksp_type)));
  PetscCall(PetscStrncpy(an->sys->fields.solve.pc_type, d->implicit ? "gamg" : "none", sizeof(an->sys->fields.solve.pc_type)));
  if (d->implicit) {
    SNES   snes;
    KSP    ksp;
    PC     pc;
    PCType pt;
    PetscCall(TSGetSNES(d->ts, &snes));
    PetscCall(SNESGetKSP(snes, &ksp));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCGetType(pc, &pt));
    PetscCall(PetscStrncpy(an->sys->fields.solve.pc_type, pt, sizeof(an->sys->fields.solve.pc_type)));
    PetscCall(TSGetSNESIterations(d->ts, &d->snes_its));
    PetscCall(TSGetKSPIterations(d->ts, &d->ksp_its));
  }
  PetscCall(PetscStrncpy(an->sys->fields.solve.converged_reason, an->sys->run.interrupted ? "INTERRUPTED" : "TS_CONVERGED_TIME", sizeof(an->sys->fields.solve.converged_reason)));
  an->sys->fields.solve.iterations    = d->nsteps;
  an->sys->fields.solve.residual_norm = d->worst; /* explicit: no solve, 0 */
  PetscCall(PetscStrncpy(an->sys->fields.solve.checked, "energy drift", sizeof(an->sys->fields.solve.checked)));
  an->sys->fields.solve.checked_value = d->drift;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  Run_Dynamic - integrates from rest (with the initial pulse and the held values) to t_end. The
  output describes the last completed step. Options: every -ts_* option, and for the implicit
  integrator the -snes_*, -ksp_* and -pc_* options. Collective.
@*/
/* solver.operator: auto gives both integrators the matrix-free operator where the model allows:
 * 12 bytes per bond (28 before the spring form) instead of an assembled K's ~150 in 3D, the same results, and no slower per
 * step (explicit: the EOI at 51,200 particles, 101 MB against 540, peak 506 MB against 910, the
 * time loop 0.86-0.92 of the assembled one's; docs/dynamics.md). The implicit step's J is then a
 * shell over the same bond data plus shift M (CreateJacobianShell), with the short range plus
 * shift M assembled for a PC that needs entries (AssembledPreconditioningMatrix). */
static PetscErrorCode ChooseOperator(PeriAnalysis an)
{
  PeriStiffness *S = &an->sys->stiffness;

  PetscFunctionBeginUser;
  if (S->operator_kind == PERI_OPERATOR_AUTO) S->operator_kind = !PeriMatrixFreeWhyNot(an->sys) ? PERI_OPERATOR_MATRIX_FREE : PERI_OPERATOR_ASSEMBLED;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The load terms: f_0 = every load without an amplitude of its own (the system's f less the
 * others), under analysis.amplitude; then each load with its own. */
static PetscErrorCode LoadTerms(PeriAnalysis an)
{
  Dynamic *d = DYN(an);
  PetscInt n = 1;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < d->nloads; k++) n += d->own_amp[k];
  PetscCheck(n <= PERI_DYN_MAX_TERMS, an->comm, PETSC_ERR_SUP, "%s: %" PetscInt_FMT " loads with an amplitude of their own; at most %d", an->sys->scene->file, n - 1, PERI_DYN_MAX_TERMS - 1);
  PetscCall(PetscMalloc4(n, &d->term_amp, n, &d->term_f, n, &d->term_prev, n, &d->term_fv));
  PetscCall(PetscArrayzero(d->term_fv, n));
  PetscCall(VecDuplicate(an->sys->fields.f, &d->term_f[0]));
  PetscCall(VecCopy(an->sys->fields.f, d->term_f[0]));
  d->term_amp[0] = &d->amp;
  d->nterms      = 1;
  for (PetscInt k = 0; k < d->nloads; k++) {
    if (!d->own_amp[k]) continue;
    PetscCall(VecDuplicate(an->sys->fields.f, &d->term_f[d->nterms]));
    PetscCall(PeriLoadAssemble(an->sys, k, d->term_f[d->nterms]));
    PetscCall(VecAXPY(d->term_f[0], -1, d->term_f[d->nterms]));
    d->term_amp[d->nterms++] = &d->load_amp[k];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A step the TS could not complete fails the run, naming the solver's reason and what to try. */
static PetscErrorCode CheckSteps(PeriAnalysis an)
{
  Dynamic            *d = DYN(an);
  TSConvergedReason   reason;
  SNES                snes;
  KSP                 ksp;
  PC                  pc;
  SNESConvergedReason sr;
  KSPConvergedReason  kr;
  PCType              pctype;
  PetscReal           t;
  PetscBool           jacobi;

  PetscFunctionBeginUser;
  PetscCall(TSGetConvergedReason(d->ts, &reason));
  if (reason >= 0) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(TSGetTime(d->ts, &t));
  PetscCheck(d->implicit, an->comm, PETSC_ERR_NOT_CONVERGED, "%s: the time step after t = %g failed (%s)", an->sys->scene->file, (double)t, TSConvergedReasons[reason]);
  PetscCall(TSGetSNES(d->ts, &snes));
  PetscCall(SNESGetConvergedReason(snes, &sr));
  PetscCall(SNESGetKSP(snes, &ksp));
  PetscCall(KSPGetConvergedReason(ksp, &kr));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCGetType(pc, &pctype));
  PetscCall(PetscStrcmp(pctype, PCJACOBI, &jacobi));
  if (kr > 0) { /* the linear solves converged: Newton did not (a term without a Jacobian, large steps) */
    PetscInt its;
    PetscCall(SNESGetTolerances(snes, NULL, NULL, NULL, &its, NULL));
    SETERRQ(an->comm, PETSC_ERR_NOT_CONVERGED, "%s: the implicit step after t = %g failed: %s (Newton's iterations, %" PetscInt_FMT " at most; its linear solves converged, after %" PetscInt_FMT " bonds broke): the run is no result; try a smaller dt, a larger -snes_max_it, or the explicit integrator", an->sys->scene->file, (double)t, SNESConvergedReasons[sr], its, d->broken);
  }
  SETERRQ(an->comm, PETSC_ERR_NOT_CONVERGED, "%s: the implicit step after t = %g failed: %s, its linear solve %s (PC %s, after %" PetscInt_FMT " bonds broke): the run is no result; try %s a smaller dt, or the explicit integrator", an->sys->scene->file, (double)t, SNESConvergedReasons[sr], KSPConvergedReasons[kr], pctype ? pctype : "none", d->broken,
          jacobi ? "a larger -ksp_max_it (CG with Jacobi converges on the step's symmetric positive definite matrix K + M/(beta dt^2), slowly when dt is many explicit limits)," : "-pc_type jacobi (slower, always valid for the step's symmetric positive definite matrix K + M/(beta dt^2)),");
}

/* What to try when the energy balance drifts. */
static const char *DriftAdvice(const Dynamic *d)
{
  static char advice[256];

  if (!d->implicit)
    PetscSNPrintf(advice, sizeof(advice), "use a smaller dt (now %g, limit %g) or the implicit integrator", (double)d->dt, (double)d->dt_limit);
  else if (d->rho_inf < 1)
    PetscSNPrintf(advice, sizeof(advice), "rho_infinity %g < 1 damps the high frequencies by design and takes their energy: raise analysis.energy_tolerance, or use rho_infinity 1 (no numerical damping)", (double)d->rho_inf);
  else
    PetscSNPrintf(advice, sizeof(advice), "use a smaller dt (now %g)", (double)d->dt);
  return advice;
}

/* -peri_checkpoint_every N: a checkpoint every N steps; without the option, at the frames' cadence
 * (about 25 over the run): a checkpoint holds the whole state, too much to write every step. */
static PetscErrorCode CheckpointCadence(PeriAnalysis an)
{
  PetscBool given;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsHasName(NULL, NULL, "-peri_checkpoint_every", &given));
  if (!given) an->checkpoint_every = DYN(an)->every;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sets up the TS (its state in *U, and *V for the implicit integrator) and integrates to t_end. */
static PetscErrorCode Integrate(PeriAnalysis an, Vec *U, Vec *V)
{
  Dynamic       *d = DYN(an);
  Vec            q, p;
  Mat            K;
  PetscLogDouble t0, t1;
  PetscReal      t;

  PetscFunctionBeginUser;
  d->started    = PETSC_TRUE;
  d->fvalid     = PETSC_FALSE; /* no force kept from an earlier run */
  d->contact    = &an->sys->contact;
  d->nimpactors = an->sys->contact.nimpactors;
  /* the explicit step only multiplies by K: BAIJ's blocks make the product about 1.6x faster than
     AIJ's (tests/perf/dynamic_lammps.sh); the implicit solve takes the static solver's type */
  if (d->implicit)
    PetscCall(PeriStaticDefaultMatType(an->sys->stiffness.mat_type, sizeof(an->sys->stiffness.mat_type)));
  else
    PetscCall(PetscStrncpy(an->sys->stiffness.mat_type, MATBAIJ, sizeof(an->sys->stiffness.mat_type)));
  PetscCall(ChooseOperator(an));
  PetscCall(PeriSystemGetJacobian(an->sys, &K));
  PetscCall(PetscTime(&t0));
  PetscCall(StabilityBound(an));
  ChooseStep(d);
  PetscCall(InverseMass(an));
  if (!an->sys->fields.u) PetscCall(PeriSystemCreateVec(an->sys, &an->sys->fields.u));
  PetscCall(VecDuplicate(an->sys->fields.u, &d->tmp));
  PetscCall(VecDuplicate(an->sys->fields.u, &d->uprev));
  PetscCall(SetUpTS(an, U, V));
  PetscCall(GetState(an, *U, &q, &p));
  PetscCall(VecCopy(q, d->uprev));
  PetscCall(RestoreState(an, *U, &q, &p));
  for (PetscInt k = 0; k < d->nterms; k++) d->term_prev[k] = PeriAmplitudeValue(d->term_amp[k], 0);
  PetscCall(CheckpointCadence(an));
  if (an->restart[0]) PetscCall(Restart(an, *U, d->implicit ? *V : NULL));
  PetscCall(PetscLogEventBegin(PERI_EVENT_Solve, 0, 0, 0, 0));
  PetscCall(TSSolve(d->ts, NULL));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Solve, 0, 0, 0, 0));
  PetscCall(CheckSteps(an));
  PetscCall(TSGetTime(d->ts, &t));
  PetscCall(PetscTime(&t1));
  an->sys->run.log.solve_s = t1 - t0;
  PetscCall(RecordSolver(an));
  PetscCall(PeriContactTally(an->sys));
  PetscCall(GetState(an, *U, &q, &p));
  PetscCall(VecCopy(q, an->sys->fields.u));
  PetscCall(PeriSystemKeepVelocity(an->sys, p));
  PetscCall(RestoreState(an, *U, &q, &p));
  PetscCall(PeriSystemEvaluateEnergy(an->sys));
  if (an->sys->bond_state.failure.active) PetscCall(PeriDamage(an->sys, &an->sys->bond_state.damage));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The run: the integration (Integrate), whose state U (and V, implicit) is freed whether it ends
 * or fails, then the energy balance's check. */
static PetscErrorCode Run_Dynamic(PeriAnalysis an)
{
  Dynamic       *d = DYN(an);
  Vec            U = NULL, V = NULL;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  ierr = Integrate(an, &U, &V);
  PetscCall(VecDestroy(&U));
  PetscCall(VecDestroy(&V));
  PetscCall(ierr);
  PetscCheck(an->sys->run.interrupted || d->drift <= d->energy_tol, an->comm, PETSC_ERR_NOT_CONVERGED, "%s: the energy balance (kinetic + strain + dissipated - work of the loads) drifted by %.3g of the energy scale, above analysis.energy_tolerance %g: the run is not consistent; %s", an->sys->scene->file, (double)d->drift, (double)d->energy_tol, DriftAdvice(d));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* history.csv's text: the header, then one row per recorded step. Returns nonzero when a write
 * failed. */
static int HistoryRows(PeriAnalysis an, FILE *fp)
{
  Dynamic       *d   = DYN(an);
  const PetscInt dim = an->sys->disc.particles.dim;
  int            bad = 0;

  bad |= fprintf(fp, "time,kinetic,strain,dissipated,work,balance,broken%s%s%s", d->pulse ? ",pulse_position" : "", an->sys->fields.nprobes ? ",probe_u" : "", d->fronts ? ",wave_front,damage_front" : "") < 0;
  for (PetscInt m = 0; m < d->nimpactors; m++)
    for (PetscInt c = 0; c < DYN_IMPACTOR_COLUMNS; c++)
      if (c % 3 < dim) bad |= fprintf(fp, ",impactor%" PetscInt_FMT "_%s%c", m + 1, c < 3 ? "" : (c < 6 ? "v" : "f"), (char)('x' + c % 3)) < 0;
  bad |= fprintf(fp, "\n") < 0;
  for (PetscInt k = 0; k < d->nhist; k++) {
    const PetscReal *r = &d->hist[DYN_ROW(d) * k];
    bad |= fprintf(fp, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%" PetscInt_FMT, (double)r[0], (double)r[1], (double)r[2], (double)r[3], (double)r[4], (double)r[5], (PetscInt)r[6]) < 0;
    if (d->pulse) bad |= fprintf(fp, ",%.10g", (double)r[7]) < 0;
    if (an->sys->fields.nprobes) bad |= fprintf(fp, ",%.17g", (double)r[8]) < 0;
    if (d->fronts) bad |= fprintf(fp, ",%.10g,%.10g", (double)r[9], (double)r[10]) < 0;
    for (PetscInt c = DYN_HISTORY_COLUMNS; c < DYN_ROW(d); c++)
      if ((c - DYN_HISTORY_COLUMNS) % 3 < dim) bad |= fprintf(fp, ",%.17g", (double)r[c]) < 0;
    bad |= fprintf(fp, "\n") < 0;
  }
  return bad;
}

/* history.csv: one row per step. Rank 0 writes (temporary name, then rename). */
static PetscErrorCode WriteHistory(PeriAnalysis an, const char dir[])
{
  char path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/history.csv", dir));
  PetscCall(PeriAnalysisWriteTable(an, PETSC_TRUE, HistoryRows, path, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* history.csv's text into fp for the embedding (rank 0; nothing before the run began). */
static PetscErrorCode Table_Dynamic(PeriAnalysis an, FILE *fp)
{
  PetscFunctionBeginUser;
  PetscCall(PeriAnalysisWriteTable(an, DYN(an)->started, HistoryRows, NULL, fp));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* dynamics.png from history.csv and particles.vtu (output.plots). */
static PetscErrorCode DrawPlots(PeriAnalysis an, const char dir[])
{
  Dynamic    *d = DYN(an);
  char        arg[2][64];
  const char *args[3] = {arg[0], arg[1], NULL};

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(arg[0], sizeof(arg[0]), "integrator=%s", d->implicit ? "implicit" : "explicit"));
  PetscCall(PetscSNPrintf(arg[1], sizeof(arg[1]), "drift=%.2g", (double)d->drift));
  PetscCall(PeriPlotsDraw(an->comm, dir, "dynamic", args, &an->plots));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* history.csv, dynamics.png, and with snapshots particles.pvd over the physical time. */
static PetscErrorCode Files_Dynamic(PeriAnalysis an, const char dir[])
{
  Dynamic *d = DYN(an);
  char     path[PETSC_MAX_PATH_LEN], base[32], **files;

  PetscFunctionBeginUser;
  if (!d->started) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(WriteHistory(an, dir));
  PetscCall(DrawPlots(an, dir));
  if (!d->nsnap || an->rank) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc1(d->nsnap, &files));
  for (PetscInt k = 0; k < d->nsnap; k++) {
    PetscCall(PetscSNPrintf(base, sizeof(base), "particles_%04" PetscInt_FMT, d->snap_idx[k]));
    PetscCall(PetscMalloc1(40, &files[k]));
    PetscCall(PeriParticlesFileName(an->comm, base, files[k], 40));
  }
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/particles.pvd", dir));
  PetscCall(PeriWritePVD(path, d->nsnap, d->snap_time, (const char *const *)files));
  for (PetscInt k = 0; k < d->nsnap; k++) PetscCall(PetscFree(files[k]));
  PetscCall(PetscFree(files));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A front's speed: the least-squares slope of its distance over time, over the rows where it has
 * left the origin and not yet stopped at its farthest (a wave reaching the end of the body), or 0. */
static PetscReal FrontSpeed(const Dynamic *d, PetscInt col)
{
  PetscReal n = 0, st = 0, sx = 0, stt = 0, stx = 0, last = 0;

  for (PetscInt k = 0; k < d->nhist; k++) last = PetscMax(last, d->hist[DYN_ROW(d) * k + col]);
  for (PetscInt k = 0; k < d->nhist; k++) {
    const PetscReal t = d->hist[DYN_ROW(d) * k], x = d->hist[DYN_ROW(d) * k + col];
    if (x <= 0 || x >= last) continue;
    n += 1, st += t, sx += x, stt += t * t, stx += t * x;
  }
  return n > 1 && n * stt - st * st > 0 ? (n * stx - st * sx) / (n * stt - st * st) : 0;
}

/* summary.json's "dynamic" object. */
static PetscErrorCode Summary_Dynamic(PeriAnalysis an, PeriJSON j)
{
  Dynamic *d = DYN(an);

  PetscFunctionBeginUser;
  if (!d->started) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriJSONBeginObject(j, "dynamic"));
  PetscCall(PeriJSONString(j, "integrator", d->implicit ? "implicit" : "explicit"));
  PetscCall(PeriJSONReal(j, "dt", d->dt));
  PetscCall(PeriJSONReal(j, "dt_limit", d->dt_limit));
  PetscCall(PeriJSONReal(j, "omega2_max_bound", d->omega2_max));
  PetscCall(PeriJSONInt(j, "steps", d->nsteps));
  PetscCall(PeriJSONReal(j, "time", d->t_prev));
  PetscCall(PeriJSONReal(j, "kinetic_energy", d->kinetic));
  PetscCall(PeriJSONReal(j, "strain_energy", d->strain));
  PetscCall(PeriJSONReal(j, "dissipated_energy", d->dissipated));
  PetscCall(PeriJSONReal(j, "work_of_loads", d->work));
  PetscCall(PeriJSONReal(j, "energy_drift", d->drift));
  PetscCall(PeriJSONReal(j, "energy_tolerance", d->energy_tol));
  PetscCall(PeriJSONInt(j, "broken_bonds", d->broken));
  PetscCall(PeriJSONInt(j, "checkpoints", d->checkpoints));
  if (d->restart_step) PetscCall(PeriJSONString(j, "restarted_from", an->restart));
  if (d->restart_step) PetscCall(PeriJSONInt(j, "restart_step", d->restart_step));
  PetscCall(PeriContactSummary(an->sys, j));
  if (d->implicit) {
    PetscCall(PeriJSONInt(j, "ksp_iterations", d->ksp_its));
    PetscCall(PeriJSONReal(j, "rho_infinity", d->rho_inf));
    PetscCall(PeriJSONReal(j, "resolved_frequency_1pct", PeriAlpha2ResolvedFrequency(d->rho_inf, d->dt, 0.01)));
  }
  if (d->fronts) {
    PetscCall(PeriJSONReal(j, "wave_front", d->wave_front));
    PetscCall(PeriJSONReal(j, "damage_front", d->damage_front));
    PetscCall(PeriJSONReal(j, "wave_front_speed", FrontSpeed(d, 9)));
    PetscCall(PeriJSONReal(j, "damage_front_speed", FrontSpeed(d, 10)));
  }
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Report_Dynamic(PeriAnalysis an)
{
  Dynamic *d            = DYN(an);
  char     resolved[96] = "";

  PetscFunctionBeginUser;
  if (d->implicit) PetscCall(PetscSNPrintf(resolved, sizeof(resolved), ", modes below %g within 1 %% in period", (double)PeriAlpha2ResolvedFrequency(d->rho_inf, d->dt, 0.01)));
  PetscCall(PetscPrintf(an->comm, "perilin: %s dynamics to t = %g in %" PetscInt_FMT " steps of %g (explicit limit %g%s), energy drift %.2g, %" PetscInt_FMT " bonds broken; results in %s/\n", d->implicit ? "implicit" : "explicit", (double)d->t_prev, d->nsteps, (double)d->dt, (double)d->dt_limit, resolved, (double)d->drift, d->broken, an->output_dir));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Destroy_Dynamic(PeriAnalysis an)
{
  Dynamic *d = DYN(an);

  PetscFunctionBeginUser;
  PetscCall(TSDestroy(&d->ts));
  PetscCall(MatDestroy(&d->J));
  PetscCall(MatDestroy(&d->Kh));
  PetscCall(MatDestroy(&d->Pa));
  PetscCall(VecDestroy(&d->jshift));
  PetscCall(VecDestroy(&d->jwork));
  PetscCall(ISDestroy(&d->isq));
  PetscCall(ISDestroy(&d->isp));
  PetscCall(VecDestroy(&d->minv));
  PetscCall(VecDestroy(&d->uprev));
  PetscCall(PetscFree(d->reaction));
  PetscCall(VecDestroy(&d->tmp));
  PetscCall(VecDestroy(&d->fq));
  PetscCall(VecDestroy(&d->fkq));
  PetscCall(VecDestroy(&d->ff));
  PetscCall(PetscFree(d->hist));
  PetscCall(PetscFree(d->snap_time));
  PetscCall(PetscFree(d->snap_idx));
  for (PetscInt k = 0; k < d->nterms; k++) PetscCall(VecDestroy(&d->term_f[k]));
  PetscCall(PetscFree4(d->term_amp, d->term_f, d->term_prev, d->term_fv));
  for (PetscInt k = 0; k < d->nloads; k++) PetscCall(PeriAmplitudeDestroy(&d->load_amp[k]));
  PetscCall(PetscFree2(d->load_amp, d->own_amp));
  PetscCall(PeriAmplitudeDestroy(&d->amp));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static const char *const dyn_files[] = {"history.csv", "dynamics.png", "checkpoint", "particles.pvd", "particles_#.vtu", "particles_#.pvtu", "particles_#", NULL};

/* K is assembled, or matrix-free for the explicit integrator (solver.operator: matrix_free); the
   implicit step copies it into J. */
const PeriAnalysisType PeriAnalysis_Dynamic = {
    .name          = "dynamic",
    .help          = "transient dynamics M a + K u = f(t) on PETSc TS, explicit or implicit, with bond failure",
    .schema        = dyn_schema,
    .option_prefix = "",
    .files         = dyn_files,
    .table         = "history.csv",
    .needs         = {.matrix_free = PETSC_TRUE, .static_solver = PETSC_TRUE, .matrix_copies = 1, .transient = PETSC_TRUE},
    .checkpoints   = PETSC_TRUE,
    .ops           = {.setfromscene = SetFromScene_Dynamic, .setup = SetUp_Dynamic, .run = Run_Dynamic, .files = Files_Dynamic, .summary = Summary_Dynamic, .report = Report_Dynamic, .table = Table_Dynamic, .destroy = Destroy_Dynamic},
};
