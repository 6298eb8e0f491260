#!/usr/bin/env bash
# Issue 17, item 6: peak memory of every rank (the process's own peak RSS, /usr/bin/time) and the
# phase times on the 2D PMB plate (examples/bench/plate_2d.yaml) for 1, 2, 4, 8 ranks
# (oversubscribed: on a 2-core machine this records memory and work per rank, not speed-up).
# A benchmark, not a test.
# Usage: tests/perf/ranks.sh build/perilin [spacing] [ranks ...] [-- perilin options]
set -euo pipefail
perilin=$(realpath "$1")
shift
h=${1:-1/1001}
[[ $# -gt 0 ]] && shift
source "$(dirname "$0")/args.sh"
perf_args ranks "$@"
set -- "${PERF_REST[@]}"
[[ ${#ranks[@]} -gt 0 ]] || ranks=(1 2 4 8)
scene=$(cd "$(dirname "$0")/../.." && pwd)/examples/bench/plate_2d.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
for P in "${ranks[@]}"; do
  rm -f mem.*
  /usr/bin/time -f "%e" -o wall.txt mpiexec --oversubscribe -n "$P" sh -c '/usr/bin/time -f %M -o mem.$OMPI_COMM_WORLD_RANK "$0" "$@"' \
    "$perilin" "$scene" -grid_spacing "$h" -output_dir out -output_vtk false -quiet "$@" > /dev/null
  /usr/bin/python3 - "$P" <<'PY'
import glob, json, sys
P = int(sys.argv[1])
d = json.load(open("out/summary.json"))
mem = [int(open(f).read().split()[-1]) / 1024 for f in sorted(glob.glob("mem.*"))]
t = d["timing"]
wall = float(open("wall.txt").read().split()[-1])
ph = d["memory_phases_mb"]  # the largest rank's peak at the end of each phase
print(f"| {P} | {d['particles']} | {max(mem):.0f} | {min(mem):.0f} | {sum(mem):.0f} | {ph['setup']:.0f} | {ph['assembly']:.0f} | {ph['run']:.0f} | {d['edge_cut']} | {t['neighbors_s']:.2f} | {t['assembly_s']:.2f} | {t['solve_s']:.2f} | {t['total_s']:.2f} | {wall:.1f} |")
PY
done
