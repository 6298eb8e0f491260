#!/usr/bin/python3
"""Errors, J and cost of the antiplane/torsion benchmarks (Oterkus & Madenci 8.1, 8.2, 8.4) at the
paper's resolutions, for both models: prints the Markdown table of docs/models/antiplane.md.

    /usr/bin/python3 docs/tools/antiplane_table.py [build/perilin]

The exact solutions are the same series as tests/scenes/test_antiplane.c (independent of perilin)."""
import json, os, subprocess, sys, tempfile
import numpy as np
from common import read_vtu

EXE = sys.argv[1] if len(sys.argv) > 1 else "build/perilin"
S, MU = 12000.0, 12e6


def square_bar(x, y):
    n = np.arange(1, 4000, 2)[:, None]
    k = n * np.pi
    d = 4 * np.where(((n - 1) // 2) % 2, -1, 1) / (n * np.pi)
    r = (np.exp(k * (y - 0.5)) + np.exp(-k * (y + 1.5))) / (1 - np.exp(-2 * k))
    return (S / MU * d / k * np.cos(k * x) * r).sum(axis=0)


def bimaterial(x, y):
    return np.where(y < 0, S * (y + 0.5) / MU, S * 0.5 / MU + S * y / 6e6)


def torsion(x, y, a=0.5, b=1.0, psi=1.0):
    n = np.arange(1, 6000, 2)[:, None]
    k = n * np.pi / (2 * b)
    c = 2 / b * np.where(((n - 1) // 2) % 2, -1, 1) / k**2
    A = 2 * psi * c / k
    e, f, den = np.exp(k * (abs(x) - a)), np.exp(-k * (abs(x) + a)), 1 + np.exp(-2 * k * a)
    sh = np.sign(x) * (e - f) / den
    ch = (e + f) / den
    w = -psi * x * y + (A * sh * np.sin(k * y)).sum(axis=0)
    txz = MU * (-2 * psi * y + (A * k * ch * np.sin(k * y)).sum(axis=0))
    tyz = MU * (A * k * sh * np.cos(k * y)).sum(axis=0)
    return w, txz, tyz


def run(scene, *opts):
    out = tempfile.mkdtemp()
    subprocess.run([EXE, scene, "-output_dir", out, *opts], check=True, capture_output=True)
    return json.load(open(os.path.join(out, "summary.json"))), read_vtu(os.path.join(out, "particles.vtu"))


def rel(a, b):
    return np.sqrt(((a - b) ** 2).sum() / (b**2).sum())


rows = []
for model in ["antiplane", "antiplane_os"]:
    for name, scene, exact, h in [("8.1 square bar", "examples/antiplane/square_bar.yaml", square_bar, "0.01"),
                                  ("8.2 bimaterial", "examples/antiplane/bimaterial.yaml", bimaterial, "0.01")]:
        s, v = run(scene, "-model_type", model, "-grid_spacing", h)
        body = v["mirror_of"][:, 0] < 0
        x, y = v["Points"][body, 0], v["Points"][body, 1]
        err = rel(v["displacement"][body, 2], exact(x, y))
        rows.append((name, model, h, s["particles"], f"u_z {100 * err:.3f} %", "", s["timing"]["total_s"]))
    for h in ["0.04", "0.02", "0.01"]:
        s, v = run("examples/torsion/rect_bar.yaml", "-model_type", model, "-grid_spacing", h)
        body = v["mirror_of"][:, 0] < 0
        x, y = v["Points"][body, 0], v["Points"][body, 1]
        w, txz, tyz = torsion(x, y)
        ew = rel(v["displacement"][body, 2], w)
        et = np.sqrt(((v["shear_stress"][body, 0] - txz) ** 2 + (v["shear_stress"][body, 1] - tyz) ** 2).sum() / (txz**2 + tyz**2).sum())
        t = s["torsion"]
        rows.append(("8.4 torsion", model, h, s["particles"], f"warping {100 * ew:.4f} %, tau {100 * et:.3f} %",
                     f"J = {t['J']:.5f} ({100 * t['J_error_vs_rectangle']:+.3f} %), tau_max {t['max_shear_stress'] / 1e6:.3f}e6",
                     s["timing"]["total_s"]))

print("| benchmark | model | dx [in] | particles (with layers) | l2 error vs exact | torsion | time [s] |")
print("|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | {r[4]} | {r[5]} | {r[6]:.2f} |")
