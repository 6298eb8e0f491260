#!/usr/bin/env python3
"""The 2D targets of issue 15, item 2, measured for each calibration of the bond constants
(model.calibration: continuum | lattice) on Diana & Casolo's lamina (examples/lamina/*.yaml).

Targets (pass/fail per run; E = 70000 MPa, plane stress):
  traction  pds, mppd, gerstle, nu in {-0.5, 0, 0.1, 0.25, 1/3}, m in {2, 3, 4}:
            |effective.nu - nu| <= 0.01                       (traction.yaml)
  shear     the same runs' shear scene: |effective.G / (E / (2 (1 + nu))) - 1| <= 1.5 %  (shear.yaml)
  bending   mppd, gerstle, m = 3: error.l2_rel <= 3 %         (bending.yaml)
  modal     mppd, gerstle, m = 3: f_I, f_II, f_III within 1.5 % of the converged plane-stress FEM
            at the scene's spacing (modal.yaml, dx = 10 mm), and |error| decreasing when dx is
            halved (--modal-levels 3: and quartered) at fixed m; the observed orders are printed.
The modes are picked as in docs/modal.md (first flexural, first axial, second flexural); the FEM
frequencies are the converged Q9 values of docs/modal.md (docs/tools/lamina_fem.py), or, with
--fem, recomputed here by lamina_fem.py (needs numpy/scipy: run with Debian's /usr/bin/python3).

Each run is, from the repository root,
    build/perilin examples/lamina/SCENE.yaml -model_type M -material_nu NU -horizon_m m
        -grid_spacing DX [-model_calibration C] -output_dir TMP
(and -corrections_surface volume with continuum, the paper's setting; none with lattice, which
corrects surfaces itself)
reading TMP/summary.json; TMP lives in a temporary directory removed at the end. When the binary
does not know model.calibration (perilin -help), continuum runs omit the option and lattice runs
are refused: use --calibrations continuum.

    python3 docs/tools/lattice_targets.py                          # markdown report to stdout
    python3 docs/tools/lattice_targets.py REPORT.md                # to a file (written atomically)
    python3 docs/tools/lattice_targets.py --calibrations continuum # one calibration only
    python3 docs/tools/lattice_targets.py --modal-levels 3         # also dx/4 (+3 min)
    python3 docs/tools/lattice_targets.py --check                  # exit 1 if a lattice target fails

Standard library only (except --fem). The binary is $PERILIN if set, else build/perilin. Runs go
two at a time (--jobs): both calibrations take about 3 minutes on 2 cores (240 runs); each modal
run at dx/4 takes ~20 s and 2 GB, so --modal-levels 3 adds about 1.5 minutes per calibration.
"""
import argparse
import collections
import concurrent.futures
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from fractions import Fraction

from common import write_atomically

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PERILIN = os.environ.get("PERILIN", os.path.join(ROOT, "build", "perilin"))
CALIBRATIONS = ["continuum", "lattice"]
MODELS = ["pds", "mppd", "gerstle"]
MICROPOLAR = ["mppd", "gerstle"]
NUS = ["-0.5", "0", "0.1", "0.25", "1/3"]
MS = ["2", "3", "4"]
SPACINGS = ["0.01", "0.005", "0.0025"]  # the modal scene's dx, then halved at fixed m = 3
E = 7.0e10  # Pa, as in the scenes
TOL_NU, TOL_G, TOL_BENDING, TOL_FREQ = 0.01, 0.015, 0.03, 0.015
MODES = [("I", "flexural", 0), ("II", "axial", 0), ("III", "flexural", 1)]
# The converged plane-stress FEM (Hz) of the cantilever (docs/modal.md, "Against the converged
# FEM"; docs/tools/lamina_fem.py, Q9 elements refined until the changes are below 1e-5).
FEM = {
    "I": {"-0.5": 1194.53, "0": 1047.11, "0.1": 1027.78, "0.25": 1002.28, "1/3": 989.61},
    "II": {"-0.5": 2399.91, "0": 2320.83, "0.1": 2322.61, "0.25": 2330.32, "1/3": 2336.15},
    "III": {"-0.5": 3244.57, "0": 2771.45, "0.1": 2712.31, "0.25": 2636.22, "1/3": 2599.35},
}
PASS, FAIL = "✓", "✗"

Run = collections.namedtuple("Run", "calibration scene model nu m spacing")


# ---------------------------------------------------------------- the runs

def planned_runs(calibrations, levels):
    """Every run the targets need, the most expensive first (for the worker pool)."""
    runs = []
    for c in calibrations:
        for model in MODELS:
            for nu in NUS:
                for m in MS:
                    runs += [Run(c, "traction", model, nu, m, None), Run(c, "shear", model, nu, m, None)]
                if model in MICROPOLAR:
                    runs.append(Run(c, "bending", model, nu, "3", None))
                    runs += [Run(c, "modal", model, nu, "3", s) for s in SPACINGS[:levels]]
    cost = lambda r: (r.spacing is not None and 0.01 / float(r.spacing)) or 0
    return sorted(runs, key=cost, reverse=True)


def knows_calibration():
    """Whether this perilin has the scene key model.calibration."""
    proc = subprocess.run([PERILIN, os.path.join(ROOT, "examples", "lamina", "traction.yaml"), "-help"],
                          cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    return any(line.split()[:1] == ["model.calibration"] for line in proc.stdout.splitlines())


def command(run, out, explicit):
    args = [PERILIN, os.path.join("examples", "lamina", run.scene + ".yaml"), "-model_type", run.model,
            "-material_nu", run.nu, "-horizon_m", run.m, "-output_dir", out]
    if run.spacing is not None:
        args += ["-grid_spacing", run.spacing]
    if explicit:
        args += ["-model_calibration", run.calibration]
    # continuum: the paper's setting, with the volume surface correction; lattice corrects surfaces
    # itself (perilin refuses both at once)
    args += ["-corrections_surface", "none" if run.calibration == "lattice" else "volume"]
    return args


def perform(run, tmp, explicit):
    """(summary dict or None, perilin's notes and warnings, error text or None)."""
    out = tempfile.mkdtemp(prefix="run_", dir=tmp)
    env = dict(os.environ)
    env.setdefault("OPENBLAS_NUM_THREADS", "1")  # two runs share the two cores
    env.setdefault("OMP_NUM_THREADS", "1")
    try:
        proc = subprocess.run(command(run, out, explicit), cwd=ROOT, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True)
        lines = proc.stdout.splitlines()
        notes = [l for l in lines if l.startswith(("perilin: note:", "perilin: warning:"))]
        if proc.returncode != 0:
            errors = [l for l in lines if l.startswith("perilin: error:")] or lines[-3:]
            return None, notes, "exit %d: %s" % (proc.returncode, " ".join(errors))
        with open(os.path.join(out, "summary.json")) as f:
            return json.load(f), notes, None
    finally:
        shutil.rmtree(out, ignore_errors=True)


def run_all(runs, jobs, explicit):
    """{run: summary or None}, {message: [run labels]}, {run: error}."""
    results, notes, errors = {}, collections.defaultdict(list), {}
    tmp = tempfile.mkdtemp(prefix="lattice_targets_")
    try:
        with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
            futures = {pool.submit(perform, r, tmp, explicit): r for r in runs}
            for fut in concurrent.futures.as_completed(futures):
                r = futures[fut]
                results[r], msgs, err = fut.result()
                for msg in msgs:
                    notes[msg].append(label(r))
                if err:
                    errors[r] = err
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return results, notes, errors


def label(r):
    extra = " dx %s" % r.spacing if r.spacing else (" m %s" % r.m if r.m != "3" else "")
    return "%s/%s/%s/%s%s" % (r.calibration, r.scene, r.model, r.nu, extra)


# ---------------------------------------------------------------- the FEM reference

def fem_reference():
    """Recompute FEM with docs/tools/lamina_fem.py (numpy, scipy), refining as its main() does."""
    sys.path.insert(0, os.path.join(ROOT, "docs", "tools"))
    import lamina_fem
    ref = {name: {} for name, _, _ in MODES}
    for nu in NUS:
        prev = None
        for ex in (10, 20, 40, 80):
            f3 = lamina_fem.three(*lamina_fem.frequencies(ex, round(ex * lamina_fem.H / lamina_fem.W),
                                                         float(Fraction(nu))))
            if prev is not None and max(abs(f3 / prev - 1)) < 1e-5:
                break
            prev = f3
        for (name, _, _), f in zip(MODES, f3):
            ref[name][nu] = float(f)
    return ref


# ---------------------------------------------------------------- measures

def fraction(nu):
    return float(Fraction(nu))


def G_target(nu):
    return E / (2 * (1 + fraction(nu)))


def measure_nu(s, nu):
    value = s["effective"]["nu"]
    return value, abs(value - fraction(nu)) <= TOL_NU


def measure_G(s, nu):
    err = s["effective"]["G"] / G_target(nu) - 1
    return err, abs(err) <= TOL_G


def measure_bending(s, nu):
    err = s["error"]["l2_rel"]
    return err, err <= TOL_BENDING


def frequency(s, kind, index):
    found = [mode["f_hz"] for mode in s["modal"]["modes"] if mode["kind"] == kind]
    return found[index] if index < len(found) else None


def modal_errors(s, nu, fem):
    """[relative error of f_I, f_II, f_III against the FEM] (None where no such mode)."""
    out = []
    for name, kind, index in MODES:
        f = frequency(s, kind, index)
        out.append(None if f is None else f / fem[name][nu] - 1)
    return out


def order(a, b, ratio=2.0):
    """log_ratio(|a| / |b|): the observed order of a quantity going from a to b."""
    if a is None or b is None or a == 0 or b == 0:
        return None
    return math.log(abs(a) / abs(b)) / math.log(ratio)


# ---------------------------------------------------------------- formatting

def mark(ok):
    return PASS if ok else FAIL


def pct(x, digits=2):
    return "—" if x is None else "%+.*f %%" % (digits, 100 * x)


def fmt_order(p):
    return "—" if p is None else "%.1f" % p


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(row) + " |" for row in rows]
    return out


class Report:
    """The measured values, each target's cells and pass/fail tally."""

    def __init__(self, res, errors, calibrations, levels, fem):
        self.res, self.errors, self.cals, self.levels, self.fem = res, errors, calibrations, levels, fem
        self.tally = collections.defaultdict(lambda: [0, 0])  # (target, calibration) -> [passed, total]
        self.failures = collections.defaultdict(list)          # calibration -> failing cells

    def summary(self, cal, scene, model, nu, m="3", spacing=None):
        return self.res.get(Run(cal, scene, model, nu, m, spacing))

    def count(self, target, cal, ok, what):
        t = self.tally[(target, cal)]
        t[0] += bool(ok)
        t[1] += 1
        if not ok:
            self.failures[cal].append("%s: %s" % (target, what))

    def cell(self, target, cal, scene, model, nu, m, measure, show):
        s = self.summary(cal, scene, model, nu, m)
        what = "%s ν = %s m = %s" % (model, nu, m)
        if s is None:
            self.count(target, cal, False, what + " (run failed)")
            return "run failed " + FAIL
        value, ok = measure(s, nu)
        self.count(target, cal, ok, what)
        return "%s %s" % (show(value), mark(ok))


# ---------------------------------------------------------------- the tables

def static_tables(rep, lines):
    A = lines.extend
    cals = rep.cals
    specs = [
        ("traction", "Effective ν (traction, m = 3): |ν_eff − ν| ≤ %.2f" % TOL_NU, "traction", MODELS,
         measure_nu, lambda v: "%.3f" % v),
        ("shear", "Effective G (shear, m = 3): |G_eff / G − 1| ≤ %.1f %%" % (100 * TOL_G), "shear", MODELS,
         measure_G, pct),
        ("bending", "Bending: error.l2_rel ≤ %.0f %% (m = 3)" % (100 * TOL_BENDING), "bending", MICROPOLAR,
         measure_bending, lambda v: "%.2f %%" % (100 * v)),
    ]
    for target, title, scene, models, measure, show in specs:
        rows = [[model, nu] + [rep.cell(target, c, scene, model, nu, "3", measure, show) for c in cals]
                for model in models for nu in NUS]
        A(["## %s" % title, ""] + table(["model", "ν"] + cals, rows) + [""])
    # the m sweep: both measures at every m (m = 3 repeats the rows above)
    rows = []
    for model in MODELS:
        for nu in NUS:
            for m in MS:
                cells = []
                for c in cals:
                    a = rep.cell("m sweep ν", c, "traction", model, nu, m, measure_nu, lambda v: "ν %.3f" % v)
                    b = rep.cell("m sweep G", c, "shear", model, nu, m, measure_G, lambda v: "G " + pct(v))
                    cells.append(a + ", " + b)
                rows.append([model, nu, m] + cells)
    A(["## Traction and shear at m ∈ {2, 3, 4}: ν_eff within %.2f, G_eff within %.1f %%" % (TOL_NU, 100 * TOL_G), ""]
      + table(["model", "ν", "m"] + cals, rows) + [""])


# The exact isotropic continuum on the same scenes, loaded and measured as perilin does (Δx = 10 mm,
# m = 3; docs/tools/lamina_static_fem.py, an independent Q9 FEM): E_eff/E - 1, nu_eff, G_eff/G - 1,
# bending l2_rel. The scenes' δ-deep loaded layers bias every exact material this much.
SCENE_FEM = {"-0.5": (0.011187, -0.48546, -0.06947, 0.0143), "0": (0.0, 0.0, -0.06172, 0.0),
             "0.1": (-0.001611, 0.09732, -0.06101, 0.00252), "0.25": (-0.003645, 0.24370, -0.06016, 0.00612),
             "1/3": (-0.004579, 0.32530, -0.05977, 0.00804)}


def scene_fem_table(rep, lines):
    """Each calibration's distance to the exact continuum of the same scene."""
    rows = []
    for model in MODELS:
        for nu in NUS:
            fe, fnu, fg, fb = SCENE_FEM[nu]
            cells = []
            for c in rep.cals:
                t, sh, b = (rep.summary(c, sc, model, nu) for sc in ("traction", "shear", "bending"))
                if t is None or sh is None:
                    cells.append("run failed")
                    continue
                cell = "ν %+.4f, E %s, G %s" % (t["effective"]["nu"] - fnu, pct(t["effective"]["E"] / E - 1 - fe),
                                                  pct(sh["effective"]["G"] / (E / (2 * (1 + fraction(nu)))) - 1 - fg))
                if model in MICROPOLAR and b is not None:
                    cell += ", bending %+.2f pp" % (100 * (b["error"]["l2_rel"] - fb))
                cells.append(cell)
            rows.append([model, nu] + cells)
    lines.extend(["## Against the exact continuum of the same scene (Δx = 10 mm, m = 3)", "",
                  "PD minus an exact isotropic continuum loaded and measured as these scenes are "
                  "(`docs/tools/lamina_static_fem.py`): the scenes' δ-deep loaded layers give an exact material "
                  "G_eff 6.0–6.9 % below G, ν_eff −0.4855 at ν = −0.5 and bending l2 0.0–1.4 %. pds is not rotation "
                  "invariant, so its shear (a pinned rotation stores energy) and bending are its own.", ""]
                 + table(["model", "ν"] + rep.cals, rows) + [""])


def modal_cell(rep, cal, model, nu, i):
    """(the text of the convergence cell of mode i, ok)."""
    errs = []
    for spacing in SPACINGS[:rep.levels]:
        s = rep.summary(cal, "modal", model, nu, "3", spacing)
        errs.append(None if s is None else modal_errors(s, nu, rep.fem)[i])
    if any(e is None for e in errs):
        return "run failed or mode missing " + FAIL, False
    ok = all(abs(b) < abs(a) for a, b in zip(errs, errs[1:]))
    orders = [order(a, b) for a, b in zip(errs, errs[1:])]
    text = " → ".join(pct(e) for e in errs) + " (p " + ", ".join(fmt_order(p) for p in orders)
    if len(errs) == 3:
        f = [rep.fem[MODES[i][0]][nu] * (1 + e) for e in errs]
        text += "; self q %s" % fmt_order(order(f[0] - f[1], f[1] - f[2]))
    return text + ") " + mark(ok), ok


def modal_tables(rep, lines):
    A = lines.extend
    cals = rep.cals
    rows = []
    for model in MICROPOLAR:
        for nu in NUS:
            cells = []
            for c in cals:
                s = rep.summary(c, "modal", model, nu, "3", SPACINGS[0])
                errs = [None] * 3 if s is None else modal_errors(s, nu, rep.fem)
                parts = []
                for (name, _, _), e in zip(MODES, errs):
                    ok = e is not None and abs(e) <= TOL_FREQ
                    rep.count("modal", c, ok, "%s ν = %s f_%s" % (model, nu, name))
                    parts.append("%s %s" % (pct(e), mark(ok)))
                cells.append(" / ".join(parts))
            rows.append([model, nu] + cells)
    A(["## Modal: f_I / f_II / f_III against the converged FEM at Δx = %s m, m = 3: within %.1f %%"
       % (SPACINGS[0], 100 * TOL_FREQ), ""] + table(["model", "ν"] + cals, rows) + [""])
    rows = []
    for model in MICROPOLAR:
        for nu in NUS:
            for i, (name, _, _) in enumerate(MODES):
                cells = []
                for c in cals:
                    text, ok = modal_cell(rep, c, model, nu, i)
                    rep.count("modal convergence", c, ok, "%s ν = %s f_%s" % (model, nu, name))
                    cells.append(text)
                rows.append([model, nu, "f_" + name] + cells)
    A(["## Modal convergence at fixed m = 3: error at Δx = %s m, |error| decreasing"
       % " → ".join(SPACINGS[:rep.levels]), ""]
      + ["p = log₂(|e(Δx)| / |e(Δx/2)|), the observed order of the error against the FEM for each halving"
         " (negative: the error grows)." + (" self q = log₂(|f(Δx) − f(Δx/2)| / |f(Δx/2) − f(Δx/4)|), the"
         " order at which the frequencies themselves settle, whatever their limit." if rep.levels == 3 else ""),
         ""]
      + table(["model", "ν", "mode"] + cals, rows) + [""])


def worst_over_m(rep, cal, scene, model, nu, deviation):
    """The largest |deviation(summary, nu)| over m in MS (None when no run succeeded)."""
    values = [abs(deviation(s, nu)) for s in (rep.summary(cal, scene, model, nu, m) for m in MS) if s]
    return max(values) if values else None


def nu_deviation(s, nu):
    return s["effective"]["nu"] - fraction(nu)


def G_deviation(s, nu):
    return measure_G(s, nu)[0]


def worst_modal(s, nu, fem):
    errs = [e for e in modal_errors(s, nu, fem) if e is not None]
    return "%.2f %%" % (100 * max(abs(e) for e in errs)) if len(errs) == 3 else "mode missing"


def before_after_row(rep, model, nu):
    def across(fn, *key):
        values = []
        for c in rep.cals:
            s = rep.summary(c, *key)
            values.append("—" if s is None else fn(s))
        return " → ".join(values)

    def worst(scene, deviation, show):
        return " → ".join(show(worst_over_m(rep, c, scene, model, nu, deviation)) for c in rep.cals)

    row = [model, nu,
           across(lambda s: "%.3f" % s["effective"]["nu"], "traction", model, nu),
           across(lambda s: pct(G_deviation(s, nu), 1), "shear", model, nu),
           worst("traction", nu_deviation, lambda v: "—" if v is None else "%.3f" % v),
           worst("shear", G_deviation, lambda v: "—" if v is None else "%.1f %%" % (100 * v))]
    if model not in MICROPOLAR:
        return row + ["—", "—"]
    return row + [across(lambda s: "%.1f %%" % (100 * s["error"]["l2_rel"]), "bending", model, nu),
                  across(lambda s: worst_modal(s, nu, rep.fem), "modal", model, nu, "3", SPACINGS[0])]


def before_after(rep, lines):
    """continuum → lattice for every model and ν: the headline number of each target."""
    rows = [before_after_row(rep, model, nu) for model in MODELS for nu in NUS]
    lines.extend(["## Before / after: %s" % " → ".join(rep.cals), ""]
                 + table(["model", "ν", "ν_eff (m = 3)", "G_eff / G − 1 (m = 3)", "max \\|ν_eff − ν\\| (m = 2–4)",
                          "max \\|G_eff / G − 1\\| (m = 2–4)", "bending l2_rel", "max \\|f / f_FEM − 1\\| (Δx = 10 mm)"],
                         rows) + [""])


def tally_table(rep, lines):
    targets = ["traction", "shear", "bending", "modal", "modal convergence", "m sweep ν", "m sweep G"]
    rows = [[t] + ["%d / %d" % tuple(rep.tally[(t, c)]) for c in rep.cals] for t in targets]
    lines.extend(["## Passed / measured", ""] + table(["target"] + rep.cals, rows) + [""])


def document(rep, notes, meta):
    lines = ["# Issue 15, item 2: the 2D targets per calibration", "",
             "Generated by `python3 docs/tools/lattice_targets.py` (%s)." % meta, "",
             "Lamina scenes `examples/lamina/{traction,shear,bending,modal}.yaml` (E = 70000 MPa, plane stress,"
             " Δx = 10 mm, m = 3 unless stated); each cell is one run's `summary.json` and ✓/✗ against the target"
             " in the table's title. Modal errors are against the converged plane-stress FEM (docs/modal.md).", ""]
    body = []
    static_tables(rep, body)
    scene_fem_table(rep, body)
    modal_tables(rep, body)
    before_after(rep, body)
    tally_table(rep, lines)
    lines += body
    if rep.errors:
        lines += ["## Failed runs", ""] + ["- %s: %s" % (label(r), e) for r, e in sorted(rep.errors.items())] + [""]
    if notes:
        lines += ["## Messages printed by perilin", ""]
        for msg, runs in sorted(notes.items()):
            lines.append("- `%s` (%d runs: %s)" % (msg, len(runs), ", ".join(sorted(runs))))
        lines.append("")
    return "\n".join(lines)


# ---------------------------------------------------------------- main

def arguments():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("output", nargs="?", help="write the markdown report here (atomically) instead of stdout")
    p.add_argument("--calibrations", default=",".join(CALIBRATIONS),
                   help="comma-separated subset of continuum,lattice (default both)")
    p.add_argument("--modal-levels", type=int, default=2, choices=[2, 3],
                   help="modal spacings: 2 = dx, dx/2 (default); 3 = also dx/4 (~20 s, 2 GB per run)")
    p.add_argument("--jobs", type=int, default=2, help="runs at a time (default 2)")
    p.add_argument("--fem", action="store_true", help="recompute the FEM frequencies (numpy, scipy)")
    p.add_argument("--check", action="store_true", help="exit 1 if any lattice target fails")
    a = p.parse_args()
    a.calibrations = [c.strip() for c in a.calibrations.split(",") if c.strip()]
    bad = [c for c in a.calibrations if c not in CALIBRATIONS]
    if bad or not a.calibrations:
        p.error("unknown calibration(s) %s: choose from %s" % (bad, CALIBRATIONS))
    if a.check and "lattice" not in a.calibrations:
        p.error("--check judges the lattice calibration: include it in --calibrations")
    return a


def main():
    a = arguments()
    start = time.time()
    explicit = knows_calibration()
    if not explicit and a.calibrations != ["continuum"]:
        sys.exit("lattice_targets: %s has no scene key model.calibration (perilin -help): "
                 "run with --calibrations continuum" % PERILIN)
    fem = fem_reference() if a.fem else FEM
    runs = planned_runs(a.calibrations, a.modal_levels)
    res, notes, errors = run_all(runs, a.jobs, explicit)
    meta = "%d runs, %.0f s wall with %d jobs; FEM %s; %s" % (
        len(runs), time.time() - start, a.jobs, "recomputed (--fem)" if a.fem else "as in docs/modal.md",
        "-model_calibration passed" if explicit else "binary without model.calibration: continuum = its default")
    rep = Report(res, errors, a.calibrations, a.modal_levels, fem)
    text = document(rep, notes, meta)
    if a.output:
        write_atomically(a.output, text)
    else:
        sys.stdout.write(text)
    print("lattice_targets: %s" % meta, file=sys.stderr)
    if a.check and rep.failures["lattice"]:
        print("lattice_targets: %d lattice target(s) fail, e.g. %s"
              % (len(rep.failures["lattice"]), "; ".join(rep.failures["lattice"][:5])), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
