#!/usr/bin/env bash
# Issue 29 item 3: perilin's geometric multigrid (-pc_type mg, src/system/multigrid.c; the default
# on grid bodies with a matrix-free K) against GAMG on the short-range stiffness, paired and
# interleaved, REPEAT runs each, one rank. Prints per case the medians of the solve time, the
# whole run's wall time, the CG iterations and the peak resident memory, and the peak over the
# bytes an assembled BAIJ K would take (blocks = particles + 2 bonds, bs^2 doubles and a column
# index each, and a row pointer per particle; the item's target is <= 1.5 at 640,000 particles).
# A benchmark, not a test.
# Usage: tests/perf/multigrid_cost.sh build/perilin [REPEAT] [-- perilin options for every run]
set -euo pipefail
perilin=$(realpath "$1")
repeat=${2:-3}
shift $(($# < 2 ? $# : 2))
[[ ${1:-} == -- ]] && shift
root=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cases=(
  "plate_2d_160k|$root/examples/bench/plate_2d.yaml -grid_spacing 1/401"
  "plate_2d_642k|$root/examples/bench/plate_2d.yaml -grid_spacing 1/801"
  "plate_2d_m3_58k|$root/examples/bench/plate_2d.yaml -grid_spacing 1/240 -horizon_m 3"
  "block_3d_64k|$root/examples/bench/block_3d.yaml"
  "gerstle_lamina_58k|$root/examples/bench/lamina_bending_2d.yaml -grid_spacing 0.6/240"
)
printf "| case | PC | particles | CG its | solve s | wall s | peak MB | peak / BAIJ K |\n|---|---|---|---|---|---|---|---|\n"
for c in "${cases[@]}"; do
  name=${c%%|*}
  args=${c#*|}
  for r in $(seq "$repeat"); do
    for pc in gamg mg; do
      # shellcheck disable=SC2086
      /usr/bin/time -f "%e %M" -o "time_${pc}_$r.txt" "$perilin" $args -pc_type $pc -output_dir "out_${pc}_$r" -output_vtk false -quiet "$@" > /dev/null
    done
  done
  for pc in gamg mg; do
    /usr/bin/python3 - "$name" "$pc" "$repeat" <<'PY'
import json, statistics, sys
name, pc, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
rows = []
for r in range(1, n + 1):
    d = json.load(open(f"out_{pc}_{r}/summary.json"))
    wall, kb = open(f"time_{pc}_{r}.txt").read().split()[-2:]
    rows.append((d, float(wall), int(kb) / 1024))
d = rows[0][0]
bs = d["dofs"] // d["particles"]
baij = ((d["particles"] + 2 * d["bonds"]) * (bs * bs * 8 + 4) + 4 * (d["particles"] + 1)) / 1048576
med = lambda f: statistics.median(f(x) for x in rows)
peak = med(lambda x: x[2])
print(f"| {name} | {pc} | {d['particles']} | {d['solver']['iterations']} | {med(lambda x: x[0]['timing']['solve_s']):.3f} | {med(lambda x: x[1]):.2f} | {peak:.0f} | {peak / baij:.2f} |")
PY
  done
done
