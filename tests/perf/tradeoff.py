#!/usr/bin/env python3
"""Speed against accuracy: sweeps perilin's settings on four benchmarks that have an exact or a
tabulated reference, and records the error, the time and the memory of every run.

    /usr/bin/python3 tests/perf/tradeoff.py --out docs            # 89 runs, ~10 min on 2 cores

writes docs/tradeoff.csv (one row per run), docs/tradeoff.png (error against seconds, one panel
per benchmark, the Pareto front drawn; needs matplotlib) and the generated blocks of
docs/tradeoff.md (the text between <!-- BEGIN GENERATED: name --> and <!-- END GENERATED: name -->
is replaced, everything else is kept; a missing file is created with the blocks only). The
markdown is also printed. Without --out nothing is written and the markdown is printed.

    --from-csv docs/tradeoff.csv    rebuild the plot and the tables from an earlier sweep, no runs
                                    (the "regenerate" block of tradeoff.md is then left as it is)
    --only a,d                      some benchmarks only (a b c d, see BENCHMARKS)
    --repeat N                      run each setting shorter than 10 s N times and keep the fastest
                                    (default 2: the machine is shared and short runs are noisy)
    --timeout S                     seconds per run before it counts as failed (default 900)
    --dry-run                       print the commands only

Benchmarks (error measure, all from summary.json):
  a  examples/lamina/bending.yaml, mppd, nu = 0.25: error.l2_rel (exact plane elasticity)
  b  examples/lamina/modal.yaml, mppd, nu = 0: |f1 / 1047.2 - 1| (FEM, Diana & Casolo Table 4)
  c  examples/pmb/bar_modes.yaml, npmb: |longitudinal_speed / theory_speed - 1|
  d  examples/pmb/plate_traction.yaml, pmb: |e_xx E / sigma - 1|, e_xx = (u_b - u_a)/(x_b - x_a)
Settings vary one factor at a time around a base (m = 3, the middle spacing, partial volume
linear_continued, surface correction volume (none for npmb), CG + GAMG at rtol 1e-10), plus the
m x spacing grid for a and d (with m = 1 and m = 6 as extremes). Seconds are timing.total_s of
summary.json (problem creation to the end of the analysis; process start-up and output writing
excluded); memory is memory_mb (peak resident set). A run that fails is recorded with perilin's
message. Each row also carries the lattice limit of its setting (what the infinite lattice gives
when dx -> 0 at fixed m, computed here from lattice sums: see lattice_value), against which the
convergence table compares the three-point extrapolation of the runs. The binary is $PERILIN if
set, else build/perilin. Standard library (+ matplotlib for the plot).
"""
import argparse
import csv
import datetime
import errno
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from fractions import Fraction

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PERILIN = os.environ.get("PERILIN", os.path.join(ROOT, "build", "perilin"))

F1_FEM = 1047.2  # Diana & Casolo Table 4, FEM, nu = 0 (flexural I)
PLATE_SIGMA, PLATE_E = 1.0e6, 1.0e9

M_SWEEP = ["2", "3", "3.015", "3.2", "4", "5"]
M_EXTREME = ["1", "6"]
PV = ["none", "linear", "linear_continued"]
SOLVERS = ["gamg:1e-10", "gamg:1e-8", "gamg:1e-6", "gamg:1e-4", "gamg:1e-3", "gamg:1e-2", "mumps"]
BASE_SOLVER = "gamg:1e-10"
REPEAT_BELOW_S = 10  # --repeat applies to runs shorter than this (the noisy ones); longer runs run once

# key: name, scene, fixed options, spacings (coarse, middle, fine), measure, what is varied
BENCHMARKS = {
    "a": dict(name="lamina bending (mppd, ν = 0.25)", short="bending", scene="examples/lamina/bending.yaml",
              opts=["-model_type", "mppd", "-material_nu", "0.25"], dx=["0.01", "1/300", "0.002"],
              quantity="error.l2_rel", static=True, surface=True, grid=True, m_extra=[]),
    "b": dict(name="cantilever lamina f1 (mppd, ν = 0)", short="modal f1", scene="examples/lamina/modal.yaml",
              opts=["-model_type", "mppd", "-material_nu", "0"], dx=["0.01", "0.005", "0.0025"],
              quantity="f1 / 1047.2", static=False, surface=True, grid=False, m_extra=[]),
    "c": dict(name="npmb bar sound speed", short="npmb bar", scene="examples/pmb/bar_modes.yaml",
              opts=["-model_type", "npmb"], dx=["2", "1", "0.5"],
              quantity="c / c_theory", static=False, surface=False, grid=False, m_extra=["2.5"]),
    "d": dict(name="PMB plate traction strain", short="pmb plate", scene="examples/pmb/plate_traction.yaml",
              opts=["-model_type", "pmb"], dx=["0.01", "0.005", "0.0025"],
              quantity="e_xx E / σ", static=True, surface=True, grid=True, m_extra=[]),
}

COLUMNS = ["benchmark", "label", "sweeps", "m", "dx", "partial_volume", "surface", "solver", "status", "message",
           "error", "value", "lattice_value", "particles", "bonds", "dofs", "iterations", "converged_reason",
           "residual_norm", "neighbors_s", "assembly_s", "solve_s", "total_s", "wall_s", "memory_mb", "command"]


# ---------------------------------------------------------------------------------------------
# settings

def base_setting(key):
    b = BENCHMARKS[key]
    return dict(m="3", dx=b["dx"][1], pv="linear_continued", surface="volume" if b["surface"] else "none",
                solver=BASE_SOLVER)


def settings(key):
    """The settings of one benchmark: a list of (setting, set of sweep names), without duplicates."""
    b = BENCHMARKS[key]
    base = base_setting(key)
    out = {}

    def add(sweep, **change):
        s = dict(base, **change)
        k = tuple(sorted(s.items()))
        out.setdefault(k, (s, set()))[1].add(sweep)

    add("base")
    for m in M_SWEEP + b["m_extra"]:
        add("m", m=m)
    for dx in b["dx"]:
        add("dx", dx=dx)
    for pv in PV:
        add("partial volume", pv=pv)
    if b["surface"]:
        add("surface", surface="none")
    if b["static"]:
        for so in SOLVERS:
            add("solver", solver=so)
    if key == "c":  # the scene as written: delta = 2.5 dx, no partial volumes
        add("scene as is", m="2.5", pv="none")
    if b["grid"]:
        for dx in b["dx"]:
            for m in M_SWEEP:
                add("m x dx", m=m, dx=dx)
            for m in M_EXTREME:
                add("extreme m", m=m, dx=dx)
    return list(out.values())


def dx_value(dx):
    return float(Fraction(dx))


def label(key, s):
    base = base_setting(key)
    parts = []
    if s["m"] != base["m"]:
        parts.append("m=%s" % s["m"])
    if s["dx"] != base["dx"]:
        parts.append("Δx=%s" % s["dx"])
    if s["pv"] != base["pv"]:
        parts.append("pv=%s" % s["pv"])
    if s["surface"] != base["surface"]:
        parts.append("surface=%s" % s["surface"])
    if s["solver"] != base["solver"]:
        parts.append(solver_label(s["solver"]))
    return ", ".join(parts) if parts else "base"


def solver_label(so):
    if so == "mumps":
        return "MUMPS Cholesky"
    return "CG+GAMG rtol %s" % so.split(":")[1]


def command(key, s, outdir):
    b = BENCHMARKS[key]
    cmd = [PERILIN, b["scene"]] + b["opts"] + ["-grid_spacing", s["dx"]]
    if key == "c":  # the scene gives horizon.delta; -horizon_m would add a second horizon key
        cmd += ["-horizon_delta", "%.12g" % (float(s["m"]) * dx_value(s["dx"]))]
    else:
        cmd += ["-horizon_m", s["m"]]
    cmd += ["-corrections_partial_volume", s["pv"], "-corrections_surface", s["surface"]]
    if b["static"]:
        if s["solver"] == "mumps":
            cmd += ["-ksp_type", "preonly", "-pc_type", "cholesky", "-pc_factor_mat_solver_type", "mumps"]
        else:
            cmd += ["-ksp_rtol", s["solver"].split(":")[1]]
    return cmd + ["-output_vtk", "false", "-output_dir", outdir]


# ---------------------------------------------------------------------------------------------
# measures

def measure(key, s):
    """(value, error) of one summary, or raises ValueError with the reason."""
    if key == "a":
        v = s["error"]["l2_rel"]
        return v, v
    if key == "b":
        f = s["modal"]["modes"][0]["f_hz"]
        return f / F1_FEM, abs(f / F1_FEM - 1)
    if key == "c":
        md = s["modal"]
        if "longitudinal_speed" not in md:
            raise ValueError("no longitudinal mode among the modes computed")
        r = md["longitudinal_speed"] / md["theory_speed"]
        return r, abs(r - 1)
    pa, pb = s["probes"]["a"], s["probes"]["b"]
    exx = (pb["u"][0] - pa["u"][0]) / (pb["particle_x"][0] - pa["particle_x"][0])
    r = exx * PLATE_E / PLATE_SIGMA
    return r, abs(r - 1)


def alpha(r, d, h, rule):
    """Partial volume of a neighbour at distance r (docs/theory.md)."""
    eps = 1e-10 * d
    if rule == "none":
        return 1.0 if r <= d + eps else 0.0
    if rule == "linear" and r > d + eps:
        return 0.0
    if r >= d + h / 2 - eps:
        return 0.0
    if r <= d - h / 2:
        return 1.0
    return min(1.0, (d + h / 2 - r) / h)


def mppd_lattice(m, nu, pv, surface):
    """(nu_eff, E_eff / E) of the infinite square mppd lattice (plane stress, unit spacing) in
    homogeneous strain (theta = 0), as docs/tools/lamina_tables.py and tests/scenes/test_lamina.c
    compute it, with the partial-volume rule and the surface factor of a bulk particle."""
    c = 6 / (math.pi * m ** 3 * (1 - nu))
    g = 6 * (1 - 3 * nu) / (math.pi * m ** 3 * (1 - nu * nu))
    C = [[0.0] * 3 for _ in range(3)]
    R = int(m) + 2
    vol = 1.0
    for i in range(-R, R + 1):
        for j in range(-R, R + 1):
            if i == j == 0:
                continue
            L = math.hypot(i, j)
            a = alpha(L, m, 1.0, pv)
            if a <= 0:
                continue
            vol += a
            ex, ey = i / L, j / L
            tx, ty = -ey, ex
            bs = (ex * ex, ey * ey, ex * ey)
            bg = (tx * ex, ty * ey, 0.5 * (tx * ey + ty * ex))
            for p in range(3):
                for q in range(3):
                    C[p][q] += 0.5 * a * (c * L * bs[p] * bs[q] + g * L * bg[p] * bg[q])
    lam = math.pi * m * m / vol if surface == "volume" else 1.0
    det = C[0][0] * C[1][1] - C[0][1] * C[1][0]
    return C[0][1] / C[0][0], lam * det / C[0][0]


def bending_l2(nu, nu_eff, e_eff, n=100):
    """error.l2_rel of the elastic bending solution with (E_eff, nu_eff) against the one with (E, nu)
    on the whole square (the interior of src/reference.c when delta -> 0), rigid motion removed."""
    pts = [((i + 0.5) / n * 2 - 1, (j + 0.5) / n * 2 - 1) for i in range(n) for j in range(n)]
    ref = [(x * y, -(x * x + nu * y * y) / 2) for x, y in pts]
    s = 1 / e_eff
    err = [(s * x * y - r[0], -s * (x * x + nu_eff * y * y) / 2 - r[1]) for (x, y), r in zip(pts, ref)]
    mx, my = sum(e[0] for e in err) / len(err), sum(e[1] for e in err) / len(err)
    w = sum(-y * e[0] + x * e[1] for (x, y), e in zip(pts, err)) / sum(x * x + y * y for x, y in pts)
    err = [(e[0] - mx + w * y, e[1] - my - w * x) for (x, y), e in zip(pts, err)]
    return math.sqrt(sum(a * a + b * b for a, b in err) / sum(a * a + b * b for a, b in ref))


def lattice_value(key, m, pv, surface):
    """What the infinite lattice of the setting predicts for the benchmark's quantity when dx -> 0 at
    fixed m (homogeneous strain, long waves):
      a: error.l2_rel of the elastic bending solution with the mppd lattice's E_eff, nu_eff;
      b: f1 / f_exact = sqrt(E_eff / E) (at nu = 0 the mppd lattice is E_eff times the isotropic
         stiffness, so every frequency scales by sqrt(E_eff/E)); the reference is FEM, not exact;
      c: c / c_theory = sqrt(C11 / (K + 4G/3)) of the cubic npmb lattice;
      d: e_xx E / sigma of the plane-stress pmb lattice."""
    if key == "a":
        nu_eff, e_eff = mppd_lattice(float(m), 0.25, pv, surface)
        return bending_l2(0.25, nu_eff, e_eff)
    if key == "b":
        return math.sqrt(mppd_lattice(float(m), 0.0, pv, surface)[1])
    m = float(m)
    R = int(m + 2)
    if key == "c":
        s4 = n = 0.0
        for i in range(-R, R + 1):
            for j in range(-R, R + 1):
                for k in range(-R, R + 1):
                    if i == j == k == 0:
                        continue
                    r = math.sqrt(i * i + j * j + k * k)
                    a = alpha(r, m, 1.0, pv)
                    s4 += a * (i / r) ** 4
                    n += a
        return math.sqrt(5 * s4 / n)  # C11 / (K + 4G/3) = 9 sum a e_x^4 / sum a / (9/5)
    if key == "d":
        c11 = c12 = c22 = 0.0
        vol = 1.0
        for i in range(-R, R + 1):
            for j in range(-R, R + 1):
                if i == j == 0:
                    continue
                r = math.hypot(i, j)
                a = alpha(r, m, 1.0, pv)
                if a == 0:
                    continue
                ex, ey = i / r, j / r
                c11 += a * r * ex ** 4
                c12 += a * r * ex * ex * ey * ey
                c22 += a * r * ey ** 4
                vol += a
        lam = math.pi * m * m / vol if surface == "volume" else 1.0
        k = lam * 9 / (math.pi * m ** 3) / 2
        c11, c12, c22 = c11 * k, c12 * k, c22 * k
        return c22 / (c11 * c22 - c12 * c12)
    return None


# ---------------------------------------------------------------------------------------------
# running

def start(cmd, timeout):
    """Run perilin; while the binary is being relinked (EACCES, ETXTBSY), wait and retry."""
    for attempt in range(60):
        try:
            return subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=timeout)
        except OSError as e:
            if e.errno not in (errno.EACCES, errno.ETXTBSY, errno.ENOENT) or attempt == 59:
                raise
            sys.stderr.write("(binary busy: %s; retrying in 5 s)\n" % e.strerror)
            time.sleep(5)


def binary_id():
    try:
        st = os.stat(PERILIN)
        return "%d-%d" % (st.st_mtime_ns, st.st_size)
    except OSError:
        return None


def run_one(key, s, repeat, timeout):
    row = dict(benchmark=key, m=s["m"], dx=s["dx"], partial_volume=s["pv"], surface=s["surface"], solver=s["solver"])
    best = None
    for _ in range(repeat):
        with tempfile.TemporaryDirectory(prefix="perilin-tradeoff-") as out:
            cmd = command(key, s, out)
            row["command"] = " ".join(["build/perilin" if c == PERILIN else c for c in cmd[:-2]] + ["-output_dir", "TMP"])
            t0 = time.time()
            try:
                res = start(cmd, timeout)
            except subprocess.TimeoutExpired:
                row.update(status="failed", message="timeout after %d s" % timeout, wall_s=time.time() - t0)
                return row
            wall = time.time() - t0
            path = os.path.join(out, "summary.json")
            if res.returncode or not os.path.exists(path):
                msgs = [l for l in (res.stderr + res.stdout).splitlines() if "error" in l.lower()]
                msg = (msgs[0] if msgs else (res.stderr.strip().splitlines() or ["exit %d" % res.returncode])[-1]).strip()
                row.update(status="failed", message=msg, wall_s=wall)
                return row
            with open(path) as f:
                summ = json.load(f)
        if best is None or summ["timing"]["total_s"] < best[0]["timing"]["total_s"]:
            best = (summ, wall)
        if summ["timing"]["total_s"] > REPEAT_BELOW_S:
            break
    summ, wall = best
    try:
        value, err = measure(key, summ)
    except (KeyError, IndexError, ValueError) as e:
        row.update(status="failed", message="no measure: %s" % e, wall_s=wall)
        return row
    t, so = summ["timing"], summ["solver"]
    row.update(status="ok", message="", error=err, value=value, particles=summ["particles"], bonds=summ["bonds"],
               dofs=summ["dofs"], iterations=so["iterations"], converged_reason=so["converged_reason"],
               residual_norm=so["residual_norm"], neighbors_s=t["neighbors_s"], assembly_s=t["assembly_s"],
               solve_s=t["solve_s"], total_s=t["total_s"], wall_s=wall, memory_mb=summ["memory_mb"])
    if key == "b" and summ["modal"]["modes"][0]["kind"] != "flexural":
        row["message"] = "mode 1 is %s" % summ["modal"]["modes"][0]["kind"]
    return row


def sweep(keys, repeat, timeout, dry):
    rows = []
    todo = [(k, s, sw) for k in keys for s, sw in settings(k)]
    t0 = time.time()
    for n, (k, s, sw) in enumerate(todo, 1):
        if dry:
            print(" ".join(command(k, s, "TMP")))
            continue
        row = run_one(k, s, repeat, timeout)
        row["label"] = label(k, s)
        row["sweeps"] = "; ".join(sorted(sw))
        row["lattice_value"] = lattice_value(k, s["m"], s["pv"], s["surface"])
        rows.append(row)
        sys.stderr.write("[%d/%d %5.0f s] %s %-40s %s\n" % (
            n, len(todo), time.time() - t0, k, row["label"],
            "error %.4g  %.2f s  %.0f MB" % (row["error"], row["total_s"], row["memory_mb"]) if row["status"] == "ok"
            else "FAILED: " + row["message"]))
    return rows, time.time() - t0


def read_csv(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            for c in ["error", "value", "lattice_value", "residual_norm", "neighbors_s", "assembly_s", "solve_s", "total_s",
                      "wall_s", "memory_mb"]:
                r[c] = float(r[c]) if r.get(c) not in (None, "") else None
            for c in ["particles", "bonds", "dofs", "iterations"]:
                r[c] = int(r[c]) if r.get(c) not in (None, "") else None
            rows.append(r)
    return rows


def write_csv(rows, path):
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({c: ("%.6g" % r[c]) if isinstance(r.get(c), float) else r.get(c, "") for c in COLUMNS})
    os.replace(path + ".tmp", path)


# ---------------------------------------------------------------------------------------------
# analysis

def pareto(rows):
    """The runs not beaten in both seconds and error by another run, by increasing seconds."""
    ok = sorted([r for r in rows if r["status"] == "ok"], key=lambda r: (r["total_s"], r["error"]))
    front, best = [], float("inf")
    for r in ok:
        if r["error"] < best:
            front.append(r)
            best = r["error"]
    return front


def fit(xs, ys):
    """Least-squares slope of log y against log x, and the local slopes between neighbours."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if y > 0]
    if len(pts) < 2:
        return None, []
    n = len(pts)
    mx, my = sum(p[0] for p in pts) / n, sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    slope = sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx
    local = [(pts[i + 1][1] - pts[i][1]) / (pts[i + 1][0] - pts[i][0]) for i in range(n - 1)]
    return slope, local


def extrapolate(hs, vs):
    """v = v_inf + C h^p through three points (h decreasing): (v_inf, p), or None when the values are
    not monotone or no p in [0.02, 10] fits."""
    (h1, h2, h3), (v1, v2, v3) = hs, vs
    d1, d2 = v1 - v2, v2 - v3
    if d1 * d2 <= 0:
        return None
    r = d1 / d2

    def g(p):
        return (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - r
    lo, hi = 0.02, 10.0
    if g(lo) * g(hi) > 0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    c = d2 / (h2 ** p - h3 ** p)
    return v3 - c * h3 ** p, p


def find(rows, key, **kw):
    for r in rows:
        if r["benchmark"] == key and all(r[k] == v for k, v in kw.items()):
            return r
    return None


def pct(x, digits=2):
    if x is None:
        return "—"
    return ("%." + str(digits) + "f %%") % (100 * x)


def fmt_s(x):
    return "—" if x is None else ("%.3f" % x if x < 1 else "%.2f" % x if x < 10 else "%.1f" % x)


# ---------------------------------------------------------------------------------------------
# markdown

def table_runs(rows, key):
    b = BENCHMARKS[key]
    front = set(id(r) for r in pareto([r for r in rows if r["benchmark"] == key]))
    mine = [r for r in rows if r["benchmark"] == key]
    order = {"base": 0, "m": 1, "dx": 2, "partial volume": 3, "surface": 4, "solver": 5, "scene as is": 6,
             "m x dx": 7, "extreme m": 8}
    mine.sort(key=lambda r: (min(order.get(s, 9) for s in r["sweeps"].split("; ")), dx_value(r["dx"]), float(r["m"]),
                             r["partial_volume"], r["surface"], r["solver"]))
    has_lat = any(r["lattice_value"] is not None for r in mine)
    head = ["setting (vs base)", "sweeps", "error", b["quantity"]] + (["lattice limit"] if has_lat else []) + \
        ["seconds", "memory MB", "particles", "its", "front"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in mine:
        if r["status"] != "ok":
            cells = [r["label"], r["sweeps"], "**failed**", r["message"].replace("|", "\\|")] + (["—"] if has_lat else []) + \
                ["—", "—", "—", "—", ""]
        else:
            val = "%.5f" % r["value"] if key != "a" else pct(r["value"])
            cells = [r["label"], r["sweeps"], pct(r["error"]), val] + \
                ([lattice_cell(key, r["lattice_value"])] if has_lat else []) + \
                [fmt_s(r["total_s"]), "%.0f" % r["memory_mb"], "{:,}".format(r["particles"]), str(r["iterations"]),
                 "★" if id(r) in front else ""]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def lattice_cell(key, v):
    if v is None:
        return "—"
    return pct(v) if key == "a" else "%.5f" % v


def table_grid(rows, key):
    b = BENCHMARKS[key]
    ms = ["1"] + M_SWEEP + ["6"]
    head = ["m \\ Δx"] + ["Δx = %s" % dx for dx in b["dx"]]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for m in ms:
        cells = ["m = %s" % m]
        for dx in b["dx"]:
            r = find(rows, key, m=m, dx=dx, partial_volume="linear_continued", surface=base_setting(key)["surface"],
                     solver=BASE_SOLVER)
            if r is None:
                cells.append("")
            elif r["status"] != "ok":
                cells.append("failed")
            else:
                cells.append("%s (%s s)" % (pct(r["error"]), fmt_s(r["total_s"])))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def orders(rows):
    """Slopes of log(error) against log(dx) at fixed m and against log(m) at fixed dx, the dx -> 0
    limit of the three-point fit, and the lattice's own error where it is computed."""
    lines = ["| benchmark | fixed | varied | errors | fitted order | local orders | Δx → 0 (3-point fit "
             "v = v∞ + C Δxᵖ): limit, error, p | lattice error |", "|---|---|---|---|---|---|---|---|"]
    for key, b in BENCHMARKS.items():
        base = base_setting(key)
        same = dict(partial_volume=base["pv"], surface=base["surface"], solver=BASE_SOLVER)
        ms = (["1"] + M_SWEEP + ["6"]) if b["grid"] else ["3"]
        for m in ms:
            pts = [find(rows, key, m=m, dx=dx, **same) for dx in b["dx"]]
            pts = [r for r in pts if r and r["status"] == "ok"]
            if len(pts) < 2:
                continue
            slope, local = fit([dx_value(r["dx"]) for r in pts], [r["error"] for r in pts])
            ex = extrapolate([dx_value(r["dx"]) for r in pts], [r["value"] for r in pts]) if len(pts) == 3 else None
            if ex is None:
                lim = "not monotone" if len(pts) == 3 else "—"
            elif key == "a":
                lim = "%s, p = %.2f" % (pct(ex[0]), ex[1]) if ex[0] > 0 else "none (the fit's limit is negative)"
            else:
                lim = "%.5f, %s, p = %.2f" % (ex[0], pct(abs(ex[0] - 1)), ex[1])
            lat = lattice_value(key, m, base["pv"], base["surface"])
            lines.append("| %s | m = %s | Δx = %s | %s | %.2f | %s | %s | %s |" % (
                key, m, " → ".join(r["dx"] for r in pts), " → ".join(pct(r["error"]) for r in pts),
                slope, ", ".join("%.2f" % x for x in local), lim, lattice_error(key, lat)))
        dxs = b["dx"] if b["grid"] else [base["dx"]]
        for dx in dxs:
            pts = [find(rows, key, m=m, dx=dx, **same) for m in M_SWEEP + (["6"] if b["grid"] else [])]
            pts = [r for r in pts if r and r["status"] == "ok"]
            if len(pts) < 2:
                continue
            slope, _ = fit([float(r["m"]) for r in pts], [r["error"] for r in pts])
            lats = [lattice_value(key, r["m"], base["pv"], base["surface"]) for r in pts]
            lines.append("| %s | Δx = %s | m = %s | %s | %.2f | — | — | %s |" % (
                key, dx, ", ".join(r["m"] for r in pts), " → ".join(pct(r["error"]) for r in pts), slope,
                " → ".join(lattice_error(key, v) for v in lats)))
    return "\n".join(lines)


def lattice_error(key, v):
    if v is None:
        return "—"
    return pct(v) if key == "a" else pct(abs(v - 1))


def floors():
    """The lattice's own error (infinite lattice, homogeneous strain / long waves) against m."""
    ms = ["1", "1.5", "2", "2.5", "3", "3.015", "3.2", "4", "5", "6", "8", "10"]
    cols = [("c", "linear_continued", "none"), ("c", "linear", "none"), ("c", "none", "none"),
            ("d", "linear_continued", "volume"), ("d", "linear_continued", "none"), ("d", "linear", "volume"),
            ("d", "none", "none")]
    head = ["m"] + ["(%s) %s%s" % (k, pv, ", surface " + sf if k == "d" else "") for k, pv, sf in cols]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for m in ms:
        lines.append("| %s | %s |" % (m, " | ".join("%+.2f %%" % (100 * (lattice_value(k, m, pv, sf) - 1)) for k, pv, sf in cols)))
    return "\n".join(lines)


USES = [("quick look", 0.10), ("design check", 0.03), ("publication-grade", 0.01)]


def recommended(rows):
    """For each use, the fastest run whose error is within the use's tolerance (any setting)."""
    lines = ["| benchmark | use (error ≤) | fastest setting meeting it | error | seconds | memory MB |",
             "|---|---|---|---|---|---|"]
    for key, b in BENCHMARKS.items():
        ok = [r for r in rows if r["benchmark"] == key and r["status"] == "ok"]
        if not ok:
            continue
        for use, tol in USES:
            good = [r for r in ok if r["error"] <= tol]
            if good:
                r = min(good, key=lambda r: r["total_s"])
                lines.append("| %s | %s (%s) | %s | %s | %s | %.0f |" % (
                    key, use, pct(tol, 0), r["label"], pct(r["error"]), fmt_s(r["total_s"]), r["memory_mb"]))
            else:
                r = min(ok, key=lambda r: r["error"])
                lines.append("| %s | %s (%s) | not reached; smallest error: %s | %s | %s | %.0f |" % (
                    key, use, pct(tol, 0), r["label"], pct(r["error"]), fmt_s(r["total_s"]), r["memory_mb"]))
    return "\n".join(lines)


def failures(rows):
    bad = [r for r in rows if r["status"] != "ok" or r["message"]]
    if not bad:
        return "No run failed."
    lines = ["| benchmark | setting | message | command |", "|---|---|---|---|"]
    for r in bad:
        lines.append("| %s | %s | %s | `%s` |" % (r["benchmark"], r["label"], r["message"].replace("|", "\\|"), r["command"]))
    return "\n".join(lines)


def overhead(rows):
    d = sorted(r["wall_s"] - r["total_s"] for r in rows if r["status"] == "ok" and r["wall_s"] is not None)
    if not d:
        return "?", "?", "?"
    return "%.2f" % d[len(d) // 2], "%.2f" % d[0], "%.2f" % d[-1]


def blocks(rows, info):
    out = {}
    if info:  # with --from-csv the block of the sweep that made the CSV is kept
        out["regenerate"] = "\n".join([
            "    /usr/bin/python3 tests/perf/tradeoff.py --out docs",
            "",
            "Last sweep: %s, %d runs (%d failed), %s of runs (sum of the processes' wall clock: %.0f s);"
            " load average at the start %s on %d cores. Binary: `build/perilin`, commit `%s`." % (
                info["date"], len(rows), sum(r["status"] != "ok" for r in rows), info["elapsed"],
                sum(r["wall_s"] or 0 for r in rows), info["load"], os.cpu_count() or 0, info["commit"]),
            "",
            "Seconds below are `timing.total_s`. Each process also spends %s s (median; range %s–%s s) outside it:"
            " MPI/PETSc start-up, output writing and exit." % overhead(rows)])
    for key, b in BENCHMARKS.items():
        if any(r["benchmark"] == key for r in rows):
            base = base_setting(key)
            out["runs_" + key] = "Base: m = 3, Δx = %s, partial volume linear_continued, surface %s, %s. " \
                "Command: `%s`.\n\n%s" % (
                    base["dx"], base["surface"], "CG + GAMG rtol 1e-10" if b["static"] else "modal (shift-invert, "
                    "MUMPS Cholesky)", find(rows, key, label="base")["command"] if find(rows, key, label="base") else "?",
                    table_runs(rows, key))
            if b["grid"]:
                out["grid_" + key] = table_grid(rows, key)
    out["orders"] = orders(rows)
    out["floors"] = floors()
    out["recommended"] = recommended(rows)
    out["failures"] = failures(rows)
    return out


def render(blocks_, path):
    """Replace the generated blocks of an existing file, or write a skeleton."""
    def tag(name, body):
        return "<!-- BEGIN GENERATED: %s -->\n%s\n<!-- END GENERATED: %s -->" % (name, body, name)
    if path and os.path.exists(path):
        with open(path) as f:
            text = f.read()
        for name, body in blocks_.items():
            pat = re.compile(r"<!-- BEGIN GENERATED: %s -->.*?<!-- END GENERATED: %s -->" % (re.escape(name), re.escape(name)), re.S)
            if pat.search(text):
                text = pat.sub(lambda _m: tag(name, body), text)
            else:
                text += "\n" + tag(name, body) + "\n"
        return text
    return "# Speed and accuracy\n\n" + "\n\n".join(tag(n, b) for n, b in blocks_.items()) + "\n"


# ---------------------------------------------------------------------------------------------
# plot

def plot(rows, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.stderr.write("matplotlib missing: no plot (apt-get install python3-matplotlib)\n")
        return False
    styles = {"base": ("k", "*"), "m": ("tab:blue", "o"), "dx": ("tab:green", "s"), "m x dx": ("tab:cyan", "."),
              "extreme m": ("tab:purple", "v"), "partial volume": ("tab:orange", "D"), "surface": ("tab:red", "^"),
              "solver": ("tab:brown", "P"), "scene as is": ("tab:pink", "X")}
    prio = ["base", "solver", "surface", "partial volume", "scene as is", "dx", "m", "extreme m", "m x dx"]
    keys = [k for k in BENCHMARKS if any(r["benchmark"] == k and r["status"] == "ok" for r in rows)]
    fig, axes = plt.subplots(2, 2, figsize=(13, 10.5))
    used = set()
    for ax, key in zip(axes.flat, keys):
        mine = [r for r in rows if r["benchmark"] == key and r["status"] == "ok"]
        for r in mine:
            sw = min(r["sweeps"].split("; "), key=lambda s: prio.index(s) if s in prio else 99)
            c, mk = styles.get(sw, ("gray", "o"))
            ax.scatter(r["total_s"], max(r["error"], 1e-16), c=c, marker=mk, s=70 if mk == "*" else 30, zorder=3,
                       label=sw if sw not in used else None, edgecolors="none")
            used.add(sw)
        front = pareto(mine)
        xs, ys = [], []
        for r in front:
            if xs:
                xs.append(r["total_s"])
                ys.append(ys[-1])
            xs.append(r["total_s"])
            ys.append(r["error"])
        ax.plot(xs, ys, "-", color="0.4", lw=1, zorder=2)
        for i, r in enumerate(front):
            ax.annotate(r["label"], (r["total_s"], r["error"]), fontsize=6.5, xytext=(4, 3 if i % 2 == 0 else -9),
                        textcoords="offset points")
        nfail = sum(r["benchmark"] == key and r["status"] != "ok" for r in rows)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title("(%s) %s — %s%s" % (key, BENCHMARKS[key]["name"], "error = |%s − 1|" % BENCHMARKS[key]["quantity"]
                                         if key != "a" else "error = error.l2_rel",
                                         ", %d failed" % nfail if nfail else ""), fontsize=9)
        ax.set_xlabel("seconds (timing.total_s)")
        ax.set_ylabel("relative error")
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(keys):]:
        ax.axis("off")
    handles, labels = [], []
    for ax in axes.flat:
        h, l = ax.get_legend_handles_labels()
        handles += h
        labels += l
    fig.legend(handles, labels, loc="lower center", ncol=9, fontsize=8, title="varied factor (grey line: Pareto front)")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(path + ".tmp.png", dpi=110)
    os.replace(path + ".tmp.png", path)
    plt.close(fig)
    return True


# ---------------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", help="directory for tradeoff.csv, tradeoff.png and tradeoff.md")
    ap.add_argument("--from-csv", help="no runs: read this CSV of an earlier sweep")
    ap.add_argument("--only", default=",".join(BENCHMARKS), help="benchmarks, e.g. a,d")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--timeout", type=int, default=900, help="seconds per run")
    ap.add_argument("--dry-run", action="store_true")
    a = ap.parse_args()
    keys = [k for k in a.only.split(",") if k]
    for k in keys:
        if k not in BENCHMARKS:
            ap.error("unknown benchmark %s" % k)
    info = {}
    if a.from_csv:
        rows = [r for r in read_csv(a.from_csv) if r["benchmark"] in keys]
    else:
        if not a.dry_run and not os.access(PERILIN, os.X_OK):
            sys.exit("no perilin binary at %s (build it, or set PERILIN)" % PERILIN)
        load = "%.1f" % os.getloadavg()[0]
        started = datetime.datetime.now()
        bin0 = binary_id()
        rows, elapsed = sweep(keys, a.repeat, a.timeout, a.dry_run)
        if a.dry_run:
            return
        if binary_id() != bin0:
            sys.stderr.write("warning: build/perilin changed during the sweep\n")
        try:
            commit = subprocess.run(["git", "log", "-1", "--format=%h"], capture_output=True, text=True, cwd=ROOT).stdout.strip()
            dirty = subprocess.run(["git", "status", "--porcelain", "src", "include", "models"], capture_output=True, text=True,
                                   cwd=ROOT).stdout.strip()
            commit += " (with uncommitted changes in src/, include/ or models/)" if dirty else ""
        except OSError:
            commit = "?"
        if binary_id() != bin0:
            commit += "; **build/perilin was rebuilt during the sweep**"
        info = dict(date=started.strftime("%Y-%m-%d %H:%M"), elapsed="%.1f min" % (elapsed / 60), load=load, commit=commit)
    bl = blocks(rows, info)
    text = render(bl, None)
    print(text)
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        if not a.from_csv:
            write_csv(rows, os.path.join(a.out, "tradeoff.csv"))
        plot(rows, os.path.join(a.out, "tradeoff.png"))
        md = os.path.join(a.out, "tradeoff.md")
        text = render(bl, md)
        with open(md + ".tmp", "w") as f:
            f.write(text)
        os.replace(md + ".tmp", md)


if __name__ == "__main__":
    main()
