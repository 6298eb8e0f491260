/* analysis.type: anisotropy. The failure anisotropy of the lattice (Diana & Casolo sec. 4, Tables
 * 7-9): the family of one particle of a square lattice (the bonds n = (i, j) with |n| <= m, in
 * units of the spacing) under the homogeneous stretch F = Q diag(1 + s1, 1 + s2) Q^T rotated by
 * Theta; for each criterion, path (s1, s2) and m, e_max is the largest over Theta of the load factor
 * at which the first bond fails over the one at which the continuum (every direction) fails, minus
 * one. The bonds' measures are the scene's model's, the criteria the scene's failure values, used
 * one at a time. Writes anisotropy.csv; solves nothing. */
#include "perilin/private/analysis.h"

static const char *const criteria[] = {"stretch", "sliding", "frictional", NULL};

typedef struct {
  PetscInt   npaths, nm, norient, ncrit;
  PetscReal *paths; /* s1, s2 per path, in units of the criterion's limit */
  PetscReal *m;
  PetscInt   crit[3];
  PetscReal *emax;                      /* [crit][path][m], in % */
  PetscReal *ratio;                     /* [crit][path][m][orientation]: the lattice's failure load over the continuum's */
  PetscReal *envelope;                  /* [crit][m][psi][3]: the continuum's failure load along psi, the lattice's smallest and largest over the orientations */
  PetscInt   rows_done, envelopes_done; /* the rows of emax and ratio, and the envelopes, complete: a signal stops the run between them */
} Anisotropy;

#define AN(an)                    ((Anisotropy *)(an)->data)
#define PERI_CONTINUUM_DIRECTIONS 7200 /* every 0.025 degrees over a half turn: the continuum */
#define PERI_ENVELOPE_DIRECTIONS  72   /* directions psi of the envelopes in the (s1, s2) plane: every 5 degrees */
#define PERI_ENVELOPE_NEVER       1e6  /* a load factor above this many limits: a measure zero but for rounding (sliding under s1 = s2), so nothing fails */

/* The load factor at which a bond of direction a and length len fails under H = F - I (2 x 2,
 * row-major), rotations held at 0. */
static PetscReal DirectionLoad(PeriSystem sys, PetscReal a, PetscReal len, const PetscReal H[])
{
  PeriModel        m                = sys->model;
  PeriBondGeometry g                = {0};
  PetscReal        ui[PERI_MAX_DOF] = {0}, uj[PERI_MAX_DOF] = {0}, meas[PERI_MAX_MEASURE] = {0};

  g.xi[0]  = len * PetscCosReal(a);
  g.xi[1]  = len * PetscSinReal(a);
  g.length = len;
  g.Vi = g.Vj = g.weight = 1;
  uj[0]                  = H[0] * g.xi[0] + H[1] * g.xi[1];
  uj[1]                  = H[2] * g.xi[0] + H[3] * g.xi[1];
  m->ops.bond_measures(m, &g, ui, uj, meas);
  return PeriBondCriticalLoad(sys, &g, meas, m->nmeasures);
}

/* The smallest failure load factor over the lattice family of ratio m. */
static PetscReal LatticeLoad(PeriSystem sys, PetscReal m, const PetscReal H[])
{
  const PetscInt r       = (PetscInt)PetscFloorReal(m);
  PetscReal      lattice = PETSC_INFINITY;

  for (PetscInt i = -r; i <= r; i++)
    for (PetscInt j = -r; j <= r; j++)
      if ((i || j) && i * i + j * j <= m * m * (1 + 1e-12)) lattice = PetscMin(lattice, DirectionLoad(sys, PetscAtan2Real(j, i), PetscSqrtReal(i * i + j * j), H));
  return lattice;
}

/* The smallest failure load factor over the continuum (every direction). */
static PetscReal ContinuumLoad(PeriSystem sys, const PetscReal H[])
{
  PetscReal continuum = PETSC_INFINITY;

  for (PetscInt k = 0; k < PERI_CONTINUUM_DIRECTIONS; k++) continuum = PetscMin(continuum, DirectionLoad(sys, PETSC_PI * k / PERI_CONTINUUM_DIRECTIONS, 1, H));
  return continuum;
}

/* H = Q diag(s1, s2) Q^T of orientation k of n, Q = [c sn; -sn c] (eq. 70). */
static void Rotated(PetscInt k, PetscInt n, const PetscReal s[], PetscReal H[])
{
  const PetscReal th = -0.5 * PETSC_PI * k / (n - 1), c = PetscCosReal(th), sn = PetscSinReal(th);

  H[0] = c * c * s[0] + sn * sn * s[1];
  H[1] = H[2] = -c * sn * s[0] + sn * c * s[1];
  H[3]        = sn * sn * s[0] + c * c * s[1];
}

/* Whether a signal (SIGINT, SIGTERM, SIGHUP) asks the run to stop: polled by every rank at the same
 * points (each computes the whole study). Collective. */
static PetscErrorCode Interrupted(PeriAnalysis an, PetscBool *stop)
{
  PetscFunctionBeginUser;
  PetscCall(PeriSignalReceived(an->comm, &an->sys->run.interrupted));
  *stop = an->sys->run.interrupted ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* e_max (%) of one path (in units of s0t, scaled by unit) and m under the criterion now in
 * sys->bond_state.failure, and the ratio of the lattice's failure load to the continuum's at each
 * orientation (inf where nothing fails along the path); *stop when a signal came first. */
static PetscErrorCode MaxError(PeriAnalysis an, const PetscReal path[], PetscReal unit, PetscReal m, PetscReal ratio[], PetscReal *emax, PetscBool *stop)
{
  const PetscInt  n     = AN(an)->norient;
  const PetscReal s[2]  = {unit * path[0], unit * path[1]};
  PetscReal       worst = 0, H[4], cont;

  PetscFunctionBeginUser;
  /* the continuum is isotropic: its failure load at Theta = 0 holds at every orientation (with
     the 0.9-degree steps of 101 orientations its sampled directions are even the same set) */
  Rotated(0, n, s, H);
  cont = ContinuumLoad(an->sys, H);
  for (PetscInt k = 0; k < n; k++) {
    PetscReal lat;
    PetscCall(Interrupted(an, stop));
    if (*stop) PetscFunctionReturn(PETSC_SUCCESS);
    Rotated(k, n, s, H);
    lat      = LatticeLoad(an->sys, m, H);
    ratio[k] = PETSC_INFINITY;
    if (cont >= PETSC_INFINITY) continue; /* nothing fails along this path (PETSC_INFINITY is finite) */
    ratio[k] = lat / cont;
    worst    = PetscMax(worst, lat / cont - 1);
  }
  *emax = 100 * worst;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The failure envelope of one m in the (s1, s2) plane under the criterion now in
 * sys->bond_state.failure: along each direction psi the load factor (in units of s0t) at which
 * the continuum fails (isotropic: at Theta = 0), and the smallest and largest over the lattice's
 * orientations; *stop when a signal came first. */
static PetscErrorCode Envelope(PeriAnalysis an, PetscReal unit, PetscReal m, PetscReal env[], PetscBool *stop)
{
  const PetscInt n = AN(an)->norient;

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < PERI_ENVELOPE_DIRECTIONS; d++) {
    const PetscReal psi = 2 * PETSC_PI * d / PERI_ENVELOPE_DIRECTIONS, s[2] = {unit * PetscCosReal(psi), unit * PetscSinReal(psi)};
    PetscReal       H[4], *e                                                = &env[3 * d];
    PetscCall(Interrupted(an, stop));
    if (*stop) PetscFunctionReturn(PETSC_SUCCESS);
    Rotated(0, n, s, H);
    e[0] = ContinuumLoad(an->sys, H);
    e[1] = PETSC_INFINITY;
    e[2] = 0;
    for (PetscInt k = 0; k < n; k++) {
      PetscReal lat;
      Rotated(k, n, s, H);
      lat  = LatticeLoad(an->sys, m, H);
      e[1] = PetscMin(e[1], lat);
      e[2] = PetscMax(e[2], lat);
    }
    for (PetscInt k = 0; k < 3; k++)
      if (e[k] > PERI_ENVELOPE_NEVER) e[k] = PETSC_INFINITY;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* sys->bond_state.failure with only criterion c of the scene's (0 stretch: tension and compression, 1
 * sliding, 2 frictional sliding with the stretch limits as its cut-offs, as Diana & Casolo pair
 * them: without them a bond in compression never fails), brittle, without G. */
static PetscErrorCode OnlyCriterion(PeriAnalysis an, PetscInt c)
{
  static const char *const select[3][4] = {{"tension", "compression", NULL}, {"sliding", NULL}, {"frictional", "tension", "compression", NULL}};
  PeriFailure             *F            = &an->sys->bond_state.failure;
  PeriNode                 node;

  PetscFunctionBeginUser;
  PetscCall(PeriFailureSelect(F, select[c], PETSC_FALSE));
  PetscCall(PeriSceneGetNode(an->sys->scene->root, "failure", &node)); /* locates the message only */
  PeriInputCheck(PeriFailureIsActive(F, select[c][0]) && (c != 2 || PeriFailureValue(F, "cohesion") > 0), an->sys->scene, node, c == 0 ? "stretch" : c == 1 ? "sliding"
                                                                                                                                                            : "friction_angle",
                 "the anisotropy analysis's criterion %s needs its limit here (%s)", criteria[c], c == 0 ? "failure.critical_stretch" : c == 1 ? "failure.sliding"
                                                                                                                                               : "failure.friction_angle and failure.cohesion");
  PeriInputCheck(c == 0 || PeriModelMeasureIndex(an->sys->model, PERI_MEASURE_SLIDING) >= 0, an->sys->scene, node, NULL, "model %s has no sliding measure: criterion %s needs a shear-bond model (pds, mppd, gerstle)", an->sys->model->type, criteria[c]);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* analysis.{criteria, paths, m, orientations}, before any particle exists. */
static PetscErrorCode SetFromScene_Anisotropy(PeriAnalysis an, PeriScene s, PeriNode a)
{
  Anisotropy *A;
  PeriNode    list;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&A));
  an->data = A;
  PetscCall(PeriSceneGetMap(s, s->root, "analysis", PETSC_TRUE, &a));
  PetscCall(PeriSceneGetNode(a, "criteria", &list));
  PeriInputCheck(list && list->kind == PERI_NODE_SEQ && list->n >= 1 && list->n <= 3, s, list ? list : a, list ? NULL : "criteria", "is required: a list of one to three of stretch, sliding, frictional");
  A->ncrit = list->n;
  for (PetscInt c = 0; c < list->n; c++) {
    PetscBool found = PETSC_FALSE;
    PeriInputCheck(list->child[c]->kind == PERI_NODE_SCALAR, s, list->child[c], NULL, "a criterion is one of stretch, sliding, frictional");
    for (PetscInt k = 0; criteria[k]; k++)
      if (!strcmp(list->child[c]->value, criteria[k])) {
        A->crit[c] = k;
        found      = PETSC_TRUE;
      }
    PeriInputCheck(found, s, list->child[c], NULL, "unknown criterion '%s': one of stretch, sliding, frictional", list->child[c]->value);
  }
  PetscCall(PeriSceneGetNode(a, "paths", &list));
  PeriInputCheck(list && list->kind == PERI_NODE_SEQ && list->n >= 1, s, list ? list : a, list ? NULL : "paths", "is required: a list of principal stretches [s1, s2] in units of failure.critical_stretch");
  A->npaths = list->n;
  PetscCall(PetscMalloc1(2 * A->npaths, &A->paths));
  for (PetscInt p = 0; p < A->npaths; p++) {
    PetscInt n;
    PetscCall(PeriSceneParseRealArray(s, list->child[p], 2, 2, &A->paths[2 * p], &n));
  }
  PetscCall(PetscMalloc1(16, &A->m));
  PetscCall(PeriSceneGetRealArray(s, a, "m", PETSC_TRUE, 1, 16, A->m, &A->nm));
  PetscCall(PeriSceneGetInt(s, a, "orientations", PETSC_FALSE, &A->norient, NULL));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A signal stops the study between two orientations (or envelope directions): the rows and
 * envelopes complete by then are written, summary.json says "complete": false. */
static PetscErrorCode Run_Anisotropy(PeriAnalysis an)
{
  Anisotropy       *A;
  PetscBool         stop = PETSC_FALSE;
  const PeriFailure all  = an->sys->bond_state.failure;
  const PetscReal   unit = PeriFailureValue(&all, "critical_stretch") > 0 ? PeriFailureValue(&all, "critical_stretch") : 1;

  PetscFunctionBeginUser;
  PetscCheck(an->sys->disc.particles.dim == 2, an->comm, PETSC_ERR_USER_INPUT, "%s: the anisotropy analysis studies the 2D square lattice: dim must be 2", an->sys->scene->file);
  A = AN(an);
  PetscCall(PetscMalloc3(A->ncrit * A->npaths * A->nm, &A->emax, A->ncrit * A->npaths * A->nm * A->norient, &A->ratio, A->ncrit * A->nm * PERI_ENVELOPE_DIRECTIONS * 3, &A->envelope));
  for (PetscInt c = 0; c < A->ncrit && !stop; c++) {
    PetscCall(OnlyCriterion(an, A->crit[c]));
    for (PetscInt p = 0; p < A->npaths && !stop; p++)
      for (PetscInt k = 0; k < A->nm && !stop; k++) {
        const PetscInt row = (c * A->npaths + p) * A->nm + k;
        PetscCall(MaxError(an, &A->paths[2 * p], unit, A->m[k], &A->ratio[row * A->norient], &A->emax[row], &stop));
        if (!stop) A->rows_done = row + 1;
      }
    for (PetscInt k = 0; k < A->nm && !stop; k++) {
      PetscCall(Envelope(an, unit, A->m[k], &A->envelope[(c * A->nm + k) * PERI_ENVELOPE_DIRECTIONS * 3], &stop));
      if (!stop) A->envelopes_done = c * A->nm + k + 1;
    }
  }
  an->sys->bond_state.failure = all;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A load factor for the CSV files: PETSC_INFINITY (nothing fails) as inf. */
static double CSVLoad(PetscReal v)
{
  return v >= PETSC_INFINITY ? (double)INFINITY : (double)v;
}

/* anisotropy_polar.csv (criterion,s1,s2,m,theta_deg,ratio) and anisotropy_envelope.csv
 * (criterion,m,psi_deg,continuum,lattice_min,lattice_max). Rank 0 writes. */
static PetscErrorCode WriteCurves(PeriAnalysis an, const char dir[])
{
  Anisotropy *A = AN(an);
  char        path[PETSC_MAX_PATH_LEN], tmp[PETSC_MAX_PATH_LEN];
  FILE       *fp;
  int         bad = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/anisotropy_polar.csv", dir));
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "criterion,s1,s2,m,theta_deg,ratio\n") < 0;
  for (PetscInt c = 0; c < A->ncrit; c++)
    for (PetscInt p = 0; p < A->npaths; p++)
      for (PetscInt k = 0; k < A->nm; k++)
        for (PetscInt o = 0; o < A->norient && (c * A->npaths + p) * A->nm + k < A->rows_done; o++) bad |= fprintf(fp, "%s,%g,%g,%g,%.6g,%.8g\n", criteria[A->crit[c]], (double)A->paths[2 * p], (double)A->paths[2 * p + 1], (double)A->m[k], 90.0 * o / (A->norient - 1), CSVLoad(A->ratio[((c * A->npaths + p) * A->nm + k) * A->norient + o])) < 0;
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/anisotropy_envelope.csv", dir));
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "criterion,m,psi_deg,continuum,lattice_min,lattice_max\n") < 0;
  for (PetscInt c = 0; c < A->ncrit; c++)
    for (PetscInt k = 0; k < A->nm; k++)
      for (PetscInt d = 0; d < PERI_ENVELOPE_DIRECTIONS && c * A->nm + k < A->envelopes_done; d++) {
        const PetscReal *e = &A->envelope[((c * A->nm + k) * PERI_ENVELOPE_DIRECTIONS + d) * 3];
        bad |= fprintf(fp, "%s,%g,%g,%.8g,%.8g,%.8g\n", criteria[A->crit[c]], (double)A->m[k], 360.0 * d / PERI_ENVELOPE_DIRECTIONS, CSVLoad(e[0]), CSVLoad(e[1]), CSVLoad(e[2])) < 0;
      }
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* anisotropy.csv: criterion,s1,s2,m,e_max_percent; the curves behind it, and their pictures. Rank 0
 * writes (temporary name, then rename). */
static PetscErrorCode Files_Anisotropy(PeriAnalysis an, const char dir[])
{
  Anisotropy *A = AN(an);
  char        path[PETSC_MAX_PATH_LEN], tmp[PETSC_MAX_PATH_LEN];
  FILE       *fp;
  int         bad = 0;

  PetscFunctionBeginUser;
  if (an->rank || !A || !A->emax) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(WriteCurves(an, dir));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/anisotropy.csv", dir));
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "criterion,s1,s2,m,e_max_percent\n") < 0;
  for (PetscInt c = 0; c < A->ncrit; c++)
    for (PetscInt p = 0; p < A->npaths; p++)
      for (PetscInt k = 0; k < A->nm && (c * A->npaths + p) * A->nm + k < A->rows_done; k++) bad |= fprintf(fp, "%s,%g,%g,%g,%.4f\n", criteria[A->crit[c]], (double)A->paths[2 * p], (double)A->paths[2 * p + 1], (double)A->m[k], (double)A->emax[(c * A->npaths + p) * A->nm + k]) < 0;
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscCall(PeriPlotsDraw(an->comm, dir, "anisotropy", NULL, &an->plots));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Summary_Anisotropy(PeriAnalysis an, PeriJSON j)
{
  Anisotropy *A     = AN(an);
  PetscReal   worst = 0;

  PetscFunctionBeginUser;
  if (!A || !A->emax) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; k < A->rows_done; k++) worst = PetscMax(worst, A->emax[k]);
  PetscCall(PeriJSONBeginObject(j, "anisotropy"));
  PetscCall(PeriJSONInt(j, "rows", A->rows_done));
  PetscCall(PeriJSONInt(j, "orientations", A->norient));
  PetscCall(PeriJSONReal(j, "largest_e_max_percent", worst));
  PetscCall(PeriJSONEndObject(j));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Report_Anisotropy(PeriAnalysis an)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPrintf(an->comm, "perilin: anisotropy of %" PetscInt_FMT " criteria x %" PetscInt_FMT " paths x %" PetscInt_FMT " m over %" PetscInt_FMT " orientations; results in %s/anisotropy.csv\n", AN(an)->ncrit, AN(an)->npaths, AN(an)->nm, AN(an)->norient, an->output_dir));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Destroy_Anisotropy(PeriAnalysis an)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(AN(an)->paths));
  PetscCall(PetscFree(AN(an)->m));
  PetscCall(PetscFree3(AN(an)->emax, AN(an)->ratio, AN(an)->envelope));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static const PeriKey anisotropy_keys[] = {
    {"criteria", PERI_KEY_LIST, "required", NULL, NULL, NULL, "the criteria studied, one at a time: stretch (failure.critical_stretch, failure.compressive_stretch), sliding (failure.sliding), frictional (failure.friction_angle, failure.cohesion, with the stretch limits as cut-offs)"},
    {"paths", PERI_KEY_LIST, "required", NULL, NULL, NULL, "principal stretches [s1, s2] of the unit cell, in units of failure.critical_stretch (Diana & Casolo eq. 68)"},
    {"m", PERI_KEY_REALS, "required", "[1, 20]", NULL, NULL, "horizon ratios of the unit cells: the bonds n = (i, j) with |n| <= m"},
    {"orientations", PERI_KEY_INT, "101", "[2, inf)", NULL, NULL, "orientations Theta of each path, evenly over [0, 90] degrees (101: Diana & Casolo's 0.9-degree steps)"},
    {NULL},
};
static const PeriSchema  anisotropy_schema[] = {{"analysis", anisotropy_keys}, {NULL}};
static const char *const anisotropy_files[]  = {"anisotropy.csv", "anisotropy_polar.csv", "anisotropy_envelope.csv", "anisotropy_polar.png", "anisotropy_envelope.png", NULL};

/* Solves nothing: K is never built (the memory estimate sizes it as a static run's, assembled). */
const PeriAnalysisType PeriAnalysis_Anisotropy = {
    .name   = "anisotropy",
    .help   = "the failure anisotropy of the lattice's unit cell (Diana & Casolo Tables 7-9): anisotropy.csv",
    .schema = anisotropy_schema,
    .files  = anisotropy_files,
    .needs  = {.static_solver = PETSC_TRUE},
    .ops    = {.setfromscene = SetFromScene_Anisotropy, .run = Run_Anisotropy, .files = Files_Anisotropy, .summary = Summary_Anisotropy, .report = Report_Anisotropy, .destroy = Destroy_Anisotropy},
};
