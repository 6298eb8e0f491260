/* Particles as a VTK XML UnstructuredGrid (.vtu) of VTK_VERTEX cells, with raw appended binary data.
 *
 * Layout of <AppendedData encoding="raw">_...: for each DataArray, in the order they are declared,
 * a UInt64 byte count followed by the bytes. A DataArray's offset counts from the byte after '_'
 * and includes the 8-byte counts of all earlier blocks. */
#include "perilin.h"

#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define VTU_MAX_ARRAYS (8 + PERI_MAX_DOF * (1 + PERI_MAX_VTU_MODES))
#define VTK_VERTEX     1

typedef enum {
  VTU_POINT_DATA,
  VTU_POINTS,
  VTU_CELLS
} VTUSection;

typedef enum {
  VTU_FLOAT64, /* gathered from PetscReal data */
  VTU_INT32,   /* converted from PetscInt data, with an overflow check */
  VTU_INT64,   /* first + i */
  VTU_UINT8    /* a constant */
} VTUKind;

/* One DataArray and where its values come from: value (i, c) is real[i * stride + map[c]], or 0
   when map[c] < 0 (e.g. uz of a 2D model). */
typedef struct {
  VTUSection       section;
  const char      *name;
  VTUKind          kind;
  PetscInt         ncomp;
  const PetscReal *real;
  PetscInt         stride, map[3];
  const PetscInt  *ints;
  int64_t          first;
  uint8_t          byte;
  uint64_t         nbytes, offset;
} VTUArray;

static const char *const VTUTypeNames[] = {"Float64", "Int32", "Int64", "UInt8"};
static const size_t      VTUTypeSizes[] = {8, 4, 8, 1};

static PetscErrorCode VTUAddReal(VTUArray a[], PetscInt *na, VTUSection section, const char name[], PetscInt ncomp, const PetscReal *real, PetscInt stride, const PetscInt map[])
{
  PetscInt c;

  PetscFunctionBeginUser;
  PetscCheck(*na < VTU_MAX_ARRAYS, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Too many VTU arrays");
  PetscCheck(real, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Cannot write VTU array %s: no data", name);
  PetscCall(PetscMemzero(&a[*na], sizeof(a[*na])));
  a[*na].section = section;
  a[*na].name    = name;
  a[*na].kind    = VTU_FLOAT64;
  a[*na].ncomp   = ncomp;
  a[*na].real    = real;
  a[*na].stride  = stride;
  for (c = 0; c < ncomp; c++) a[*na].map[c] = map ? map[c] : c;
  (*na)++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode VTUAddInt(VTUArray a[], PetscInt *na, VTUSection section, const char name[], VTUKind kind, const PetscInt *ints, int64_t first, uint8_t byte)
{
  PetscFunctionBeginUser;
  PetscCheck(*na < VTU_MAX_ARRAYS, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Too many VTU arrays");
  PetscCheck(kind != VTU_INT32 || ints, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Cannot write VTU array %s: no data", name);
  PetscCall(PetscMemzero(&a[*na], sizeof(a[*na])));
  a[*na].section = section;
  a[*na].name    = name;
  a[*na].kind    = kind;
  a[*na].ncomp   = 1;
  a[*na].ints    = ints;
  a[*na].first   = first;
  a[*na].byte    = byte;
  (*na)++;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Which arrays to write, from the problem's data. Done before the file is opened, so that a
   missing field fails without creating anything. */
static PetscErrorCode VTUDescribe(PeriProblem p, VTUArray a[], PetscInt *na)
{
  PeriModel model  = p->model;
  PetscInt  map[3] = {-1, -1, -1}, c, axis, ntrans = 0;

  PetscFunctionBeginUser;
  *na = 0;
  if (p->u_all) {
    PetscCheck(model && model->components, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Cannot write displacements to VTU: the model has no component names");
    PetscCheck(model->dofs >= 1 && model->dofs <= PERI_MAX_DOF, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "Model %s has %" PetscInt_FMT " DOFs per particle", model->type, model->dofs);
    for (c = 0; c < model->dofs; c++) {
      const char *name = model->components[c];

      axis = -1;
      if (!strcmp(name, "ux"))
        axis = 0;
      else if (!strcmp(name, "uy"))
        axis = 1;
      else if (!strcmp(name, "uz"))
        axis = 2;
      if (axis < 0) continue;
      PetscCheck(map[axis] < 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "Model %s names component %s twice", model->type, name);
      map[axis] = c;
      ntrans++;
    }
    /* No vector when the model has no translations: a zero "displacement" would be misleading. */
    if (ntrans) PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, "displacement", 3, p->u_all, model->dofs, map));
    for (c = 0; c < model->dofs; c++) {
      if (c == map[0] || c == map[1] || c == map[2]) continue;
      PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, model->components[c], 1, p->u_all, model->dofs, &c));
    }
  }
  if (p->modal) {
    /* one array per mode: its displacement vector, and each other component on its own */
    static char    names[PERI_MAX_VTU_MODES][PERI_MAX_DOF][PERI_NAME_LEN + 16];
    const PetscInt nd = p->particles.n * model->dofs;
    for (c = 0; c < model->dofs; c++) {
      axis = -1;
      if (!strcmp(model->components[c], "ux"))
        axis = 0;
      else if (!strcmp(model->components[c], "uy"))
        axis = 1;
      else if (!strcmp(model->components[c], "uz"))
        axis = 2;
      if (axis >= 0) map[axis] = c;
    }
    for (PetscInt k = 0; k < p->modal->nshapes; k++) {
      PetscCall(PetscSNPrintf(names[k][0], sizeof(names[k][0]), "mode_%" PetscInt_FMT, k + 1));
      PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, names[k][0], 3, &p->modal->shapes[k * nd], model->dofs, map));
      for (c = 0; c < model->dofs; c++) {
        if (c == map[0] || c == map[1] || c == map[2]) continue;
        PetscCall(PetscSNPrintf(names[k][c], sizeof(names[k][c]), "mode_%" PetscInt_FMT "_%s", k + 1, model->components[c]));
        PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, names[k][c], 1, &p->modal->shapes[k * nd], model->dofs, &c));
      }
    }
  }
  PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, "volume", 1, p->particles.volume, 1, NULL));
  PetscCall(VTUAddInt(a, na, VTU_POINT_DATA, "neighbors", VTU_INT32, p->neighbor_count, 0, 0));
  PetscCall(VTUAddInt(a, na, VTU_POINT_DATA, "rank", VTU_INT32, p->owner, 0, 0));
  if (p->W) PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, "strain_energy_density", 1, p->W, 1, NULL));
  if (p->tau) {
    static const PetscInt tmap[3] = {0, 1, -1}, nmap = 2;
    PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, "shear_stress", 3, p->tau, 3, tmap)); /* tau_xz, tau_yz, 0 */
    PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, "shear_stress_norm", 1, p->tau, 3, &nmap));
  }
  if (p->damage) {
    /* the total, and the share lost to each criterion the scene uses (Diana & Casolo eqs. 47, 48, 51) */
    static char           names[PERI_NCAUSES][32];
    static const PetscInt map0 = 0;
    static PetscInt       maps[PERI_NCAUSES];
    const PeriFailure    *F      = &p->failure;
    const PetscBool       used[] = {(PetscBool)(p->results.precracked_bonds > 0), (PetscBool)(F->stretch > 0 || (F->G > 0 && F->istretch >= 0)), (PetscBool)(F->compressive > 0), (PetscBool)(F->sliding > 0 || F->friction_angle > 0), (PetscBool)(F->ishear >= 0)};
    PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, "damage", 1, p->damage, PERI_NCAUSES + 1, &map0));
    for (PetscInt c = 0; c < PERI_NCAUSES; c++) {
      if (!used[c]) continue;
      maps[c] = 1 + c;
      PetscCall(PetscSNPrintf(names[c], sizeof(names[c]), "damage_%s", PeriFailureCauses[c]));
      PetscCall(VTUAddReal(a, na, VTU_POINT_DATA, names[c], 1, p->damage, PERI_NCAUSES + 1, &maps[c]));
    }
  }
  if (p->particles.image) PetscCall(VTUAddInt(a, na, VTU_POINT_DATA, "mirror_of", VTU_INT32, p->particles.image, 0, 0)); /* -1: a body particle */
  PetscCall(VTUAddReal(a, na, VTU_POINTS, "Points", 3, p->particles.x, 3, NULL));
  PetscCall(VTUAddInt(a, na, VTU_CELLS, "connectivity", VTU_INT64, NULL, 0, 0));
  PetscCall(VTUAddInt(a, na, VTU_CELLS, "offsets", VTU_INT64, NULL, 1, 0)); /* one point per cell */
  PetscCall(VTUAddInt(a, na, VTU_CELLS, "types", VTU_UINT8, NULL, 0, VTK_VERTEX));
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
      case VTU_INT32:
        PetscCheck(a->ints[i] >= INT32_MIN && a->ints[i] <= INT32_MAX, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "VTU array %s: value %" PetscInt_FMT " of particle %" PetscInt_FMT " does not fit in Int32", a->name, a->ints[i], i);
        ((int32_t *)buf)[k] = (int32_t)a->ints[i];
        break;
      case VTU_INT64:
        ((int64_t *)buf)[k] = a->first + (int64_t)i;
        break;
      case VTU_UINT8:
        ((uint8_t *)buf)[k] = a->byte;
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
      if (a[k].section != (VTUSection)s) continue;
      PetscCall(VTUPrintf(fp, file, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%" PetscInt_FMT "\" format=\"appended\" offset=\"%" PRIu64 "\"/>\n", VTUTypeNames[a[k].kind], a[k].name, a[k].ncomp, a[k].offset));
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

/* Collective on p->comm; only rank 0, which holds every particle's data, writes. */
PetscErrorCode PeriWriteVTU(PeriProblem p, const char path[])
{
  VTUArray       a[VTU_MAX_ARRAYS];
  PetscInt       na, k, n;
  uint64_t       offset = 0, maxbytes = 0;
  char           tmp[PETSC_MAX_PATH_LEN];
  FILE          *fp;
  double        *buf; /* double for alignment; also holds the Int32/Int64/UInt8 arrays */
  PetscErrorCode ierr;
  int            rc, err;

  PetscFunctionBeginUser;
  if (p->rank != 0) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCheck(path && path[0], PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG, "Empty VTU file name");
  PetscCheck(strlen(path) + sizeof(".tmp") <= sizeof(tmp), PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "VTU file name is too long: %s", path);
  n = p->particles.n;
  PetscCheck(n >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONGSTATE, "Negative number of particles %" PetscInt_FMT, n);
  PetscCall(VTUDescribe(p, a, &na));
  for (k = 0; k < na; k++) {
    a[k].nbytes = (uint64_t)n * (uint64_t)a[k].ncomp * VTUTypeSizes[a[k].kind];
    a[k].offset = offset;
    offset += sizeof(uint64_t) + a[k].nbytes;
    maxbytes = PetscMax(maxbytes, a[k].nbytes);
  }
  PetscCheck(maxbytes <= SIZE_MAX, PETSC_COMM_SELF, PETSC_ERR_MEM, "VTU array of %" PRIu64 " bytes is too large", maxbytes);
  PetscCall(PetscMalloc1((size_t)(maxbytes / sizeof(double) + 1), &buf));
  PetscCall(PetscSNPrintf(tmp, sizeof(tmp), "%s.tmp", path));
  fp = fopen(tmp, "wb");
  if (!fp) {
    err = errno;
    PetscCall(PetscFree(buf));
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "Cannot open %s for writing: %s", tmp, strerror(err));
  }
  ierr = VTUWriteFile(fp, tmp, n, na, a, buf);
  /* Buffered write errors (e.g. a full disk) only surface at fclose(). */
  rc  = fclose(fp);
  err = errno;
  PetscCall(PetscFree(buf));
  if (ierr != PETSC_SUCCESS || rc != 0) {
    (void)remove(tmp);
    PetscCall(ierr);
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "Error writing %s: %s", tmp, strerror(err));
  }
  PetscCall(PeriFileCommit(tmp, path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWritePVD - a ParaView collection (.pvd) listing files[k] at time times[k], so that a series
  (load steps, mode shapes) opens as one data set. Not collective: call it on the writing rank.
@*/
PetscErrorCode PeriWritePVD(const char path[], PetscInt n, const PetscReal times[], const char *const files[])
{
  char  tmp[PETSC_MAX_PATH_LEN];
  FILE *fp;
  int   bad = 0;

  PetscFunctionBeginUser;
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n") < 0;
  for (PetscInt k = 0; k < n; k++) bad |= fprintf(fp, "    <DataSet timestep=\"%.10g\" group=\"\" part=\"0\" file=\"%s\"/>\n", (double)times[k], files[k]) < 0;
  bad |= fprintf(fp, "  </Collection>\n</VTKFile>\n") < 0;
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWriteModeShapes - mode_NN.vtu, one file per stored mode shape with the shape as its
  "displacement", and modes.pvd listing them by mode number (ParaView steps through the modes
  like time steps). Collective; rank 0 writes.
@*/
PetscErrorCode PeriWriteModeShapes(PeriProblem p, const char dir[])
{
  PeriModal     *md    = p->modal;
  PetscReal     *u_all = p->u_all, *times;
  char         **files, path[PETSC_MAX_PATH_LEN];
  const PetscInt nd = p->particles.n * p->model->dofs;

  PetscFunctionBeginUser;
  if (p->rank || !md || !md->nshapes) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscMalloc2(md->nshapes, &times, md->nshapes, &files));
  /* each file is particles.vtu's layout with the mode as the displacement field */
  p->modal = NULL;
  for (PetscInt k = 0; k < md->nshapes; k++) {
    times[k] = (PetscReal)(k + 1);
    PetscCall(PetscMalloc1(32, &files[k]));
    PetscCall(PetscSNPrintf(files[k], 32, "mode_%02" PetscInt_FMT ".vtu", k + 1));
    PetscCall(PetscSNPrintf(path, sizeof(path), "%s/%s", dir, files[k]));
    p->u_all = &md->shapes[k * nd];
    PetscCall(PeriWriteVTU(p, path));
  }
  p->u_all = u_all;
  p->modal = md;
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/modes.pvd", dir));
  PetscCall(PeriWritePVD(path, md->nshapes, times, (const char *const *)files));
  for (PetscInt k = 0; k < md->nshapes; k++) PetscCall(PetscFree(files[k]));
  PetscCall(PetscFree2(times, files));
  PetscFunctionReturn(PETSC_SUCCESS);
}
