/* Suggestions for misspelt names (bottom of src/scene/): "did you mean X?" from the names within a
 * few typos, for unknown scene keys as for unknown options, and the comma-separated lists the
 * messages show. */
#include "perilin/private/scene_file.h"
#include <ctype.h>
#include <strings.h>

/* Optimal-string-alignment (restricted Damerau-Levenshtein) distance ignoring case: a swap of two
 * neighbours is one typo, as -ksp_rotl for -ksp_rtol. */
static PetscInt Distance(const char a[], const char b[])
{
  PetscInt la = (PetscInt)strlen(a), lb = (PetscInt)strlen(b), row[3][PERI_OPTION_LEN + 1];

  if (la > PERI_OPTION_LEN || lb > PERI_OPTION_LEN) return PETSC_MAX_INT;
  for (PetscInt j = 0; j <= lb; j++) row[0][j] = j;
  for (PetscInt i = 1; i <= la; i++) { /* row i lives in row[i % 3] */
    PetscInt *prev2 = row[(i + 1) % 3], *prev = row[(i + 2) % 3], *cur = row[i % 3];
    cur[0] = i;
    for (PetscInt j = 1; j <= lb; j++) {
      int      ai = tolower((unsigned char)a[i - 1]), bj = tolower((unsigned char)b[j - 1]);
      PetscInt v = PetscMin(PetscMin(prev[j] + 1, cur[j - 1] + 1), prev[j - 1] + (ai != bj));
      if (i > 1 && j > 1 && ai == tolower((unsigned char)b[j - 2]) && tolower((unsigned char)a[i - 2]) == bj) v = PetscMin(v, prev2[j - 2] + 1);
      cur[j] = v;
    }
  }
  return row[la % 3][lb];
}

/* How many typos a suggestion may be away: more in longer names, never so many that unrelated
 * short names match (-pc_type is not a typo of -vec_type). */
static PetscInt Allowed(const char name[])
{
  PetscInt len = (PetscInt)strlen(name);
  return PetscMax(1, PetscMin(3, (len - 1) / 4));
}

/* The distance of candidate c from name; a prefix in front of name counts as one typo (-st_ksp_rtol
 * for -ksp_rtol on a modal run, where the linear solver is the spectral transformation's). */
static PetscInt Score(const char name[], const char c[])
{
  PetscInt d  = Distance(name, c);
  size_t   ln = strlen(name), lc = strlen(c);

  if (d > 1 && lc > ln && name[0] == '-' && c[lc - ln] == '_' && !strcasecmp(c + lc - ln + 1, name + 1)) d = 1;
  return d;
}

/* "did you mean -a?" / "did you mean -a or -b?" from the closest candidates within Allowed(), or ""
 * when none is; *exact when name itself is a candidate (a real option that nothing read). */
void PeriSuggest(const char name[], char *const cand[], char buf[], size_t len, PetscBool *exact)
{
  PetscInt best = PETSC_MAX_INT, first = -1, second = -1;

  buf[0] = 0;
  *exact = PETSC_FALSE;
  for (PetscInt k = 0; cand[k]; k++) {
    PetscInt s = Score(name, cand[k]);
    if (s == 0) *exact = PETSC_TRUE;
    if (s == 0 || s > Allowed(name)) continue;
    if (s < best) {
      best   = s;
      first  = k;
      second = -1;
    } else if (s == best && second < 0)
      second = k;
  }
  if (first < 0) return;
  if (second < 0)
    snprintf(buf, len, "did you mean %s?", cand[first]);
  else
    snprintf(buf, len, "did you mean %s or %s?", cand[first], cand[second]);
}

/*@C
  PeriSceneSuggest - "did you mean X?" (or "X or Y") for the names of cand (NULL-ended) within a
  few typos of name, else "". For unknown scene keys, as for unknown options.
@*/
void PeriSceneSuggest(const char name[], const char *const cand[], char buf[], size_t len)
{
  PetscBool exact;
  PeriSuggest(name, (char *const *)cand, buf, len, &exact);
}

/* Appends ", item" (or "item" to an empty list), truncating: PetscStrlcat in PETSc 3.18 can
 * write past the end of the buffer. */
void PeriListAppend(char buf[], size_t len, const char item[])
{
  size_t used = strlen(buf);
  if (used + 1 < len) snprintf(buf + used, len - used, "%s%s", used ? ", " : "", item);
}
