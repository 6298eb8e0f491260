/* Quasi-static load stepping with bond failure (docs/failure.md). The scene's loads, prescribed
 * values and layer conditions are scaled by a load factor lambda. At each lambda: solve, break
 * the bonds past the failure criterion (all of them, or the most critical fraction), subtract
 * their blocks from K, and solve again at the same lambda until no bond breaks. Pieces cut off
 * from the constraints are held where they are; when a loaded piece is cut off, the solve fails,
 * or no equilibrium is found, the body has failed: with adaptive steps the step is halved from the
 * last equilibrium until it is below min_step, so the critical lambda is bracketed. */
#include "perilin/private/analysis.h"
#include <signal.h>

/* analysis.stepping, analysis.break */
static const char *const qs_steppings[] = {"increments", "events", NULL};
static const char *const qs_policies[]  = {"all", "fraction", NULL};

#define PERI_MAX_LOAD_STEPS 100000
/* the relative tolerance of a cascade's intermediate solves (stepping by events): the breaks need
 * the failure indices to about this, the accepted equilibria are solved to the full tolerance */
#define PERI_CASCADE_RTOL  1e-6
#define PERI_MAX_BISECTION 1048576.0 /* 2^20 */

typedef struct {
  PetscReal  max, step, min_step, fraction, runaway;
  PetscBool  adaptive, all, reuse, quiet;
  PetscBool  events; /* stepping: events (else increments) */
  PetscInt   max_iterations;
  PeriProbe *control;
  PetscInt   component, reaction; /* the control probe's component; the reaction region (index of disc.regions) or -1 */
  PetscBool  displacement;        /* displacement control: a bc item or layer prescribes a nonzero value */
  PetscBool  runaway_given;       /* analysis.runaway_fraction given (else by the control type) */
  PetscReal  load;                /* load control: the applied load along the component at load factor 1 */
  char       chosen[96];          /* why the component is what it is, for the run log */
  /* the names the scene gives, resolved against the system by SetUp_Quasistatic ("": not given) */
  char control_probe[PERI_NAME_LEN], control_component[PERI_NAME_LEN], reaction_region[PERI_NAME_LEN];
} Settings;

/* At most this many snapshots by default (output.every 0): the equilibria where bonds broke */
#define PERI_AUTO_SNAPSHOTS 50

/* The analysis' data: its results, its settings (QS(an) reads the results), and the steps whose
 * snapshots particles_NNNN.vtu were written (particles.pvd's frames). */
typedef struct {
  PeriQuasistatic q;
  Settings        st;
  PetscInt        nsnaps, capsnaps, *snaps;
  PetscInt        stop_after; /* -peri_stop_after_step: stop after this step as a SIGINT would (0: never) */
} QSData;

static inline PeriQuasistatic *QS(PeriAnalysis an)
{
  return &((QSData *)an->data)->q;
}

static inline Settings *ST(PeriAnalysis an)
{
  return &((QSData *)an->data)->st;
}

/* The load factor scales the loads, the prescribed values, the layers' values and the twist:
 * with all of them zero every step is the unloaded body, and the loop would run to the end. */
static PetscErrorCode CheckSomethingLoaded(PeriAnalysis an, PeriNode a)
{
  PetscReal fnorm, v = 0;

  PetscFunctionBeginUser;
  PetscCall(VecNorm(an->sys->fields.f, NORM_INFINITY, &fnorm));
  for (PetscInt k = 0; k < an->sys->conditions.nconstrained; k++) v = PetscMax(v, PetscAbsReal(an->sys->conditions.constrained_value[k]));
  for (PetscInt f = 0; f < 6; f++) v = PetscMax(v, an->sys->conditions.layers.kind[f] ? PetscAbsReal(an->sys->conditions.layers.value[f]) : 0);
  if (an->sys->conditions.torsion.active) v = PetscMax(v, PetscAbsReal(an->sys->conditions.torsion.twist));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPIU_REAL, MPI_MAX, an->comm));
  PeriInputCheck(fnorm > 0 || v > 0, an->sys->scene, a, "type", "a quasistatic analysis scales the loads and prescribed values, and this scene has none (no loads, every bc value 0): give loads or a bc value");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bc region a load-displacement curve reads when the scene names none: the first that
 * prescribes a nonzero value along the control component (the grip that moves), else the first
 * that holds that component, else none (-1). */
static PetscInt DefaultReactionRegion(PeriSystem sys, PetscInt c)
{
  const PeriReactions *R = &sys->conditions.reactions;
  for (PetscInt r = 0; r < R->nregions; r++)
    if (R->holds[r * PERI_MAX_DOF + c] && R->moves[r]) return r;
  for (PetscInt r = 0; r < R->nregions; r++)
    if (R->holds[r * PERI_MAX_DOF + c]) return r;
  return -1;
}

/* What drives the run, per component at load factor 1: the largest |prescribed value| (bc items
 * and displacement layers), the loads' sum, sum of magnitudes and sum of positive parts, and the
 * force of the most loaded shear-stress layer on its face (0 without one). */
typedef struct {
  PetscReal value[PERI_MAX_DOF], load[3][PERI_MAX_DOF]; /* load: sum, |.| sum, positive sum */
  PetscReal layer;
} Drive;

/* The drive of the system's conditions (sys->fields.f: the loads at load factor 1). Collective. */
static PetscErrorCode DriveOf(PeriSystem sys, Drive *d)
{
  const PetscInt     bs = sys->model->dofs;
  const PeriLayers  *L  = &sys->conditions.layers;
  const PetscReal   *lo = sys->disc.particles.lower, *hi = sys->disc.particles.upper;
  const PetscScalar *f;
  PetscInt           n;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(d, sizeof(*d)));
  for (PetscInt k = 0; k < sys->conditions.nconstrained; k++) {
    PetscInt c  = sys->conditions.constrained[k] % bs;
    d->value[c] = PetscMax(d->value[c], PetscAbsReal(sys->conditions.constrained_value[k]));
  }
  PetscCall(VecGetLocalSize(sys->fields.f, &n));
  PetscCall(VecGetArrayRead(sys->fields.f, &f));
  for (PetscInt k = 0; k < n; k++) {
    PetscReal F = PetscRealPart(f[k]);
    d->load[0][k % bs] += F;
    d->load[1][k % bs] += PetscAbsReal(F);
    d->load[2][k % bs] += PetscMax(F, 0);
  }
  PetscCall(VecRestoreArrayRead(sys->fields.f, &f));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, d->value, PERI_MAX_DOF, MPIU_REAL, MPI_MAX, sys->comm));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, d->load, 3 * PERI_MAX_DOF, MPIU_REAL, MPI_SUM, sys->comm));
  /* fictitious layers: antiplane, 2D, one component (uz) */
  for (PetscInt face = 0; face < 6; face++) {
    PetscInt  a = face / 2;
    PetscReal F = L->value[face] * (hi[1 - a] - lo[1 - a]) * sys->materials.thickness;
    if (L->kind[face] == PERI_LAYER_DISPLACEMENT) d->value[0] = PetscMax(d->value[0], PetscAbsReal(L->value[face]));
    if (L->kind[face] == PERI_LAYER_SHEAR_STRESS && a < 2 && PetscAbsReal(F) > PetscAbsReal(d->layer)) d->layer = F;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The control type and the default control component: displacement control when a nonzero value
 * is prescribed (the component of the largest), else load control (the component of the largest
 * load, by the sum of magnitudes: a body pulled at both ends has a zero total). */
static PetscErrorCode ChooseComponent(const Drive *d, PetscInt dofs, Settings *st)
{
  PetscInt cv = 0, cf = 0;

  PetscFunctionBeginUser;
  for (PetscInt c = 1; c < dofs; c++) {
    if (d->value[c] > d->value[cv]) cv = c;
    if (d->load[1][c] > d->load[1][cf]) cf = c;
  }
  st->displacement = (PetscBool)(d->value[cv] > 0);
  st->component    = st->displacement ? cv : cf;
  if (st->displacement)
    PetscCall(PetscStrncpy(st->chosen, "the component of the largest prescribed value", sizeof(st->chosen)));
  else if (d->load[1][cf] > 0)
    PetscCall(PetscStrncpy(st->chosen, "the direction of the largest applied load", sizeof(st->chosen)));
  else if (d->layer != 0)
    PetscCall(PetscStrncpy(st->chosen, "the layers' shear stress", sizeof(st->chosen)));
  else
    PetscCall(PetscStrncpy(st->chosen, "the model's first component", sizeof(st->chosen)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The applied load along c at load factor 1 (load control's force): the total of the loads; for
 * loads that balance along c (a body pulled at both ends) the total of those along +c, the force
 * that goes through the body; without loads, a shear-stress layer's force on its face. */
static PetscReal LoadAlong(const Drive *d, PetscInt c)
{
  if (d->load[1][c] == 0) return d->layer;
  if (PetscAbsReal(d->load[0][c]) > 1e-9 * d->load[1][c]) return d->load[0][c];
  return d->load[2][c];
}

/* analysis.control_component and analysis.reaction_region: the displacement and the force of
 * steps.csv's load-displacement columns; and the control type, which sets the default
 * runaway_fraction. */
static PetscErrorCode ReadLoadDisplacement(PeriAnalysis an, PeriNode a, Settings *st)
{
  PeriScene   s         = an->sys->scene;
  PeriModel   m         = an->sys->model;
  const char *name      = st->reaction_region;
  char        list[128] = "";
  Drive       d;

  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < m->dofs; c++) PeriListAppend(list, sizeof(list), m->components[c]);
  PetscCall(DriveOf(an->sys, &d));
  PetscCall(ChooseComponent(&d, m->dofs, st));
  if (st->control_component[0]) PetscCall(PeriModelComponentIndex(m, st->control_component, &st->component));
  if (st->control_component[0]) PetscCall(PetscStrncpy(st->chosen, "analysis.control_component", sizeof(st->chosen)));
  PeriInputCheck(st->component >= 0, s, a, "control_component", "'%s' is not a component of model %s; its components are: %s", st->control_component, m->type, list);
  st->load = LoadAlong(&d, st->component);
  if (!st->runaway_given) st->runaway = st->displacement ? 1 : 0.01;
  st->reaction = DefaultReactionRegion(an->sys, st->component);
  if (!name[0]) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriReactionsFindRegion(an->sys, name, &st->reaction));
  list[0] = 0;
  for (PetscInt r = 0; r < an->sys->conditions.reactions.nregions; r++) {
    PetscInt k;
    PetscCall(PeriReactionsFindRegion(an->sys, an->sys->disc.regions[r].name, &k));
    if (k == r) PeriListAppend(list, sizeof(list), an->sys->disc.regions[r].name);
  }
  PeriInputCheck(st->reaction >= 0, s, a, "reaction_region", "no bc item holds a region named '%s', so it has no reaction; the regions with one are: %s", name, list[0] ? list : "none (the scene has no bc)");
  PeriInputCheck(an->sys->conditions.reactions.holds[st->reaction * PERI_MAX_DOF + st->component], s, a, "reaction_region", "the bc items on region '%s' do not hold %s (the control component), so its reaction has no %s force: hold it there or choose another region or control_component", name, m->components[st->component], m->components[st->component]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.* before any particle exists: stepping, load factors, breaking, and the names of the
 * control probe, component and reaction region (resolved by SetUp_Quasistatic). The getters apply
 * the declared defaults and ranges; the checks here are those between keys. */
static PetscErrorCode SetFromScene_Quasistatic(PeriAnalysis an, PeriScene s, PeriNode a)
{
  QSData   *data;
  Settings *st;
  PetscInt  policy = 0, stepping = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&data));
  an->data = data;
  st       = &data->st;
  PetscCall(PeriSceneGetChoice(s, a, "stepping", qs_steppings, &stepping, NULL));
  st->events = stepping == 1 ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PeriSceneGetReal(s, a, "load_factor_max", PETSC_TRUE, &st->max, NULL));
  st->step = st->max;
  PetscCall(PeriSceneGetReal(s, a, "load_factor_step", (PetscBool)!st->events, &st->step, NULL));
  PeriInputCheck(st->step > 0 && st->step <= st->max, s, a, "load_factor_step", "must lie in (0, load_factor_max], got %g", (double)st->step);
  st->min_step = st->step / 64;
  PetscCall(PeriSceneGetReal(s, a, "min_step", PETSC_FALSE, &st->min_step, NULL));
  /* bounded so that a run ends: each halving below the step costs a failed trial's solves, and
     a bracket finer than 2^-20 of a step does not change the critical load meaningfully */
  PeriInputCheck(st->max / st->step <= PERI_MAX_LOAD_STEPS, s, a, "load_factor_step", "%g would take %.3g steps to reach load_factor_max %g (at most %d): use a larger step (adaptive steps refine it where bonds break)", (double)st->step, (double)(st->max / st->step), (double)st->max, PERI_MAX_LOAD_STEPS);
  PeriInputCheck(st->min_step >= st->step / PERI_MAX_BISECTION && st->min_step <= st->step, s, a, "min_step", "must lie in [load_factor_step / 2^20, load_factor_step] = [%g, %g], got %g", (double)(st->step / PERI_MAX_BISECTION), (double)st->step, (double)st->min_step);
  PetscCall(PeriSceneGetBool(s, a, "adaptive", &st->adaptive, NULL));
  PetscCall(PeriSceneGetChoice(s, a, "break", qs_policies, &policy, NULL));
  st->all = policy == 0 ? PETSC_TRUE : PETSC_FALSE;
  if (st->all)
    PetscCall(PeriSceneCheckAbsent(s, a, "break_fraction", "applies to break: fraction only"));
  else
    PetscCall(PeriSceneGetReal(s, a, "break_fraction", PETSC_FALSE, &st->fraction, NULL));
  PetscCall(PeriSceneGetReal(s, a, "runaway_fraction", PETSC_FALSE, &st->runaway, &st->runaway_given)); /* else by the control type (SetUp) */
  PetscCall(PeriSceneGetInt(s, a, "max_iterations", PETSC_FALSE, &st->max_iterations, NULL));
  PetscCall(PeriSceneGetBool(s, a, "reuse_preconditioner", &st->reuse, NULL));
  PetscCall(PeriSceneGetString(s, a, "control_probe", PETSC_FALSE, st->control_probe, sizeof(st->control_probe), NULL));
  PetscCall(PeriSceneGetString(s, a, "control_component", PETSC_FALSE, st->control_component, sizeof(st->control_component), NULL));
  PetscCall(PeriSceneGetString(s, a, "reaction_region", PETSC_FALSE, st->reaction_region, sizeof(st->reaction_region), NULL));
  st->quiet = PETSC_FALSE;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-quiet", &st->quiet, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-peri_stop_after_step", &data->stop_after, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What needs the system: failure criteria, brittle bonds for events, the control probe, the
 * load-displacement columns, and something to scale. */
static PetscErrorCode SetUp_Quasistatic(PeriAnalysis an)
{
  PeriScene        s  = an->sys->scene;
  Settings        *st = ST(an);
  PeriQuasistatic *q  = QS(an);
  PeriNode         a;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_TRUE, &a));
  PeriInputCheck(an->sys->bond_state.failure.active, s, a, "type", "a quasistatic analysis needs failure: (the bond failure criteria)");
  PeriInputCheck(!st->events || !an->sys->disc.bonds.intact, s, a, "stepping", "events needs brittle bonds: with softening (failure.ultimate_stretch) the bonds weaken gradually; use stepping: increments");
  st->control = an->sys->fields.nprobes ? &an->sys->fields.probes[0] : NULL;
  if (st->control_probe[0]) {
    st->control = NULL;
    for (PetscInt k = 0; k < an->sys->fields.nprobes; k++)
      if (!strcmp(an->sys->fields.probes[k].name, st->control_probe)) st->control = &an->sys->fields.probes[k];
    PeriInputCheck(st->control, s, a, "control_probe", "no probe named '%s' (probes: give it under probes:)", st->control_probe);
  }
  PetscCall(ReadLoadDisplacement(an, a, st));
  PetscCall(CheckSomethingLoaded(an, a));
  PetscCall(PetscStrncpy(q->control, st->control ? st->control->name : "", sizeof(q->control)));
  q->control_component = st->component;
  q->reaction_region   = st->reaction;
  PetscCall(PetscStrncpy(q->stepping, st->events ? "events" : "increments", sizeof(q->stepping)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Appends the step and every region's reaction at it (sys->conditions.reactions, just evaluated). */
static PetscErrorCode RecordStep(PeriQuasistatic *q, const PeriStep *s, const PeriReactions *R)
{
  const PetscInt w = R->nregions * PERI_MAX_DOF;

  PetscFunctionBeginUser;
  if (q->nsteps == q->cap) {
    PeriStep  *n;
    PetscReal *r;
    q->cap = PetscMax(64, 2 * q->cap);
    PetscCall(PetscMalloc2(q->cap, &n, q->cap * w, &r));
    if (q->nsteps) PetscCall(PetscArraycpy(n, q->steps, q->nsteps));
    if (q->nsteps) PetscCall(PetscArraycpy(r, q->reactions, q->nsteps * w));
    PetscCall(PetscFree2(q->steps, q->reactions));
    q->steps     = n;
    q->reactions = r;
  }
  PetscCall(PetscArraycpy(&q->reactions[q->nsteps * w], R->force, w));
  q->steps[q->nsteps++] = *s;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The control probe's control component at the current solution (collective). */
static PetscErrorCode ControlValue(PeriAnalysis an, PeriProbe *probe, PetscInt component, PetscReal *v)
{
  PetscInt row;

  PetscFunctionBeginUser;
  *v = 0;
  if (!probe) PetscFunctionReturn(PETSC_SUCCESS);
  if (probe->rank == an->rank) {
    PetscScalar x;
    row = (an->sys->disc.rstart + probe->particle) * an->sys->model->dofs + component;
    PetscCall(VecGetValues(an->sys->fields.u, 1, &row, &x));
    *v = PetscRealPart(x);
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, v, 1, MPIU_REAL, MPI_SUM, an->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Progress(PeriAnalysis an, const Settings *st, const PeriStep *s)
{
  char soft[48] = "", tries[32] = "";

  PetscFunctionBeginUser;
  if (st->quiet) PetscFunctionReturn(PETSC_SUCCESS);
  /* the bar where the status line would be drawn: a terminal of the user's (src/sys/progress.c) */
  if (PeriProgressActive(an->sys->run.progress)) {
    char     bar[41];
    PetscInt fill = (PetscInt)(40 * s->lambda / st->max);
    for (PetscInt k = 0; k < 40; k++) bar[k] = k < fill ? '#' : '.';
    bar[40] = 0;
    PetscCall(PetscPrintf(an->comm, "\r[%s] ", bar));
  }
  if (an->sys->bond_state.failure.softening) PetscCall(PetscSNPrintf(soft, sizeof(soft), "  softened %8" PetscInt_FMT, s->softened));
  if (s->attempts > 1) PetscCall(PetscSNPrintf(tries, sizeof(tries), " (%" PetscInt_FMT " attempts)", s->attempts));
  PetscCall(PetscPrintf(an->comm, "step %4" PetscInt_FMT "  lambda %-12.6g u %-12.5g broken %6" PetscInt_FMT " (total %8" PetscInt_FMT ")%s  equilibrium its %3" PetscInt_FMT "  ksp its %5" PetscInt_FMT "  %.2f s%s\n", QS(an)->nsteps, (double)s->lambda, (double)s->control_u, s->broken, s->broken_total, soft, s->iterations, s->ksp_iterations, (double)s->seconds, tries));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles_NNNN.vtu (or another name; .pvtu on several ranks) of the present state, in the output
 * set, through the snapshot callback the problem installed (the analysis does not know where the
 * set lives). */
static PetscErrorCode WriteState(PeriAnalysis an, const char name[])
{
  PetscFunctionBeginUser;
  PetscCall(PeriSystemEvaluateEnergy(an->sys));
  PetscCall(PeriDamage(an->sys, &an->sys->bond_state.damage));
  PetscCall(an->snapshot(an->snapshotctx, name));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* particles_NNNN of the step just accepted, recorded as a frame of particles.pvd. */
static PetscErrorCode WriteSnapshot(PeriAnalysis an)
{
  QSData *data = (QSData *)an->data;
  char    name[64];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(name, sizeof(name), "particles_%04" PetscInt_FMT, QS(an)->nsteps));
  PetscCall(WriteState(an, name));
  if (data->nsnaps == data->capsnaps) {
    PetscInt *n;
    data->capsnaps = PetscMax(64, 2 * data->capsnaps);
    PetscCall(PetscMalloc1(data->capsnaps, &n));
    if (data->nsnaps) PetscCall(PetscArraycpy(n, data->snaps, data->nsnaps));
    PetscCall(PetscFree(data->snaps));
    data->snaps = n;
  }
  data->snaps[data->nsnaps++] = QS(an)->nsteps;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether the step just accepted (s, the last recorded) gets a snapshot: every output.every
 * steps, or by default (output.every 0) each step where bonds broke or more softened, the first
 * PERI_AUTO_SNAPSHOTS of them. */
static PetscBool SnapshotDue(PeriAnalysis an, const PeriStep *s)
{
  const PeriQuasistatic *q    = QS(an);
  const PetscInt         prev = q->nsteps > 1 ? q->steps[q->nsteps - 2].softened : 0;

  if (!an->vtk) return PETSC_FALSE;
  if (an->every) return (PetscBool)(q->nsteps % an->every == 0);
  return (PetscBool)((s->broken > 0 || s->softened != prev) && ((QSData *)an->data)->nsnaps < PERI_AUTO_SNAPSHOTS);
}

/* The load-displacement columns and the control type's default, as chosen. */
static PetscErrorCode PrintControl(PeriAnalysis an, const Settings *st)
{
  const char *comp = an->sys->model->components[st->component], *why;
  char        force[160];

  PetscFunctionBeginUser;
  if (!st->displacement)
    PetscCall(PetscSNPrintf(force, sizeof(force), "applied_load = lambda x %g along %s", (double)st->load, comp));
  else if (st->reaction >= 0)
    PetscCall(PetscSNPrintf(force, sizeof(force), "reaction = the reaction of region %s along %s", an->sys->disc.regions[st->reaction].name, comp));
  else
    PetscCall(PetscSNPrintf(force, sizeof(force), "none (no bc region holds %s: no reaction)", comp));
  PetscCall(PetscPrintf(an->comm, "perilin: %s control: control_u is %s of probe %s (%s); force column %s\n", st->displacement ? "displacement" : "load", comp, st->control ? st->control->name : "(none: 0)", st->chosen, force));
  if (st->runaway_given)
    why = "analysis.runaway_fraction";
  else if (st->displacement)
    why = "the default of displacement control: the run follows the softening branch past a load drop";
  else
    why = "the default of load control: a crack that runs away at one load is the failure";
  PetscCall(PetscPrintf(an->comm, "perilin: runaway_fraction %g (%s)\n", (double)st->runaway, why));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode PrintCriteria(PeriAnalysis an, const Settings *st)
{
  PetscFunctionBeginUser;
  if (st->quiet) PetscFunctionReturn(PETSC_SUCCESS);
  if (st->events)
    PetscCall(PetscPrintf(an->comm, "perilin: quasistatic to lambda %g from bond break to bond break (events, %s breaking)\n", (double)st->max, st->all ? "all-violators" : "most-critical-fraction"));
  else
    PetscCall(PetscPrintf(an->comm, "perilin: quasistatic to lambda %g in steps of %g (%s, %s breaking)\n", (double)st->max, (double)st->step, st->adaptive ? "adaptive" : "fixed", st->all ? "all-violators" : "most-critical-fraction"));
  PetscCall(PrintControl(an, st));
  PetscCall(PetscPrintf(an->comm, "perilin: failure:"));
  PetscCall(PeriFailureView(&an->sys->bond_state.failure, an->sys->model, an->comm));
  PetscCall(PetscPrintf(an->comm, " (formulas: docs/failure.md)\n"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The loop state that survives from step to step, and the step in progress: when it began (the
 * last equilibrium, or the loop's start) and how many trials it has taken so far. */
typedef struct {
  KSP            ksp;
  PetscInt       since_setup, nbonds, nhold, npieces, *hold;
  PetscReal     *held;
  PetscBool      lost, stale;
  PetscLogDouble mark;
  PetscInt       attempts;
} Loop;

/* How one trial load factor ended. */
typedef enum {
  TRIAL_SETTLED,
  TRIAL_FAILED,
  TRIAL_INTERRUPTED
} TrialEnd;

/* One solve at the load factor lam with the present bonds (pieces cut off from the constraints
 * held in place). *end is TRIAL_SETTLED when it converged, TRIAL_FAILED (with why) when the body
 * cannot carry the load, TRIAL_INTERRUPTED on a signal. */
static PetscErrorCode SolveAt(PeriAnalysis an, const Settings *st, Loop *L, PetscReal lam, PetscInt broken, PetscBool loose, PeriStep *s, TrialEnd *end, char why[], size_t len)
{
  PeriQuasistatic   *q = QS(an);
  KSPConvergedReason reason;
  PetscBool          ok, reuse;

  PetscFunctionBeginUser;
  *end = TRIAL_INTERRUPTED;
  PetscCall(PeriSignalReceived(an->comm, &an->sys->run.interrupted));
  if (an->sys->run.interrupted) PetscFunctionReturn(PETSC_SUCCESS);
  *end = TRIAL_FAILED;
  PetscCall(PeriProgressUpdate(an->sys->run.progress, PERI_PROGRESS_ANALYSIS, "step %" PetscInt_FMT ", load factor %g, %" PetscInt_FMT " bonds broken", q->nsteps + 1, (double)lam, broken));
  /* the pieces change only when bonds do */
  if (L->stale) {
    PetscCall(PetscFree2(L->hold, L->held));
    PetscCall(PeriPieces(an->sys, &L->nhold, &L->hold, &L->held, &L->npieces, &L->lost));
    L->stale = PETSC_FALSE;
  }
  if (L->lost) {
    /* cut off before any bond broke: the scene's own cracks did it, at every load */
    PetscCheck(broken > 0, an->comm, PETSC_ERR_USER_INPUT, "%s: the body is in %" PetscInt_FMT " pieces and a loaded one is not connected to the constraints: it cannot carry its load", an->sys->scene->file, L->npieces);
    PetscCall(PetscSNPrintf(why, len, "the load-carrying path is lost: a loaded piece is cut off (%" PetscInt_FMT " pieces)", L->npieces));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  /* a new preconditioner only when many bonds changed since the last one (or never built) */
  reuse = (PetscBool)(L->ksp && st->reuse && L->since_setup < PetscMax(1, L->nbonds / 1000));
  if (L->ksp) PetscCall(KSPSetReusePreconditioner(L->ksp, reuse));
  if (!reuse) {
    q->pc_setups++;
    L->since_setup = 0;
  }
  if (loose && L->ksp) { /* an intermediate solve of a cascade: its tolerance, then back */
    PetscReal rtol, atol, dtol;
    PetscInt  maxit;
    PetscCall(KSPGetTolerances(L->ksp, &rtol, &atol, &dtol, &maxit));
    PetscCall(KSPSetTolerances(L->ksp, PetscMax(rtol, PERI_CASCADE_RTOL), atol, dtol, maxit));
    PetscCall(PeriStaticSolve(an->sys, &L->ksp, lam, PETSC_FALSE, L->nhold, L->hold, L->held, &reason));
    PetscCall(PeriStaticConverged(an->sys, L->ksp, reason, &ok));
    PetscCall(KSPSetTolerances(L->ksp, rtol, atol, dtol, maxit));
  } else {
    PetscCall(PeriStaticSolve(an->sys, &L->ksp, lam, PETSC_FALSE, L->nhold, L->hold, L->held, &reason));
    PetscCall(PeriStaticConverged(an->sys, L->ksp, reason, &ok));
  }
  /* later solves start from the last solution: few bonds change between them */
  PetscCall(KSPSetInitialGuessNonzero(L->ksp, PETSC_TRUE));
  q->solves++;
  s->ksp_iterations += an->sys->fields.solve.iterations;
  PetscCall(PeriSignalReceived(an->comm, &an->sys->run.interrupted));
  if (an->sys->run.interrupted) {
    *end = TRIAL_INTERRUPTED;
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  if (!ok) {
    /* the body as set up is linear: a solve that fails before any bond broke fails at every
       load, so it is the solver's failure, not the body's */
    if (broken == 0) PetscCall(PeriStaticCheckConverged(an->sys, reason));
    PetscCall(PetscSNPrintf(why, len, "the solve failed (%s, true relative residual %.3g): the body can no longer carry the load", KSPConvergedReasons[reason], (double)an->sys->fields.solve.residual_norm));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  *end = TRIAL_SETTLED;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Solve, break, solve again at the load factor trial until no bond breaks (or the body fails).
 * runaway: whether a cascade past st->runaway of the bonds ends the trial. event: the present
 * state is already the solution at trial (scaled from the last equilibrium, stepping by events),
 * so the first round breaks without a solve, and the cascade's intermediate solves stop at
 * PERI_CASCADE_RTOL; a tight solve confirms every equilibrium before it is accepted. */
static PetscErrorCode Trial(PeriAnalysis an, const Settings *st, Loop *L, PetscReal trial, PetscInt total, PetscBool runaway, PetscBool event, PeriStep *s, TrialEnd *end, char why[], size_t len)
{
  PetscBool loose = PETSC_FALSE; /* the present solution is a cascade's intermediate one */

  PetscFunctionBeginUser;
  *end = TRIAL_FAILED;
  for (s->iterations = 0; s->iterations < st->max_iterations; s->iterations++) {
    PetscInt nb;
    if (!(event && s->iterations == 0)) {
      PetscCall(SolveAt(an, st, L, trial, total + s->broken, loose, s, end, why, len));
      if (*end != TRIAL_SETTLED) PetscFunctionReturn(PETSC_SUCCESS);
    }
    PetscCall(PeriBondsBreak(an->sys, an->sys->fields.u, st->all, st->fraction, &nb, NULL));
    L->stale = (PetscBool)(nb > 0);
    if (!nb && !loose) {
      *end = TRIAL_SETTLED;
      PetscFunctionReturn(PETSC_SUCCESS);
    }
    loose = (PetscBool)(event && nb > 0); /* none broke after a loose solve: confirm it tightly */
    *end  = TRIAL_FAILED;
    s->broken += nb;
    L->since_setup += nb;
    /* a twist carried by the bonds themselves loses the broken bonds' share */
    if (nb && an->sys->conditions.torsion.active && !an->sys->conditions.layers.nfaces) PetscCall(PeriLoadsAssemble(an->sys, an->sys->fields.f));
    if (runaway && s->broken > st->runaway * L->nbonds) {
      /* a crack running away at this load: a smaller step tells whether it would settle */
      PetscCall(PetscSNPrintf(why, len, "runaway: %" PetscInt_FMT " bonds (more than %g of them) broke at this load without equilibrium", s->broken, (double)st->runaway));
      PetscFunctionReturn(PETSC_SUCCESS);
    }
  }
  PetscCall(PetscSNPrintf(why, len, "no equilibrium after %" PetscInt_FMT " iterations: bonds keep breaking at this load", st->max_iterations));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The body failed at trial: the trial's state goes to failed_trial.vtu (named as such), and
 * everything else describes the last equilibrium. */
static PetscErrorCode Failed(PeriAnalysis an, PeriCheckpoint *eq, PetscReal trial, const PeriStep *s, const char why[])
{
  PeriQuasistatic *q = QS(an);

  PetscFunctionBeginUser;
  q->failed               = PETSC_TRUE;
  q->critical_load_factor = trial;
  q->failure_step         = q->nsteps + 1;
  q->failed_trial_broken  = s->broken;
  PetscCall(PetscStrncpy(q->ending, why, sizeof(q->ending)));
  if (an->vtk && an->sys->fields.u) PetscCall(WriteState(an, "failed_trial"));
  PetscCall(PeriDamage(an->sys, &q->trial_damage)); /* where the failure went, for the caller */
  PetscCall(PeriCheckpointRestore(an->sys, eq, PETSC_FALSE, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* An accepted step: recorded, reported, saved, and the next step size chosen. */
static PetscErrorCode Accept(PeriAnalysis an, const Settings *st, PeriCheckpoint *eq, PeriStep *s, PetscReal *dl, Loop *L)
{
  PeriQuasistatic *q       = QS(an);
  const PetscInt   changes = s->broken; /* bonds broken or softened by more than 1 %, in every round */
  PetscLogDouble   t;

  PetscFunctionBeginUser;
  /* what the step reports: bonds counted once, dead ones apart from softened ones */
  PetscCall(PeriBondsCount(an->sys, &s->broken_total, &s->softened));
  s->broken = s->broken_total - q->broken_bonds;
  PetscCall(ControlValue(an, st->control, st->component, &s->control_u));
  /* the reactions of this equilibrium (and the check that they balance the loads) */
  PetscCall(PeriSystemEvaluateReactions(an->sys, s->lambda));
  s->imbalance = an->sys->conditions.reactions.relative_imbalance;
  if (st->reaction >= 0) s->reaction = an->sys->conditions.reactions.force[st->reaction * PERI_MAX_DOF + st->component];
  /* the step's time runs from the step before, so that it holds the attempts retried with a
     smaller increment and the steps' times add up to the loop's (with unfinished_s) */
  PetscCall(PetscTime(&t));
  s->seconds  = t - L->mark;
  s->attempts = PetscMax(L->attempts, 1); /* an event's scaled state takes no trial of its own */
  L->mark     = t;
  L->attempts = 0;
  PetscCall(RecordStep(q, s, &an->sys->conditions.reactions));
  q->peak_load_factor = s->lambda;
  q->broken_bonds     = s->broken_total;
  PetscCall(PeriCheckpointSave(an->sys, eq));
  PetscCall(Progress(an, st, s));
  if (SnapshotDue(an, s)) PetscCall(WriteSnapshot(an));
  /* a run stopped here for a test takes the path of an interrupted one: the next poll ends it */
  if (q->nsteps == ((QSData *)an->data)->stop_after) PeriSignalSimulate(SIGINT);
  /* many breaks: smaller steps; none: back towards the scene's step */
  if (st->adaptive) *dl = changes > L->nbonds / 100 ? PetscMax(0.5 * *dl, st->min_step) : changes ? *dl
                                                                                                  : PetscMin(2 * *dl, st->step);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The numbers of one step in a checkpoint: PeriStep as reals and integers (a viewer has no struct). */
#define PERI_STEP_REALS 5
#define PERI_STEP_INTS  6

static void StepPack(const PeriStep *s, PetscReal r[], PetscInt n[])
{
  r[0] = s->lambda, r[1] = s->control_u, r[2] = s->seconds, r[3] = s->reaction, r[4] = s->imbalance;
  n[0] = s->broken, n[1] = s->broken_total, n[2] = s->iterations, n[3] = s->ksp_iterations, n[4] = s->softened, n[5] = s->attempts;
}

static void StepUnpack(const PetscReal r[], const PetscInt n[], PeriStep *s)
{
  s->lambda = r[0], s->control_u = r[1], s->seconds = r[2], s->reaction = r[3], s->imbalance = r[4];
  s->broken = n[0], s->broken_total = n[1], s->iterations = n[2], s->ksp_iterations = n[3], s->softened = n[4], s->attempts = n[5];
}

/* Room for n steps (and their reactions) and n snapshots, on reading a checkpoint. */
static PetscErrorCode StepsAllocate(PeriAnalysis an, PetscInt n, PetscInt nsnaps)
{
  PeriQuasistatic *q    = QS(an);
  QSData          *data = (QSData *)an->data;

  PetscFunctionBeginUser;
  PetscCall(PetscFree2(q->steps, q->reactions));
  PetscCall(PetscFree(data->snaps));
  q->cap = PetscMax(64, n);
  PetscCall(PetscMalloc2(q->cap, &q->steps, q->cap * an->sys->conditions.reactions.nregions * PERI_MAX_DOF, &q->reactions));
  data->capsnaps = PetscMax(64, nsnaps);
  PetscCall(PetscMalloc1(data->capsnaps, &data->snaps));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The steps so far (steps.csv's rows as sr, si: PERI_STEP_REALS and PERI_STEP_INTS each, and their
 * reactions) and the snapshots written, into v or (write false) from v, checked finite. */
static PetscErrorCode StepsBinary(PeriAnalysis an, PetscViewer v, PetscReal sr[], PetscInt si[], PetscBool write)
{
  PeriQuasistatic *q    = QS(an);
  QSData          *data = (QSData *)an->data;
  const PetscInt   w    = an->sys->conditions.reactions.nregions * PERI_MAX_DOF;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; write && k < q->nsteps; k++) StepPack(&q->steps[k], &sr[k * PERI_STEP_REALS], &si[k * PERI_STEP_INTS]);
  if (write) {
    PetscCall(PetscViewerBinaryWrite(v, sr, q->nsteps * PERI_STEP_REALS, PETSC_REAL));
    PetscCall(PetscViewerBinaryWrite(v, si, q->nsteps * PERI_STEP_INTS, PETSC_INT));
    PetscCall(PetscViewerBinaryWrite(v, q->reactions, q->nsteps * w, PETSC_REAL));
    PetscCall(PetscViewerBinaryWrite(v, data->snaps, data->nsnaps, PETSC_INT));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscViewerBinaryRead(v, sr, q->nsteps * PERI_STEP_REALS, NULL, PETSC_REAL));
  PetscCall(PetscViewerBinaryRead(v, si, q->nsteps * PERI_STEP_INTS, NULL, PETSC_INT));
  PetscCall(PetscViewerBinaryRead(v, q->reactions, q->nsteps * w, NULL, PETSC_REAL));
  PetscCall(PetscViewerBinaryRead(v, data->snaps, data->nsnaps, NULL, PETSC_INT));
  PetscCall(PeriAnalysisCheckpointFinite(an, sr, q->nsteps * PERI_STEP_REALS, NULL, "steps' load factors, displacements and times"));
  PetscCall(PeriAnalysisCheckpointFinite(an, q->reactions, q->nsteps * w, NULL, "steps' reactions"));
  for (PetscInt k = 0; k < q->nsteps; k++) StepUnpack(&sr[k * PERI_STEP_REALS], &si[k * PERI_STEP_INTS], &q->steps[k]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The loop's state at an equilibrium, besides the bonds and u (PeriCheckpointView): the load factor
 * and the next step, the counters, the steps so far (steps.csv's rows and their reactions) and the
 * snapshots written (particles.pvd's frames). write: into v, else from v. Collective. */
static PetscErrorCode StateBinary(PeriAnalysis an, PetscViewer v, PetscReal *lambda, PetscReal *dl, PetscBool write)
{
  PeriQuasistatic *q    = QS(an);
  QSData          *data = (QSData *)an->data;
  const PetscInt   w    = an->sys->conditions.reactions.nregions * PERI_MAX_DOF;
  PetscReal        r[2] = {*lambda, *dl}, *sr;
  PetscInt         n[5] = {q->nsteps, q->pc_setups, q->solves, data->nsnaps, w}, *si;
  PetscErrorCode   ierr;

  PetscFunctionBeginUser;
  if (write) {
    PetscCall(PetscViewerBinaryWrite(v, r, 2, PETSC_REAL));
    PetscCall(PetscViewerBinaryWrite(v, n, 5, PETSC_INT));
  } else {
    PetscCall(PetscViewerBinaryRead(v, r, 2, NULL, PETSC_REAL));
    PetscCall(PetscViewerBinaryRead(v, n, 5, NULL, PETSC_INT));
    PetscCheck(n[4] == w && n[0] > 0, an->comm, PETSC_ERR_USER_INPUT, "-restart: the checkpoint's steps do not fit this scene's reaction regions: restart with the scene of the run that wrote it");
    /* counts and the load factor from the file, checked before they size anything (found by
       tests/fuzz/fuzz_checkpoint.c: a count of 2^62 steps) */
    PetscCall(PeriAnalysisCheckpointFits(an, v, n[0], (PERI_STEP_REALS + w) * sizeof(PetscReal) + PERI_STEP_INTS * sizeof(PetscInt)));
    PetscCall(PeriAnalysisCheckpointFits(an, v, n[3], sizeof(PetscInt)));
    PetscCheck(n[3] >= 0 && n[1] >= 0 && n[2] >= 0 && r[0] >= 0 && r[0] <= ST(an)->max && r[1] > 0 && r[1] <= ST(an)->max, an->comm, PETSC_ERR_USER_INPUT, "-restart: the checkpoint is damaged (its counts or its load factor %g and step %g are out of range for load_factor_max %g): restart from an undamaged checkpoint, or run the scene from the start", (double)r[0], (double)r[1], (double)ST(an)->max);
    PetscCall(StepsAllocate(an, n[0], n[3]));
    *lambda = r[0], *dl = r[1];
    q->nsteps = n[0], q->pc_setups = n[1], q->solves = n[2], data->nsnaps = n[3];
  }
  PetscCall(PetscMalloc2(q->nsteps * PERI_STEP_REALS, &sr, q->nsteps * PERI_STEP_INTS, &si));
  ierr = StepsBinary(an, v, sr, si, write);
  PetscCall(PetscFree2(sr, si)); /* a refused checkpoint too (found by tests/fuzz/fuzz_checkpoint.c) */
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* What a checkpoint holds of the equilibrium eq from which the loop goes on at lambda with dl. */
typedef struct {
  const PeriCheckpoint *eq;
  PetscReal             lambda, dl;
} CheckpointState;

static PetscErrorCode CheckpointBody(PeriAnalysis an, PetscViewer v, void *ctx)
{
  CheckpointState *c = (CheckpointState *)ctx;

  PetscFunctionBeginUser;
  PetscCall(StateBinary(an, v, &c->lambda, &c->dl, PETSC_TRUE));
  PetscCall(PeriCheckpointView(an->sys, c->eq, v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* After an accepted equilibrium (eq, just saved) from which the loop goes on at lambda with the
 * step dl: its checkpoint, every -peri_checkpoint_every steps (checkpoint.c). Collective. */
static PetscErrorCode WriteCheckpoint(PeriAnalysis an, const PeriCheckpoint *eq, PetscReal lambda, PetscReal dl)
{
  PeriQuasistatic *q = QS(an);
  CheckpointState  c = {eq, lambda, dl};
  PetscLogDouble   t0, t1;

  PetscFunctionBeginUser;
  if (!an->checkpoint_every || q->nsteps % an->checkpoint_every) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscTime(&t0));
  PetscCall(PeriAnalysisCheckpointWrite(an, CheckpointBody, &c));
  PetscCall(PetscTime(&t1));
  q->checkpoints++;
  q->checkpoint_s += t1 - t0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* -restart: the loop's state, the bonds and u of the checkpoint, K assembled for those bonds, and a
 * KSP that starts from u, as the interrupted run's next solve did. Its preconditioner is built
 * anew (the interrupted run's came from an earlier K): the next solves agree with the interrupted
 * run's to the solver's tolerance, not bit for bit. Collective. */
static PetscErrorCode Restart(PeriAnalysis an, Loop *L, PeriCheckpoint *eq, PetscReal *lambda, PetscReal *dl)
{
  PeriQuasistatic *q = QS(an);
  PetscViewer      v;
  char             file[PETSC_MAX_PATH_LEN + 32];
  PetscErrorCode   ierr;

  PetscFunctionBeginUser;
  PetscCall(PeriAnalysisRestartBegin(an, &v, file, sizeof(file)));
  /* PETSc's refusals of a damaged file are said by PeriAnalysisRestartEnd, naming the file */
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  ierr = StateBinary(an, v, lambda, dl, PETSC_FALSE);
  if (!ierr) ierr = PeriCheckpointLoad(an->sys, eq, v, file);
  PetscCall(PetscPopErrorHandler());
  PetscCall(PeriAnalysisRestartEnd(an, &v, file, ierr)); /* a refused checkpoint is closed too */
  PetscCall(PeriCheckpointRestore(an->sys, eq, PETSC_TRUE, PETSC_TRUE));
  PetscCall(PeriAnalysisAdoptSnapshots(an, &((QSData *)an->data)->nsnaps, ((QSData *)an->data)->snaps, NULL));
  q->peak_load_factor = q->steps[q->nsteps - 1].lambda;
  q->broken_bonds     = q->steps[q->nsteps - 1].broken_total;
  q->restart_step     = q->nsteps;
  L->stale            = PETSC_TRUE;
  L->since_setup      = L->nbonds; /* a new preconditioner at the first solve, counted */
  PetscCall(PeriStaticKSPCreate(an->sys, an->sys->fields.solve.symmetric, &L->ksp));
  PetscCall(KSPSetInitialGuessNonzero(L->ksp, PETSC_TRUE));
  if (!ST(an)->quiet) PetscCall(PetscPrintf(an->comm, "perilin: restarted from %s: step %" PetscInt_FMT " at load factor %g, %" PetscInt_FMT " bonds broken\n", file, q->nsteps, (double)*lambda, q->broken_bonds));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* said (log and summary) when the body failed before any bond broke in an equilibrium */
#define PERI_INTACT_NOTE "no bond broke before the last equilibrium: particles.vtu shows the body before the crack grew (the scene's cracks only); failed_trial.vtu shows where it went"

static PetscErrorCode Finish(PeriAnalysis an, const Settings *st)
{
  PeriQuasistatic *q        = QS(an);
  char             soft[48] = "";

  PetscFunctionBeginUser;
  q->complete = an->sys->run.interrupted ? PETSC_FALSE : PETSC_TRUE;
  if (an->sys->run.interrupted)
    PetscCall(PetscSNPrintf(q->ending, sizeof(q->ending), "interrupted (%s): the results at the last equilibrium", PeriSignalName(an->sys->run.interrupted)));
  else if (!q->failed && (q->broken_bonds || (q->nsteps && q->steps[q->nsteps - 1].softened)))
    PetscCall(PetscSNPrintf(q->ending, sizeof(q->ending), "reached lambda = %g, %" PetscInt_FMT " bonds broken and %" PetscInt_FMT " softened on the way (an equilibrium at every step)", (double)st->max, q->broken_bonds, q->nsteps ? q->steps[q->nsteps - 1].softened : 0));
  else if (!q->failed)
    PetscCall(PetscSNPrintf(q->ending, sizeof(q->ending), "reached lambda = %g without failure", (double)st->max));
  PetscCall(PeriSystemEvaluateEnergy(an->sys));
  PetscCall(PeriSystemEvaluateReactions(an->sys, q->peak_load_factor));
  PetscCall(PeriDamage(an->sys, &an->sys->bond_state.damage));
  if (st->quiet) PetscFunctionReturn(PETSC_SUCCESS);
  if (an->sys->bond_state.failure.softening && q->nsteps) PetscCall(PetscSNPrintf(soft, sizeof(soft), " (%" PetscInt_FMT " softened)", q->steps[q->nsteps - 1].softened));
  PetscCall(PetscPrintf(an->comm, "perilin: quasistatic: %s; last equilibrium at load factor %g, %" PetscInt_FMT " bonds broken%s, %" PetscInt_FMT " solves, %" PetscInt_FMT " preconditioner set-ups\n", q->ending, (double)q->peak_load_factor, q->broken_bonds, soft, q->solves, q->pc_setups));
  if (q->failed) PetscCall(PetscPrintf(an->comm, "perilin: critical load factor %g (failure between %g and %g, in step %" PetscInt_FMT ": %" PetscInt_FMT " attempt(s), %.2f s)\n", (double)q->critical_load_factor, (double)q->peak_load_factor, (double)q->critical_load_factor, q->failure_step, q->unfinished_attempts, (double)q->unfinished_s));
  if (q->failed && !q->broken_bonds) PetscCall(PetscPrintf(an->comm, "perilin: note: %s\n", PERI_INTACT_NOTE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The next event: the smallest load factor at which an intact bond fails, from the present
 * solution at load factor lam (the response to the scaled load is lam times the unit one).
 * Collective. */
static PetscErrorCode NextEvent(PeriAnalysis an, PetscReal lam, PetscReal *next)
{
  PeriBonds     *b  = &an->sys->disc.bonds;
  PeriModel      m  = an->sys->model;
  const PetscInt bs = m->dofs;
  PetscScalar   *u;

  PetscFunctionBeginUser;
  *next = PETSC_INFINITY;
  PetscCall(PeriSystemLocalDOFs(an->sys, an->sys->fields.u, &u));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PeriBondGeometry g;
      PetscReal        ui[PERI_MAX_DOF], uj[PERI_MAX_DOF], meas[PERI_MAX_MEASURE];
      if (!b->live[k] || b->j[k] == i) continue;
      PetscCall(PeriSystemBondGeometry(an->sys, i, k, &g));
      for (PetscInt c = 0; c < bs; c++) {
        ui[c] = PetscRealPart(u[i * bs + c]) / lam;
        uj[c] = PetscRealPart(u[g.j * bs + c]) / lam;
      }
      m->ops.bond_measures(m, &g, ui, uj, meas);
      *next = PetscMin(*next, PeriBondCriticalLoad(an->sys, &g, meas, m->nmeasures));
    }
  PetscCall(PetscFree(u));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, next, 1, MPIU_REAL, MPI_MIN, an->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* An equilibrium at load factor lam without a solve: the present state, whose response is linear
 * in the load factor until the next break, scaled from the load factor it was solved at. */
static PetscErrorCode AcceptScaled(PeriAnalysis an, const Settings *st, PeriCheckpoint *eq, PetscReal *at, PetscReal lam, PeriStep *solved, Loop *L)
{
  PeriStep  s  = {0};
  PetscReal dl = 0;

  PetscFunctionBeginUser;
  /* the solves that found this state (the first: the intact body's) count here */
  s.ksp_iterations       = solved->ksp_iterations;
  solved->ksp_iterations = 0;
  PetscCall(VecScale(an->sys->fields.u, lam / *at));
  *at            = lam;
  s.lambda       = lam;
  s.broken_total = QS(an)->broken_bonds;
  PetscCall(Accept(an, st, eq, &s, &dl, L));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sequentially linear stepping (stepping: events): the body is linear between breaks, so the load
 * factor of the next break is computed, not searched. From the present solution each intact
 * bond's critical load factor follows in closed form; the smallest is the next event. The state
 * scaled to it is an equilibrium (a step of steps.csv, the peak before the break); just past it
 * (PERI_EVENT_WINDOW) that bond and the cascade it starts break until equilibrium (the next step)
 * or failure. The load-displacement path comes out as its saw-tooth, event by event, with no
 * bisection and no retries. */
#define PERI_EVENT_WINDOW 1e-6
static PetscErrorCode RunEvents(PeriAnalysis an, const Settings *st, Loop *L, PeriCheckpoint *eq)
{
  PetscReal lambda = st->max;
  PeriStep  s0     = {0};
  TrialEnd  end;
  char      why[160] = "";

  PetscFunctionBeginUser;
  /* the intact body solved once, at the largest load factor: its response at any other is a
     multiple (no bond breaks in this solve); or the equilibrium of a checkpoint */
  if (an->restart[0]) {
    PetscReal dl;
    PetscCall(Restart(an, L, eq, &lambda, &dl));
    end = TRIAL_SETTLED;
  } else
    PetscCall(SolveAt(an, st, L, lambda, 0, PETSC_FALSE, &s0, &end, why, sizeof(why)));
  while (end == TRIAL_SETTLED) {
    PetscReal next, trial;
    PeriStep  s = {0};
    PetscCall(NextEvent(an, lambda, &next));
    if (next * (1 + PERI_EVENT_WINDOW) >= st->max) {
      PetscCall(AcceptScaled(an, st, eq, &lambda, st->max, &s0, L));
      break;
    }
    PetscCall(AcceptScaled(an, st, eq, &lambda, next, &s0, L));
    trial = next * (1 + PERI_EVENT_WINDOW);
    PetscCall(VecScale(an->sys->fields.u, trial / lambda)); /* the same bonds: the solution at trial */
    L->attempts++;
    PetscCall(Trial(an, st, L, trial, QS(an)->broken_bonds, PETSC_TRUE, PETSC_TRUE, &s, &end, why, sizeof(why)));
    if (end == TRIAL_FAILED) PetscCall(Failed(an, eq, trial, &s, why));
    if (end != TRIAL_SETTLED) break;
    lambda         = trial;
    s.lambda       = lambda;
    s.broken_total = QS(an)->broken_bonds + s.broken;
    {
      PetscReal dl = 0;
      PetscCall(Accept(an, st, eq, &s, &dl, L));
      /* the state at the top of this loop: a restart goes on from here */
      PetscCall(WriteCheckpoint(an, eq, lambda, dl));
    }
  }
  if (end == TRIAL_INTERRUPTED) PetscCall(PeriCheckpointRestore(an->sys, eq, PETSC_FALSE, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Incremental stepping (stepping: increments): steps of load_factor_step; with adaptive steps a
 * failed trial is retried from the last equilibrium with half the step, down to min_step, so the
 * critical load factor is bracketed. */
static PetscErrorCode RunIncrements(PeriAnalysis an, const Settings *st, Loop *L, PeriCheckpoint *eq)
{
  PetscReal lambda = 0, dl = st->step;

  PetscFunctionBeginUser;
  if (an->restart[0]) PetscCall(Restart(an, L, eq, &lambda, &dl));
  while (lambda < st->max * (1 - 1e-12)) {
    PetscReal trial = PetscMin(lambda + dl, st->max);
    PeriStep  s     = {0};
    TrialEnd  end;
    char      why[160] = "";
    L->attempts++;
    PetscCall(Trial(an, st, L, trial, QS(an)->broken_bonds, st->adaptive, PETSC_FALSE, &s, &end, why, sizeof(why)));
    if (end == TRIAL_INTERRUPTED) {
      PetscCall(PeriCheckpointRestore(an->sys, eq, PETSC_FALSE, PETSC_TRUE));
      break;
    }
    if (end == TRIAL_FAILED && st->adaptive && dl > st->min_step * (1 + 1e-12)) {
      /* back to the last equilibrium, with half the step */
      PetscCall(PeriCheckpointRestore(an->sys, eq, PETSC_TRUE, PETSC_FALSE));
      L->stale       = PETSC_TRUE;
      L->since_setup = L->nbonds;
      dl             = PetscMax(0.5 * dl, st->min_step);
      continue;
    }
    if (end == TRIAL_FAILED) {
      PetscCall(Failed(an, eq, trial, &s, why));
      break;
    }
    lambda         = trial;
    s.lambda       = lambda;
    s.broken_total = QS(an)->broken_bonds + s.broken;
    PetscCall(Accept(an, st, eq, &s, &dl, L));
    PetscCall(WriteCheckpoint(an, eq, lambda, dl));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisRun_Quasistatic - the load-stepping loop with bond failure, by increments or by
  events. The results (fields, probes, energies, damage) describe the last equilibrium; a failed
  trial is written apart as failed_trial.vtu. Collective.
@*/
static PetscErrorCode PeriAnalysisRun_Quasistatic(PeriAnalysis an)
{
  const Settings *st = ST(an);
  Loop            L  = {0};
  PeriCheckpoint  eq = {0};
  PetscLogDouble  t0, t;
  PetscErrorCode  ierr;

  PetscFunctionBeginUser;
  QS(an)->started = PETSC_TRUE;
  PetscCall(PeriStaticDefaultMatType(an->sys->stiffness.mat_type, sizeof(an->sys->stiffness.mat_type)));
  PetscCall(PeriSystemAssemble(an->sys));
  PetscCall(PeriCheckpointCreate(an->sys, &eq));
  PetscCallMPI(MPI_Allreduce(&an->sys->disc.bonds.nbonds, &L.nbonds, 1, MPIU_INT, MPI_SUM, an->comm));
  L.stale = PETSC_TRUE;
  PetscCall(PetscTime(&t0));
  L.mark = t0;
  PetscCall(PrintCriteria(an, st));
  /* the loop's solver and equilibrium are freed whatever the outcome: a refused -restart
     checkpoint is an input error of a process that may go on (the Python module; found by
     tests/fuzz/fuzz_checkpoint.c) */
  ierr = st->events ? RunEvents(an, st, &L, &eq) : RunIncrements(an, st, &L, &eq);
  PetscCall(KSPDestroy(&L.ksp));
  PetscCall(PetscFree2(L.hold, L.held));
  PetscCall(PeriCheckpointDestroy(&eq));
  PetscCall(ierr);
  PetscCall(PetscTime(&t));
  an->sys->run.log.solve_s    = t - t0;
  QS(an)->unfinished_s        = t - L.mark;
  QS(an)->unfinished_attempts = L.attempts;
  PetscCall(Finish(an, st));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The steps.csv column of the load-displacement curve's force: applied_load (load control), the
 * reaction region's reaction (displacement control), or NULL (displacement control without one). */
static const char *ForceColumn(PeriAnalysis an)
{
  if (!ST(an)->displacement) return "applied_load";
  return QS(an)->reaction_region >= 0 ? "reaction" : NULL;
}

/* steps.csv's force columns: the reaction region's reaction, the applied load (load control), the
 * relative imbalance, then R_<region>_<component> for every component a bc item holds on a region; step k's values, or
 * the header when k < 0. Returns nonzero when a write failed. */
static int ReactionColumns(PeriAnalysis an, FILE *fp, PetscInt k)
{
  const PeriQuasistatic *q   = QS(an);
  const PeriReactions   *R   = &an->sys->conditions.reactions;
  int                    bad = 0;

  if (q->reaction_region >= 0) bad |= (k < 0 ? fprintf(fp, ",reaction") : fprintf(fp, ",%.10g", (double)q->steps[k].reaction)) < 0;
  if (!ST(an)->displacement) bad |= (k < 0 ? fprintf(fp, ",applied_load") : fprintf(fp, ",%.10g", (double)(q->steps[k].lambda * ST(an)->load))) < 0;
  bad |= (k < 0 ? fprintf(fp, ",relative_imbalance") : fprintf(fp, ",%.3g", (double)q->steps[k].imbalance)) < 0;
  for (PetscInt r = 0; r < R->nregions; r++)
    for (PetscInt c = 0; c < an->sys->model->dofs; c++) {
      if (!R->holds[r * PERI_MAX_DOF + c]) continue;
      if (k < 0)
        bad |= fprintf(fp, ",R_%s_%s", an->sys->disc.regions[r].name, an->sys->model->components[c]) < 0;
      else
        bad |= fprintf(fp, ",%.10g", (double)q->reactions[(k * R->nregions + r) * PERI_MAX_DOF + c]) < 0;
    }
  return bad;
}

/* steps.csv's text: the header, then one row per load step. Returns nonzero when a write failed. */
static int StepsRows(PeriAnalysis an, FILE *fp)
{
  int bad = 0;

  bad |= fprintf(fp, "step,load_factor,control_u,broken,broken_total,softened,equilibrium_iterations,ksp_iterations,seconds,attempts") < 0;
  bad |= ReactionColumns(an, fp, -1);
  bad |= fprintf(fp, "\n") < 0;
  for (PetscInt k = 0; k < QS(an)->nsteps; k++) {
    const PeriStep *s = &QS(an)->steps[k];
    bad |= fprintf(fp, "%" PetscInt_FMT ",%.10g,%.10g,%" PetscInt_FMT ",%" PetscInt_FMT ",%" PetscInt_FMT ",%" PetscInt_FMT ",%" PetscInt_FMT ",%.4f,%" PetscInt_FMT, k + 1, (double)s->lambda, (double)s->control_u, s->broken, s->broken_total, s->softened, s->iterations, s->ksp_iterations, (double)s->seconds, s->attempts) < 0;
    bad |= ReactionColumns(an, fp, k);
    bad |= fprintf(fp, "\n") < 0;
  }
  return bad;
}

/* steps.csv: one row per load step. Rank 0 writes (temporary name, then rename). */
static PetscErrorCode PeriWriteStepsCSV(PeriAnalysis an, const char path[])
{
  PetscFunctionBeginUser;
  PetscCall(PeriAnalysisWriteTable(an, QS(an)->started, StepsRows, path, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* steps.csv's text into fp for the embedding (rank 0; nothing before the loop began). */
static PetscErrorCode QSTable(PeriAnalysis an, FILE *fp)
{
  PetscFunctionBeginUser;
  PetscCall(PeriAnalysisWriteTable(an, QS(an)->started, StepsRows, NULL, fp));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  WriteSnapshotsPVD - particles.pvd: the snapshots particles_NNNN.vtu of the accepted steps
  (output.every, or by default those where bonds broke) with the load factor as the time, and,
  when the last equilibrium is not one of them, particles.vtu (which describes it) as the last
  frame, so that the series ends where the run did (on several ranks the frames are the .pvtu
  indexes). failed_trial.vtu is no equilibrium and stays out. Rank 0 writes. Collective.
@*/
static PetscErrorCode WriteSnapshotsPVD(PeriAnalysis an, const char path[])
{
  PeriQuasistatic *q    = QS(an);
  QSData          *data = (QSData *)an->data;
  PetscReal       *times;
  char           **files;
  PetscInt         n = 0;
  char             base[32];

  PetscFunctionBeginUser;
  if (an->rank || !q->started || !an->vtk || q->nsteps < 1) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc2(data->nsnaps + 1, &times, data->nsnaps + 1, &files));
  for (PetscInt k = 0; k < data->nsnaps; k++) {
    times[n] = q->steps[data->snaps[k] - 1].lambda;
    PetscCall(PetscSNPrintf(base, sizeof(base), "particles_%04" PetscInt_FMT, data->snaps[k]));
    PetscCall(PetscMalloc1(40, &files[n]));
    PetscCall(PeriParticlesFileName(an->comm, base, files[n++], 40));
  }
  if (!data->nsnaps || data->snaps[data->nsnaps - 1] != q->nsteps) {
    times[n] = q->steps[q->nsteps - 1].lambda;
    PetscCall(PetscMalloc1(40, &files[n]));
    PetscCall(PeriParticlesFileName(an->comm, "particles", files[n++], 40));
  }
  PetscCall(PeriWritePVD(path, n, times, (const char *const *)files));
  for (PetscInt k = 0; k < n; k++) PetscCall(PetscFree(files[k]));
  PetscCall(PetscFree2(times, files));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* summary.json's "quasistatic" object: the path's end, the critical load, what broke. */
static PetscErrorCode QSSummary(PeriAnalysis an, PeriJSON j)
{

  PetscFunctionBeginUser;
  if (!QS(an)->started) PetscFunctionReturn(PETSC_SUCCESS);
  const PeriQuasistatic *q = QS(an);
  PetscCall(PeriJSONBeginObject(j, "quasistatic"));
  PetscCall(PeriJSONInt(j, "steps", q->nsteps));
  PetscCall(PeriJSONString(j, "state", "last equilibrium"));
  PetscCall(PeriJSONString(j, "stepping", q->stepping));
  PetscCall(PeriJSONReal(j, "peak_load_factor", q->peak_load_factor));
  if (q->failed) {
    PetscCall(PeriJSONReal(j, "critical_load_factor", q->critical_load_factor));
    PetscCall(PeriJSONInt(j, "failure_step", q->failure_step));
    PetscCall(PeriJSONInt(j, "failed_trial_broken_bonds", q->failed_trial_broken));
  }
  PetscCall(PeriJSONInt(j, "broken_bonds", q->broken_bonds));
  if (q->nsteps) PetscCall(PeriJSONInt(j, "softened_bonds", q->steps[q->nsteps - 1].softened));
  PetscCall(PeriJSONInt(j, "precracked_bonds", an->sys->bond_state.failure.precracked_bonds));
  PetscCall(PeriJSONBool(j, "failed", q->failed));
  PetscCall(PeriJSONBool(j, "complete", q->complete));
  PetscCall(PeriJSONString(j, "ending", q->ending));
  PetscCall(PeriJSONInt(j, "solves", q->solves));
  PetscCall(PeriJSONInt(j, "preconditioner_setups", q->pc_setups));
  if (q->control[0]) PetscCall(PeriJSONString(j, "control_probe", q->control));
  PetscCall(PeriJSONString(j, "control_component", an->sys->model->components[q->control_component]));
  if (q->reaction_region >= 0) PetscCall(PeriJSONString(j, "reaction_region", an->sys->disc.regions[q->reaction_region].name));
  PetscCall(PeriJSONString(j, "control", ST(an)->displacement ? "displacement" : "load"));
  if (ForceColumn(an)) PetscCall(PeriJSONString(j, "force_column", ForceColumn(an)));
  if (!ST(an)->displacement) PetscCall(PeriJSONReal(j, "applied_load_per_load_factor", ST(an)->load));
  PetscCall(PeriJSONReal(j, "runaway_fraction", ST(an)->runaway));
  PetscCall(PeriJSONInt(j, "checkpoints", q->checkpoints));
  PetscCall(PeriJSONReal(j, "checkpoint_s", q->checkpoint_s));
  PetscCall(PeriJSONReal(j, "unfinished_s", q->unfinished_s));
  PetscCall(PeriJSONInt(j, "unfinished_attempts", q->unfinished_attempts));
  if (q->restart_step) PetscCall(PeriJSONString(j, "restarted_from", an->restart));
  if (q->restart_step) PetscCall(PeriJSONInt(j, "restart_step", q->restart_step));
  if (q->failed && !q->broken_bonds) PetscCall(PeriJSONString(j, "note", PERI_INTACT_NOTE));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* load_displacement.png from steps.csv (output.plots), with the facts summary.json will hold. */
static PetscErrorCode QSPlots(PeriAnalysis an, const char dir[])
{
  const PeriQuasistatic *q = QS(an);
  char                   arg[8][PERI_NAME_LEN + 32];
  const char            *args[9] = {NULL};

  PetscFunctionBeginUser;
  if (!ForceColumn(an)) PetscCall(PetscStrncpy(an->plots.error, "steps.csv has no force column (displacement control without a reaction region)", sizeof(an->plots.error)));
  PetscCall(PetscSNPrintf(arg[0], sizeof(arg[0]), "force=%s", ForceColumn(an) ? ForceColumn(an) : ""));
  PetscCall(PetscSNPrintf(arg[1], sizeof(arg[1]), "component=%s", an->sys->model->components[q->control_component]));
  PetscCall(PetscSNPrintf(arg[2], sizeof(arg[2]), "probe=%s", q->control));
  PetscCall(PetscSNPrintf(arg[3], sizeof(arg[3]), "region=%s", q->reaction_region >= 0 ? an->sys->disc.regions[q->reaction_region].name : ""));
  PetscCall(PetscSNPrintf(arg[4], sizeof(arg[4]), "load=%.10g", (double)(ST(an)->displacement ? 0 : ST(an)->load)));
  PetscCall(PetscSNPrintf(arg[5], sizeof(arg[5]), "peak=%.10g", (double)q->peak_load_factor));
  PetscCall(PetscSNPrintf(arg[6], sizeof(arg[6]), "critical=%.10g", (double)(q->failed ? q->critical_load_factor : 0)));
  PetscCall(PetscSNPrintf(arg[7], sizeof(arg[7]), "broken=%" PetscInt_FMT, q->broken_bonds));
  for (PetscInt k = 0; k < 8; k++) args[k] = arg[k];
  PetscCall(PeriPlotsDraw(an->comm, dir, "quasistatic", args, &an->plots));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* steps.csv, the snapshot series particles.pvd and the picture of the curve. */
static PetscErrorCode QSFiles(PeriAnalysis an, const char dir[])
{
  char path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  if (!QS(an)->started) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/steps.csv", dir));
  PetscCall(PeriWriteStepsCSV(an, path));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/particles.pvd", dir));
  PetscCall(WriteSnapshotsPVD(an, path));
  if (QS(an)->nsteps) PetscCall(QSPlots(an, dir));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode QSDestroy(PeriAnalysis an)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree2(QS(an)->steps, QS(an)->reactions));
  PetscCall(PetscFree(QS(an)->trial_damage));
  PetscCall(PetscFree(((QSData *)an->data)->snaps));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The analysis.* keys SetFromScene_Quasistatic reads. */
static const PeriKey qs_keys[] = {
    {"load_factor_max", PERI_KEY_REAL, "required", "(0, inf)", NULL, NULL, "the largest load factor"},
    {"stepping", PERI_KEY_CHOICE, "increments", NULL, NULL, qs_steppings, "increments: steps of load_factor_step (bisected at failure); events: straight to each next bond break, computed from the linear response (brittle bonds)"},
    {"load_factor_step", PERI_KEY_REAL, "required (increments)", "(0, load_factor_max]", NULL, NULL, "the load-factor step (the largest with adaptive steps); stepping: increments"},
    {"min_step", PERI_KEY_REAL, "load_factor_step/64", "[load_factor_step/2^20, load_factor_step]", NULL, NULL, "the smallest step (adaptive)"},
    {"adaptive", PERI_KEY_BOOL, "true", NULL, NULL, NULL, "halve the step on failure or runaway"},
    {"break", PERI_KEY_CHOICE, "all", NULL, NULL, qs_policies, "all | fraction: which violating bonds break per iteration"},
    {"break_fraction", PERI_KEY_REAL, "0.1", "(0, 1]", NULL, NULL, "break: fraction: those within this top fraction of [1, worst index]"},
    {"max_iterations", PERI_KEY_INT, "100", "[1, inf)", NULL, NULL, "equilibrium iterations per step"},
    {"reuse_preconditioner", PERI_KEY_BOOL, "true", NULL, NULL, NULL, "keep the preconditioner while few bonds changed"},
    {"control_probe", PERI_KEY_STRING, "the first probe", NULL, NULL, NULL, "the probe whose displacement steps.csv reports (control_u)"},
    {"control_component", PERI_KEY_STRING, "the direction of the load: of the largest prescribed value (displacement control), else of the largest load", NULL, NULL, NULL, "the component of the control probe's displacement in steps.csv's control_u and of the force (ux, uy, uz, theta: the model's)"},
    {"reaction_region", PERI_KEY_STRING, "the first bc region with a nonzero value, else the first holding the component", NULL, NULL, NULL, "the bc region whose reaction along control_component steps.csv reports (reaction): the force of a displacement-controlled load-displacement curve (load control: applied_load)"},
    {"runaway_fraction", PERI_KEY_REAL, "1 (displacement control), 0.01 (load control)", "(0, 1]", NULL, NULL, "more bonds than this share breaking at one load is a runaway: adaptive increments retry with a smaller step, events declare the failure; 1 follows the softening branch past a load drop"},
    {NULL},
};
/* output.every, which the run's snapshots follow (problem.c reads it with output.*) */
static const PeriKey qs_output_keys[] = {
    {"every", PERI_KEY_INT, "0", "[0, inf)", NULL, NULL, "also write particles_NNNN.vtu every k equilibrium steps (0: at each equilibrium where bonds broke, at most 50); particles.pvd lists them and particles.vtu"},
    {NULL},
};
static const PeriSchema qs_schema[] = {{"analysis", qs_keys}, {"output", qs_output_keys}, {NULL}};

static const char *const qs_files[] = {"steps.csv", "particles.pvd", "particles_#.vtu", "particles_#.pvtu", "particles_#", "failed_trial.vtu", "failed_trial.pvtu", "failed_trial", "checkpoint", "load_displacement.png", NULL};

/* K is applied and changed bond by bond (matrix-free where the model allows), and the loop solves
 * on a copy of it. */
const PeriAnalysisType PeriAnalysis_Quasistatic = {
    .name          = "quasistatic",
    .help          = "load stepping with bond failure to the critical load",
    .schema        = qs_schema,
    .option_prefix = "",
    .files         = qs_files,
    .table         = "steps.csv",
    .needs         = {.matrix_free = PETSC_TRUE, .static_solver = PETSC_TRUE, .matrix_copies = 1},
    .checkpoints   = PETSC_TRUE,
    .ops           = {.setfromscene = SetFromScene_Quasistatic, .setup = SetUp_Quasistatic, .run = PeriAnalysisRun_Quasistatic, .files = QSFiles, .summary = QSSummary, .table = QSTable, .destroy = QSDestroy},
};
