#!/usr/bin/env bash
# Issue 14, item 3: the matrix-free operator (solver.operator: matrix_free, the default where it
# applies) against the assembled K, on the benchmark scenes, 1 rank. For each case the two
# operators run interleaved REPS times (default 3); prints the median wall time, the median peak
# resident memory, CG iterations and strain energy of each, and the ratios assembled/matrix_free.
# A benchmark, not a test.
# Usage: tests/perf/operator.sh build/perilin [REPS]
set -euo pipefail
perilin=$(realpath "$1")
reps=${2:-3}
root=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cases=(
  "plate_2d_m2|$root/examples/bench/plate_2d.yaml"
  "plate_2d_m4|$root/examples/bench/plate_2d.yaml -horizon_m 4 -grid_spacing 1/400"
  "block_3d_27k|$root/examples/bench/block_3d.yaml -grid_spacing 1/30"
  "block_3d_64k|$root/examples/bench/block_3d.yaml -grid_spacing 1/40"
)
printf "%-14s %-12s %9s %9s %5s %14s\n" case operator wall_s peak_MB its strain_energy
for c in "${cases[@]}"; do
  name=${c%%|*}
  args=${c#*|}
  for r in $(seq "$reps"); do
    for op in assembled matrix_free; do
      # shellcheck disable=SC2086
      /usr/bin/time -f "%e %M" -o t.txt "$perilin" $args -solver_operator $op -output_dir out -output_vtk false -quiet > /dev/null
      python3 - "$op" "$r" >> "$name.csv" <<'PY'
import json, sys
d = json.load(open("out/summary.json"))
wall, kb = open("t.txt").read().split()[-2:]
print(f"{sys.argv[1]},{sys.argv[2]},{wall},{int(kb) / 1024:.0f},{d['solver']['iterations']},{d['strain_energy']:.10g}")
PY
    done
  done
  python3 - "$name" <<'PY'
import csv, statistics, sys
name = sys.argv[1]
rows = list(csv.reader(open(f"{name}.csv")))
med = {}
for op in ("assembled", "matrix_free"):
    r = [x for x in rows if x[0] == op]
    med[op] = (statistics.median(float(x[2]) for x in r), statistics.median(float(x[3]) for x in r), r[0][4], r[0][5])
    print(f"{name:<14} {op:<12} {med[op][0]:9.2f} {med[op][1]:9.0f} {med[op][2]:>5} {med[op][3]:>14}")
a, m = med["assembled"], med["matrix_free"]
print(f"{name:<14} {'ratio':<12} {a[0] / m[0]:8.2f}x {a[1] / m[1]:8.2f}x   (assembled / matrix_free)")
PY
done
