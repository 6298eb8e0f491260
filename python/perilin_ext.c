/* perilin._perilin: the C half of the Python module perilin (python/perilin/__init__.py is the
 * other): a PeriProblem behind a capsule, its operators as petsc4py objects (petsc4py's C API),
 * every PETSc error raised as perilin.Error with perilin's message. PETSc and SLEPc are started
 * by petsc4py and slepc4py, never here (docs/python.md). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <petsc4py/petsc4py.h>
#include "perilin.h"
#include <stdlib.h>
#include <string.h>

static PyObject *PerilinError; /* perilin.Error */

/* Calls into perilin run between Begin and End: the error handler returns the error to here. */
static void Begin(void)
{
  PeriErrorReset();
  (void)PetscPushErrorHandler(PeriErrorCapture, NULL); /* the first error's message, as the command line prints it */
}

/* NULL with perilin.Error set when ierr, else Py_None (a new reference). */
static PyObject *End(PetscErrorCode ierr)
{
  (void)PetscPopErrorHandler();
  if (!ierr) Py_RETURN_NONE;
  PyErr_SetString(PerilinError, PeriErrorFirst()[0] ? PeriErrorFirst() : "PETSc error");
  return NULL;
}

#define CAPSULE "perilin.PeriProblem"

/* What a capsule holds: the problem, NULL once destroyed. */
typedef struct {
  PeriProblem p;
} Handle;

static PeriProblem GetProblem(PyObject *cap)
{
  Handle *h = (Handle *)PyCapsule_GetPointer(cap, CAPSULE);
  if (!h) return NULL;
  if (!h->p) PyErr_SetString(PerilinError, "the problem was destroyed");
  return h->p;
}

static void DestroyQuietly(PeriProblem *p)
{
  (void)PetscPushErrorHandler(PetscIgnoreErrorHandler, NULL);
  (void)PeriProblemDestroy(p);
  (void)PetscPopErrorHandler();
}

/* A problem dropped without destroy(): freed unless PETSc has ended (the interpreter's exit). */
static void CapsuleFree(PyObject *cap)
{
  Handle *h = (Handle *)PyCapsule_GetPointer(cap, CAPSULE);
  if (!h) {
    PyErr_Clear();
    return;
  }
  if (h->p && PetscInitializeCalled && !PetscFinalizeCalled) DestroyQuietly(&h->p);
  free(h);
}

static PyObject *Initialize(PyObject *self, PyObject *args)
{
  (void)self;
  (void)args;
  if (!PetscInitializeCalled) {
    PyErr_SetString(PerilinError, "PETSc is not initialized: import petsc4py.PETSc and slepc4py.SLEPc first");
    return NULL;
  }
  Begin();
  return End(PeriInitializeEmbedded());
}

static PyObject *Version(PyObject *self, PyObject *args)
{
  char           perilin[PERI_VERSION_LEN], petsc[PERI_VERSION_LEN], slepc[PERI_VERSION_LEN];
  PetscErrorCode ierr;
  PyObject      *ok;

  (void)self;
  (void)args;
  Begin();
  ierr = PeriGetVersions(perilin, petsc, slepc, PERI_VERSION_LEN);
  if (!(ok = End(ierr))) return NULL;
  Py_DECREF(ok);
  return Py_BuildValue("(sss)", perilin, petsc, slepc);
}

/* A new problem; with old, set up on old's particles and bonds where the changed keys allow it
 * (*reused). */
static PetscErrorCode CreateProblem(MPI_Comm comm, const char file[], PetscInt n, const char *const keys[], const char *const values[], PeriProblem old, PetscInt nchanged, const char *const changed[], PeriProblem *p, PetscBool *reused)
{
  PetscFunctionBeginUser;
  *reused = PETSC_FALSE;
  PetscCall(PeriProblemCreate(comm, p));
  PetscCall(PeriProblemLoadOverrides(*p, file, n, keys, values));
  if (old)
    PetscCall(PeriProblemSetUpFrom(*p, old, nchanged, changed, reused));
  else
    PetscCall(PeriProblemSetUp(*p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A Python list of str as a NULL-ended C array (borrowed strings; free the array); NULL on error. */
static const char **Strings(PyObject *list)
{
  Py_ssize_t   n = PyList_Size(list);
  const char **a = (const char **)calloc((size_t)n + 1, sizeof(*a));

  if (!a) return (const char **)PyErr_NoMemory();
  for (Py_ssize_t i = 0; i < n; i++)
    if (!(a[i] = PyUnicode_AsUTF8(PyList_GetItem(list, i)))) {
      free(a);
      return NULL;
    }
  return a;
}

/* create(file, keys, values, comm[, old, changed]): a problem set up from the scene file with the
 * overrides keys[k] = values[k] (strings), on comm (a petsc4py Comm, or None: PETSC_COMM_WORLD);
 * with old (a problem of the same file) and the keys changed from its overrides, set up on old's
 * particles and bonds where they allow it. Returns (problem, reused). */
static PyObject *Create(PyObject *self, PyObject *args)
{
  const char    *file;
  PyObject      *keys, *values, *comm_obj, *ok, *old_obj = Py_None, *changed = NULL, *cap;
  MPI_Comm       comm = PETSC_COMM_WORLD;
  const char   **k = NULL, **v = NULL, **c = NULL;
  PeriProblem    p = NULL, old = NULL;
  PetscBool      reused = PETSC_FALSE;
  Handle        *h;
  PetscErrorCode ierr;

  (void)self;
  if (!PyArg_ParseTuple(args, "sO!O!O|OO!", &file, &PyList_Type, &keys, &PyList_Type, &values, &comm_obj, &old_obj, &PyList_Type, &changed)) return NULL;
  if (PyList_Size(values) != PyList_Size(keys)) {
    PyErr_SetString(PyExc_ValueError, "keys and values differ in length");
    return NULL;
  }
  if (comm_obj != Py_None) {
    comm = PyPetscComm_Get(comm_obj);
    if (PyErr_Occurred()) return NULL;
  }
  if (old_obj != Py_None && !(old = GetProblem(old_obj))) return NULL;
  if (!(k = Strings(keys)) || !(v = Strings(values)) || (changed && !(c = Strings(changed)))) {
    free(k);
    free(v);
    return NULL;
  }
  Begin();
  Py_BEGIN_ALLOW_THREADS;
  ierr = CreateProblem(comm, file, (PetscInt)PyList_Size(keys), k, v, old, changed ? (PetscInt)PyList_Size(changed) : 0, c, &p, &reused);
  Py_END_ALLOW_THREADS;
  free(k);
  free(v);
  free(c);
  if (!(ok = End(ierr))) {
    DestroyQuietly(&p);
    return NULL;
  }
  Py_DECREF(ok);
  if (!(h = (Handle *)malloc(sizeof(*h)))) {
    DestroyQuietly(&p);
    return PyErr_NoMemory();
  }
  h->p = p;
  if (!(cap = PyCapsule_New(h, CAPSULE, CapsuleFree))) {
    DestroyQuietly(&h->p);
    free(h);
    return NULL;
  }
  return Py_BuildValue("(NO)", cap, reused ? Py_True : Py_False);
}

/* bonds(problem): (address of this rank's bond storage, its bond count): the same address after a
 * set() that kept the bonds. */
static PyObject *Bonds(PyObject *self, PyObject *args)
{
  PyObject      *cap, *ok;
  PeriProblem    p;
  const void    *id = NULL;
  PetscInt       n  = 0;
  PetscErrorCode ierr;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  Begin();
  ierr = PeriProblemGetBonds(p, &id, &n);
  if (!(ok = End(ierr))) return NULL;
  Py_DECREF(ok);
  return Py_BuildValue("(KL)", (unsigned long long)(size_t)id, (long long)n);
}

static PyObject *Destroy(PyObject *self, PyObject *args)
{
  PyObject *cap;
  Handle   *h;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(h = (Handle *)PyCapsule_GetPointer(cap, CAPSULE))) return NULL;
  if (!h->p) Py_RETURN_NONE;
  Begin();
  return End(PeriProblemDestroy(&h->p));
}

static PyObject *Run(PyObject *self, PyObject *args)
{
  PyObject      *cap;
  PeriProblem    p;
  PetscErrorCode ierr;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  Begin();
  Py_BEGIN_ALLOW_THREADS;
  ierr = PeriProblemRun(p);
  Py_END_ALLOW_THREADS;
  return End(ierr);
}

/* layout(p): (dim, dofs, components, N, rstart, nowned, x): x the owned particles' positions as
 * bytes of 3 doubles each. */
static PyObject *Layout(PyObject *self, PyObject *args)
{
  PyObject          *cap, *ok, *names;
  PeriProblem        p;
  PetscInt           dim, dofs, N, rstart, nowned;
  const char *const *components;
  const PetscReal   *x;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  Begin();
  if (!(ok = End(PeriProblemGetLayout(p, &dim, &dofs, &components, &N, &rstart, &nowned, &x)))) return NULL;
  Py_DECREF(ok);
  if (!(names = PyTuple_New(dofs))) return NULL;
  for (PetscInt c = 0; c < dofs; c++) PyTuple_SET_ITEM(names, c, PyUnicode_FromString(components[c]));
  if (!nowned) x = (const PetscReal *)""; /* y# makes NULL None */
  return Py_BuildValue("(nnNnnny#)", (Py_ssize_t)dim, (Py_ssize_t)dofs, names, (Py_ssize_t)N, (Py_ssize_t)rstart, (Py_ssize_t)nowned, (const char *)x, (Py_ssize_t)(3 * nowned * sizeof(PetscReal)));
}

/* solution(p): this rank's part of u as bytes of doubles, or None before a solution. */
static PyObject *Solution(PyObject *self, PyObject *args)
{
  PyObject          *cap, *ok, *out;
  PeriProblem        p;
  Vec                u;
  PetscBool          solved;
  PetscInt           n = 0;
  const PetscScalar *a = NULL;
  PetscErrorCode     ierr;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  Begin();
  ierr = PeriProblemGetSolution(p, &u, &solved);
  if (!ierr && solved) ierr = VecGetLocalSize(u, &n);
  if (!ierr && solved) ierr = VecGetArrayRead(u, &a);
  if (!(ok = End(ierr))) return NULL;
  Py_DECREF(ok);
  if (!solved) Py_RETURN_NONE;
  out = PyBytes_FromStringAndSize((const char *)a, (Py_ssize_t)(n * sizeof(PetscScalar)));
  (void)VecRestoreArrayRead(u, &a);
  return out;
}

/* constraints(p): (rows, values, sizeof(PetscInt)): this rank's prescribed global DOFs and values
 * as bytes. */
static PyObject *Constraints(PyObject *self, PyObject *args)
{
  PyObject        *cap, *ok;
  PeriProblem      p;
  PetscInt         n;
  const PetscInt  *rows;
  const PetscReal *values;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  Begin();
  if (!(ok = End(PeriProblemGetConstraints(p, &n, &rows, &values)))) return NULL;
  Py_DECREF(ok);
  if (!n) return Py_BuildValue("(y#y#n)", "", (Py_ssize_t)0, "", (Py_ssize_t)0, (Py_ssize_t)sizeof(PetscInt)); /* y# makes NULL None */
  return Py_BuildValue("(y#y#n)", (const char *)rows, (Py_ssize_t)(n * sizeof(PetscInt)), (const char *)values, (Py_ssize_t)(n * sizeof(PetscReal)), (Py_ssize_t)sizeof(PetscInt));
}

static PyObject *Stiffness(PyObject *self, PyObject *args)
{
  PyObject      *cap, *ok, *out;
  PeriProblem    p;
  Mat            K = NULL;
  PetscErrorCode ierr;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  Begin();
  Py_BEGIN_ALLOW_THREADS;
  ierr = PeriProblemGetStiffness(p, &K);
  Py_END_ALLOW_THREADS;
  if (!(ok = End(ierr))) return NULL;
  Py_DECREF(ok);
  out = PyPetscMat_New(K); /* takes its own reference */
  (void)MatDestroy(&K);
  return out;
}

/* operator(p): the body's K as a petsc4py shell Mat (perilin's MATSHELL, applied bond by bond). */
static PyObject *Operator(PyObject *self, PyObject *args)
{
  PyObject      *cap, *ok, *out;
  PeriProblem    p;
  Mat            A = NULL;
  PetscErrorCode ierr;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  Begin();
  Py_BEGIN_ALLOW_THREADS;
  ierr = PeriProblemGetOperator(p, &A);
  Py_END_ALLOW_THREADS;
  if (!(ok = End(ierr))) return NULL;
  Py_DECREF(ok);
  out = PyPetscMat_New(A); /* takes its own reference */
  (void)MatDestroy(&A);
  return out;
}

/* One mode as (f_hz, residual, kind, shape bytes of this rank's DOFs or None). */
static PyObject *ModeTuple(PeriProblem p, PetscInt k, Py_ssize_t nl)
{
  PetscReal        f, res;
  const char      *kind;
  const PetscReal *shape;
  PyObject        *ok;

  Begin();
  if (!(ok = End(PeriProblemGetMode(p, k, &f, &res, &kind, &shape)))) return NULL;
  Py_DECREF(ok);
  if (!shape) return Py_BuildValue("(ddsO)", (double)f, (double)res, kind, Py_None);
  if (!nl) shape = (const PetscReal *)""; /* y# makes NULL None */
  return Py_BuildValue("(ddsy#)", (double)f, (double)res, kind, (const char *)shape, (Py_ssize_t)(nl * sizeof(PetscReal)));
}

/* modes(p, nlocal): a list of ModeTuple, nlocal the DOFs this rank owns. */
static PyObject *Modes(PyObject *self, PyObject *args)
{
  PyObject   *cap, *ok, *list;
  PeriProblem p;
  PetscInt    n, nshapes;
  Py_ssize_t  nl;

  (void)self;
  if (!PyArg_ParseTuple(args, "On", &cap, &nl) || !(p = GetProblem(cap))) return NULL;
  Begin();
  if (!(ok = End(PeriProblemGetModes(p, &n, &nshapes)))) return NULL;
  Py_DECREF(ok);
  if (!(list = PyList_New(n))) return NULL;
  for (PetscInt k = 0; k < n; k++) {
    PyObject *t = ModeTuple(p, k, nl);
    if (!t) {
      Py_DECREF(list);
      return NULL;
    }
    PyList_SET_ITEM(list, k, t);
  }
  return list;
}

/* table(p): (file name, CSV text) of the analysis' table, (None, None) without one, (name, None)
 * before the run. Collective. */
static PyObject *Table(PyObject *self, PyObject *args)
{
  PyObject      *cap, *ok, *out;
  PeriProblem    p;
  const char    *name = NULL;
  char          *text = NULL;
  PetscErrorCode ierr;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  Begin();
  ierr = PeriProblemGetTable(p, &name, &text);
  if (!(ok = End(ierr))) {
    free(text);
    return NULL;
  }
  Py_DECREF(ok);
  out = Py_BuildValue("(zz)", name, text);
  free(text);
  return out;
}

static PyObject *VecResult(PeriProblem p, PetscErrorCode (*get)(PeriProblem, Vec *))
{
  PyObject *ok, *out;
  Vec       v = NULL;

  Begin();
  if (!(ok = End(get(p, &v)))) return NULL;
  Py_DECREF(ok);
  out = PyPetscVec_New(v);
  (void)VecDestroy(&v);
  return out;
}

static PyObject *Loads(PyObject *self, PyObject *args)
{
  PyObject   *cap;
  PeriProblem p;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  return VecResult(p, PeriProblemGetLoads);
}

static PyObject *Mass(PyObject *self, PyObject *args)
{
  PyObject   *cap;
  PeriProblem p;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  return VecResult(p, PeriProblemGetMass);
}

static PyObject *TextResult(PeriProblem p, PetscErrorCode (*get)(PeriProblem, char **))
{
  PyObject      *ok, *out;
  char          *text = NULL;
  PetscErrorCode ierr;

  Begin();
  ierr = get(p, &text);
  if (!(ok = End(ierr))) {
    free(text);
    return NULL;
  }
  Py_DECREF(ok);
  out = PyUnicode_FromString(text ? text : "");
  free(text);
  return out;
}

static PyObject *Summary(PyObject *self, PyObject *args)
{
  PyObject   *cap;
  PeriProblem p;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  return TextResult(p, PeriProblemGetSummary);
}

static PyObject *Scene(PyObject *self, PyObject *args)
{
  PyObject   *cap;
  PeriProblem p;

  (void)self;
  if (!PyArg_ParseTuple(args, "O", &cap) || !(p = GetProblem(cap))) return NULL;
  return TextResult(p, PeriProblemGetScene);
}

static PetscErrorCode WriteOutput(PeriProblem p, const char dir[])
{
  PetscFunctionBeginUser;
  PetscCall(PeriProblemSetOutputDir(p, dir));
  PetscCall(PeriProblemWriteOutput(p));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PyObject *Write(PyObject *self, PyObject *args)
{
  PyObject      *cap;
  PeriProblem    p;
  const char    *dir;
  PetscErrorCode ierr;

  (void)self;
  if (!PyArg_ParseTuple(args, "Os", &cap, &dir) || !(p = GetProblem(cap))) return NULL;
  Begin();
  Py_BEGIN_ALLOW_THREADS;
  ierr = WriteOutput(p, dir);
  Py_END_ALLOW_THREADS;
  return End(ierr);
}

static PyMethodDef methods[] = {
    {"initialize", Initialize, METH_NOARGS, "perilin's registries in the PETSc session petsc4py and slepc4py started"},
    {"versions", Version, METH_NOARGS, "(perilin, PETSc, SLEPc) versions"},
    {"create", Create, METH_VARARGS, "create(file, keys, values, comm[, old, changed]): (a problem set up from the scene, whether it reused old's bonds)"},
    {"bonds", Bonds, METH_VARARGS, "bonds(problem): (address of this rank's bond storage, bond count)"},
    {"destroy", Destroy, METH_VARARGS, "destroy(problem)"},
    {"run", Run, METH_VARARGS, "run(problem): the scene's analysis"},
    {"layout", Layout, METH_VARARGS, "layout(problem): (dim, dofs, components, N, rstart, nowned, x bytes)"},
    {"solution", Solution, METH_VARARGS, "solution(problem): this rank's part of u as bytes, or None"},
    {"constraints", Constraints, METH_VARARGS, "constraints(problem): (rows bytes, values bytes, sizeof(PetscInt))"},
    {"stiffness", Stiffness, METH_VARARGS, "stiffness(problem): a new assembled K (petsc4py Mat)"},
    {"operator", Operator, METH_VARARGS, "operator(problem): the body's K as a new shell Mat, applied bond by bond (petsc4py Mat)"},
    {"modes", Modes, METH_VARARGS, "modes(problem, nlocal): [(f_hz, residual, kind, shape bytes or None)] of a modal run"},
    {"table", Table, METH_VARARGS, "table(problem): (file name, CSV text) of the analysis' table of rows"},
    {"loads", Loads, METH_VARARGS, "loads(problem): a new vector of the loads f (petsc4py Vec)"},
    {"mass", Mass, METH_VARARGS, "mass(problem): a new vector of the lumped mass per DOF (petsc4py Vec)"},
    {"summary", Summary, METH_VARARGS, "summary(problem): summary.json's text"},
    {"scene", Scene, METH_VARARGS, "scene(problem): the resolved scene as YAML"},
    {"write", Write, METH_VARARGS, "write(problem, dir): the output set into dir"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_perilin", "the C half of perilin (docs/python.md)", -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__perilin(void)
{
  PyObject *m;

  if (import_petsc4py() < 0) return NULL;
  if (!(m = PyModule_Create(&module))) return NULL;
  PerilinError = PyErr_NewExceptionWithDoc("perilin.Error", "an input error or a failed run, with perilin's message (what the command line prints after 'perilin: error: ')", NULL, NULL);
  if (!PerilinError || PyModule_AddObject(m, "Error", PerilinError) < 0) {
    Py_XDECREF(PerilinError);
    Py_DECREF(m);
    return NULL;
  }
  Py_INCREF(PerilinError);
  return m;
}
