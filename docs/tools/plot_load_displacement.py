#!/usr/bin/env python3
"""Plot the load-displacement curve of a quasi-static run from its steps.csv (docs/reactions.md).

    python3 docs/tools/plot_load_displacement.py OUTDIR [-o PNG]

Reads OUTDIR/steps.csv (control_u: the control probe's displacement along
analysis.control_component; the force: applied_load under load control, lambda times the applied
load along that component, or reaction under displacement control, the reaction of
analysis.reaction_region along it) and the names from OUTDIR/summary.json (quasistatic.force_column
says which), and writes OUTDIR/load_displacement.png (or PNG). The axes are in the scene's own
consistent units (perilin has no unit system). Needs matplotlib (Debian: python3-matplotlib).
A run draws the same picture itself (output.plots, src/output/draw_plots.py, whose drawing this
script shares): this script redraws it from a finished output set, e.g. after -output_plots false."""
import argparse
import csv
import json
import os
import sys

ME = "plot_load_displacement.py"


def fail(msg):
    sys.exit("%s: %s" % (ME, msg))


def read_run(outdir):
    """summary.json's quasistatic object and steps.csv's rows, or a clear message."""
    summary = os.path.join(outdir, "summary.json")
    if not os.path.isfile(summary):
        fail("%s has no summary.json: give the output directory of a perilin run" % outdir)
    try:
        s = json.load(open(summary))
    except ValueError as e:
        fail("%s is not valid JSON (%s)" % (summary, e))
    qs = s.get("quasistatic")
    if qs is None:
        kind = s.get("analysis", {}).get("type") if isinstance(s.get("analysis"), dict) else s.get("analysis")
        fail("%s is the output of a %s run, not a quasi-static one: it has no load steps to plot "
             "(analysis.type: quasistatic writes steps.csv)" % (outdir, kind or "static"))
    path = os.path.join(outdir, "steps.csv")
    if not os.path.isfile(path):
        fail("%s has no steps.csv: the run stopped before its first load step" % outdir)
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        fail("%s has no load step (no equilibrium was reached)" % path)
    return qs, rows


def force_column(qs, rows):
    """The column of the force and its axis label."""
    col = qs.get("force_column") or ("reaction" if "reaction" in rows[0] else
                                     "applied_load" if "applied_load" in rows[0] else None)
    if not col or col not in rows[0]:
        fail("steps.csv has no force column: a displacement-controlled run without a bc region "
             "holding the control component has no reaction (analysis.reaction_region; docs/reactions.md)")
    comp = qs.get("control_component", "u")
    if col == "reaction":
        label = "reaction of region %s along %s [force, scene units]" % (qs.get("reaction_region", "?"), comp)
    else:
        label = "applied load along %s, lambda x %.6g [force, scene units]" % (
            comp, qs.get("applied_load_per_load_factor", float("nan")))
    return col, label


def title(qs, F):
    """What happened, from the summary's facts (not a claim the curve contradicts)."""
    control = qs.get("control", "")
    head = "%s control" % control if control else "load-displacement"
    broken = qs.get("broken_bonds", 0)
    if qs.get("failed"):
        what = "failed at load factor %.6g (last equilibrium %.6g)" % (qs["critical_load_factor"],
                                                                       qs.get("peak_load_factor", float("nan")))
    elif not qs.get("complete", True):
        what = "interrupted at load factor %.6g" % qs.get("peak_load_factor", float("nan"))
    else:
        what = "reached load factor %.6g" % qs.get("peak_load_factor", float("nan"))
    peak = max(F, key=abs)
    return "%s: %s; %d bonds broken; peak force %.4g" % (head, what, broken, peak)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="a quasi-static run's output directory")
    ap.add_argument("-o", "--output", help="the image (default OUTDIR/load_displacement.png)")
    args = ap.parse_args()
    qs, rows = read_run(args.outdir)
    col, ylabel = force_column(qs, rows)
    try:
        import matplotlib
        matplotlib.use("Agg")  # no display needed
        import matplotlib.pyplot as plt
    except ImportError:
        fail("matplotlib is not installed (Debian: apt-get install python3-matplotlib)")
    # the picture a run draws itself (output.plots), from the script perilin runs
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "src", "output"))
    from draw_plots import draw_load_displacement
    u = [0.0] + [float(r["control_u"]) for r in rows]  # the unloaded state first
    F = [0.0] + [float(r[col]) for r in rows]
    comp = qs.get("control_component", "u")
    probe = qs.get("control_probe")
    xlabel = ("%s of probe %s [length, scene units]" % (comp, probe) if probe else
              "%s (no probe: 0) [length, scene units]" % comp)
    out = args.output or os.path.join(args.outdir, "load_displacement.png")
    draw_load_displacement(plt, u, F, xlabel, ylabel, title(qs, F), out)
    print("wrote %s (%d steps, force: %s)" % (out, len(rows), col))


if __name__ == "__main__":
    main()
