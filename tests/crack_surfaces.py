"""3D cracks (cracks: polygon, disc, surface; docs/failure.md) against an independent count.

usage: crack_surfaces.py PERILIN WORKDIR

A 10 x 10 x 10 grid (spacing 0.1, horizon 2.5 spacings, no partial volumes, so that the bonds are
exactly the pairs closer than the horizon and each has the factor 1) is cut by one crack per run:
an axis-aligned disc, a tilted disc, a tilted square as a polygon and as the same square's two
triangles in an ASCII STL, a binary STL and a Gmsh .msh, and an L-shaped (non-convex) polygon.
This script counts the cut bonds itself from the particles' positions in particles.vtu, by another
route than perilin's (the crossing point's coordinates along the square's own axes; the L as a
union of two rectangles; the distance to the disc's centre), and checks on 1 and 2 ranks:
summary.json's bonds and precracked_bonds exactly, and each particle's damage, which is then
(cut bonds)/(bonds) exactly, to 1e-12. The cracks are placed so that no crossing point lies
within 1e-9 of a crack's edge and no particle within 1e-9 of its plane: the count is unambiguous.
"""
import json
import os
import struct
import subprocess
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader

perilin, work = sys.argv[1:3]
MPI = ["mpiexec", "--oversubscribe", "-n", "2"]
os.environ.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
SCENE = """dim: 3
model: {type: pmb}
material: {E: 1.0e9}
grid: {lower: [0, 0, 0], upper: [1, 1, 1], spacing: 0.1}
horizon: {m: 2.5}
corrections: {partial_volume: none, surface: none}
analysis: {type: setup}
cracks:
  - %s
"""
failures = 0


def check(ok, what):
    global failures
    print(("ok: " if ok else "FAIL: ") + what)
    failures += not ok


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


# the tilted square: centre, unit normal, in-plane axes e1, e2, half side h
SQ_C = np.array([0.503, 0.488, 0.517])
SQ_N = unit([0.3, 1.0, 0.2])
SQ_E1 = unit(np.cross(SQ_N, [0, 0, 1]))
SQ_E2 = np.cross(SQ_N, SQ_E1)
SQ_H = 0.2713
SQUARE = [SQ_C + SQ_H * (a * SQ_E1 + b * SQ_E2) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
TRIANGLES = [(SQUARE[0], SQUARE[1], SQUARE[2]), (SQUARE[0], SQUARE[2], SQUARE[3])]
L_Z = 0.4711
L = [(0.2113, 0.2113), (0.7887, 0.2113), (0.7887, 0.4319), (0.4319, 0.4319), (0.4319, 0.7887), (0.2113, 0.7887)]


def fmt(p):
    return "[%s]" % ", ".join("%.17g" % v for v in p)


def write_stl_ascii(path):
    with open(path, "w") as f:
        f.write("solid square\n")
        for t in TRIANGLES:
            f.write("facet normal %s\n outer loop\n" % " ".join("%.17g" % v for v in SQ_N))
            for p in t:
                f.write("  vertex %s\n" % " ".join("%.17g" % v for v in p))
            f.write(" endloop\nendfacet\n")
        f.write("endsolid square\n")


def write_stl_binary(path):
    with open(path, "wb") as f:
        f.write(b"perilin test square".ljust(80, b" ") + struct.pack("<I", len(TRIANGLES)))
        for t in TRIANGLES:
            f.write(struct.pack("<12fH", *SQ_N, *t[0], *t[1], *t[2], 0))


def write_msh(path):
    with open(path, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n")
        for k, p in enumerate(SQUARE):
            f.write("%d %s\n" % (k + 1, " ".join("%.17g" % v for v in p)))
        f.write("$EndNodes\n$Elements\n2\n1 2 2 0 1 1 2 3\n2 2 2 0 1 1 3 4\n$EndElements\n")


def crossings(x, i, j, c, n):
    """The pairs (i, j) whose segment crosses the plane (c, n) strictly, and where."""
    sa, sb = (x[i] - c) @ n, (x[j] - c) @ n
    check(min(np.abs(sa).min(), np.abs(sb).min()) > 1e-9, "no particle within 1e-9 of the crack's plane")
    m = sa * sb < 0
    t = sa[m] / (sa[m] - sb[m])
    return m, x[i[m]] + t[:, None] * (x[j[m]] - x[i[m]])


def inside_square(X):
    u, v = np.abs((X - SQ_C) @ SQ_E1), np.abs((X - SQ_C) @ SQ_E2)
    check(min(np.abs(u - SQ_H).min(), np.abs(v - SQ_H).min()) > 1e-9, "no crossing within 1e-9 of the square's edges")
    return (u < SQ_H) & (v < SQ_H)


def inside_l(X):
    a, b, c = L[0][0], L[1][0], L[2][1]
    edges = np.abs(np.concatenate([X[:, 0] - a, X[:, 0] - b, X[:, 0] - c, X[:, 1] - a, X[:, 1] - b, X[:, 1] - c]))
    check(edges.min() > 1e-9, "no crossing within 1e-9 of the L's edges")
    box = lambda x0, x1, y0, y1: (X[:, 0] > x0) & (X[:, 0] < x1) & (X[:, 1] > y0) & (X[:, 1] < y1)
    return box(a, b, a, c) | box(a, c, a, b)


DISC_AXIS = (np.array([0.52, 0.5, 0.5]), unit([1, 0, 0]), 0.3031)
DISC_TILT = (np.array([0.5, 0.47, 0.51]), unit([1, 0.4, 0.25]), 0.3317)


def inside_disc(disc):
    def inside(X):
        r = np.linalg.norm(X - disc[0], axis=1)
        check(np.abs(r - disc[2]).min() > 1e-9, "no crossing within 1e-9 of the disc's rim")
        return r < disc[2]
    return inside


def disc_item(disc):
    c, n, r = disc
    return "disc: {center: %s, normal: %s, radius: %.17g}" % (fmt(c), fmt(n), r)


# name: (crack item, plane point, plane normal, inside test)
square = (SQ_C, SQ_N, inside_square)
CASES = {
    "disc_axis": (disc_item(DISC_AXIS), DISC_AXIS[0], DISC_AXIS[1], inside_disc(DISC_AXIS)),
    "disc_tilted": (disc_item(DISC_TILT), DISC_TILT[0], DISC_TILT[1], inside_disc(DISC_TILT)),
    "polygon_square": ("polygon: [%s]" % ", ".join(fmt(p) for p in SQUARE),) + square,
    "stl_ascii": ("surface: square.stl",) + square,
    "stl_binary": ("surface: square_binary.stl",) + square,
    "msh": ("surface: square.msh",) + square,
    "polygon_l": ("polygon: [%s]" % ", ".join(fmt((a, b, L_Z)) for a, b in L), np.array([0, 0, L_Z]), np.array([0, 0, 1.0]), inside_l),
}


def read(out):
    pvtu = os.path.join(out, "particles.pvtu")
    reader = vtkXMLPUnstructuredGridReader() if os.path.exists(pvtu) else vtkXMLUnstructuredGridReader()
    reader.SetFileName(pvtu if os.path.exists(pvtu) else os.path.join(out, "particles.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    pd = grid.GetPointData()
    return vtk_to_numpy(grid.GetPoints().GetData()).astype(float), vtk_to_numpy(pd.GetArray("damage")).astype(float)


def expected(x, delta, case):
    """The bonds (pairs closer than delta), the cut ones, and each particle's share of cut bonds."""
    _, c, n, inside = CASES[case]
    d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)
    i, j = np.nonzero(np.triu(d <= delta, 1))
    m, X = crossings(x, i, j, c, n)
    cut = np.zeros(len(i), bool)
    cut[np.nonzero(m)[0][inside(X)]] = True
    nb = np.bincount(i, minlength=len(x)) + np.bincount(j, minlength=len(x))
    nc = np.bincount(i[cut], minlength=len(x)) + np.bincount(j[cut], minlength=len(x))
    return len(i), int(cut.sum()), nc / nb


def run(case, ranks):
    scene = os.path.join(work, case + ".yaml")
    with open(scene, "w") as f:
        f.write(SCENE % CASES[case][0])
    out = os.path.join(work, "%s_%d" % (case, ranks))
    cmd = (MPI if ranks > 1 else []) + [perilin, scene, "-quiet", "-output_dir", out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode:
        check(False, "%s on %d rank(s) runs: %s" % (case, ranks, r.stderr.strip()))
        return
    s = json.load(open(os.path.join(out, "summary.json")))
    x, damage = read(out)
    nbonds, ncut, share = expected(x, s["horizon"], case)
    print("%s, %d rank(s): %d bonds, %d cut (perilin: %d, %d)" % (case, ranks, nbonds, ncut, s["bonds"], s.get("precracked_bonds", -1)))
    check(s["bonds"] == nbonds, "%s: bonds %d == %d" % (case, s["bonds"], nbonds))
    check(s.get("precracked_bonds") == ncut and ncut > 0, "%s: precracked_bonds %s == %d" % (case, s.get("precracked_bonds"), ncut))
    check(np.abs(damage - share).max() < 1e-12, "%s: damage == cut/bonds per particle (largest %.4f)" % (case, share.max()))


write_stl_ascii(os.path.join(work, "square.stl"))
write_stl_binary(os.path.join(work, "square_binary.stl"))
write_msh(os.path.join(work, "square.msh"))
for case in CASES:
    for ranks in (1, 2):
        run(case, ranks)
sys.exit(1 if failures else 0)
