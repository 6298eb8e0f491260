#!/usr/bin/env python3
"""Convergence of the edge crack's critical load (issue 15, item 3): examples/fracture/edge_crack.yaml
(npmb, G = 1 J/m^2, E = 1e4 Pa, plane stress; LEFM: 130.6 Pa, docs/failure.md) with the events
stepping, for every model, calibration, spacing and horizon factor m given, and the table along
the paths the issue names: fixed m (dx halves), fixed dx (m grows), fixed delta (m doubles as dx
halves), delta halved while m doubles.

    /usr/bin/python3 docs/tools/crack_convergence.py [--spacings 0.04,0.02,0.01,0.005] [--m 2,3,4,6]
        [--models npmb,pmb] [--calibrations continuum,lattice] [--runs DX:M,DX:M,...] [--jobs 2]
        [--save results.json] [--load results.json ...]

--runs adds single (dx, m) runs to the grid spacings x m (e.g. the path delta ~ dx^(1/2):
0.04:2,0.02:2.828,0.01:4,0.005:5.657, where delta halves while m doubles every two steps).
--jobs runs that many single-rank runs at once (their wall times then share the cores).
--save writes every result as JSON, --load reads earlier ones instead of running them again.

Prints one markdown row per run (model, calibration, spacing, m, delta, particles, bonds, solves,
the load of the first bond break (the first step of steps.csv that broke one; a stable growth
follows up to the critical load), critical (runaway) load, error against LEFM, wall time), then per model and calibration the paths with the
observed order in delta where the last three runs of a path refine delta by one ratio r:
p = ln(|l1 - l2| / |l2 - l3|) / ln r and the Richardson value l3 + (l3 - l2)/(r^p - 1) (only when
the differences shrink with the same sign). Uses build/perilin (or $PERILIN).
"""
import argparse
import concurrent.futures
import csv
import json
import math
import os
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PERILIN = os.environ.get("PERILIN", os.path.join(ROOT, "build", "perilin"))
LEFM = 130.6


def run(model, cal, dx, m):
    with tempfile.TemporaryDirectory() as out:
        t0 = time.time()
        subprocess.run([PERILIN, os.path.join(ROOT, "examples/fracture/edge_crack.yaml"), "-grid_spacing", str(dx),
                        "-horizon_m", str(m), "-model_type", model, "-model_calibration", cal,
                        "-analysis_stepping", "events", "-quiet", "-output_dir", out, "-output_vtk", "false"],
                       check=True, stdout=subprocess.DEVNULL)
        wall = time.time() - t0
        with open(os.path.join(out, "summary.json")) as f:
            d = json.load(f)
        with open(os.path.join(out, "steps.csv")) as f:
            steps = list(csv.DictReader(f))
    # first break: the load of the first step in equilibrium that broke a bond, else the runaway
    first = next((float(s["load_factor"]) for s in steps if int(s["broken"]) > 0),
                 d["quasistatic"].get("critical_load_factor"))
    return {"model": model, "calibration": cal, "dx": dx, "m": m, "particles": d["particles"], "bonds": d["bonds"],
            "solves": d["quasistatic"]["solves"], "load": d["quasistatic"].get("critical_load_factor"), "first": first, "wall": wall}


def err(lam):
    return "%+.1f %%" % (100 * (lam / LEFM - 1)) if lam else "—"


def row(r):
    lam = r["load"]
    return (f"| {r['model']} | {r['calibration']} | {r['dx']:g} | {r['m']:g} | {r['dx'] * r['m']:.4g} | {r['particles']:,} | "
            f"{r['bonds']:,} | {r['solves']} | {r['first']:.1f} | {lam:.2f} | {err(lam)} | {r['wall']:.1f} |" if lam else
            f"| {r['model']} | {r['calibration']} | {r['dx']:g} | {r['m']:g} | {r['dx'] * r['m']:.4g} | — | — | — | — | — | — | {r['wall']:.1f} |")


def order(p):
    """Observed order in delta and Richardson value from the last three runs of a path whose delta
    shrinks by one constant ratio r: p = ln(|l1 - l2| / |l2 - l3|) / ln r, l3 + (l3 - l2)/(r^p - 1)."""
    if len(p) < 3 or None in [r["load"] for r in p[-3:]]:
        return "", ""
    d = [r["dx"] * r["m"] for r in p[-3:]]
    r1, r2 = d[0] / d[1], d[1] / d[2]
    if abs(r1 / r2 - 1) > 0.01 or r1 < 1.05:
        return "", ""
    l1, l2, l3 = [r["load"] for r in p[-3:]]
    d1, d2 = l2 - l1, l3 - l2
    if d1 == 0 or d2 == 0 or d1 * d2 < 0 or abs(d2) >= abs(d1):
        return "none (differences %+.1f, %+.1f)" % (d1, d2), ""
    q = math.log(abs(d1) / abs(d2)) / math.log(r1)
    rich = l3 + d2 / (r1 ** q - 1)
    return "%.2f" % q, "%.1f (%s)" % (rich, err(rich))


def paths(res):
    """The paths through the runs of one model and calibration: (name, [runs in refinement order])."""
    key = {(round(r["dx"], 6), round(r["m"], 4)): r for r in res}
    dxs = sorted({k[0] for k in key}, reverse=True)
    ms = sorted({k[1] for k in key})
    out = []
    for m in ms:
        p = [key[(dx, m)] for dx in dxs if (dx, m) in key]
        if len(p) >= 2:
            out.append(("fixed m = %g" % m, p))
    for dx in dxs:
        p = [key[(dx, m)] for m in ms if (dx, m) in key]
        if len(p) >= 2:
            out.append(("fixed Δx = %g, m grows" % dx, p))
    # delta halved while m doubles: dx quartered; and delta ~ dx^(1/2): dx halved, m times sqrt 2
    for name, fdx, fm in (("δ halved, m doubles", 4, 2), ("δ ∝ Δx^½ (m × √2 per halving)", 2, math.sqrt(2))):
        for (dx0, m0) in sorted(key, key=lambda k: (-k[0], k[1])):
            p, dx, m = [], dx0, m0
            while True:
                k = next((k for k in key if abs(k[0] - dx) < 1e-9 and abs(k[1] - m) < 2e-3), None)
                if k is None:
                    break
                p.append(key[k])
                dx, m = dx / fdx, m * fm
            prev = next((k for k in key if abs(k[0] - dx0 * fdx) < 1e-9 and abs(k[1] - m0 / fm) < 2e-3), None)
            if len(p) >= 2 and prev is None:
                out.append((name, p))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spacings", default="0.04,0.02,0.01,0.005")
    ap.add_argument("--m", default="2,3,4,6")
    ap.add_argument("--models", default="npmb")
    ap.add_argument("--calibrations", default="continuum")
    ap.add_argument("--runs", default="", help="extra DX:M pairs")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--save", default="")
    ap.add_argument("--load", default="", help="comma-separated JSON files of earlier results")
    a = ap.parse_args()
    res = []
    for f in filter(None, a.load.split(",")):
        with open(f) as fh:
            res += json.load(fh)
    pairs = [(float(dx), float(m)) for dx in a.spacings.split(",") if dx for m in a.m.split(",") if m]
    pairs += [tuple(float(x) for x in p.split(":")) for p in a.runs.split(",") if p]
    pairs = [p for i, p in enumerate(pairs) if p not in pairs[:i]]
    todo = [(mo, c, dx, m) for mo in a.models.split(",") for c in a.calibrations.split(",") for dx, m in pairs
            if not any(r["model"] == mo and r["calibration"] == c and abs(r["dx"] - dx) < 1e-9 and abs(r["m"] - m) < 1e-9
                       for r in res)]
    print("| model | calibration | Δx | m | δ | particles | bonds | solves | first break (Pa) | critical load (Pa) "
          "| vs LEFM 130.6 | wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in res:
        print(row(r), flush=True)
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as ex:
        for r in ex.map(lambda t: run(*t), todo):
            res.append(r)
            print(row(r), flush=True)
            if a.save:
                with open(a.save, "w") as fh:
                    json.dump(res, fh, indent=1)
    for mo in a.models.split(","):
        for c in a.calibrations.split(","):
            sub = [r for r in res if r["model"] == mo and r["calibration"] == c]
            if not sub:
                continue
            print(f"\n{mo}, {c}:\n")
            print("| path | runs (Δx, m) | δ | critical load (Pa) | vs LEFM | observed order | Richardson |")
            print("|---|---|---|---|---|---|---|")
            for name, p in paths(sub):
                loads = [r["load"] for r in p]
                o, rich = order(p)
                print(f"| {name} | " + " → ".join("(%g, %g)" % (r["dx"], r["m"]) for r in p) + " | "
                      + " → ".join("%.4g" % (r["dx"] * r["m"]) for r in p) + " | "
                      + " → ".join("%.1f" % l if l else "—" for l in loads) + " | "
                      + " → ".join(err(l) for l in loads) + f" | {o} | {rich} |")


if __name__ == "__main__":
    main()
