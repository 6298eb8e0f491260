#!/usr/bin/env bash
# analysis.stepping: events (docs/failure.md, "Stepping"). The edge crack (examples/fracture,
# Δx 0.04) is run by increments (the bracket [peak, critical] of bisection to min_step) and by
# events; checks: the events' critical load factor lies in the increments' bracket, widened by
# the event window (1e-6); events need fewer solves; 2 ranks give the same critical load factor to
# 1e-6; the pre-break and post-cascade rows of steps.csv are equilibria of increasing load.
# Usage: events.sh PERILIN SCENE
set -euo pipefail
perilin=$1 scene=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
common=(-grid_spacing 0.04 -quiet)
"$perilin" "$scene" "${common[@]}" -analysis_stepping increments -output_dir inc > inc.log
"$perilin" "$scene" "${common[@]}" -analysis_stepping events -output_dir ev1 > ev1.log
mpiexec --oversubscribe -n 2 "$perilin" "$scene" "${common[@]}" -analysis_stepping events -output_dir ev2 > ev2.log
python3 - <<'PY'
import csv, json, sys
inc, ev1, ev2 = (json.load(open(f"{d}/summary.json"))["quasistatic"] for d in ("inc", "ev1", "ev2"))
lo, hi, c1, c2 = inc["peak_load_factor"], inc["critical_load_factor"], ev1["critical_load_factor"], ev2["critical_load_factor"]
rows = list(csv.DictReader(open("ev1/steps.csv")))
lams = [float(r["load_factor"]) for r in rows]
checks = {
  f"events failed, as increments did ({ev1['failed']}, {inc['failed']})": ev1["failed"] and inc["failed"],
  f"stepping recorded (events, increments)": ev1["stepping"] == "events" and inc["stepping"] == "increments",
  f"critical load factor {c1:.6f} in the increments' bracket [{lo}, {hi}]": lo * (1 - 1e-6) <= c1 <= hi * (1 + 1e-6),
  f"fewer solves by events ({ev1['solves']} vs {inc['solves']})": ev1["solves"] < inc["solves"],
  f"2 ranks: critical load factor {c2:.9f} vs {c1:.9f}": abs(c2 - c1) <= 1e-6 * c1,
  f"steps.csv: {len(lams)} rows of non-decreasing load factor up to the peak {ev1['peak_load_factor']}": len(lams) >= 1 and all(b >= a for a, b in zip(lams, lams[1:])) and abs(lams[-1] - ev1["peak_load_factor"]) <= 1e-9 * lams[-1],
}
bad = [k for k, ok in checks.items() if not ok]
for k, ok in checks.items():
    print(("ok   " if ok else "FAIL ") + k)
sys.exit(1 if bad else 0)
PY
