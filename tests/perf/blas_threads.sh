#!/usr/bin/env bash
# Issue 14, item 2: CPU time against wall time of a 1-rank static run (the 160,801-particle plate
# of examples/bench/plate_2d.yaml): with OpenBLAS's threads spinning the CPU time was 1.5x the wall
# time; perilin now runs one BLAS thread outside factorizations (src/sys/threads.c). Prints the
# medians of user, sys and wall seconds, and cpu/wall. A benchmark, not a test.
# Usage: tests/perf/blas_threads.sh build/perilin [runs]
set -euo pipefail
perilin=$1 runs=${2:-3}
scene=$(cd "$(dirname "$0")/../.." && pwd)/examples/bench/plate_2d.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
for ((k = 0; k < runs; k++)); do
  /usr/bin/time -f "%U %S %e" -o t.$k "$perilin" "$scene" -output_dir out -output_vtk false > /dev/null
done
cat t.* | python3 -c '
import statistics, sys
rows = [list(map(float, l.split())) for l in sys.stdin if l.strip()]
u, s, w = (statistics.median(c) for c in zip(*rows))
print(f"user {u:.2f} s  sys {s:.2f} s  wall {w:.2f} s  cpu/wall {(u + s) / w:.2f}  (medians of {len(rows)})")'
