#!/usr/bin/env bash
# Issue 29, item 2: micropolar statics at PMB's cost per DOF. The gerstle cantilever lamina in
# bending (examples/bench/lamina_bending_2d.yaml, 3 DOFs per particle) with the assembled K
# (before) and the default operator (after: matrix-free, AMG on the diagonally matched short-range
# stiffness), against the PMB plate of the same particle count (examples/bench/plate_2d.yaml at
# m = 2, its default, and at m = 3, the lamina's horizon). Interleaved runs, medians of REPS
# (default 3), 1 rank. Prints CG iterations, assembly + solve seconds (summary.json), wall and peak
# per run kind, the time per DOF and the ratio gerstle / pmb. A benchmark, not a test.
# Usage: tests/perf/micropolar_cost.sh build/perilin [CELLS [REPS [options...]]]
#   CELLS 240 (default): 240 x 240 = 57,600 particles in both bodies. Extra options go to every run.
set -euo pipefail
perilin=$(realpath "$1")
cells=${2:-240}
reps=${3:-3}
shift $(($# < 3 ? $# : 3))
repo=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
lamina="$repo/examples/bench/lamina_bending_2d.yaml -grid_spacing 0.6/$cells"
plate="$repo/examples/bench/plate_2d.yaml -grid_spacing 1/$cells"
declare -A runs=(
  [gerstle_assembled]="$lamina -solver_operator assembled"
  [gerstle_default]="$lamina"
  [pmb_m2_default]="$plate"
  [pmb_m3_default]="$plate -horizon_m 3"
)
for r in $(seq "$reps"); do
  for k in gerstle_assembled gerstle_default pmb_m2_default pmb_m3_default; do
    # shellcheck disable=SC2086
    /usr/bin/time -f "%e %M" -o t.txt "$perilin" ${runs[$k]} -output_dir "$k" -output_vtk false -quiet "$@" > /dev/null
    python3 - "$k" "$(cat t.txt)" >> runs.txt <<'PY'
import json, sys
d = json.load(open(sys.argv[1] + "/summary.json"))
t = d["timing"]
wall, kb = sys.argv[2].split()
print(sys.argv[1], d["dofs"], d["solver"]["iterations"], t["assembly_s"] + t["solve_s"], wall, int(kb) / 1024, d["solver"]["stiffness"])
PY
  done
done
python3 - <<'PY'
import statistics
rows = {}
for line in open("runs.txt"):
    k, dofs, its, cost, wall, mb, stiffness = line.split()
    rows.setdefault(k, []).append((int(dofs), int(its), float(cost), float(wall), float(mb), stiffness))
med = {}
print(f"{'run':<18} {'stiffness':<12} {'DOFs':>8} {'CG its':>6} {'assembly+solve s':>16} {'wall s':>7} {'peak MB':>8} {'us/DOF':>7}")
for k, v in rows.items():
    dofs, its, st = v[0][0], v[0][1], v[0][5]
    cost = statistics.median(x[2] for x in v)
    med[k] = cost / dofs
    print(f"{k:<18} {st:<12} {dofs:>8} {its:>6} {cost:>16.3f} {statistics.median(x[3] for x in v):>7.2f} {statistics.median(x[4] for x in v):>8.0f} {1e6 * med[k]:>7.2f}")
for g in ("gerstle_assembled", "gerstle_default"):
    print(f"time per DOF {g} / pmb m=2: {med[g] / med['pmb_m2_default']:.2f}   / pmb m=3: {med[g] / med['pmb_m3_default']:.2f}")
PY
