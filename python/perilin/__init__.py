"""perilin in-process: a scene as a Problem, its solution as numpy arrays, its operators as
petsc4py objects (docs/python.md).

    import perilin
    p = perilin.Problem("examples/pmb/plate_traction.yaml", {"material.E": 2e9})
    r = p.solve()            # r.x, r.u: particles x dim numpy arrays; r.summary: summary.json
    K, f = p.stiffness(), p.rhs()

PETSc and SLEPc are started by petsc4py and slepc4py (import them first to pass your own options:
petsc4py.init(sys.argv)); perilin's input errors are raised as perilin.Error with the message the
command line prints.
"""
import json
import os
import tempfile

import numpy as np


def _singleton_mpi_defaults():
    """A script started without mpiexec is an MPI singleton: Open MPI's probing of fast networks
    (UCX) and its helper daemon are pure start-up cost (0.25 s of importing petsc4py here), so its
    own switches are set where the user set none, as the perilin command does (src/package.c).
    Under mpiexec, or once MPI is started, nothing changes; other MPIs ignore them."""
    launched = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID", "MPI_LOCALNRANKS")
    if any(v in os.environ for v in launched):
        return
    for k, v in (("OMPI_MCA_pml", "ob1"), ("OMPI_MCA_osc", "pt2pt"), ("OMPI_MCA_ess_singleton_isolated", "1")):
        os.environ.setdefault(k, v)


_singleton_mpi_defaults()
import petsc4py  # noqa: E402 (after the MPI defaults)
from petsc4py import PETSc  # noqa: E402
import slepc4py  # noqa: E402
from slepc4py import SLEPc  # noqa: F401, E402 (starts SLEPc, which perilin's modal analysis uses)

from . import _perilin  # noqa: E402
from ._perilin import Error  # noqa: E402

_perilin.initialize()
__version__, petsc_version, slepc_version = _perilin.versions()

__all__ = ["Problem", "Result", "Modes", "Error", "__version__"]

# the columns of steps.csv and history.csv that count (int64 in Result.steps, Result.history);
# every other column is float64
_COUNT_COLUMNS = {"step", "broken", "broken_total", "softened", "equilibrium_iterations", "ksp_iterations", "attempts"}


def _table(text):
    """A CSV table (header line, then rows) as a dict column -> numpy array, in the file's column
    order."""
    lines = text.strip().split("\n")
    names = lines[0].split(",")
    rows = [line.split(",") for line in lines[1:]]
    out = {}
    for c, name in enumerate(names):
        dtype = np.int64 if name in _COUNT_COLUMNS else np.float64
        out[name] = np.array([float(r[c]) for r in rows], dtype=np.float64).astype(dtype)
    return out


def _text(value):
    """A Python value as the command line gives it (-material_E 2e9, -grid_upper 1,0.5)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple, np.ndarray)):
        return ",".join(_text(v) for v in value)
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    return str(value)


def _typed(value):
    """A scalar of the resolved scene as a number where it reads as one."""
    if isinstance(value, str):
        for kind in (int, float):
            try:
                return kind(value)
            except ValueError:
                pass
    if isinstance(value, list):
        return [_typed(v) for v in value]
    if isinstance(value, dict):
        return {k: _typed(v) for k, v in value.items()}
    return value


def _petsc_comm(comm):
    if comm is None:
        return PETSc.COMM_WORLD
    if isinstance(comm, PETSc.Comm):
        return comm
    return PETSc.Comm(comm)  # an mpi4py communicator


class Result:
    """One solution: x (positions) and u (the DOFs, ux uy [uz] or the model's components) as
    particles x dim and particles x dofs numpy arrays in the global particle order (the order of
    particles.vtu; on several ranks, the pieces of particles.pvtu one after the other), on every
    rank; components names u's columns; summary is the dict summary.json holds.

    steps (quasi-static runs) and history (dynamic runs): the rows of steps.csv and history.csv as
    a dict column name -> numpy array (one entry per row; the counting columns int64, the others
    float64), None for the other analyses."""

    def __init__(self, x, u, components, summary, steps=None, history=None):
        self.x, self.u, self.components, self.summary = x, u, components, summary
        self.steps, self.history = steps, history

    def __repr__(self):
        return "perilin.Result(%d particles, components %s)" % (len(self.x), ", ".join(self.components))


class Modes:
    """The modes of a modal run, by rising frequency: frequencies (Hz) and residuals (each pair's
    ||K x - omega^2 M x|| / (omega^2 ||M x||) on the free DOFs) as numpy arrays of n; kinds (n
    strings: flexural, longitudinal, ...); shapes, an nshapes x particles x dofs numpy array of the
    first nshapes modes (at most 12: those perilin keeps for modes.pvd), in Result.u's global order
    and columns (components), each scaled to max |translation| = 1, zero on the prescribed DOFs."""

    def __init__(self, frequencies, residuals, kinds, shapes, components):
        self.frequencies, self.residuals, self.kinds = frequencies, residuals, kinds
        self.shapes, self.components = shapes, components

    def __len__(self):
        return len(self.frequencies)

    def __repr__(self):
        return "perilin.Modes(%d modes, %.6g to %.6g Hz, %d shapes)" % (len(self), self.frequencies[0], self.frequencies[-1], len(self.shapes))


class Problem:
    """A scene set up in this process: particles, bonds, model, conditions (perilin's set-up).

    scene: a scene file, or a dict with the same schema (written to a temporary file; give paths in
    it absolute). overrides: {'dotted.key': value}, as the command line's -dotted_key value.
    comm: a petsc4py or mpi4py communicator (default PETSc.COMM_WORLD)."""

    def __init__(self, scene, overrides=None, comm=None):
        self._handle = None
        self._tmp = None
        self._result = None
        self.comm = _petsc_comm(comm)
        if isinstance(scene, dict):
            fd, self._tmp = tempfile.mkstemp(prefix="perilin-scene-", suffix=".yaml")
            with os.fdopen(fd, "w") as out:
                json.dump(scene, out, indent=1)  # JSON is YAML: one key a line, for the messages
            self.file = self._tmp
        else:
            self.file = os.path.abspath(os.fspath(scene))
        self._overrides = dict(overrides or {})
        self.rebuilt = True  # whether the last set-up built the particles and bonds (False: set() kept them)
        self.setups = 1  # set-ups so far, and of them those that built the particles and bonds
        self.builds = 1
        try:
            self._handle, _ = self._build(self._overrides)
        except BaseException:
            self._remove_tmp()
            raise

    def _build(self, overrides, old=None, changed=()):
        """A new problem's handle and whether it reused old's particles and bonds."""
        keys = list(overrides)
        values = [_text(overrides[k]) for k in keys]
        if old is None:
            return _perilin.create(self.file, keys, values, self.comm)
        return _perilin.create(self.file, keys, values, self.comm, old, list(changed))

    def _remove_tmp(self):
        if self._tmp:
            try:
                os.unlink(self._tmp)
            except OSError:
                pass
            self._tmp = None

    def close(self):
        """Frees the problem (collective); the object is unusable after it. Also frees the petsc4py
        objects on the problem's communicator that Python dropped without destroy(): petsc4py 3.18
        keeps a dropped parallel object (one on a communicator, as K, f, M are) in PETSc's garbage
        until a collective PETSc.garbage_cleanup(), which this calls (docs/python.md, "Memory")."""
        if self._handle is not None:
            _perilin.destroy(self._handle)
            self._handle = None
            PETSc.garbage_cleanup(self.comm)
        self._remove_tmp()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self._remove_tmp()
        except Exception:
            pass

    @property
    def overrides(self):
        """The overrides in force (a copy)."""
        return dict(self._overrides)

    # scene keys
    def scene(self):
        """The resolved scene (what scene.yaml holds: every key read, with its value) as a dict."""
        import yaml

        return _typed(yaml.safe_load(_perilin.scene(self._handle)))

    def get(self, key):
        """The value the problem uses for the dotted key ('material.E', 'bc.0.region')."""
        node = self.scene()
        for part in key.split("."):
            if isinstance(node, list) and part.isdigit() and int(part) < len(node):
                node = node[int(part)]
            elif isinstance(node, dict) and part in node:
                node = node[part]
            else:
                raise Error("%s: no such key in the resolved scene of %s (docs/scene.md lists the keys)" % (key, self.file))
        return node

    def set(self, key, value):
        """Sets the dotted key to value and sets the problem up again with every override. Keys of
        the material (but material.thickness), loads, bc, analysis (but analysis.type), solver and
        output keep the particles and bonds: only the model's constants and calibration, the
        conditions, the loads and the analysis are set up again (self.rebuilt is False after
        it); every other key (grid, particles, horizon, corrections, regions, model, dim, ...)
        builds them anew, as do scenes whose bonds a run may break (failure), with fictitious
        layers or torsion, or with horizon.neighbors (docs/python.md). On an error the problem
        stays as it was."""
        overrides = dict(self._overrides)
        overrides[key] = value
        handle, reused = self._build(overrides, self._handle, [key])
        _perilin.destroy(self._handle)
        self._handle, self._overrides, self._result = handle, overrides, None
        self.rebuilt = not reused
        self.setups += 1
        self.builds += 0 if reused else 1

    def _bonds(self):
        """(address of this rank's bond storage, its bond count): for the tests."""
        return _perilin.bonds(self._handle)

    # the run
    def solve(self):
        """Runs the scene's analysis (analysis.type) once and returns its Result (the same Result
        again until a set())."""
        if self._result is None:
            _perilin.run(self._handle)
            self._result = self._gather_result()
        return self._result

    run = solve

    def _gather(self, local):
        if self.comm.getSize() == 1:
            return local
        return np.concatenate(self.comm.tompi4py().allgather(local))

    def _gather_result(self):
        dim, dofs, components, n, rstart, nowned, xb = _perilin.layout(self._handle)
        x = np.frombuffer(xb, dtype=np.float64).reshape(nowned, 3)[:, :dim].copy()
        ub = _perilin.solution(self._handle)
        u = None
        if ub is not None:
            u = np.frombuffer(ub, dtype=np.float64).reshape(-1, dofs).copy()
            u = self._gather(u)
        summary = json.loads(_perilin.summary(self._handle))
        name, text = _perilin.table(self._handle)
        table = _table(text) if text else None
        return Result(self._gather(x), u, components, summary, steps=table if name == "steps.csv" else None, history=table if name == "history.csv" else None)

    def modes(self):
        """The modes of a modal scene (runs the analysis first if solve() has not): a Modes with
        the frequencies in Hz, each pair's residual, and the shapes as numpy arrays in Result.u's
        order. perilin.Error for another analysis."""
        dim, dofs, components, n, rstart, nowned, _ = _perilin.layout(self._handle)
        _perilin.modes(self._handle, nowned * dofs)  # raises for another analysis, before a run
        self.solve()
        got = _perilin.modes(self._handle, nowned * dofs)
        f = np.array([m[0] for m in got])
        res = np.array([m[1] for m in got])
        shapes = [self._gather(np.frombuffer(m[3], dtype=np.float64).reshape(-1, dofs).copy()) for m in got if m[3] is not None]
        shapes = np.array(shapes) if shapes else np.zeros((0, n, dofs))
        return Modes(f, res, tuple(m[2] for m in got), shapes, components)

    def write(self, directory):
        """The usual output set (summary.json, scene.yaml, particles.vtu, the analysis' files) in
        directory, replaced as a whole. Collective."""
        _perilin.write(self._handle, os.path.abspath(os.fspath(directory)))

    # the operators
    def stiffness(self, conditions=False):
        """A new assembled stiffness K (petsc4py Mat) of the body, every DOF (particle-major: DOF d
        of particle i is row i*dofs + d), before the conditions are applied. conditions=True: the
        system the static solve and the modal eigensolve reduce to, K_ff on the free DOFs
        (free_dofs(), in their order); its solution with rhs(conditions=True) is solve()'s u there."""
        K = _perilin.stiffness(self._handle)
        return self._free_block(K, "stiffness") if conditions else K

    def rhs(self, conditions=False):
        """A new petsc4py Vec with the scene's loads f (load factor 1), in K's layout.
        conditions=True: the reduced right-hand side f_f - K_fc u_c on the free DOFs, u_c the
        prescribed values (constraints())."""
        f = _perilin.loads(self._handle)
        if not conditions:
            return f
        self._reducible("rhs")
        K, uc = _perilin.stiffness(self._handle), f.duplicate()
        rows, values = self.constraints()
        lo, hi = uc.getOwnershipRange()
        mine = (rows >= lo) & (rows < hi)
        uc.setValues(rows[mine].astype(PETSc.IntType), values[mine])
        uc.assemble()
        b = f - K * uc
        free = self.free_dofs()
        bf = b.getSubVector(free)
        out = bf.copy()
        b.restoreSubVector(free, bf)
        for o in (K, uc, b, f, free):
            o.destroy()
        return out

    def mass(self, as_matrix=False, conditions=False):
        """A new petsc4py Vec with the lumped mass per DOF (the diagonal of M), in K's layout; with
        as_matrix=True, M itself as a new diagonal petsc4py Mat (AIJ, one entry a row) in that
        layout, for SLEPc's K x = lambda M x; conditions=True (with as_matrix): M_ff on the free
        DOFs, beside stiffness(conditions=True), as the modal analysis gives them to SLEPc."""
        m = _perilin.mass(self._handle)
        if not as_matrix:
            if conditions:
                raise Error("mass(conditions=True) needs as_matrix=True (the free block of M)")
            return m
        M = PETSc.Mat().createAIJ((m.getSizes(), m.getSizes()), nnz=(1, 0), comm=m.getComm())
        M.setDiagonal(m)
        M.assemble()
        m.destroy()
        return self._free_block(M, "mass") if conditions else M

    def _reducible(self, what):
        """Fictitious layers (boundary_layers, torsion) enter K through a transfer matrix, not as
        prescribed DOFs: no free block describes that system."""
        sc = self.scene()
        if sc.get("boundary_layers") or sc.get("torsion"):
            raise Error("%s(conditions=True): the scene's fictitious layers (boundary_layers, torsion) are not prescribed DOFs; take the operators before the conditions" % what)

    def _free_block(self, A, what):
        self._reducible(what)
        free = self.free_dofs()
        B = A.createSubMatrix(free, free)
        A.destroy()
        free.destroy()
        return B

    def operator(self):
        """The body's K as a new petsc4py shell Mat applied bond by bond (perilin's matrix-free
        operator, no matrix stored), in stiffness()'s layout and before the conditions: mult
        equals stiffness() times x to round-off (lps's states included). perilin.Error for models
        whose bonds it cannot apply (3D shear bonds, dense family blocks)."""
        return _perilin.operator(self._handle)

    def constraints(self):
        """The prescribed DOFs (rows of K, sorted) and their values, as numpy arrays on every rank."""
        rows, values, isize = _perilin.constraints(self._handle)
        r = np.frombuffer(rows, dtype=np.int64 if isize == 8 else np.int32).astype(np.int64)
        v = np.frombuffer(values, dtype=np.float64).copy()
        return self._gather(r), self._gather(v)

    def free_dofs(self):
        """This rank's free DOFs (not prescribed) as a petsc4py IS, for K.createSubMatrix(is, is)."""
        rows, _, isize = _perilin.constraints(self._handle)
        held = np.frombuffer(rows, dtype=np.int64 if isize == 8 else np.int32)
        start, end = self.rhs().getOwnershipRange()
        free = np.setdiff1d(np.arange(start, end), held).astype(PETSc.IntType)
        return PETSc.IS().createGeneral(free, comm=self.comm)
