/* The tables an analysis writes beside its output set (steps.csv, history.csv): one writer for
 * the file and for the embedding's text, below the analyses that use it. */
#include "perilin/private/analysis.h"

/*@C
  PeriAnalysisWriteTable - an analysis' table (steps.csv, history.csv) as rows(an, fp) writes it
  (non-zero when a write failed): into the file path (temporary name, then rename) when fp is
  NULL, else into fp (the embedding's text). Rank 0 writes; nothing before the run began
  (started false). Not collective.
@*/
PetscErrorCode PeriAnalysisWriteTable(PeriAnalysis an, PetscBool started, int (*rows)(PeriAnalysis, FILE *), const char path[], FILE *fp)
{
  char tmp[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  if (an->rank || !started) PetscFunctionReturn(PETSC_SUCCESS);
  if (fp) {
    PetscCheck(!rows(an, fp), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "writing the %s table failed", an->type->name);
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  PetscCall(PeriFileCloseCommit(fp, tmp, path, rows(an, fp)));
  PetscFunctionReturn(PETSC_SUCCESS);
}
