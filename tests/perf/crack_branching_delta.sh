#!/usr/bin/env bash
# The crack-branching plate's delta-convergence (docs/dynamics.md, "Crack branching in glass"):
# examples/dynamics/crack_branching.yaml at delta = 2, 1 and 0.5 mm with m = 3 (dx = delta/3, the
# loaded layers dx/2 deep), each run's branch point and crack speeds by docs/tools/branch_point.py.
# Ha & Bobaru (2010) studied the same plate under decreasing delta (their abstract; their numbers
# were not at hand). About 1, 20 and 160 s on one core.
# usage: tests/perf/crack_branching_delta.sh [BUILD_DIR] [DELTAS_MM...]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
exe=${1:-$repo/build}/perilin
shift || true
deltas=${*:-2 1 0.5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
for d in $deltas; do
  dx=$(python3 -c "print($d * 1e-3 / 3)")
  half=$(python3 -c "print($d * 1e-3 / 6)")
  start=$(date +%s.%N)
  "$exe" "$repo/examples/dynamics/crack_branching.yaml" -quiet -horizon_delta "${d}e-3" -grid_spacing "$dx" \
    -regions_top_depth "$half" -regions_bottom_depth "$half" -output_dir "$tmp/d$d"
  wall=$(python3 -c "import time; print('%.1f' % (time.time() - $start))")
  echo "== delta $d mm, dx $dx m, wall $wall s"
  python3 -c "import json; d = json.load(open('$tmp/d$d/summary.json')); y = d['dynamic']; print('particles', d['particles'], 'bonds broken', y['broken_bonds'], 'drift %.4f' % y['energy_drift'])"
  (cd "$repo" && /usr/bin/python3 docs/tools/branch_point.py "$tmp/d$d")
done
