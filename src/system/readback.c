/* A DOF field read back from a particles file perilin wrote (a mode shape, a state of an earlier
 * run): the file's points are matched to this body's particles by their reference positions,
 * which perilin writes exactly (Float64 of the same numbers), so the file may come from any rank
 * count and partition. */
#include "perilin/private/system.h"
#include "perilin/private/output.h"

#include <stdlib.h>
#include <string.h>

typedef struct {
  PetscReal x[3];
  PetscInt  k; /* the point's index in the file */
} Point;

static int ComparePoint(const void *a, const void *b)
{
  const PetscReal *x = ((const Point *)a)->x, *y = ((const Point *)b)->x;
  for (int d = 0; d < 3; d++)
    if (x[d] != y[d]) return x[d] < y[d] ? -1 : 1;
  return 0;
}

/* The index of the array holding component c of the DOFs in d, and the component within it: the
 * translations in the vector array named array, every other DOF in array_<name> ("displacement"
 * pairs with plain names: theta), as PeriFieldListAddSolution names them. */
static PetscErrorCode ComponentArray(PeriSystem sys, const PeriVTUData *d, const char path[], const char array[], PetscInt c, PetscInt *k, PetscInt *comp)
{
  char      name[2 * PERI_NAME_LEN + 2];
  PeriModel m = sys->model;

  PetscFunctionBeginUser;
  if (m->axis[c] >= 0)
    PetscCall(PetscStrncpy(name, array, sizeof(name)));
  else if (!strcmp(array, "displacement"))
    PetscCall(PetscStrncpy(name, m->components[c], sizeof(name)));
  else
    PetscCall(PetscSNPrintf(name, sizeof(name), "%s_%s", array, m->components[c]));
  *k    = PeriVTUDataFind(d, name);
  *comp = m->axis[c] >= 0 ? m->axis[c] : 0;
  if (*k < 0) {
    char list[1024] = "";
    for (PetscInt a = 0; a < d->narrays; a++) {
      PetscCall(PetscStrlcat(list, a ? ", " : "", sizeof(list)));
      PetscCall(PetscStrlcat(list, d->names[a], sizeof(list)));
    }
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s has no array %s for component %s of model %s; its arrays: %s", path, name, m->components[c], m->type, list);
  }
  PetscCheck(d->ncomp[*k] == (m->axis[c] >= 0 ? 3 : 1), PETSC_COMM_SELF, PETSC_ERR_USER_INPUT, "%s: array %s has %" PetscInt_FMT " components, expected %d", path, name, d->ncomp[*k], m->axis[c] >= 0 ? 3 : 1);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* For each owned particle, the index of its point in d (by exact position); *missing: the first
 * owned particle the file lacks (local index), or -1. */
static PetscErrorCode MatchParticles(PeriSystem sys, const PeriVTUData *d, PetscInt match[], PetscInt *missing)
{
  const PeriParticles *p = &sys->disc.particles;
  Point               *pts;

  PetscFunctionBeginUser;
  *missing = -1;
  PetscCall(PetscMalloc1(d->n, &pts));
  for (PetscInt k = 0; k < d->n; k++) {
    for (int c = 0; c < 3; c++) pts[k].x[c] = d->points[3 * k + c];
    pts[k].k = k;
  }
  qsort(pts, (size_t)d->n, sizeof(Point), ComparePoint);
  for (PetscInt i = 0; i < sys->disc.nowned; i++) {
    Point        key = {{p->x[3 * i], p->x[3 * i + 1], p->x[3 * i + 2]}, 0};
    const Point *hit = (const Point *)bsearch(&key, pts, (size_t)d->n, sizeof(Point), ComparePoint);
    if (!hit) {
      *missing = i;
      break;
    }
    match[i] = hit->k;
  }
  PetscCall(PetscFree(pts));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Every rank fails when one owns a particle the file lacks; the lowest such particle is named. */
static PetscErrorCode ReportMissing(PeriSystem sys, const char path[], PetscInt miss)
{
  const PeriParticles *p    = &sys->disc.particles;
  PetscInt             g    = miss >= 0 ? p->global[miss] : PETSC_MAX_INT, first;
  PetscReal            x[3] = {0, 0, 0};

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&g, &first, 1, MPIU_INT, MPI_MIN, sys->comm));
  if (first == PETSC_MAX_INT) PetscFunctionReturn(PETSC_SUCCESS);
  if (g == first)
    for (int c = 0; c < 3; c++) x[c] = p->x[3 * miss + c];
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, x, 3, MPIU_REAL, MPI_SUM, sys->comm));
  SETERRQ(sys->comm, PETSC_ERR_USER_INPUT, "%s has no point at particle %" PetscInt_FMT "'s position (%g, %g, %g): the file must come from a run of the same body (grid, spacing, mesh) as this scene", path, first, (double)x[0], (double)x[1], (double)x[2]);
}

/* PeriSystemReadDOFs' part once the file d is read: its particles and arrays checked against the
 * body and the model, then copied into u. Collective. */
static PetscErrorCode ReadInto(PeriSystem sys, const PeriVTUData *d, const char path[], const char array[], PetscReal scale, Vec u)
{
  const PetscInt bs = sys->model->dofs;
  PetscInt      *match, k[PERI_MAX_DOF], comp[PERI_MAX_DOF], N, miss;
  PetscScalar   *a;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&d->n, &N, 1, MPIU_INT, MPI_MAX, sys->comm));
  PetscCheck(N == sys->disc.N, sys->comm, PETSC_ERR_USER_INPUT, "%s holds %" PetscInt_FMT " particles, the body %" PetscInt_FMT ": the file must come from the same body", path, N, sys->disc.N);
  for (PetscInt c = 0; c < bs; c++) PetscCall(ComponentArray(sys, d, path, array, c, &k[c], &comp[c]));
  PetscCall(PetscMalloc1(sys->disc.nowned, &match));
  ierr = MatchParticles(sys, d, match, &miss);
  if (!ierr) ierr = ReportMissing(sys, path, miss);
  if (!ierr) ierr = VecGetArray(u, &a);
  for (PetscInt i = 0; !ierr && i < sys->disc.nowned; i++)
    for (PetscInt c = 0; c < bs; c++) a[i * bs + c] = scale * d->data[k[c]][d->ncomp[k[c]] * match[i] + comp[c]];
  if (!ierr) ierr = VecRestoreArray(u, &a);
  PetscCall(PetscFree(match));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSystemReadDOFs - sets the owned DOFs of u to scale times the field array of the particles
  file path (a .vtu or .pvtu perilin wrote of the same body): the translations from the vector
  array, the other DOFs from array_<component> (plain <component> when array is "displacement":
  mode_01.vtu's displacement and theta; particles.vtu's mode_1 and mode_1_theta). Collective: an
  error on one rank fails every rank.
@*/
PetscErrorCode PeriSystemReadDOFs(PeriSystem sys, const char path[], const char array[], PetscReal scale, Vec u)
{
  PeriVTUData    d;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(PeriReadParticles(path, &d));
  /* the file's arrays are freed on a refusal too: the Python module lives on after an input error */
  ierr = ReadInto(sys, &d, path, array, scale, u);
  PetscCall(PeriVTUDataDestroy(&d));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}
