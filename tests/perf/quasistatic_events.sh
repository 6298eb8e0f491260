#!/usr/bin/env bash
# Issue 14, item 1: quasi-static stepping by events against increments, and against one static
# solve of the same body, on the edge crack at dx 0.01 (10,000 particles). Prints each run's wall
# time, solves and critical load factor, and the ratios. A benchmark, not a test.
# Usage: tests/perf/quasistatic_events.sh build/perilin [dx]
set -euo pipefail
perilin=$1 dx=${2:-0.01}
scene=$(cd "$(dirname "$0")/../.." && pwd)/examples/fracture/edge_crack.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
sed '/^analysis:/,/^  min_step/d' "$scene" > static.yaml # the same body, one static solve
run() { # name args...
  local name=$1
  shift
  local t0 t1
  t0=$(date +%s.%N)
  "$perilin" "$@" -grid_spacing "$dx" -quiet -output_dir "$name" -output_vtk false > "$name.log"
  t1=$(date +%s.%N)
  echo "$name $(echo "$t1 - $t0" | bc)"
}
for k in 1 2 3; do
  run static static.yaml
  run events "$scene" -analysis_stepping events
done > times.txt
run increments "$scene" -analysis_stepping increments >> times.txt
python3 - <<'PY'
import json, statistics
t = {}
for line in open("times.txt"):
    name, s = line.split(); t.setdefault(name, []).append(float(s))
med = {k: statistics.median(v) for k, v in t.items()}
for k in ("events", "increments"):
    q = json.load(open(f"{k}/summary.json"))["quasistatic"]
    print(f"{k:11s} wall {med[k]:7.2f} s (median of {len(t[k])})  solves {q['solves']:4d}  critical load factor {q.get('critical_load_factor')}  = {med[k] / med['static']:.1f} static runs")
print(f"static      wall {med['static']:7.2f} s (median of {len(t['static'])})")
print(f"increments / events: {med['increments'] / med['events']:.1f}x")
PY
