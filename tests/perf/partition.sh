#!/usr/bin/env bash
# Issue 17, item 2: the partitioners (-peri_partition metis | ptscotch | geometric) compared on
# 2, 4 and 8 ranks (oversubscribed): the bonds between ranks (summary.json edge_cut: horizon
# bonds whose ends are owned by different ranks), the partition's time (the PeriPartition event
# of -log_view, its shortest time over the ranks: the others include waiting for the last rank to
# arrive), the set-up (timing.neighbors_s: partition + neighbour search), the KSP iterations and
# solve time of a static solve, and the peak memory of the largest rank and of all ranks. One row
# on 1 rank for reference. A benchmark, not a test: the times are wall times on whatever the
# machine runs beside it. Prints a Markdown table (docs/performance.md, "Partitioners").
# Usage: tests/perf/partition.sh build/perilin [case ...] [-- perilin options]
#   cases: plate_160k (2D plate, 1/401, static), plate_1m (1/1001, set-up only),
#          block_64k (3D block, 1/40, static), block_216k (1/60, set-up only), plate_hole (Gmsh
#          triangles around a hole, examples/mesh/plate_hole.yaml, static); default all five
set -euo pipefail
perilin=$(realpath "$1")
shift
source "$(dirname "$0")/args.sh"
perf_args cases "$@"
set -- "${PERF_REST[@]}"
[[ ${#cases[@]} -gt 0 ]] || cases=(plate_160k plate_1m block_64k block_216k plate_hole)
ranks=${PARTITION_RANKS:-2 4 8}
bench=$(cd "$(dirname "$0")/../.." && pwd)/examples/bench
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

scene_of() {
  case $1 in
    plate_160k) echo "$bench/plate_2d.yaml -grid_spacing 1/401" ;;
    plate_1m) echo "$bench/plate_2d.yaml -grid_spacing 1/1001 -analysis_type setup" ;;
    block_64k) echo "$bench/block_3d.yaml -grid_spacing 1/40" ;;
    block_216k) echo "$bench/block_3d.yaml -grid_spacing 1/60 -analysis_type setup" ;;
    plate_hole) echo "$bench/../mesh/plate_hole.yaml" ;;
    *) echo "partition.sh: unknown case $1" >&2; exit 2 ;;
  esac
}

row() { # row CASE RANKS PARTITIONER
  python3 - "$@" <<'PY'
import json, sys
case, ranks, part = sys.argv[1:4]
d = json.load(open("out/summary.json"))
t = 0.0
for line in open("log.txt"):
    f = line.split()
    if f and f[0] == "PeriPartition":
        t = float(f[3]) / float(f[4])  # max / (max / min)
s = d.get("solver", {})
its = s.get("iterations", "-")
solve = f"{d['timing']['solve_s']:.2f}" if s else "-"
print(f"| {case} | {d['particles']} | {ranks} | {part} | {d['edge_cut']} | {t:.3f} | {d['timing']['neighbors_s']:.2f} | {its} | {solve} | {d['memory_mb_max_rank']:.0f} | {d['memory_mb']:.0f} |")
PY
}

echo "| case | particles | ranks | partitioner | bonds between ranks | partition (s) | set-up (s) | KSP its | solve (s) | peak MB, largest rank | peak MB, all ranks |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for c in "${cases[@]}"; do
  read -r -a scene <<< "$(scene_of "$c")"
  "$perilin" "${scene[@]}" -output_dir out -output_vtk false -log_view :log.txt "$@" > /dev/null
  row "$c" 1 "-"
  for np in $ranks; do
    for part in metis ptscotch geometric; do
      mpiexec --oversubscribe -n "$np" "$perilin" "${scene[@]}" -output_dir out -output_vtk false -peri_partition "$part" -log_view :log.txt "$@" > /dev/null
      row "$c" "$np" "$part"
    done
  done
done
