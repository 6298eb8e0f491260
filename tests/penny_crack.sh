#!/usr/bin/env bash
# A penny-shaped crack in a 3D block in tension (examples/fracture/penny_crack.yaml, issue 38,
# item 7; docs/penny_crack.md): pmb, m = 3, a/dx = 4 and 5, stepping by events, stopped by
# load_factor_max just past the first break. The remote stress of the first bond break against
# Sneddon's sigma_S = K_Ic sqrt(pi/a)/2 = 91.53 Pa (K_Ic = sqrt(G E/(1 - nu^2)), plane strain).
# Measured (docs/penny_crack.md): 58.2526 Pa at a/dx = 4 (0.636), 47.5269 Pa at a/dx = 5 (0.519):
# a miss. The load is deterministic (the events' closed form on a solve to rtol 1e-10), so the
# test pins it to 1 % (what a change of solver or ordering cannot move, a change of the model,
# the crack cut or the criterion does) and asserts what the docs conclude from it: the first
# break is far below Sneddon's load (ratio < 0.8), the bonds that break first are at the crack
# front (their particles within a horizon, 3 dx, of the circle r = a, z = 3: measured 1.67 dx at
# a/dx = 4, oblique bonds, and 0.52 dx at a/dx = 5, the short bonds across the plane), and the
# finer grid, whose discrete front passes closer to the nearest uncut bond across the plane
# (0.148 dx against 0.301 dx), breaks first at a lower load.
# Usage: penny_crack.sh PERILIN SCENE
set -euo pipefail
perilin=$1 scene=$2
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
common=(-quiet -output_plots false)
"$perilin" "$scene" "${common[@]}" -grid_spacing 1/4 -analysis_load_factor_max 60 -output_dir r4 > r4.log
"$perilin" "$scene" "${common[@]}" -grid_spacing 1/5 -analysis_load_factor_max 50 -output_dir r5 > r5.log
/usr/bin/python3 - << 'PY'
import csv, json, math, sys
E, nu, G, a = 1.0e4, 0.25, 1.0, 1.0
KIc = math.sqrt(G * E / (1 - nu * nu))
sS = KIc * math.sqrt(math.pi / a) / 2
measured = {4: 58.2526, 5: 47.5269}
first, bad = {}, 0
def check(ok, text):
    global bad
    bad |= not ok
    print(("ok: " if ok else "FAIL: ") + text)
for n in (4, 5):
    rows = list(csv.DictReader(open(f"r{n}/steps.csv")))
    q = json.load(open(f"r{n}/summary.json"))["quasistatic"]
    check(q["complete"] and not q["failed"] and q["stepping"] == "events", f"a/dx = {n}: events, complete, not failed")
    check(len(rows) >= 2 and int(rows[0]["broken_total"]) == 0 and int(rows[1]["broken"]) > 0,
          f"a/dx = {n}: steps.csv row 1 the peak before the first break, row 2 its cascade")
    s = float(rows[0]["load_factor"])
    first[n] = s
    check(abs(s / measured[n] - 1) < 0.01, f"a/dx = {n}: first break at {s:.4f} Pa, measured {measured[n]} (tolerance 1 %)")
    check(s / sS < 0.8, f"a/dx = {n}: sigma_c / sigma_Sneddon = {s:.2f} / {sS:.2f} = {s / sS:.3f} < 0.8 (the miss the docs report)")
check(first[5] < first[4], f"the front nearer a short bond breaks first at a lower load: {first[5]:.2f} (a/dx = 5) < {first[4]:.2f} (a/dx = 4)")
try:
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
    import numpy as np
except ImportError:
    print("note: no python3 vtk: the place of the first breaks is not checked")
    sys.exit(bad)
for n in (4, 5):
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(f"r{n}/particles.vtu")
    r.Update()
    g = r.GetOutput()
    X = vtk_to_numpy(g.GetPoints().GetData())
    d = vtk_to_numpy(g.GetPointData().GetArray("damage_tension"))
    P = X[d > 0]
    dx = 1.0 / n
    rad = np.hypot(P[:, 0] - 3, P[:, 1] - 3)
    front = np.hypot(rad - a, P[:, 2] - 3).max() / dx
    check(len(P) > 0 and front <= 3, f"a/dx = {n}: {len(P)} particles damaged by tension, within {front:.2f} dx of the front (r - a in [{(rad.min() - a) / dx:.3f}, {(rad.max() - a) / dx:.3f}] dx; tolerance the horizon, 3 dx)")
sys.exit(bad)
PY
