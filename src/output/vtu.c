/* Particles as a VTK XML UnstructuredGrid (.vtu) of VTK_VERTEX cells, with raw appended binary data.
 *
 * Layout of <AppendedData encoding="raw">_...: for each DataArray, in the order they are declared,
 * a UInt64 byte count followed by the bytes. A DataArray's offset counts from the byte after '_'
 * and includes the 8-byte counts of all earlier blocks. */
#include "perilin/private/output.h"

#include <errno.h>
#include <float.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define VTK_VERTEX     1
#define PERI_PIECE_FMT "piece_%04d.vtu" /* a rank's piece, in the directory named as the .pvtu */

typedef enum {
  VTU_POINT_DATA,
  VTU_POINTS,
  VTU_CELLS
} VTUSection;

typedef enum {
  VTU_FLOAT64, /* gathered from PetscReal data */
  VTU_INT32,   /* converted from PetscInt data, with an overflow check */
  VTU_INT64,   /* first + i */
  VTU_UINT8    /* flags (0/1) per particle and component, or a constant */
} VTUKind;

/* One DataArray and where its values come from: value (i, c) is real[i * stride + map[c]], or 0
   when map[c] < 0 (e.g. uz of a 2D model). */
typedef struct {
  VTUSection       section;
  char            *name;
  VTUKind          kind;
  PetscInt         ncomp;
  const PetscReal *real;
  PetscInt         stride, map[9]; /* up to a tensor's 9 components */
  const PetscInt  *ints;
  int64_t          first;
  uint8_t          byte;
  const uint8_t   *bytes;  /* UInt8: bytes[i * ncomp + c], or the constant byte */
  char            *cnames; /* the components' names, one after the other ('\0' between), or NULL */
  uint64_t         nbytes, offset;
} VTUArray;

static const char *const VTUTypeNames[] = {"Float64", "Int32", "Int64", "UInt8"};
static const size_t      VTUTypeSizes[] = {8, 4, 8, 1};

/* The arrays of one file: per-particle fields (PointData), then the points and the cells. */
struct _p_PeriFieldList {
  PetscInt         n;
  const PetscReal *x;
  PetscInt         na, cap;
  VTUArray        *a;
};

static PetscErrorCode FieldListPush(PeriFieldList fl, VTUSection section, const char name[], VTUKind kind, PetscInt ncomp, VTUArray **a)
{
  PetscFunctionBeginUser;
  if (fl->na == fl->cap) {
    VTUArray *grown;
    PetscCall(PetscCalloc1(2 * fl->cap + 8, &grown));
    if (fl->na) PetscCall(PetscArraycpy(grown, fl->a, fl->na));
    PetscCall(PetscFree(fl->a));
    fl->a   = grown;
    fl->cap = 2 * fl->cap + 8;
  }
  *a = &fl->a[fl->na++];
  PetscCall(PetscMemzero(*a, sizeof(**a)));
  (*a)->section = section;
  (*a)->kind    = kind;
  (*a)->ncomp   = ncomp;
  PetscCall(PetscStrallocpy(name, &(*a)->name));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFieldListCreate - an empty list of per-particle fields over n points x (3 per point). The
  arrays are referenced, not copied: they must live until the list is written.
@*/
PetscErrorCode PeriFieldListCreate(PetscInt n, const PetscReal x[], PeriFieldList *list)
{
  PetscFunctionBeginUser;
  PetscCheck(n >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Negative number of particles %" PetscInt_FMT, n);
  PetscCall(PetscNew(list));
  (*list)->n = n;
  (*list)->x = x;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriFieldListDestroy(PeriFieldList *list)
{
  PetscFunctionBeginUser;
  if (!*list) PetscFunctionReturn(PETSC_SUCCESS);
  for (PetscInt k = 0; k < (*list)->na; k++) {
    PetscCall(PetscFree((*list)->a[k].name));
    PetscCall(PetscFree((*list)->a[k].cnames));
  }
  PetscCall(PetscFree((*list)->a));
  PetscCall(PetscFree(*list));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFieldListAddReal - a field of ncomp components: component c of particle i is
  real[i * stride + map[c]] (map NULL: c), or 0 where map[c] < 0 (uz of a 2D model).
@*/
PetscErrorCode PeriFieldListAddReal(PeriFieldList fl, const char name[], PetscInt ncomp, const PetscReal *real, PetscInt stride, const PetscInt map[])
{
  VTUArray *a = NULL;

  PetscFunctionBeginUser;
  PetscCheck(real, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Cannot write field %s: no data", name);
  PetscCheck((ncomp >= 1 && ncomp <= 3) || ncomp == 9, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Field %s: %" PetscInt_FMT " components (1 to 3, or 9: a tensor)", name, ncomp);
  PetscCall(FieldListPush(fl, VTU_POINT_DATA, name, VTU_FLOAT64, ncomp, &a));
  a->real   = real;
  a->stride = stride;
  for (PetscInt c = 0; c < ncomp; c++) a->map[c] = map ? map[c] : c;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* An integer field (Int32, with an overflow check when written). */
PetscErrorCode PeriFieldListAddInt(PeriFieldList fl, const char name[], const PetscInt *ints)
{
  VTUArray *a = NULL;

  PetscFunctionBeginUser;
  PetscCheck(ints, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Cannot write field %s: no data", name);
  PetscCall(FieldListPush(fl, VTU_POINT_DATA, name, VTU_INT32, 1, &a));
  a->ints = ints;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFieldListAddFlags - a UInt8 field of ncomp components (flags 0/1: a byte per value, not a
  double): component c of particle i is bytes[i * ncomp + c], named components[c] in the file
  (ParaView's component names; NULL: none).
@*/
PetscErrorCode PeriFieldListAddFlags(PeriFieldList fl, const char name[], PetscInt ncomp, const unsigned char *bytes, const char *const components[])
{
  VTUArray *a = NULL;

  PetscFunctionBeginUser;
  PetscCheck(bytes || !fl->n, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Cannot write field %s: no data", name);
  PetscCheck(ncomp >= 1 && ncomp <= 3, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Field %s: %" PetscInt_FMT " components (1 to 3)", name, ncomp);
  PetscCall(FieldListPush(fl, VTU_POINT_DATA, name, VTU_UINT8, ncomp, &a));
  a->bytes = bytes;
  if (components) {
    size_t len = 0, used = 0;
    char  *names;
    for (PetscInt c = 0; c < ncomp; c++) len += strlen(components[c]) + 1;
    PetscCall(PetscMalloc1(len, &names));
    for (PetscInt c = 0; c < ncomp; c++) {
      PetscCall(PetscStrcpy(names + used, components[c]));
      used += strlen(components[c]) + 1;
    }
    a->cnames = names;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The attributes ' ComponentName0="ux" ...' of a, or "". */
static void ComponentNames(const VTUArray *a, char buf[], size_t len)
{
  const char *c = a->cnames;

  buf[0] = 0;
  for (PetscInt k = 0; c && k < a->ncomp; k++, c += strlen(c) + 1) {
    size_t used = strlen(buf);
    snprintf(buf + used, len - used, " ComponentName%" PetscInt_FMT "=\"%s\"", k, c);
  }
}

/* An integer field of one value at every particle (Int32). */
PetscErrorCode PeriFieldListAddIntConstant(PeriFieldList fl, const char name[], PetscInt value)
{
  VTUArray *a = NULL;

  PetscFunctionBeginUser;
  PetscCall(FieldListPush(fl, VTU_POINT_DATA, name, VTU_INT32, 1, &a));
  a->first = value;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriFieldListAddSolution - the DOFs u (dofs per particle, named components[], the translations
  along axis[c] >= 0) as fields: the translations as one vector "displacement" (none when the model has no translation: a zero vector would
  mislead), every other component as its own field ("theta"). With a prefix ("mode_3") the vector
  is named by the prefix and the others "mode_3_theta".
@*/
PetscErrorCode PeriFieldListAddSolution(PeriFieldList fl, const char prefix[], PetscInt dofs, const char *const components[], const PetscInt axis[], const PetscReal *u)
{
  PetscInt map[3] = {-1, -1, -1}, ntrans = 0;
  char     name[PERI_NAME_LEN + 32];

  PetscFunctionBeginUser;
  PetscCheck(components && dofs >= 1 && dofs <= PERI_MAX_DOF, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Cannot write a solution of %" PetscInt_FMT " named DOFs per particle", dofs);
  for (PetscInt c = 0; c < dofs; c++) {
    const PetscInt d = axis[c];
    if (d < 0) continue;
    PetscCheck(d < 3 && map[d] < 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Component %s: axis %" PetscInt_FMT " out of range or taken twice", components[c], d);
    map[d] = c;
    ntrans++;
  }
  if (ntrans) PetscCall(PeriFieldListAddReal(fl, prefix[0] ? prefix : "displacement", 3, u, dofs, map));
  for (PetscInt c = 0; c < dofs; c++) {
    if (c == map[0] || c == map[1] || c == map[2]) continue;
    PetscCall(PetscSNPrintf(name, sizeof(name), "%s%s%s", prefix, prefix[0] ? "_" : "", components[c]));
    PetscCall(PeriFieldListAddReal(fl, name, 1, u, dofs, &c));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Convert one array into buf (n * ncomp values of its VTK type). */
static PetscErrorCode VTUFill(const VTUArray *a, PetscInt n, void *buf)
{
  PetscInt i, c;

  PetscFunctionBeginUser;
  for (i = 0; i < n; i++) {
    for (c = 0; c < a->ncomp; c++) {
      const PetscInt k = i * a->ncomp + c;

      switch (a->kind) {
      case VTU_FLOAT64:
        ((double *)buf)[k] = a->map[c] < 0 ? 0.0 : (double)a->real[i * a->stride + a->map[c]];
        break;
      case VTU_INT32: {
        const PetscInt v = a->ints ? a->ints[i] : (PetscInt)a->first; /* no array: the constant first */
        PetscCheck(v >= INT32_MIN && v <= INT32_MAX, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "VTU array %s: value %" PetscInt_FMT " of particle %" PetscInt_FMT " does not fit in Int32", a->name, v, i);
        ((int32_t *)buf)[k] = (int32_t)v;
      } break;
      case VTU_INT64:
        ((int64_t *)buf)[k] = a->first + (int64_t)i;
        break;
      case VTU_UINT8:
        ((uint8_t *)buf)[k] = a->bytes ? a->bytes[k] : a->byte;
        break;
      }
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* One appended block: the UInt64 byte count, then the data. */
static PetscErrorCode VTUWriteBlock(FILE *fp, const char file[], uint64_t nbytes, const void *data)
{
  PetscFunctionBeginUser;
  PetscCheck(fwrite(&nbytes, sizeof(nbytes), 1, fp) == 1, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Error writing %s: %s", file, strerror(errno));
  if (nbytes) PetscCheck(fwrite(data, 1, (size_t)nbytes, fp) == (size_t)nbytes, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Error writing %s: %s", file, strerror(errno));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode VTUPrintf(FILE *fp, const char file[], const char fmt[], ...) PETSC_ATTRIBUTE_FORMAT(3, 4);
static PetscErrorCode VTUPrintf(FILE *fp, const char file[], const char fmt[], ...)
{
  va_list ap;
  int     rc;

  PetscFunctionBeginUser;
  va_start(ap, fmt);
  rc = vfprintf(fp, fmt, ap);
  va_end(ap);
  PetscCheck(rc >= 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Error writing %s: %s", file, strerror(errno));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The whole file; the caller owns fp and buf, and removes the tmp file if this fails. */
static PetscErrorCode VTUWriteFile(FILE *fp, const char file[], PetscInt n, PetscInt na, const VTUArray a[], void *buf)
{
  static const char *const opentag[]  = {"<PointData>", "<Points>", "<Cells>"};
  static const char *const closetag[] = {"</PointData>", "</Points>", "</Cells>"};
  const uint16_t           one        = 1;
  const char *const        order      = *(const unsigned char *)&one ? "LittleEndian" : "BigEndian";
  PetscInt                 s, k;

  PetscFunctionBeginUser;
  PetscCall(VTUPrintf(fp, file, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" header_type=\"UInt64\">\n", order));
  PetscCall(VTUPrintf(fp, file, "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"%" PetscInt_FMT "\" NumberOfCells=\"%" PetscInt_FMT "\">\n", n, n));
  for (s = VTU_POINT_DATA; s <= VTU_CELLS; s++) {
    PetscCall(VTUPrintf(fp, file, "      %s\n", opentag[s]));
    for (k = 0; k < na; k++) {
      char names[256];
      if (a[k].section != (VTUSection)s) continue;
      ComponentNames(&a[k], names, sizeof(names));
      PetscCall(VTUPrintf(fp, file, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%" PetscInt_FMT "\"%s format=\"appended\" offset=\"%" PRIu64 "\"/>\n", VTUTypeNames[a[k].kind], a[k].name, a[k].ncomp, names, a[k].offset));
    }
    PetscCall(VTUPrintf(fp, file, "      %s\n", closetag[s]));
  }
  PetscCall(VTUPrintf(fp, file, "    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _"));
  for (k = 0; k < na; k++) {
    PetscCall(VTUFill(&a[k], n, buf));
    PetscCall(VTUWriteBlock(fp, file, a[k].nbytes, buf));
  }
  PetscCall(VTUPrintf(fp, file, "\n  </AppendedData>\n</VTKFile>\n"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The points and the cells (one vertex per point), after the fields; once per list. */
static PetscErrorCode PeriFieldListAddGeometry(PeriFieldList fl)
{
  VTUArray *a = NULL;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < fl->na; k++)
    if (fl->a[k].section == VTU_POINTS) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCheck(fl->x, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Cannot write VTU: no points");
  PetscCall(FieldListPush(fl, VTU_POINTS, "Points", VTU_FLOAT64, 3, &a));
  a->real   = fl->x;
  a->stride = 3;
  for (PetscInt c = 0; c < 3; c++) a->map[c] = c;
  PetscCall(FieldListPush(fl, VTU_CELLS, "connectivity", VTU_INT64, 1, &a));
  PetscCall(FieldListPush(fl, VTU_CELLS, "offsets", VTU_INT64, 1, &a));
  a->first = 1; /* one point per cell */
  PetscCall(FieldListPush(fl, VTU_CELLS, "types", VTU_UINT8, 1, &a));
  a->byte = VTK_VERTEX;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Sizes and offsets of the arrays (the geometry added first), and the largest array in bytes. */
static PetscErrorCode VTULayout(PeriFieldList fl, uint64_t *maxbytes)
{
  uint64_t offset = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriFieldListAddGeometry(fl));
  *maxbytes = 0;
  for (PetscInt k = 0; k < fl->na; k++) {
    VTUArray *a = &fl->a[k];
    a->nbytes   = (uint64_t)fl->n * (uint64_t)a->ncomp * VTUTypeSizes[a->kind];
    a->offset   = offset;
    offset += sizeof(uint64_t) + a->nbytes;
    *maxbytes = PetscMax(*maxbytes, a->nbytes);
  }
  PetscCheck(*maxbytes <= SIZE_MAX, PETSC_COMM_SELF, PETSC_ERR_MEM, "VTU array of %" PRIu64 " bytes is too large", *maxbytes);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The whole file as tmp (path.tmp), closed; on failure tmp is removed. Not collective. */
static PetscErrorCode VTUWriteTemporary(PeriFieldList fl, const char path[], char tmp[], size_t len)
{
  uint64_t       maxbytes = 0;
  FILE          *fp;
  double        *buf; /* double for alignment; also holds the Int32/Int64/UInt8 arrays */
  PetscErrorCode ierr;
  int            rc, err;

  PetscFunctionBeginUser;
  PetscCheck(path && path[0], PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "Empty VTU file name");
  PetscCheck(strlen(path) + sizeof(".tmp") <= len, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "VTU file name is too long: %s", path);
  PetscCall(VTULayout(fl, &maxbytes));
  PetscCall(PetscMalloc1((size_t)(maxbytes / sizeof(double) + 1), &buf));
  PetscCall(PetscSNPrintf(tmp, len, "%s.tmp", path));
  fp = fopen(tmp, "wb");
  if (!fp) {
    err = errno;
    PetscCall(PetscFree(buf));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "Cannot open %s for writing: %s", tmp, strerror(err));
  }
  ierr = VTUWriteFile(fp, tmp, fl->n, fl->na, fl->a, buf);
  /* Buffered write errors (e.g. a full disk) only surface at fclose(). */
  rc  = fclose(fp);
  err = errno;
  PetscCall(PetscFree(buf));
  if (ierr != PETSC_SUCCESS || rc != 0) {
    (void)remove(tmp);
    PetscCall(ierr);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Error writing %s: %s", tmp, strerror(err));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWriteVTU - the fields of the list, the points and one vertex cell per point, written to
  path through a temporary file (nothing is left behind on failure). Not collective: one rank
  writes the particles of its list (PeriWriteParticles writes a set of them).
@*/
PetscErrorCode PeriWriteVTU(PeriFieldList fl, const char path[])
{
  char tmp[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(VTUWriteTemporary(fl, path, tmp, sizeof(tmp)));
  PetscCall(PeriFileCommit(tmp, path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The parallel index: the arrays' names, types and components (those of every piece: each rank
 * builds the same list over its own particles) and the pieces, relative to the .pvtu. */
static PetscErrorCode WritePVTU(PeriFieldList fl, const char path[], const char base[], PetscMPIInt size)
{
  const uint16_t    one   = 1;
  const char *const order = *(const unsigned char *)&one ? "LittleEndian" : "BigEndian";
  char              tmp[PETSC_MAX_PATH_LEN];
  FILE             *fp;
  int               bad = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriFieldListAddGeometry(fl));
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" header_type=\"UInt64\">\n  <PUnstructuredGrid GhostLevel=\"0\">\n    <PPointData>\n", order) < 0;
  for (PetscInt k = 0; k < fl->na; k++) {
    const VTUArray *a = &fl->a[k];
    char            names[256];
    if (a->section == VTU_POINTS) bad |= fprintf(fp, "    </PPointData>\n    <PPoints>\n") < 0;
    if (a->section == VTU_CELLS) break; /* the cells come from the pieces */
    ComponentNames(a, names, sizeof(names));
    bad |= fprintf(fp, "      <PDataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%" PetscInt_FMT "\"%s/>\n", VTUTypeNames[a->kind], a->name, a->ncomp, names) < 0;
  }
  bad |= fprintf(fp, "    </PPoints>\n") < 0;
  for (PetscMPIInt r = 0; r < size; r++) bad |= fprintf(fp, "    <Piece Source=\"%s/" PERI_PIECE_FMT "\"/>\n", base, r) < 0;
  bad |= fprintf(fp, "  </PUnstructuredGrid>\n</VTKFile>\n") < 0;
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every rank learns whether any failed (ierr) and which (the highest): a file set is renamed
 * only when all ranks wrote their part, and then all ranks fail together (none waits in a
 * collective call), removing their own temporary file tmp (or NULL). */
static PetscErrorCode Agree(MPI_Comm comm, PetscErrorCode ierr, const char tmp[], const char what[], const char path[])
{
  PetscMPIInt rank, bad;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  bad = ierr ? rank + 1 : 0;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_MAX, comm));
  if (bad && tmp && tmp[0]) (void)remove(tmp);
  PetscCall(ierr); /* the failing rank reports its own cause */
  PetscCheck(!bad, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Cannot write %s: rank %d failed to %s", path, bad - 1, what);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The name of the particle file base.vtu (one rank) or base.pvtu (several). */
PetscErrorCode PeriParticlesFileName(MPI_Comm comm, const char base[], char name[], size_t len)
{
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscSNPrintf(name, len, "%s.%s", base, size > 1 ? "pvtu" : "vtu"));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWriteParticles - the particles of every rank's list as dir/base.vtu (one rank) or, without
  gathering them, as VTK's parallel format: each rank writes its own particles to
  dir/base/piece_RRRR.vtu and rank 0 the index dir/base.pvtu. Every file goes through a temporary
  name; the pieces are renamed only after all ranks wrote theirs, and the index after all pieces
  were renamed, so a failure on any rank leaves no base.pvtu (and the run's set is discarded).
  Collective.
@*/
PetscErrorCode PeriWriteParticles(MPI_Comm comm, PeriFieldList fl, const char dir[], const char base[])
{
  char           path[PETSC_MAX_PATH_LEN], piece[PETSC_MAX_PATH_LEN], tmp[PETSC_MAX_PATH_LEN] = "";
  PetscMPIInt    rank, size;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/%s.%s", dir, base, size > 1 ? "pvtu" : "vtu"));
  if (size == 1) {
    PetscCall(PeriWriteVTU(fl, path));
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscSNPrintf(piece, sizeof(piece), "%s/%s", dir, base));
  ierr = PeriOutputDirCreate(piece); /* every rank: mkdir -p tolerates the others' */
  PetscCall(PetscSNPrintf(piece, sizeof(piece), "%s/%s/" PERI_PIECE_FMT, dir, base, rank));
  if (!ierr) ierr = VTUWriteTemporary(fl, piece, tmp, sizeof(tmp));
  PetscCall(Agree(comm, ierr, tmp, "write its piece", path));
  ierr = PeriFileCommit(tmp, piece);
  PetscCall(Agree(comm, ierr, NULL, "rename its piece", path));
  ierr = rank ? PETSC_SUCCESS : WritePVTU(fl, path, base, size);
  PetscCall(Agree(comm, ierr, NULL, "write the index", path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWritePVD - a ParaView collection (.pvd) listing files[k] at time times[k], so that a series
  (load steps, mode shapes) opens as one data set. The caller gives the times in ascending order;
  ParaView needs them strictly increasing (equal times collapse into one frame), so a time not
  above the one before it is written as that one x (1 + 1e-12) (or the smallest normal number
  above 0): equal load factors of an event's peak and cascade, degenerate frequencies. The times
  are printed to 17 digits, so that a reader gets the value back to the last bit. Not collective:
  call it on the writing rank.
@*/
PetscErrorCode PeriWritePVD(const char path[], PetscInt n, const PetscReal times[], const char *const files[])
{
  char      tmp[PETSC_MAX_PATH_LEN];
  FILE     *fp;
  int       bad  = 0;
  PetscReal prev = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n") < 0;
  for (PetscInt k = 0; k < n; k++) {
    PetscReal t = times[k];
    if (k && !(t > prev)) t = prev != 0 ? prev + 1e-12 * PetscAbsReal(prev) : (PetscReal)DBL_MIN;
    bad |= fprintf(fp, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"%s\"/>\n", (double)t, files[k]) < 0;
    prev = t;
  }
  bad |= fprintf(fp, "  </Collection>\n</VTKFile>\n") < 0;
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}
