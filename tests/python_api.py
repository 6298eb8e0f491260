"""The Python module perilin (issue 39, docs/python.md) against the command line and against
petsc4py's own algebra, on one rank or several (mpiexec -n P /usr/bin/python3 python_api.py ...).

usage: python_api.py REPO CLI_OUT VERSION_LINE TMPDIR QS_OUT DYN_OUT
  CLI_OUT: the output set of `perilin examples/pmb/plate_traction.yaml` on as many ranks as this
  script runs on (particles.vtu or particles.pvtu; the same partition, so the same global order);
  VERSION_LINE: the first line `perilin -version` prints; QS_OUT, DYN_OUT: the command line's output
  sets of the small quasi-static and dynamic scenes below (QS, DYN: the same overrides), as many
  ranks.

Checks, each with its number:
  1. perilin.__version__ is what `perilin -version` prints;
  2. the displacements solved in-process equal the command line's particles file to 1e-12 (relative
     to the largest), the positions exactly, and the summary's counts and energy its summary.json's;
  3. K u - f from stiffness() and rhs() (petsc4py) vanishes on the free DOFs (relative 1e-8), u
     holds the prescribed values on the others, and an LU solve of the free block with petsc4py
     gives solve()'s u to 1e-8; with a prescribed value that is not 0 (the plate's roller moved),
     stiffness(conditions=True) and rhs(conditions=True) solved by petsc4py give solve()'s u on the
     free DOFs to 1e-8;
  4. a misspelt key and a bad value raise perilin.Error naming the key (and the file and line), and
     the same process goes on to solve again with the same result;
  5. set('material.E', 2 E) halves u (1e-10), a failing set() leaves the problem as it was;
  6. a dict scene gives the file's result; write(dir) writes the output set with the same u;
  7. operator() (perilin's matrix-free K as a shell Mat) times a random x equals stiffness() times x
     to 1e-13 (relative, 2-norm) on the plate (pmb's central bonds) and the lamina (mppd's
     micropolar bonds); mass(as_matrix=True) is the diagonal Mat of mass();
  8. modes() of the lamina (coarsened to 0.02 m): the frequencies equal slepc4py's on
     stiffness(conditions=True) and mass(as_matrix=True, conditions=True) to 1e-8; each shape's residual ||K x - w^2 M x|| /
     (w^2 ||M x||), computed here with petsc4py, is below 1e-7 and within 10 % of the one modes()
     reports (relative to it + 1e-11: both are near round-off); shapes vanish on the prescribed DOFs and have max |translation| 1;
  9. Result.steps (quasi-static) and Result.history (dynamic) hold the command line's steps.csv and
     history.csv: every column equal (the seconds column excepted: wall time), the same columns.
"""
import json
import os
import sys

import numpy as np
from petsc4py import PETSc
import yaml

import perilin
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader

repo, cli_out, version_line, tmpdir, qs_out, dyn_out = sys.argv[1:7]
# the small scenes of check 9; tests/python_api.sh gives the command line the same overrides
QS = ("examples/antiplane/cracked_bar.yaml", {"grid.spacing": 0.025, "output.plots": False})
DYN = ("examples/dynamics/pulse.yaml", {"grid.upper": [100, 4, 4], "analysis.t_end": 10, "output.plots": False})
comm = PETSc.COMM_WORLD
rank, size = comm.getRank(), comm.getSize()
failures = 0


def lu_solve(A, b):
    """x with A x = b by petsc4py's LU (MUMPS on several ranks)."""
    ksp = PETSc.KSP().create(A.getComm())
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    if A.getComm().getSize() > 1:
        ksp.getPC().setFactorSolverType("mumps")
    x = b.duplicate()
    ksp.solve(b, x)
    return x


def check(ok, what):
    global failures
    if rank == 0:
        print(("ok: " if ok else "FAIL: ") + what, flush=True)
    failures += not ok


def read_particles(out):
    """positions and displacements of an output set, in the files' order."""
    path = os.path.join(out, "particles.pvtu")
    reader = vtkXMLPUnstructuredGridReader() if os.path.exists(path) else vtkXMLUnstructuredGridReader()
    reader.SetFileName(path if os.path.exists(path) else os.path.join(out, "particles.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    return vtk_to_numpy(grid.GetPoints().GetData()), vtk_to_numpy(grid.GetPointData().GetArray("displacement"))


plate = os.path.join(repo, "examples/pmb/plate_traction.yaml")

# 1. the version
check(version_line.split() == ["perilin", perilin.__version__], "__version__ %s is `perilin -version`'s (%s)" % (perilin.__version__, version_line))

# 2. the in-process solve against the command line
p = perilin.Problem(plate)
r = p.solve()
x_cli, u_cli = read_particles(cli_out)
dim = r.x.shape[1]
scale = np.abs(u_cli).max()
check(r.x.shape == (5000, 2) and r.u.shape == (5000, 2) and r.components == ("ux", "uy"), "x, u are particles x dim: %s, %s, %s" % (r.x.shape, r.u.shape, r.components))
check(np.array_equal(r.x, x_cli[:, :dim]), "the positions are the command line's, in its order")
diff = np.abs(r.u - u_cli[:, :dim]).max() / scale
check(diff <= 1e-12, "u equals the command line's to %.2g of max |u| = %.4g (<= 1e-12)" % (diff, scale))
cli = json.load(open(os.path.join(cli_out, "summary.json")))
s = r.summary
check(all(s[k] == cli[k] for k in ("particles", "bonds", "dofs", "ranks", "model", "analysis")), "the summary's counts are summary.json's")
check(abs(s["strain_energy"] - cli["strain_energy"]) <= 1e-12 * abs(cli["strain_energy"]), "strain energy %.15g, the command line's %.15g" % (s["strain_energy"], cli["strain_energy"]))

# 3. K and f as petsc4py objects
K, f = p.stiffness(), p.rhs()
u = f.duplicate()
lo, hi = u.getOwnershipRange()
u.setValues(np.arange(lo, hi, dtype=PETSc.IntType), r.u.ravel()[lo:hi])
u.assemble()
res = K * u - f
free = p.free_dofs()
rf, ff = res.getSubVector(free), f.getSubVector(free)
rel = rf.norm() / ff.norm()
res.restoreSubVector(free, rf)
f.restoreSubVector(free, ff)
check(K.getSize() == (10000, 10000) and rel < 1e-8, "||K u - f|| / ||f|| on the free DOFs: %.2g (< 1e-8)" % rel)
rows, values = p.constraints()
check(len(rows) > 0 and np.array_equal(r.u.ravel()[rows], values), "u holds the %d prescribed values" % len(rows))
Kff = K.createSubMatrix(free, free)
b = f.getSubVector(free).copy()  # the prescribed values are 0 on this plate: no K_fc u_c term
check(not np.any(values), "the plate's prescribed values are 0")
x = lu_solve(Kff, b)
uf = u.getSubVector(free)
lu = (x - uf).norm(PETSc.NormType.INFINITY) / uf.norm(PETSc.NormType.INFINITY)
u.restoreSubVector(free, uf)
check(lu < 1e-8, "petsc4py's LU solve of the free block gives solve()'s u to %.2g (< 1e-8)" % lu)

# 3b. the reduced system with a prescribed value that is not 0: stiffness(conditions=True) and
# rhs(conditions=True) solved by petsc4py give solve()'s u on the free DOFs
scene = yaml.safe_load(open(plate))
scene["bc"][0] = {"region": "left", "value": {"ux": -2e-5}}
with perilin.Problem(scene, comm=comm) as q:
    rq = q.solve()
    Kff, bf, free = q.stiffness(conditions=True), q.rhs(conditions=True), q.free_dofs()
    x = lu_solve(Kff, bf)
    uq = PETSc.Vec().createWithArray(rq.u.ravel()[free.getIndices()], comm=comm)
    rel = (x - uq).norm(PETSc.NormType.INFINITY) / uq.norm(PETSc.NormType.INFINITY)
    check(Kff.getSize()[0] == free.getSize() and rel < 1e-8, "stiffness(conditions=True), rhs(conditions=True) with ux = -2e-5 prescribed: petsc4py's LU gives solve()'s u on the %d free DOFs to %.2g (< 1e-8)" % (free.getSize(), rel))

# 4. errors are perilin.Error, and the process goes on
for overrides, words in (({"materal.E": 1e9}, ["materal", "did you mean -material_E"]), ({"material.E": -1}, ["material.E", "plate_traction.yaml", "(0, inf)"])):
    try:
        perilin.Problem(plate, overrides)
        check(False, "%s raises perilin.Error" % overrides)
    except perilin.Error as e:
        check(all(w in str(e) for w in words), "%s raises perilin.Error: %s" % (overrides, e))
try:
    perilin.Problem(os.path.join(tmpdir, "no_such_scene.yaml"))
    check(False, "a missing scene file raises perilin.Error")
except perilin.Error as e:
    check("no_such_scene.yaml" in str(e), "a missing scene file raises perilin.Error: %s" % e)
again = perilin.Problem(plate).solve()
check(np.array_equal(again.u, r.u), "after the errors, the same scene solves to the same u")

# 5. set(): a new modulus
E = p.get("material.E")
check(E == 1e9, "get('material.E') = %g" % E)
p.set("material.E", 2 * E)
r2 = p.solve()
half = np.abs(2 * r2.u - r.u).max() / scale
check(p.get("material.E") == 2 * E and half <= 1e-10, "set('material.E', 2E) halves u: max |2 u' - u| / max |u| = %.2g (<= 1e-10)" % half)
try:
    p.set("material.nu", 0.2)
    check(False, "set('material.nu', 0.2) on pmb raises perilin.Error")
except perilin.Error as e:
    check("material.nu" in str(e) and p.get("material.E") == 2 * E and p.solve() is r2, "a failing set() raises (%s) and leaves the problem as it was" % e)

# 6. a dict scene, and write()
scene = yaml.safe_load(open(plate))
d = perilin.Problem(scene, comm=comm).solve()
check(np.array_equal(d.u, r.u), "a dict scene solves to the file's u")
out = os.path.join(tmpdir, "py-out")
p.write(out)
x_w, u_w = read_particles(out)
written = json.load(open(os.path.join(out, "summary.json")))
check(np.array_equal(u_w[:, :dim], r2.u) and written["material"]["E"] == 2 * E, "write(dir): particles file with u, summary.json with E = %g" % written["material"]["E"])
p.close()

# 7. the matrix-free operator and the mass matrix
lamina = os.path.join(repo, "examples/lamina/modal.yaml")
for scene, overrides in ((plate, {}), (lamina, {"grid.spacing": 0.02, "output.plots": False})):
    with perilin.Problem(scene, overrides) as q:
        K, A = q.stiffness(), q.operator()
        x = K.createVecRight()
        rnd = PETSc.Random().create(comm)
        rnd.setSeed(7)
        x.setRandom(rnd)
        y = K * x
        rel = (A * x - y).norm() / y.norm()
        check(A.getType() == "shell" and A.getSizes() == K.getSizes() and rel <= 1e-13, "operator() of %s: a %s Mat, ||A x - K x|| / ||K x|| = %.2g (<= 1e-13)" % (os.path.basename(scene), A.getType(), rel))
        if scene == lamina:
            m, M = q.mass(), q.mass(as_matrix=True)
            d = M.getDiagonal()
            z = M * x - m * x
            check(M.getInfo()["nz_used"] == M.getSize()[0] and (d - m).norm() == 0 and z.norm() == 0, "mass(as_matrix=True): the diagonal Mat of mass(), M x = m .* x exactly")

# 8. modes() against slepc4py on stiffness() and mass(as_matrix=True)
from slepc4py import SLEPc

with perilin.Problem(lamina, {"grid.spacing": 0.02, "output.plots": False}) as q:
    md = q.modes()
    K, M, free = q.stiffness(), q.mass(as_matrix=True), q.free_dofs()
    Kff, Mff = q.stiffness(conditions=True), q.mass(as_matrix=True, conditions=True)  # what SLEPc gets in the modal analysis
    eps = SLEPc.EPS().create(comm=comm)
    eps.setOperators(Kff, Mff)
    eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
    eps.setDimensions(len(md))
    eps.setTarget(0.0)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    eps.getST().setType(SLEPc.ST.Type.SINVERT)
    eps.getST().getKSP().setType("preonly")
    eps.getST().getKSP().getPC().setType("lu")
    if size > 1:
        eps.getST().getKSP().getPC().setFactorSolverType("mumps")
    eps.setTolerances(1e-12)
    eps.solve()
    lam = sorted(eps.getEigenvalue(k).real for k in range(eps.getConverged()))[: len(md)]
    theirs = np.sqrt(lam) / (2 * np.pi)
    rel = np.max(np.abs(md.frequencies - theirs) / theirs) if len(theirs) == len(md) else np.inf
    check(len(md) == q.get("analysis.nev") and rel <= 1e-8, "modes(): %d frequencies %.6f .. %.6f Hz equal slepc4py's to %.2g (<= 1e-8)" % (len(md), md.frequencies[0], md.frequencies[-1], rel))
    rows, _ = q.constraints()
    n, dofs = md.shapes.shape[1:]
    ok_shapes, worst, ratio = md.shapes.shape[0] == len(md), 0.0, 0.0
    for k in range(md.shapes.shape[0]):
        phi = md.shapes[k].ravel()
        translations = md.shapes[k][:, [c != "theta" for c in md.components]]
        ok_shapes = ok_shapes and not np.any(phi[rows]) and abs(np.abs(translations).max() - 1) < 1e-15
        v = K.createVecRight()
        lo, hi = v.getOwnershipRange()
        v.setValues(np.arange(lo, hi, dtype=PETSc.IntType), phi[lo:hi])
        v.assemble()
        w2 = (2 * np.pi * md.frequencies[k]) ** 2
        mx = M * v
        rv = K * v - mx * w2
        rf, mf = rv.getSubVector(free), mx.getSubVector(free)
        res = rf.norm() / (w2 * mf.norm())
        rv.restoreSubVector(free, rf)
        mx.restoreSubVector(free, mf)
        worst, ratio = max(worst, res), max(ratio, abs(res - md.residuals[k]) / (md.residuals[k] + 1e-11))
    check(ok_shapes, "modes(): %d shapes of %d particles x %d, zero on the %d prescribed DOFs, max |translation| 1" % (md.shapes.shape[0], n, dofs, len(rows)))
    # both residuals sit near round-off (1e-13 .. 1e-10 here), where they differ by a few %:
    # compared relative to the larger of modes()' own and 1e-11
    check(worst <= 1e-7 and ratio <= 0.1, "modes(): the shapes' residuals by petsc4py, worst %.2g (<= 1e-7), within %.2g of modes()' own (relative to it + 1e-11, <= 0.1)" % (worst, ratio))
try:
    p2 = perilin.Problem(plate)
    p2.modes()
    check(False, "modes() of a static scene raises perilin.Error")
except perilin.Error as e:
    check("modal" in str(e), "modes() of a static scene raises perilin.Error: %s" % e)
    p2.close()


# 9. the quasi-static steps and the dynamic history against the command line's CSV files
def read_csv(path):
    names = open(path).readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return names, data


for (scene, overrides), out, attr, csv in ((QS, qs_out, "steps", "steps.csv"), (DYN, dyn_out, "history", "history.csv")):
    with perilin.Problem(os.path.join(repo, scene), overrides) as q:
        table = getattr(q.solve(), attr)
    names, data = read_csv(os.path.join(out, csv))
    same = list(table) == names and all(len(table[c]) == len(data) for c in names)
    same = same and all(np.array_equal(table[c], data[:, i]) for i, c in enumerate(names) if c != "seconds")
    check(same and len(data) > 2, "Result.%s: %d rows x %d columns, equal to the command line's %s (seconds excepted)" % (attr, len(data), len(names), csv))

failures = comm.tompi4py().allreduce(failures)
if rank == 0:
    print("%s: %d failure(s) on %d rank(s)" % ("FAIL" if failures else "ok", failures, size))
sys.exit(1 if failures else 0)
