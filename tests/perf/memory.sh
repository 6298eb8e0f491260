#!/usr/bin/env bash
# Issue 14, item 4: peak memory against the assembled operator's bytes, by phase, on the 2D PMB
# plate (examples/bench/plate_2d.yaml) at the given spacings (default 1/401: 160,801 particles;
# 1/801: 641,601). Prints summary.json's memory_phases_mb, matrix_mb, peak/matrix and the wall
# time and peak of the process (/usr/bin/time). Options after -- go to every run, e.g.
# -- -peri_release_bond_geometry false -peri_malloc_mmap_threshold 0 for the behaviour before
# issue 14 item 4. A benchmark, not a test.
# Usage: tests/perf/memory.sh build/perilin [spacing ...] [-- perilin options]
set -euo pipefail
perilin=$(realpath "$1")
shift
source "$(dirname "$0")/args.sh"
perf_args spacings "$@"
set -- "${PERF_REST[@]}"
[[ ${#spacings[@]} -gt 0 ]] || spacings=(1/401)
scene=$(cd "$(dirname "$0")/../.." && pwd)/examples/bench/plate_2d.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
for h in "${spacings[@]}"; do
  /usr/bin/time -f "%e %M" -o time.txt "$perilin" "$scene" -grid_spacing "$h" -output_dir out -output_vtk false "$@" > /dev/null
  python3 - "$h" <<'PY'
import json, sys
d = json.load(open("out/summary.json"))
ph = d["memory_phases_mb"]
wall, kb = open("time.txt").read().split()[-2:]
print(f"spacing {sys.argv[1]}: {d['particles']} particles, set-up {ph['setup']:.0f} MB, assembly {ph.get('assembly', 0):.0f} MB, run {ph['run']:.0f} MB; K {d['matrix_mb']:.0f} MB; peak/matrix {d['memory_mb_max_rank'] / d['matrix_mb']:.2f}; wall {float(wall):.2f} s, process peak {int(kb) / 1024:.0f} MB")
PY
done
