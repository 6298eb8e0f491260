#!/usr/bin/env python3
"""Convergence of the edge crack's critical load (issue 15, item 3): examples/fracture/edge_crack.yaml
(npmb, G = 1 J/m^2, E = 1e4 Pa, plane stress; LEFM: 130.6 Pa, docs/failure.md) with the events
stepping, for every spacing and horizon factor m given, and the table along the paths the issue
names: fixed m (dx halves), fixed delta (m doubles as dx halves), delta halved while m doubles.

    /usr/bin/python3 docs/tools/crack_convergence.py [--spacings 0.04,0.02,0.01,0.005] [--m 2,3,4,6]

Prints one markdown row per run (spacing, m, delta, particles, bonds, solves, critical load,
error against LEFM) and the wall time. Uses build/perilin (or $PERILIN).
"""
import argparse
import json
import os
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PERILIN = os.environ.get("PERILIN", os.path.join(ROOT, "build", "perilin"))
LEFM = 130.6


def run(dx, m):
    with tempfile.TemporaryDirectory() as out:
        t0 = time.time()
        subprocess.run([PERILIN, os.path.join(ROOT, "examples/fracture/edge_crack.yaml"), "-grid_spacing", str(dx),
                        "-horizon_m", str(m), "-analysis_stepping", "events", "-quiet", "-output_dir", out,
                        "-output_vtk", "false"], check=True, stdout=subprocess.DEVNULL)
        wall = time.time() - t0
        with open(os.path.join(out, "summary.json")) as f:
            d = json.load(f)
    return d, wall


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spacings", default="0.04,0.02,0.01,0.005")
    ap.add_argument("--m", default="2,3,4,6")
    a = ap.parse_args()
    print("| Δx | m | δ | particles | bonds | solves | critical load (Pa) | vs LEFM 130.6 | wall s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for dx in [float(x) for x in a.spacings.split(",")]:
        for m in [float(x) for x in a.m.split(",")]:
            d, wall = run(dx, m)
            lam = d["quasistatic"].get("critical_load_factor")
            err = "%+.1f %%" % (100 * (lam / LEFM - 1)) if lam else "—"
            print(f"| {dx:g} | {m:g} | {dx * m:g} | {d['particles']:,} | {d['bonds']:,} | {d['quasistatic']['solves']} | "
                  f"{lam:.2f} | {err} | {wall:.1f} |" if lam else f"| {dx:g} | {m:g} | {dx * m:g} | — | — | — | — | — | {wall:.1f} |",
                  flush=True)


if __name__ == "__main__":
    main()
