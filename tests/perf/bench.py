#!/usr/bin/env python3
"""perilin's benchmark harness: runs scene families at growing sizes on 1 and 2 ranks and writes one
row per run (from summary.json) to a CSV file and a markdown table. Timings are measurements, not
tests: nothing here passes or fails.

    python3 tests/perf/bench.py [--max-particles N] [--ranks 1,2] [--out DIR] [--baseline]

--baseline adds the peer baseline: the same 2D PMB plate assembled with scipy.sparse and solved
with scipy's direct solver and with CG (what a user writes without perilin; needs python3-scipy),
timed in the same run, with perilin/baseline ratios.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PERILIN = os.path.join(ROOT, "build", "perilin")

# family -> (scene, [(spacing, approximate particles)], extra options)
FAMILIES = {
    "plate_pmb_2d_m2": ("examples/bench/plate_2d.yaml", [("1/100", 1e4), ("1/200", 4e4), ("1/401", 160801), ("1/700", 4.9e5), ("1/1000", 1e6)], []),
    "plate_pmb_2d_m4": ("examples/bench/plate_2d.yaml", [("1/100", 1e4), ("1/201", 40401), ("1/400", 1.6e5)], ["-horizon_m", "4"]),
    "lamina_gerstle_2d": ("examples/bench/lamina_2d.yaml", [("1/101", 10201), ("1/200", 4e4), ("1/400", 1.6e5), ("1/700", 4.9e5)], []),
    "block_npmb_3d": ("examples/bench/block_3d.yaml", [("1/22", 10648), ("1/30", 27000), ("1/40", 64000)], []),
}

COLUMNS = ["family", "ranks", "particles", "bonds", "dofs", "neighbors_s", "assembly_s", "solve_s", "total_s", "iterations",
           "memory_mb", "bonds_per_s", "solve_s_per_mdof", "wall_s"]


def run_perilin(scene, spacing, extra, ranks):
    with tempfile.TemporaryDirectory() as out:
        cmd = [PERILIN, os.path.join(ROOT, scene), "-grid_spacing", spacing, "-output_dir", out] + extra
        if ranks > 1:
            env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
            cmd = ["mpiexec", "--oversubscribe", "-n", str(ranks)] + cmd
        else:
            env = os.environ
        t0 = time.time()
        res = subprocess.run(cmd, capture_output=True, text=True, env=env)
        wall = time.time() - t0
        if res.returncode:
            sys.stderr.write("failed: %s\n%s" % (" ".join(cmd), res.stderr[-2000:]))
            return None
        with open(os.path.join(out, "summary.json")) as f:
            s = json.load(f)
    t = s["timing"]
    return {
        "ranks": ranks, "particles": s["particles"], "bonds": s["bonds"], "dofs": s["dofs"],
        "neighbors_s": t["neighbors_s"], "assembly_s": t["assembly_s"], "solve_s": t["solve_s"], "total_s": t["total_s"],
        "iterations": s["solver"]["iterations"], "memory_mb": s["memory_mb"],
        "bonds_per_s": s["bonds"] / max(t["assembly_s"], 1e-9), "solve_s_per_mdof": t["solve_s"] / (s["dofs"] / 1e6), "wall_s": wall,
    }


def baseline(n_side, m=2.0):
    """The plate of examples/bench/plate_2d.yaml written the way a user would without perilin:
    scipy.spatial.cKDTree for the bonds, a COO assembly of the PMB bond blocks, the same BCs."""
    import numpy as np
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    from scipy.spatial import cKDTree
    E, t, h = 1e9, 0.01, 1.0 / n_side
    delta = m * h
    x = (np.stack(np.meshgrid(np.arange(n_side), np.arange(n_side), indexing="xy"), -1).reshape(-1, 2) + 0.5) * h
    n = len(x)
    t0 = time.time()
    pairs = cKDTree(x).query_pairs(delta + h / 2, output_type="ndarray")
    xi = x[pairs[:, 1]] - x[pairs[:, 0]]
    L = np.linalg.norm(xi, axis=1)
    alpha = np.clip((delta + h / 2 - L) / h, 0, 1)
    keep = alpha > 0
    pairs, xi, L, alpha = pairs[keep], xi[keep], L[keep], alpha[keep]
    t1 = time.time()
    c = 9 * E / (np.pi * t * delta ** 3)
    V = h * h * t
    k = c * V * V * alpha / L
    e = xi / L[:, None]
    rows, cols, vals = [], [], []
    i0, j0 = 2 * pairs[:, 0], 2 * pairs[:, 1]
    for a in range(2):
        for b in range(2):
            kv = k * e[:, a] * e[:, b]
            rows += [i0 + a, j0 + a, i0 + a, j0 + a]
            cols += [i0 + b, j0 + b, j0 + b, i0 + b]
            vals += [kv, kv, -kv, -kv]
    K = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(2 * n, 2 * n)).tocsr()
    f = np.zeros(2 * n)
    right = x[:, 0] > 1 - delta - 1e-12
    f[2 * np.where(right)[0]] = 1e6 * t * 1.0 / right.sum()
    free = np.ones(2 * n, bool)
    left = np.where(x[:, 0] < delta + 1e-12)[0]
    free[2 * left] = free[2 * left + 1] = False
    Kf = K[free][:, free].tocsc()
    t2 = time.time()
    out = {"neighbors_s": t1 - t0, "assembly_s": t2 - t1, "particles": n, "bonds": len(L)}
    t3 = time.time()
    spla.spsolve(Kf, f[free])
    out["direct_s"] = time.time() - t3
    t4 = time.time()
    _, info = spla.cg(Kf.tocsr(), f[free], maxiter=200000, **({"rtol": 1e-10} if "rtol" in spla.cg.__code__.co_varnames else {"tol": 1e-10}))
    out["cg_s"] = time.time() - t4
    out["cg_converged"] = info == 0
    return out


def markdown(rows, cols):
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        lines.append("| " + " | ".join(("%.3g" % r[c]) if isinstance(r.get(c), float) else str(r.get(c, "")) for c in cols) + " |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--max-particles", type=float, default=2e5)
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--families", default=",".join(FAMILIES))
    ap.add_argument("--out", default=None, help="directory for bench.csv and bench.md (default: print only)")
    ap.add_argument("--baseline", action="store_true")
    a = ap.parse_args()
    rows = []
    for fam in a.families.split(","):
        scene, sizes, extra = FAMILIES[fam]
        for spacing, approx in sizes:
            if approx > a.max_particles:
                continue
            for r in [int(x) for x in a.ranks.split(",")]:
                row = run_perilin(scene, spacing, extra, r)
                if row:
                    row["family"] = fam
                    rows.append(row)
                    sys.stderr.write("%s ranks=%d particles=%d solve=%.3fs\n" % (fam, r, row["particles"], row["solve_s"]))
    text = "## perilin\n\n" + markdown(rows, COLUMNS) + "\n"
    if a.baseline:
        brows = []
        for n_side, spacing in [(100, "1/100"), (200, "1/200"), (401, "1/401")]:
            if n_side * n_side > a.max_particles:
                continue
            b = baseline(n_side)
            p = run_perilin(FAMILIES["plate_pmb_2d_m2"][0], spacing, [], 1)
            b["perilin_solve_s"] = p["solve_s"]
            b["perilin_assembly_s"] = p["assembly_s"]
            b["direct/perilin"] = b["direct_s"] / p["solve_s"]
            b["cg/perilin"] = b["cg_s"] / p["solve_s"]
            brows.append(b)
            sys.stderr.write("baseline n=%d direct=%.2fs cg=%.2fs perilin=%.2fs\n" % (b["particles"], b["direct_s"], b["cg_s"], p["solve_s"]))
        text += "\n## Peer baseline (scipy), same 2D PMB plate, m = 2\n\n" + markdown(brows, ["particles", "bonds", "neighbors_s", "assembly_s", "direct_s", "cg_s", "cg_converged", "perilin_assembly_s", "perilin_solve_s", "direct/perilin", "cg/perilin"]) + "\n"
    print(text)
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        with open(os.path.join(a.out, "bench.csv.tmp"), "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=COLUMNS)
            w.writeheader()
            for r in rows:
                w.writerow({c: r.get(c) for c in COLUMNS})
        os.replace(os.path.join(a.out, "bench.csv.tmp"), os.path.join(a.out, "bench.csv"))
        with open(os.path.join(a.out, "bench.md.tmp"), "w") as f:
            f.write(text)
        os.replace(os.path.join(a.out, "bench.md.tmp"), os.path.join(a.out, "bench.md"))


if __name__ == "__main__":
    main()
