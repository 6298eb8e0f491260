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
  PetscReal *emax; /* [crit][path][m], in % */
} Anisotropy;

#define AN(an)                    ((Anisotropy *)(an)->data)
#define PERI_CONTINUUM_DIRECTIONS 7200 /* every 0.025 degrees over a half turn: the continuum */

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

/* The smallest failure load factor over the lattice family of ratio m, and over the continuum. */
static void FailureLoads(PeriSystem sys, PetscReal m, const PetscReal H[], PetscReal *lattice, PetscReal *continuum)
{
  const PetscInt r = (PetscInt)PetscFloorReal(m);

  *lattice = *continuum = PETSC_INFINITY;
  for (PetscInt i = -r; i <= r; i++)
    for (PetscInt j = -r; j <= r; j++)
      if ((i || j) && i * i + j * j <= m * m * (1 + 1e-12)) *lattice = PetscMin(*lattice, DirectionLoad(sys, PetscAtan2Real(j, i), PetscSqrtReal(i * i + j * j), H));
  for (PetscInt k = 0; k < PERI_CONTINUUM_DIRECTIONS; k++) *continuum = PetscMin(*continuum, DirectionLoad(sys, PETSC_PI * k / PERI_CONTINUUM_DIRECTIONS, 1, H));
}

/* e_max (%) of one path (in units of s0t, scaled by unit) and m under the criterion now in
 * sys->bond_state.failure. */
static PetscReal MaxError(PeriAnalysis an, const PetscReal path[], PetscReal unit, PetscReal m)
{
  const PetscInt  n     = AN(an)->norient;
  const PetscReal s[2]  = {unit * path[0], unit * path[1]};
  PetscReal       worst = 0;

  for (PetscInt k = 0; k < n; k++) {
    const PetscReal th = -0.5 * PETSC_PI * k / (n - 1), c = PetscCosReal(th), sn = PetscSinReal(th);
    /* H = Q diag(s1, s2) Q^T, Q = [c sn; -sn c] (eq. 70) */
    const PetscReal H[4] = {c * c * s[0] + sn * sn * s[1], -c * sn * s[0] + sn * c * s[1], -sn * c * s[0] + c * sn * s[1], sn * sn * s[0] + c * c * s[1]};
    PetscReal       lat, cont;
    FailureLoads(an->sys, m, H, &lat, &cont);
    if (PetscIsInfReal(cont)) continue; /* nothing fails along this path */
    worst = PetscMax(worst, lat / cont - 1);
  }
  return 100 * worst;
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
  PetscCall(PeriSceneGetMap(an->sys->scene, an->sys->scene->root, "failure", PETSC_FALSE, &node));
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

static PetscErrorCode Run_Anisotropy(PeriAnalysis an)
{
  Anisotropy       *A;
  const PeriFailure all  = an->sys->bond_state.failure;
  const PetscReal   unit = PeriFailureValue(&all, "critical_stretch") > 0 ? PeriFailureValue(&all, "critical_stretch") : 1;

  PetscFunctionBeginUser;
  PetscCheck(an->sys->disc.particles.dim == 2, an->comm, PETSC_ERR_USER_INPUT, "%s: the anisotropy analysis studies the 2D square lattice: dim must be 2", an->sys->scene->file);
  A = AN(an);
  PetscCall(PetscMalloc1(A->ncrit * A->npaths * A->nm, &A->emax));
  for (PetscInt c = 0; c < A->ncrit; c++) {
    PetscCall(OnlyCriterion(an, A->crit[c]));
    for (PetscInt p = 0; p < A->npaths; p++)
      for (PetscInt k = 0; k < A->nm; k++) A->emax[(c * A->npaths + p) * A->nm + k] = MaxError(an, &A->paths[2 * p], unit, A->m[k]);
  }
  an->sys->bond_state.failure = all;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* anisotropy.csv: criterion,s1,s2,m,e_max_percent. Rank 0 writes (temporary name, then rename). */
static PetscErrorCode Files_Anisotropy(PeriAnalysis an, const char dir[])
{
  Anisotropy *A = AN(an);
  char        path[PETSC_MAX_PATH_LEN], tmp[PETSC_MAX_PATH_LEN];
  FILE       *fp;
  int         bad = 0;

  PetscFunctionBeginUser;
  if (an->rank || !A || !A->emax) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/anisotropy.csv", dir));
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "criterion,s1,s2,m,e_max_percent\n") < 0;
  for (PetscInt c = 0; c < A->ncrit; c++)
    for (PetscInt p = 0; p < A->npaths; p++)
      for (PetscInt k = 0; k < A->nm; k++) bad |= fprintf(fp, "%s,%g,%g,%g,%.4f\n", criteria[A->crit[c]], (double)A->paths[2 * p], (double)A->paths[2 * p + 1], (double)A->m[k], (double)A->emax[(c * A->npaths + p) * A->nm + k]) < 0;
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode Summary_Anisotropy(PeriAnalysis an, PeriJSON j)
{
  Anisotropy *A     = AN(an);
  PetscReal   worst = 0;

  PetscFunctionBeginUser;
  if (!A || !A->emax) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; k < A->ncrit * A->npaths * A->nm; k++) worst = PetscMax(worst, A->emax[k]);
  PetscCall(PeriJSONBeginObject(j, "anisotropy"));
  PetscCall(PeriJSONInt(j, "rows", A->ncrit * A->npaths * A->nm));
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
  PetscCall(PetscFree(AN(an)->emax));
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
static const char *const anisotropy_files[]  = {"anisotropy.csv", NULL};

/* Solves nothing: K is never built (the memory estimate sizes it as a static run's, assembled). */
const PeriAnalysisType PeriAnalysis_Anisotropy = {
    .name   = "anisotropy",
    .help   = "the failure anisotropy of the lattice's unit cell (Diana & Casolo Tables 7-9): anisotropy.csv",
    .schema = anisotropy_schema,
    .files  = anisotropy_files,
    .needs  = {.static_solver = PETSC_TRUE},
    .ops    = {.setfromscene = SetFromScene_Anisotropy, .run = Run_Anisotropy, .files = Files_Anisotropy, .summary = Summary_Anisotropy, .report = Report_Anisotropy, .destroy = Destroy_Anisotropy},
};
