/* Amplitudes in time, a(t), for the loads of a transient analysis: analysis.amplitude (every load)
 * and loads.<k>.amplitude (that load); bc.<k>.amplitude scales a moving boundary's velocity, which
 * needs a's rate and integral too. step, ramp, sine, or a table read from a two-column CSV
 * (time, amplitude) and interpolated linearly, constant beyond its ends. */
#include "perilin/private/system.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const amplitude_shapes[]  = {"step", "ramp", "sine", "table", NULL};
const PeriKey            PeriAmplitudeKeys[] = {
               {"shape", PERI_KEY_CHOICE, "step", NULL, NULL, amplitude_shapes, "step: 1 from t = 0; ramp: linear from 0 to 1 at rise_time; sine: sin(2 pi t / period); table: from file"},
               {"rise_time", PERI_KEY_REAL, NULL, "(0, inf)", "[time]", NULL, "ramp: when the load reaches its value"},
               {"period", PERI_KEY_REAL, NULL, "(0, inf)", "[time]", NULL, "sine: the period"},
               {"file", PERI_KEY_STRING, NULL, NULL, NULL, NULL, "table: a CSV of time, amplitude rows (increasing times; '#' comments and a header line allowed), relative to the scene file; linear between rows, the end values beyond them"},
               {NULL},
};

/* One data row of the table (*isrow), or a blank or comment line, or the header (one line of
 * text before the first row: *header). */
static PetscErrorCode TableRow(PeriScene s, PeriNode node, const char path[], char line[], PetscInt lineno, PetscInt nrows, PetscBool *header, PetscReal row[2], PetscBool *isrow)
{
  char *end, *p = line;

  PetscFunctionBeginUser;
  *isrow = PETSC_FALSE;
  while (*p == ' ' || *p == '\t') p++;
  if (*p == '#' || *p == '\n' || *p == '\r' || !*p) PetscFunctionReturn(PETSC_SUCCESS);
  errno  = 0;
  row[0] = strtod(p, &end);
  if (end == p && nrows == 0 && !*header) {
    *header = PETSC_TRUE;
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PeriInputCheck(end != p && errno == 0, s, node, "file", "%s:%" PetscInt_FMT ": expected 'time, amplitude', got '%s'", path, lineno, p);
  p = end;
  while (*p == ' ' || *p == '\t' || *p == ',' || *p == ';') p++;
  row[1] = strtod(p, &end);
  PeriInputCheck(end != p && errno == 0 && !PetscIsInfOrNanReal(row[0]) && !PetscIsInfOrNanReal(row[1]), s, node, "file", "%s:%" PetscInt_FMT ": expected two finite numbers 'time, amplitude'", path, lineno);
  *isrow = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The rows of amplitude.file's text (NUL-terminated, changed in place) appended to a. */
static PetscErrorCode ParseTable(PeriScene s, PeriNode node, const char path[], char text[], PeriAmplitude *a)
{
  char     *line, *next;
  PetscInt  lineno = 0, cap = 0;
  PetscReal row[2];
  PetscBool isrow, header = PETSC_FALSE;

  PetscFunctionBeginUser;
  for (line = text; line && *line; line = next) {
    next = strchr(line, '\n');
    if (next) *next++ = 0;
    PetscCall(TableRow(s, node, path, line, ++lineno, a->n, &header, row, &isrow));
    if (!isrow) continue;
    PeriInputCheck(a->n == 0 || row[0] > a->t[a->n - 1], s, node, "file", "%s:%" PetscInt_FMT ": times must increase (%g after %g)", path, lineno, (double)row[0], (double)a->t[a->n - 1]);
    if (a->n == cap) {
      cap = PetscMax(16, 2 * cap);
      PetscCall(PetscRealloc(sizeof(PetscReal) * cap, &a->t));
      PetscCall(PetscRealloc(sizeof(PetscReal) * cap, &a->a));
    }
    a->t[a->n]   = row[0];
    a->a[a->n++] = row[1];
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* amplitude.file: every rank reads it whole (a few rows), then parses it line by line. */
static PetscErrorCode ReadTable(PeriScene s, PeriNode node, PeriAmplitude *a)
{
  char           path[PETSC_MAX_PATH_LEN], *text;
  FILE          *fp;
  long           len;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetPath(s, node, "file", PETSC_TRUE, path, sizeof(path), NULL));
  fp = fopen(path, "rb");
  PeriInputCheck(fp, s, node, "file", "cannot read %s: %s", path, strerror(errno));
  len = fseek(fp, 0, SEEK_END) ? -1 : ftell(fp);
  if (len < 0 || fseek(fp, 0, SEEK_SET)) len = -1;
  text = len >= 0 ? (char *)malloc((size_t)len + 1) : NULL;
  if (text && fread(text, 1, (size_t)len, fp) != (size_t)len) len = -1;
  (void)fclose(fp);
  if (len < 0 || !text) free(text);
  PeriInputCheck(len >= 0 && text, s, node, "file", "cannot read %s", path);
  text[len] = 0;
  /* the text is freed whether its rows parse or not (an input error) */
  ierr = ParseTable(s, node, path, text, a);
  free(text);
  PetscCall(ierr);
  PeriInputCheck(a->n >= 1, s, node, "file", "%s holds no 'time, amplitude' row", path);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAmplitudeFromScene - the amplitude of the map node (PeriAmplitudeKeys), or a step when node
  is NULL. Not collective (every rank reads the same). Free with PeriAmplitudeDestroy.
@*/
PetscErrorCode PeriAmplitudeFromScene(PeriScene s, PeriNode node, PeriAmplitude *a)
{
  PeriNode file;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(a, sizeof(*a)));
  if (!node) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriSceneGetChoice(s, node, "shape", amplitude_shapes, &a->shape, NULL));
  PetscCall(PeriSceneGetReal(s, node, "rise_time", a->shape == PERI_AMPLITUDE_RAMP ? PETSC_TRUE : PETSC_FALSE, &a->rise, NULL));
  PetscCall(PeriSceneGetReal(s, node, "period", a->shape == PERI_AMPLITUDE_SINE ? PETSC_TRUE : PETSC_FALSE, &a->period, NULL));
  PetscCall(PeriSceneGetNode(node, "file", &file));
  PeriInputCheck(!file || a->shape == PERI_AMPLITUDE_TABLE, s, node, "file", "is read with shape: table only");
  if (a->shape == PERI_AMPLITUDE_TABLE) PetscCall(ReadTable(s, node, a));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* a(t). */
PetscReal PeriAmplitudeValue(const PeriAmplitude *a, PetscReal t)
{
  PetscInt lo = 0, hi;

  switch (a->shape) {
  case PERI_AMPLITUDE_RAMP:
    return PetscMin(1, t / a->rise);
  case PERI_AMPLITUDE_SINE:
    return PetscSinReal(2 * PETSC_PI * t / a->period);
  case PERI_AMPLITUDE_TABLE:
    if (t <= a->t[0]) return a->a[0];
    if (t >= a->t[a->n - 1]) return a->a[a->n - 1];
    hi = a->n - 1;
    while (hi - lo > 1) { /* bisection: t[lo] < t <= t[hi] */
      PetscInt mid = (lo + hi) / 2;
      if (a->t[mid] < t)
        lo = mid;
      else
        hi = mid;
    }
    return a->a[lo] + (a->a[hi] - a->a[lo]) * (t - a->t[lo]) / (a->t[hi] - a->t[lo]);
  default:
    return 1;
  }
}

/* a'(t) (the slope of the table's segment; 0 beyond its ends and after a ramp's rise). */
PetscReal PeriAmplitudeRate(const PeriAmplitude *a, PetscReal t)
{
  PetscInt k = 0;

  switch (a->shape) {
  case PERI_AMPLITUDE_RAMP:
    return t < a->rise ? 1 / a->rise : 0;
  case PERI_AMPLITUDE_SINE:
    return 2 * PETSC_PI / a->period * PetscCosReal(2 * PETSC_PI * t / a->period);
  case PERI_AMPLITUDE_TABLE:
    if (t < a->t[0] || t >= a->t[a->n - 1]) return 0;
    while (a->t[k + 1] <= t) k++;
    return (a->a[k + 1] - a->a[k]) / (a->t[k + 1] - a->t[k]);
  default:
    return 0;
  }
}

/* The table's integral from 0 to t: the trapezoids of its segments clipped to [0, t], its end
 * values beyond them. */
static PetscReal TableIntegral(const PeriAmplitude *a, PetscReal t)
{
  PetscReal sum = 0, lo, hi;

  if (t <= 0) return 0;
  if (a->t[0] > 0) sum += a->a[0] * PetscMin(t, a->t[0]);
  for (PetscInt k = 0; k + 1 < a->n; k++) {
    lo = PetscMax(0, a->t[k]), hi = PetscMin(t, a->t[k + 1]);
    if (hi > lo) sum += 0.5 * (PeriAmplitudeValue(a, lo) + PeriAmplitudeValue(a, hi)) * (hi - lo);
  }
  if (t > a->t[a->n - 1]) sum += a->a[a->n - 1] * (t - PetscMax(0, a->t[a->n - 1]));
  return sum;
}

/* The integral of a from 0 to t (a moving boundary's displacement per unit velocity). */
PetscReal PeriAmplitudeIntegral(const PeriAmplitude *a, PetscReal t)
{
  switch (a->shape) {
  case PERI_AMPLITUDE_RAMP:
    return t < a->rise ? 0.5 * t * t / a->rise : t - 0.5 * a->rise;
  case PERI_AMPLITUDE_SINE:
    return a->period / (2 * PETSC_PI) * (1 - PetscCosReal(2 * PETSC_PI * t / a->period));
  case PERI_AMPLITUDE_TABLE:
    return TableIntegral(a, t);
  default:
    return t;
  }
}

PetscErrorCode PeriAmplitudeDestroy(PeriAmplitude *a)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(a->t));
  PetscCall(PetscFree(a->a));
  PetscFunctionReturn(PETSC_SUCCESS);
}
