/* Reading back what src/output/vtu.c wrote: the points and the Float64 point arrays of a perilin
 * .vtu (raw appended data, UInt64 byte counts, this machine's byte order), or of a .pvtu and its
 * pieces, concatenated. Not a general VTK reader: other encodings are refused with the reason
 * (ParaView's "Save Data" writes them; give perilin's own file). The dynamic analysis starts from
 * such a file (analysis.initial: a mode shape of the modal analysis, a state of an earlier run). */
#include "perilin/private/output.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

/* The whole file, NUL-terminated (the XML part is searched as a string; the appended part is
 * read by offsets and may hold NULs). */
static PetscErrorCode Slurp(const char path[], char **buf, size_t *len)
{
  FILE       *fp = fopen(path, "rb");
  long        n;
  struct stat st;

  PetscFunctionBeginUser;
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "Cannot open %s: %s", path, strerror(errno));
  /* a directory opens too, and its "size" is LONG_MAX (found by tests/fuzz/fuzz_vtu.c: a .pvtu
     piece with an empty Source, the .pvtu's own directory); a FIFO or a device never ends */
  if (fstat(fileno(fp), &st) || !S_ISREG(st.st_mode)) {
    (void)fclose(fp);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "%s is no regular file", path);
  }
  if (fseek(fp, 0, SEEK_END) || (n = ftell(fp)) < 0 || fseek(fp, 0, SEEK_SET)) {
    (void)fclose(fp);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "Cannot read %s: %s", path, strerror(errno));
  }
  PetscCall(PetscMalloc1((size_t)n + 1, buf));
  *len = fread(*buf, 1, (size_t)n, fp);
  (void)fclose(fp);
  PetscCheck(*len == (size_t)n, PETSC_COMM_SELF, PETSC_ERR_FILE_READ, "Cannot read %s: short read", path);
  (*buf)[n] = 0;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The value of attribute name="..." in the tag starting at tag (up to its '>'), or "" if absent. */
static void Attribute(const char *tag, const char name[], char value[], size_t len)
{
  const char *end = strchr(tag, '>'), *p = tag;
  size_t      nl = strlen(name);

  value[0] = 0;
  while ((p = strstr(p, name)) && (!end || p < end)) {
    if (p > tag && p[-1] == ' ' && p[nl] == '=' && p[nl + 1] == '"') {
      const char *q = strchr(p + nl + 2, '"');
      size_t      k = q ? (size_t)(q - (p + nl + 2)) : 0;
      if (k >= len) k = len - 1;
      memcpy(value, p + nl + 2, k);
      value[k] = 0;
      return;
    }
    p += nl;
  }
}

/* Adds the array of the DataArray tag at tag to d (Points, or a Float64 point array); others are
 * skipped. data: the byte after '_'. */
static PetscErrorCode ReadArray(const char path[], const char *tag, const char *data, size_t avail, PetscInt n, PeriVTUData *d)
{
  char     type[16], name[PERI_NAME_LEN], comp[16], off[32];
  uint64_t nbytes;
  size_t   o;
  PetscInt nc, k;

  PetscFunctionBeginUser;
  Attribute(tag, "type", type, sizeof(type));
  Attribute(tag, "Name", name, sizeof(name));
  Attribute(tag, "NumberOfComponents", comp, sizeof(comp));
  Attribute(tag, "offset", off, sizeof(off));
  if (strcmp(type, "Float64")) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCheck(off[0], PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: array %s is not in appended data: not a file perilin wrote", path, name);
  nc = (PetscInt)strtol(comp[0] ? comp : "1", NULL, 10);
  o  = (size_t)strtoull(off, NULL, 10);
  /* every count from the file is checked against the bytes it has before it sizes anything, without
     overflow (found by tests/fuzz/fuzz_vtu.c: offsets near 2^64, 2^60 points) */
  PetscCheck(avail >= 8 && o <= avail - 8, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: array %s lies past the end of the file", path, name);
  memcpy(&nbytes, data + o, 8);
  PetscCheck(nc >= 1 && nc <= 64 && (uint64_t)n <= (avail - 8 - o) / 8 / (size_t)nc && nbytes == (uint64_t)(8 * n * nc), PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: array %s holds %" PRIu64 " bytes, not %" PetscInt_FMT " points x %" PetscInt_FMT " components", path, name, nbytes, n, nc);
  if (!n) PetscFunctionReturn(PETSC_SUCCESS); /* an empty piece (a rank without particles) */
  if (!strcmp(name, "Points")) {
    PetscCheck(nc == 3, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: Points with %" PetscInt_FMT " components", path, nc);
    PetscCall(PetscRealloc(sizeof(PetscReal) * 3 * (d->n + n), &d->points));
    memcpy(d->points + 3 * d->n, data + o + 8, nbytes);
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  for (k = 0; k < d->narrays && strcmp(d->names[k], name); k++)
    ;
  if (k == d->narrays) {
    PetscCheck(d->narrays < PERI_VTU_MAX_ARRAYS, PETSC_COMM_SELF, PETSC_ERR_SUP, "%s: more than %d Float64 arrays", path, PERI_VTU_MAX_ARRAYS);
    PetscCheck(d->n == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: array %s is missing from an earlier piece", path, name);
    PetscCall(PetscStrncpy(d->names[k], name, sizeof(d->names[k])));
    d->ncomp[k] = nc;
    d->narrays++;
  }
  PetscCheck(d->ncomp[k] == nc, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: array %s has %" PetscInt_FMT " components here, %" PetscInt_FMT " in an earlier piece", path, name, nc, d->ncomp[k]);
  PetscCall(PetscRealloc(sizeof(PetscReal) * nc * (d->n + n), &d->data[k]));
  memcpy(d->data[k] + nc * d->n, data + o + 8, nbytes);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Appends the points and arrays of one .vtu to d. */
static PetscErrorCode ReadPiece(const char path[], PeriVTUData *d)
{
  char          *buf, val[32];
  size_t         len;
  const char    *app, *data, *tag;
  PetscInt       n, before = d->narrays;
  PetscErrorCode ierr = PETSC_SUCCESS;

  PetscFunctionBeginUser;
  PetscCall(Slurp(path, &buf, &len));
  Attribute(buf + (strstr(buf, "<VTKFile") ? strstr(buf, "<VTKFile") - buf : 0), "header_type", val, sizeof(val));
  app = strstr(buf, "<AppendedData encoding=\"raw\">");
  /* the data start after the '_' that follows the tag (none: the file was cut there; found by
     tests/fuzz/fuzz_vtu.c) */
  data = app ? strchr(app, '_') : NULL;
  if (!data || strcmp(val, "UInt64") || !strstr(buf, "byte_order=\"LittleEndian\"") || !(tag = strstr(buf, "<Piece NumberOfPoints="))) {
    PetscCall(PetscFree(buf));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s is not a .vtu perilin wrote (raw appended data, UInt64 headers, little-endian): give perilin's own file, not one re-saved by another program", path);
  }
  Attribute(tag, "NumberOfPoints", val, sizeof(val));
  n = (PetscInt)strtol(val, NULL, 10);
  if (n < 0) {
    PetscCall(PetscFree(buf));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: NumberOfPoints %" PetscInt_FMT " is negative", path, n);
  }
  data++;
  for (tag = strstr(buf, "<DataArray"); tag && tag < app && !ierr; tag = strstr(tag + 1, "<DataArray")) ierr = ReadArray(path, tag, data, len - (size_t)(data - buf), n, d);
  PetscCall(PetscFree(buf)); /* a bad array too */
  PetscCall(ierr);
  PetscCheck(d->n == 0 || d->narrays == before, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s has arrays the earlier pieces lack", path);
  d->n += n;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriReadParticles - reads the points and the Float64 point arrays of a .vtu perilin wrote, or of
  a .pvtu and all its pieces (concatenated in the pieces' order). Destroy with PeriVTUDataDestroy.
  Not collective: each caller reads the whole file.
@*/
PetscErrorCode PeriReadParticles(const char path[], PeriVTUData *d)
{
  size_t len = strlen(path);

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(d, sizeof(*d)));
  if (len > 5 && !strcmp(path + len - 5, ".pvtu")) {
    char       *buf, src[PETSC_MAX_PATH_LEN], piece[PETSC_MAX_PATH_LEN], dir[PETSC_MAX_PATH_LEN];
    size_t      blen;
    const char *tag, *slash = strrchr(path, '/');
    PetscCall(PetscSNPrintf(dir, sizeof(dir), "%.*s", slash ? (int)(slash - path + 1) : 0, path));
    PetscErrorCode ierr = PETSC_SUCCESS;
    PetscCall(Slurp(path, &buf, &blen));
    for (tag = strstr(buf, "<Piece Source="); tag && !ierr; tag = strstr(tag + 1, "<Piece Source=")) {
      Attribute(tag, "Source", src, sizeof(src));
      ierr = PetscSNPrintf(piece, sizeof(piece), "%s%s", src[0] == '/' ? "" : dir, src);
      if (!ierr) ierr = ReadPiece(piece, d);
    }
    PetscCall(PetscFree(buf)); /* a bad piece too: the index is freed (found by tests/fuzz/fuzz_vtu.c) */
    PetscCall(ierr);
  } else
    PetscCall(ReadPiece(path, d));
  PetscCheck(d->n > 0 && d->points, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s holds no points", path);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The index of array name in d, or -1. */
PetscInt PeriVTUDataFind(const PeriVTUData *d, const char name[])
{
  for (PetscInt k = 0; k < d->narrays; k++)
    if (!strcmp(d->names[k], name)) return k;
  return -1;
}

PetscErrorCode PeriVTUDataDestroy(PeriVTUData *d)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(d->points));
  for (PetscInt k = 0; k < d->narrays; k++) PetscCall(PetscFree(d->data[k]));
  PetscCall(PetscMemzero(d, sizeof(*d)));
  PetscFunctionReturn(PETSC_SUCCESS);
}
