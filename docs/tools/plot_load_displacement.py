#!/usr/bin/env python3
"""Plot the load-displacement curve of a quasi-static run from its steps.csv (docs/reactions.md).

    python3 docs/tools/plot_load_displacement.py OUTDIR [-o PNG]

Reads OUTDIR/steps.csv (columns control_u and reaction: the control probe's displacement along
analysis.control_component, and the reaction of analysis.reaction_region along it) and the names
from OUTDIR/summary.json, and writes OUTDIR/load_displacement.png (or PNG). Needs matplotlib
(Debian: python3-matplotlib); perilin itself never calls this script."""
import argparse
import csv
import json
import os
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="a quasi-static run's output directory")
    ap.add_argument("-o", "--output", help="the image (default OUTDIR/load_displacement.png)")
    args = ap.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")  # no display needed
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("plot_load_displacement.py: matplotlib is not installed (Debian: apt-get install python3-matplotlib)")
    with open(os.path.join(args.outdir, "steps.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows or "reaction" not in rows[0]:
        sys.exit("plot_load_displacement.py: %s/steps.csv has no reaction column: the run has no reaction region "
                 "(analysis.reaction_region; docs/reactions.md)" % args.outdir)
    qs = json.load(open(os.path.join(args.outdir, "summary.json"))).get("quasistatic", {})
    u = [0.0] + [float(r["control_u"]) for r in rows]  # the unloaded state first
    F = [0.0] + [float(r["reaction"]) for r in rows]
    comp = qs.get("control_component", "u")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(u, F, "o-", ms=3)
    ax.set_xlabel("%s of probe %s" % (comp, qs.get("control_probe", "?")))
    ax.set_ylabel("reaction of %s along %s" % (qs.get("reaction_region", "?"), comp))
    ax.set_title("load-displacement (%s)" % ("failed at load factor %g" % qs["critical_load_factor"]
                                              if qs.get("failed") else qs.get("ending", "")), fontsize=9)
    ax.grid(True, alpha=0.3)
    out = args.output or os.path.join(args.outdir, "load_displacement.png")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print("wrote %s (%d steps)" % (out, len(rows)))


if __name__ == "__main__":
    main()
