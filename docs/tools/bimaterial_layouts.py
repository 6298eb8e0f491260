#!/usr/bin/python3
"""The bimaterial bar (Oterkus & Madenci 8.2) with the interface between two rows of particles
(layout A, y0 = 0) and through a row (layout B, y0 = dx/2), at three spacings (m = 3.015), for
both models: prints the Markdown table of docs/models/antiplane.md ("Bimaterial (8.2)").

    /usr/bin/python3 docs/tools/bimaterial_layouts.py [build/perilin]

Columns: the relative l2 error of u_z against the exact 1D solution for the interface where the
scene puts it, and, for layout B, against the solution for y0 = 0 (what layout B is "off" by if the
reference keeps the interface at 0: S |1/mu1 - 1/mu2| dx/2, first order, the solver plays no part).
"""
import os, subprocess, sys, tempfile
import numpy as np
from common import read_vtu

EXE = sys.argv[1] if len(sys.argv) > 1 else "build/perilin"
SCENE = "examples/antiplane/bimaterial.yaml"
S, MU1, MU2 = 12000.0, 12e6, 6e6


def exact(y, y0):
    return np.where(y < y0, S * (y + 0.5) / MU1, S * (y0 + 0.5) / MU1 + S * (y - y0) / MU2)


def solve(model, dx, y0):
    """u_z and y of the body's particles"""
    out = tempfile.mkdtemp()
    subprocess.run([EXE, SCENE, "-output_dir", out, "-model_type", model, "-grid_spacing", f"{dx:g}",
                    "-regions_upper_lower_1", f"{y0:g}"], check=True, capture_output=True)
    v = read_vtu(os.path.join(out, "particles.vtu"))
    body = v["mirror_of"][:, 0] < 0
    return v["displacement"][body, 2], v["Points"][body, 1]


def rel(u, ue):
    return np.sqrt(((u - ue) ** 2).sum() / (ue**2).sum())


print("| model | dx [in] | layout A (y0 = 0) | layout B (y0 = dx/2) | layout B vs the y0 = 0 solution |")
print("|---|---|---|---|---|")
for model in ["antiplane", "antiplane_os"]:
    for dx in [0.02, 0.01, 0.005]:
        ua, ya = solve(model, dx, 0.0)
        ub, yb = solve(model, dx, dx / 2)
        print(f"| {model} | {dx:g} | {rel(ua, exact(ya, 0)):.2e} | {rel(ub, exact(yb, dx / 2)):.2e} | {rel(ub, exact(yb, 0)):.2e} |")
