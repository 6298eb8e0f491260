#!/bin/bash
# Issue 37 item 5: lps against pmb on the same 3D plate, the whole static run and the explicit step.
#   tests/perf/lps_cost.sh PERILIN [RUNS]
# 1. Static: tests/perf/lammps/plate_3d.yaml scaled to 320 x 80 x 4 = 102,400 particles
#    (4,372,220 bonds; the plate of tests/perf/lammps_3d.sh at SCALE 2 along x and y), pmb
#    (nu = 1/4) against lps at nu = 0.3, each with its defaults (matrix-free K, CG + GAMG on the
#    short-range springs), paired and interleaved by farm-bench --vs: the ratio lps/pmb of the
#    whole process (wall and cpu, medians). Target: <= 2.5.
# 2. Explicit step: tests/perf/lammps/dynamic_3d.yaml (the free 25,600-particle plate of
#    tests/perf/dynamic_lammps.sh, 200 steps), pmb against lps at nu = 0.3; the ratio of
#    timing.solve_s (the time loop) over the same steps. Target: <= 2.5.
set -euo pipefail
exe=$(readlink -f "${1:?usage: lps_cost.sh PERILIN [RUNS]}")
runs=${2:-3}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d /tmp/lps_cost.XXXXXX)
plate=(-grid_lower_0 -0.3185 -grid_upper_1 0.0795 -loads_0_force 48,0,0)
echo "== static, 102,400 particles: lps (nu 0.3) vs pmb"
farm-bench -n "$runs" --timeout 3600 --vs "$exe $here/lammps/plate_3d.yaml ${plate[*]} -output_dir $tmp/pmb" -- \
  "$exe" "$here/lammps/plate_3d.yaml" "${plate[@]}" -model_type lps -material_nu 0.3 -output_dir "$tmp/lps"
echo "== explicit step, 25,600 particles, 200 steps: timing.solve_s"
for r in $(seq "$runs"); do
  for m in pmb lps; do
    extra=()
    [ $m = lps ] && extra=(-model_type lps -material_nu 0.3)
    "$exe" "$here/lammps/dynamic_3d.yaml" "${extra[@]}" -output_dir "$tmp/dyn_$m" > /dev/null 2>&1
    python3 -c "import json,sys; print(sys.argv[1], json.load(open(sys.argv[2]))['timing']['solve_s'])" $m "$tmp/dyn_$m/summary.json"
  done
done | python3 -c "
import sys, statistics
t = {}
for line in sys.stdin:
    m, s = line.split(); t.setdefault(m, []).append(float(s))
pm, lm = statistics.median(t['pmb']), statistics.median(t['lps'])
print(f'pmb {pm:.3f} s, lps {lm:.3f} s (medians of {len(t[\"pmb\"])}): lps/pmb {lm / pm:.2f}')"
rm -rf "$tmp"
