/* A tiny streaming JSON writer (pretty-printed, 2-space indentation) for the run summary.
 * Not collective: use it on one rank only.
 *
 * Any error (a write failure, a non-finite value, misuse) abandons the writer at once: the tmp file
 * is closed and removed, so even a caller that simply propagates the error with PetscCall() leaves
 * no partial file behind. Later calls on an abandoned writer fail; PeriJSONClose() still frees it. */
#include "perilin/private/output.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define PERI_JSON_MAX_DEPTH 64

struct _PeriJSON {
  FILE    *fp; /* NULL once closed or abandoned */
  char     tmp[PETSC_MAX_PATH_LEN];
  char     final[PETSC_MAX_PATH_LEN];
  int      depth;                                     /* 0 is the root object */
  char     kind[PERI_JSON_MAX_DEPTH];                 /* '{' or '[' per open container */
  PetscInt count[PERI_JSON_MAX_DEPTH];                /* members written so far; 0 means "first" */
  char     label[PERI_JSON_MAX_DEPTH][PERI_NAME_LEN]; /* how each container is named in its parent, for messages */
};

static PetscErrorCode JSONAbandon(PeriJSON j)
{
  PetscFunctionBeginUser;
  if (j->fp) {
    (void)fclose(j->fp);
    (void)remove(j->tmp);
    j->fp = NULL;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Abandon the file, then raise the error. The message arguments are evaluated after the abandon,
   so never pass strerror(errno) here: save errno first. */
#define JSONCheck(j, cond, code, ...)              \
  do {                                             \
    if (PetscUnlikely(!(cond))) {                  \
      PetscCall(JSONAbandon(j));                   \
      SETERRQ(PETSC_COMM_SELF, code, __VA_ARGS__); \
    }                                              \
  } while (0)

static PetscErrorCode JSONPrintf(PeriJSON j, const char fmt[], ...) PETSC_ATTRIBUTE_FORMAT(2, 3);
static PetscErrorCode JSONPrintf(PeriJSON j, const char fmt[], ...)
{
  va_list ap;
  int     rc;

  PetscFunctionBeginUser;
  va_start(ap, fmt);
  rc = vfprintf(j->fp, fmt, ap);
  va_end(ap);
  if (rc < 0) {
    int err = errno;

    PetscCall(JSONAbandon(j));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Error writing %s: %s", j->tmp, strerror(err));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode JSONCheckUsable(PeriJSON j)
{
  PetscFunctionBeginUser;
  PetscCheck(j, PETSC_COMM_SELF, PETSC_ERR_ARG_NULL, "NULL JSON writer");
  PetscCheck(j->fp, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "JSON file %s was abandoned after an earlier error", j->final);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Bounded append that truncates. Not PetscStrlcat(): in PETSc 3.18 it writes past the end of the
   buffer when the result does not fit. */
static PetscErrorCode JSONAppend(char dst[], const char src[], size_t size)
{
  size_t len = strlen(dst), add = strlen(src);

  PetscFunctionBeginUser;
  if (len + 1 >= size) PetscFunctionReturn(PETSC_SUCCESS);
  if (add > size - 1 - len) add = size - 1 - len;
  memcpy(dst + len, src, add);
  dst[len + add] = '\0';
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Dotted path of the value about to be written ("max_abs_u[2]"), for error messages. */
static PetscErrorCode JSONPath(PeriJSON j, const char key[], char path[], size_t len)
{
  char last[PERI_NAME_LEN + 32];
  int  d;

  PetscFunctionBeginUser;
  path[0] = '\0';
  for (d = 1; d <= j->depth; d++) {
    if (j->label[d][0] != '[' && path[0]) PetscCall(JSONAppend(path, ".", len));
    PetscCall(JSONAppend(path, j->label[d], len));
  }
  if (j->kind[j->depth] == '[')
    PetscCall(PetscSNPrintf(last, sizeof(last), "[%" PetscInt_FMT "]", j->count[j->depth]));
  else
    PetscCall(PetscSNPrintf(last, sizeof(last), "%s%s", path[0] ? "." : "", key ? key : "(null)"));
  PetscCall(JSONAppend(path, last, len));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode JSONWriteString(PeriJSON j, const char s[])
{
  const unsigned char *c;

  PetscFunctionBeginUser;
  PetscCall(JSONPrintf(j, "\""));
  for (c = (const unsigned char *)s; *c; c++) {
    switch (*c) {
    case '"':
      PetscCall(JSONPrintf(j, "\\\""));
      break;
    case '\\':
      PetscCall(JSONPrintf(j, "\\\\"));
      break;
    case '\n':
      PetscCall(JSONPrintf(j, "\\n"));
      break;
    case '\r':
      PetscCall(JSONPrintf(j, "\\r"));
      break;
    case '\t':
      PetscCall(JSONPrintf(j, "\\t"));
      break;
    case '\b':
      PetscCall(JSONPrintf(j, "\\b"));
      break;
    case '\f':
      PetscCall(JSONPrintf(j, "\\f"));
      break;
    default:
      if (*c < 0x20)
        PetscCall(JSONPrintf(j, "\\u%04x", (unsigned)*c));
      else
        PetscCall(JSONPrintf(j, "%c", *c));
    }
  }
  PetscCall(JSONPrintf(j, "\""));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Separator, indentation and (inside objects) the key of the next member. Inside arrays the key
   is not written; callers may still pass one, it then only names the value in error messages. */
static PetscErrorCode JSONBeginValue(PeriJSON j, const char key[])
{
  PetscFunctionBeginUser;
  PetscCall(JSONCheckUsable(j));
  JSONCheck(j, j->kind[j->depth] == '[' || key, PETSC_ERR_ARG_NULL, "JSON file %s: a member of an object needs a key", j->final);
  PetscCall(JSONPrintf(j, "%s\n%*s", j->count[j->depth] ? "," : "", 2 * (j->depth + 1), ""));
  if (j->kind[j->depth] == '{') {
    PetscCall(JSONWriteString(j, key));
    PetscCall(JSONPrintf(j, ": "));
  }
  j->count[j->depth]++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode JSONBegin(PeriJSON j, const char key[], char kind)
{
  char label[PERI_NAME_LEN];

  PetscFunctionBeginUser;
  PetscCall(JSONCheckUsable(j));
  JSONCheck(j, j->depth + 1 < PERI_JSON_MAX_DEPTH, PETSC_ERR_ARG_OUTOFRANGE, "JSON file %s: nesting deeper than %d levels", j->final, PERI_JSON_MAX_DEPTH - 1);
  /* The label must be taken before JSONBeginValue() counts this member. */
  if (j->kind[j->depth] == '[')
    PetscCall(PetscSNPrintf(label, sizeof(label), "[%" PetscInt_FMT "]", j->count[j->depth]));
  else
    PetscCall(PetscStrncpy(label, key ? key : "", sizeof(label)));
  PetscCall(JSONBeginValue(j, key));
  PetscCall(JSONPrintf(j, "%c", kind));
  j->depth++;
  j->kind[j->depth]  = kind;
  j->count[j->depth] = 0;
  PetscCall(PetscStrncpy(j->label[j->depth], label, sizeof(j->label[j->depth])));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Also closes the root object (depth 0). */
static PetscErrorCode JSONEnd(PeriJSON j, char kind)
{
  const char close = kind == '{' ? '}' : ']';

  PetscFunctionBeginUser;
  PetscCall(JSONCheckUsable(j));
  JSONCheck(j, j->kind[j->depth] == kind, PETSC_ERR_ARG_WRONGSTATE, "JSON file %s: '%c' does not close %s, which was opened with '%c'", j->final, close, j->depth ? j->label[j->depth] : "the root", j->kind[j->depth]);
  /* Empty containers stay on one line: {} and []. */
  if (j->count[j->depth])
    PetscCall(JSONPrintf(j, "\n%*s%c", 2 * j->depth, "", close));
  else
    PetscCall(JSONPrintf(j, "%c", close));
  j->depth--;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONOpen(const char final[], PeriJSON *j)
{
  PeriJSON       J;
  PetscErrorCode ierr;
  size_t         len;

  PetscFunctionBeginUser;
  PetscCheck(final && final[0], PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "Empty JSON file name");
  PetscCheck(j, PETSC_COMM_SELF, PETSC_ERR_ARG_NULL, "NULL JSON writer pointer");
  *j  = NULL;
  len = strlen(final);
  PetscCheck(len + sizeof(".tmp") <= PETSC_MAX_PATH_LEN, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "JSON file name is too long: %s", final);
  PetscCall(PetscNew(&J));
  PetscCall(PetscStrncpy(J->final, final, sizeof(J->final)));
  PetscCall(PetscSNPrintf(J->tmp, sizeof(J->tmp), "%s.tmp", final));
  J->fp = fopen(J->tmp, "w");
  if (!J->fp) {
    int err = errno;

    PetscCall(PetscFree(J));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "Cannot open %s.tmp for writing: %s", final, strerror(err));
  }
  J->depth    = 0;
  J->kind[0]  = '{';
  J->count[0] = 0;
  ierr        = JSONPrintf(J, "{");
  if (ierr) PetscCall(PetscFree(J)); /* JSONPrintf() already removed the tmp */
  PetscCall(ierr);
  *j = J;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Closes the root object, the file, and renames tmp -> final; on any failure the tmp is gone. */
static PetscErrorCode JSONFinish(PeriJSON j)
{
  int bad, rc, err;

  PetscFunctionBeginUser;
  PetscCheck(j->fp, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "JSON file %s was abandoned after an earlier error: not writing it", j->final);
  JSONCheck(j, j->depth == 0, PETSC_ERR_ARG_WRONGSTATE, "JSON file %s: %s is still open", j->final, j->label[j->depth]);
  PetscCall(JSONEnd(j, '{'));
  PetscCall(JSONPrintf(j, "\n"));
  /* Buffered write errors (e.g. a full disk) only surface here. */
  bad   = ferror(j->fp);
  rc    = fclose(j->fp);
  err   = errno;
  j->fp = NULL;
  if (bad || rc != 0) {
    (void)remove(j->tmp);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Error writing %s: %s", j->tmp, rc != 0 ? strerror(err) : "stream error");
  }
  PetscCall(PeriFileCommit(j->tmp, j->final));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONClose(PeriJSON *j, PetscBool commit)
{
  PeriJSON       J;
  PetscErrorCode ierr = PETSC_SUCCESS;

  PetscFunctionBeginUser;
  if (!j || !*j) PetscFunctionReturn(PETSC_SUCCESS);
  J  = *j;
  *j = NULL;
  if (commit)
    ierr = JSONFinish(J); /* propagated only after J is freed */
  else
    PetscCall(JSONAbandon(J));
  PetscCall(PetscFree(J));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONBeginObject(PeriJSON j, const char key[])
{
  PetscFunctionBeginUser;
  PetscCall(JSONBegin(j, key, '{'));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONEndObject(PeriJSON j)
{
  PetscFunctionBeginUser;
  PetscCall(JSONCheckUsable(j));
  JSONCheck(j, j->depth > 0, PETSC_ERR_ARG_WRONGSTATE, "JSON file %s: the root object is closed by PeriJSONClose(), not PeriJSONEndObject()", j->final);
  PetscCall(JSONEnd(j, '{'));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONBeginArray(PeriJSON j, const char key[])
{
  PetscFunctionBeginUser;
  PetscCall(JSONBegin(j, key, '['));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONEndArray(PeriJSON j)
{
  PetscFunctionBeginUser;
  PetscCall(JSONEnd(j, '['));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A NULL value is written as JSON null. */
PetscErrorCode PeriJSONString(PeriJSON j, const char key[], const char value[])
{
  PetscFunctionBeginUser;
  PetscCall(JSONBeginValue(j, key));
  if (value)
    PetscCall(JSONWriteString(j, value));
  else
    PetscCall(JSONPrintf(j, "null"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* JSON has no NaN/Inf, and a summary that silently says "null" would hide a failed run. */
static PetscErrorCode JSONCheckFinite(PeriJSON j, const char key[], PetscInt n, const PetscReal v[], PetscBool indexed)
{
  char     path[4 * PERI_NAME_LEN];
  PetscInt i;

  PetscFunctionBeginUser;
  for (i = 0; i < n; i++) {
    if (!PetscIsInfOrNanReal(v[i])) continue;
    PetscCall(JSONPath(j, key, path, sizeof(path)));
    if (indexed) {
      char index[32];

      PetscCall(PetscSNPrintf(index, sizeof(index), "[%" PetscInt_FMT "]", i));
      PetscCall(JSONAppend(path, index, sizeof(path)));
    }
    PetscCall(JSONAbandon(j));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FP, "summary value %s is not finite (NaN or Inf): refusing to write it", path);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONReal(PeriJSON j, const char key[], PetscReal v)
{
  PetscFunctionBeginUser;
  PetscCall(JSONCheckUsable(j));
  PetscCall(JSONCheckFinite(j, key, 1, &v, PETSC_FALSE));
  PetscCall(JSONBeginValue(j, key));
  PetscCall(JSONPrintf(j, "%.17g", (double)v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONInt(PeriJSON j, const char key[], PetscInt v)
{
  PetscFunctionBeginUser;
  PetscCall(JSONBeginValue(j, key));
  PetscCall(JSONPrintf(j, "%" PetscInt_FMT, v));
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriJSONBool(PeriJSON j, const char key[], PetscBool v)
{
  PetscFunctionBeginUser;
  PetscCall(JSONBeginValue(j, key));
  PetscCall(JSONPrintf(j, "%s", v ? "true" : "false"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Written on one line: "key": [a, b, c]. */
PetscErrorCode PeriJSONRealArray(PeriJSON j, const char key[], PetscInt n, const PetscReal v[])
{
  PetscInt i;

  PetscFunctionBeginUser;
  PetscCall(JSONCheckUsable(j));
  JSONCheck(j, n >= 0 && (n == 0 || v), PETSC_ERR_ARG_WRONG, "JSON file %s: invalid array %s (n = %" PetscInt_FMT ")", j->final, key ? key : "(null)", n);
  PetscCall(JSONCheckFinite(j, key, n, v, PETSC_TRUE));
  PetscCall(JSONBeginValue(j, key));
  PetscCall(JSONPrintf(j, "["));
  for (i = 0; i < n; i++) PetscCall(JSONPrintf(j, "%s%.17g", i ? ", " : "", (double)v[i]));
  PetscCall(JSONPrintf(j, "]"));
  PetscFunctionReturn(PETSC_SUCCESS);
}
