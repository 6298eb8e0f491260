#!/usr/bin/python3
"""CalculiX reference: natural frequencies of a free-free 3D elastic bar.

The bar is the box [0,Lx]x[0,Ly]x[0,Lz] (default 0.5 x 0.1 x 0.05 m), steel (E = 200e9 Pa,
rho = 7850 kg/m^3, nu given), no supports. The script writes a CalculiX input itself (a
structured mesh of 20-node hexahedra, C3D20R by default, generated here), runs `ccx` (Debian's
calculix-ccx) with a *FREQUENCY step, parses the eigenvalues and the nodal mode shapes from the
.dat file, drops the 6 rigid-body modes (near-zero frequency), classifies the elastic modes by
their mirror symmetries about the mid-planes y = Ly/2 and z = Lz/2 and prints the lowest elastic
frequencies in Hz.

Usage:
  tests/reference/ccx_free_bar.py [--nu 0.3] [--mesh 20x4x2 ...] [--converge] [--json FILE]

  --mesh NXxNYxNZ    one or more meshes (elements along x, y, z); default 20x4x2
  --converge         refine 10x2x1, 20x4x2, 40x8x4, 80x16x8 ... (each dimension doubled) until
                     the largest relative change of the lowest NPRINT elastic frequencies is
                     below --tol (default 1e-3), or --max-level is reached
  --nu NU            Poisson ratio (repeatable: --nu 0.3 --nu 0.25)
  --element C3D20R|C3D20
  --nprint N         elastic frequencies printed/compared (default 8)
  --modes N          eigenvalues asked of ccx (default 16: 6 rigid + 10 elastic)
  --json FILE        write the finest result per nu (frequencies, mode types, meshes) as JSON
  --keep DIR         keep the CalculiX files in DIR (default: a temporary directory)

Mode classes (from the mirror symmetry of the displacement field):
  sym about y-mid and z-mid  -> axial (or a cross-section breathing mode)
  antisym y, sym z           -> bending in y (displacement along y, the 0.1 m side)
  sym y, antisym z           -> bending in z (displacement along z, the 0.05 m side)
  antisym y and z            -> torsion about x
The order within a class is counted (bending-y 1, bending-y 2, ...).
Only python3's standard library is needed.
"""

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

E_DEFAULT = 200e9
RHO_DEFAULT = 7850.0


def build_mesh(nx, ny, nz, lx, ly, lz):
    """Nodes and 20-node hexahedra of a structured nx x ny x nz mesh of the box.

    The nodes live on the (2nx+1)(2ny+1)(2nz+1) half-step grid; those with two or more odd
    indices (face and body centres) are not used by serendipity elements and are dropped.
    Returns (nodes: dict id -> (x,y,z), grid index -> id, elements: list of 20-tuples)."""
    gid = {}
    nodes = {}
    nid = 0
    for k in range(2 * nz + 1):
        for j in range(2 * ny + 1):
            for i in range(2 * nx + 1):
                if (i % 2) + (j % 2) + (k % 2) >= 2:
                    continue
                nid += 1
                gid[(i, j, k)] = nid
                nodes[nid] = (lx * i / (2 * nx), ly * j / (2 * ny), lz * k / (2 * nz))
    # CalculiX/Abaqus C3D20 numbering: corners 1-4 on the bottom face (z-), 5-8 on the top,
    # 9-12 mid-edges of the bottom face, 13-16 of the top face, 17-20 vertical mid-edges.
    corner = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0), (0, 0, 2), (2, 0, 2), (2, 2, 2), (0, 2, 2)]
    mid = [(1, 0, 0), (2, 1, 0), (1, 2, 0), (0, 1, 0), (1, 0, 2), (2, 1, 2), (1, 2, 2), (0, 1, 2),
           (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1)]
    elements = []
    for ek in range(nz):
        for ej in range(ny):
            for ei in range(nx):
                base = (2 * ei, 2 * ej, 2 * ek)
                elements.append(tuple(gid[(base[0] + a, base[1] + b, base[2] + c)]
                                      for (a, b, c) in corner + mid))
    return nodes, gid, elements


def write_input(path, nodes, elements, element_type, e, nu, rho, nmodes):
    with open(path, "w") as f:
        f.write("** free-free bar, written by tests/reference/ccx_free_bar.py\n")
        f.write("*NODE, NSET=NALL\n")
        for nid in sorted(nodes):
            x, y, z = nodes[nid]
            f.write("%d, %.17g, %.17g, %.17g\n" % (nid, x, y, z))
        f.write("*ELEMENT, TYPE=%s, ELSET=EALL\n" % element_type)
        for eid, conn in enumerate(elements, start=1):
            # at most 16 entries a line: the element number and 15 nodes, then 5 more
            f.write("%d, %s,\n%s\n" % (eid, ", ".join(map(str, conn[:15])),
                                       ", ".join(map(str, conn[15:]))))
        f.write("*MATERIAL, NAME=STEEL\n*ELASTIC\n%.17g, %.17g\n*DENSITY\n%.17g\n" % (e, nu, rho))
        f.write("*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n")
        f.write("*STEP\n*FREQUENCY\n%d\n" % nmodes)
        f.write("*NODE PRINT, NSET=NALL\nU\n")
        f.write("*END STEP\n")


NUM = r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?"


def parse_dat(path):
    """Eigenvalue table (mode, eigenvalue, omega, f in Hz) and the mode shapes {node: (u)}."""
    with open(path) as f:
        lines = f.read().splitlines()
    freqs = []
    shapes = []
    i = 0
    n = len(lines)
    while i < n:
        line = lines[i]
        if "E I G E N V A L U E   O U T P U T" in line:
            i += 1
            # skip to the first numeric row
            while i < n and not re.match(r"^\s*\d+\s+" + NUM, lines[i]):
                i += 1
            while i < n and re.match(r"^\s*\d+\s+" + NUM, lines[i]):
                parts = lines[i].split()
                freqs.append((int(parts[0]), float(parts[1]), float(parts[2]), float(parts[3])))
                i += 1
            continue
        if line.strip().startswith("displacements (vx,vy,vz)"):
            shape = {}
            i += 1
            while i < n and not lines[i].strip():
                i += 1
            while i < n and lines[i].strip():
                parts = lines[i].split()
                shape[int(parts[0])] = (float(parts[1]), float(parts[2]), float(parts[3]))
                i += 1
            shapes.append(shape)
            continue
        i += 1
    return freqs, shapes


def mirror_corr(shape, gid, nx, ny, nz, axis):
    """<u, R u> / <u, u> for the mirror R about the mid-plane normal to axis (1: y, 2: z)."""
    num = 0.0
    den = 0.0
    for (i, j, k), nid in gid.items():
        if axis == 1:
            mid_ = gid[(i, 2 * ny - j, k)]
        else:
            mid_ = gid[(i, j, 2 * nz - k)]
        u = shape[nid]
        v = list(shape[mid_])
        v[axis] = -v[axis]
        num += u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
        den += u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
    return num / den if den > 0 else 0.0


def classify(shape, gid, nx, ny, nz):
    cy = mirror_corr(shape, gid, nx, ny, nz, 1)
    cz = mirror_corr(shape, gid, nx, ny, nz, 2)
    sy = "S" if cy > 0.5 else ("A" if cy < -0.5 else "?")
    sz = "S" if cz > 0.5 else ("A" if cz < -0.5 else "?")
    return {("S", "S"): "axial", ("A", "S"): "bending-y", ("S", "A"): "bending-z",
            ("A", "A"): "torsion"}.get((sy, sz), "mixed")


def run_case(nx, ny, nz, nu, args, workdir):
    nodes, gid, elements = build_mesh(nx, ny, nz, args.lx, args.ly, args.lz)
    job = "bar_%dx%dx%d_nu%s" % (nx, ny, nz, ("%g" % nu).replace(".", "p"))
    write_input(os.path.join(workdir, job + ".inp"), nodes, elements, args.element,
                args.E, nu, args.rho, args.modes)
    env = dict(os.environ)
    env.setdefault("OMP_NUM_THREADS", "1")
    env.setdefault("CCX_NPROC_EQUATION_SOLVER", "1")
    t0 = time.time()
    with open(os.path.join(workdir, job + ".log"), "w") as log:
        rc = subprocess.call([args.ccx, job], cwd=workdir, stdout=log, stderr=subprocess.STDOUT,
                             env=env)
    wall = time.time() - t0
    if rc != 0:
        sys.exit("ccx failed (rc %d) for %s: see %s" % (rc, job, os.path.join(workdir, job + ".log")))
    freqs, shapes = parse_dat(os.path.join(workdir, job + ".dat"))
    if len(freqs) < 6 + args.nprint:
        sys.exit("ccx returned %d eigenvalues for %s, need %d" % (len(freqs), job, 6 + args.nprint))
    fmax = max(f[3] for f in freqs)
    # rigid-body modes: the 6 lowest, each far below the first elastic one
    # (a slightly negative eigenvalue is printed with a zero real frequency: use |eigenvalue|)
    rigid = [math.copysign(math.sqrt(abs(f[1])) / (2 * math.pi), f[1]) for f in freqs[:6]]
    elastic = freqs[6:]
    if max(abs(f) for f in rigid) > 1e-3 * elastic[0][3]:
        sys.exit("the 6 lowest modes are not rigid-body modes: %r" % (rigid,))
    types = []
    counts = {}
    for m in range(6, len(freqs)):
        kind = classify(shapes[m], gid, nx, ny, nz) if m < len(shapes) else "?"
        counts[kind] = counts.get(kind, 0) + 1
        types.append("%s %d" % (kind, counts[kind]))
    return {
        "mesh": [nx, ny, nz],
        "nodes": len(nodes),
        "elements": len(elements),
        "dofs": 3 * len(nodes),
        "wall_s": round(wall, 2),
        "rigid_hz": rigid,
        "freq_hz": [f[3] for f in elastic],
        "types": types,
        "fmax": fmax,
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--nu", type=float, action="append")
    p.add_argument("--mesh", action="append")
    p.add_argument("--converge", action="store_true")
    p.add_argument("--tol", type=float, default=1e-3)
    p.add_argument("--max-level", type=int, default=4, help="meshes tried by --converge")
    p.add_argument("--element", default="C3D20R", choices=["C3D20R", "C3D20"])
    p.add_argument("--nprint", type=int, default=8)
    p.add_argument("--modes", type=int, default=16)
    p.add_argument("--E", type=float, default=E_DEFAULT)
    p.add_argument("--rho", type=float, default=RHO_DEFAULT)
    p.add_argument("--lx", type=float, default=0.5)
    p.add_argument("--ly", type=float, default=0.1)
    p.add_argument("--lz", type=float, default=0.05)
    p.add_argument("--ccx", default=shutil.which("ccx") or "ccx")
    p.add_argument("--json")
    p.add_argument("--keep")
    args = p.parse_args()
    nus = args.nu or [0.3]
    if args.converge:
        meshes = [(10 * 2 ** l, 2 * 2 ** l, 1 * 2 ** l) for l in range(args.max_level)]
    else:
        meshes = [tuple(int(v) for v in m.lower().split("x")) for m in (args.mesh or ["20x4x2"])]
    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
        workdir = args.keep
    else:
        workdir = tempfile.mkdtemp(prefix="ccx_free_bar_")
    try:
        ver = subprocess.run([args.ccx, "-v"], capture_output=True, text=True).stdout
        ver = " ".join(ver.split())
    except OSError:
        ver = "?"
    out = {"command": " ".join(["tests/reference/ccx_free_bar.py"] + sys.argv[1:]),
           "ccx_version": ver,
           "note": "rigid-body modes (6) dropped; frequencies in Hz as ccx prints them (7 digits); "
                   "the finest mesh's values per nu, with the refinement history",
           "problem": {"box_m": [args.lx, args.ly, args.lz], "E_Pa": args.E, "rho_kg_m3": args.rho,
                       "supports": "none (free-free)", "element": args.element,
                       "solver": "CalculiX ccx *FREQUENCY"},
           "tolerance": args.tol, "cases": {}}
    try:
        for nu in nus:
            print("nu = %g, %s, E = %g Pa, rho = %g kg/m^3, box %g x %g x %g m" %
                  (nu, args.element, args.E, args.rho, args.lx, args.ly, args.lz))
            history = []
            prev = None
            for (nx, ny, nz) in meshes:
                r = run_case(nx, ny, nz, nu, args, workdir)
                f = r["freq_hz"][:args.nprint]
                change = None
                if prev is not None:
                    change = max(abs(a - b) / abs(a) for a, b in zip(f, prev))
                r["max_rel_change"] = change
                history.append(r)
                print("  mesh %dx%dx%d (%d nodes, %d dofs, %.1f s): max |rigid| %.3g Hz (signed sqrt of the eigenvalue / 2 pi)" %
                      (nx, ny, nz, r["nodes"], r["dofs"], r["wall_s"], max(map(abs, r["rigid_hz"]))))
                print("    Hz: " + " ".join("%.7g" % v for v in f))
                if change is not None:
                    print("    max relative change from the previous mesh: %.3e" % change)
                prev = f
                if args.converge and change is not None and change < args.tol:
                    break
            fin = history[-1]
            print("  lowest %d elastic modes on mesh %s:" % (args.nprint, "x".join(map(str, fin["mesh"]))))
            for m in range(args.nprint):
                print("    %2d  %12.7g Hz  %s" % (m + 1, fin["freq_hz"][m], fin["types"][m]))
            out["cases"]["%g" % nu] = {
                "nu": nu,
                "mesh": fin["mesh"],
                "freq_hz": fin["freq_hz"][:args.nprint],
                "types": fin["types"][:args.nprint],
                "history": [{"mesh": h["mesh"], "dofs": h["dofs"], "wall_s": h["wall_s"],
                             "freq_hz": h["freq_hz"][:args.nprint],
                             "max_rel_change": h["max_rel_change"]} for h in history],
            }
    finally:
        if not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
