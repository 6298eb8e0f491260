#!/usr/bin/env bash
# Issue 17: the peak memory of particle creation and partition, per rank, for the whole-body path
# (every rank creates the whole body, PeriPartition, permutation, slice) and the owned path
# (PeriParticlesCreateOwned: grid share, or rank 0 dealing a file out; parallel partition;
# migration), on the 2D plate of examples/bench/plate_2d.yaml (1/1001: 1,002,001 particles) from
# its grid and from a CSV file of the same particles. Each rank's peak resident memory is its own
# (getrusage in test_create -peak), process start-up included: PETSc and MPI alone take about
# 30-40 MB. A benchmark, not a test. Prints a Markdown table (docs/distributed.md).
# Usage: tests/perf/create.sh BUILD/tests/test_create [ranks ...] [-- options, e.g. -peri_partition metis]
set -euo pipefail
exe=$(realpath "$1")
shift
source "$(dirname "$0")/args.sh"
perf_args ranks "$@"
set -- "${PERF_REST[@]}"
[[ ${#ranks[@]} -gt 0 ]] || ranks=(1 2 4)
h=${CREATE_SPACING:-1/1001}
scene=$(cd "$(dirname "$0")/../.." && pwd)/examples/bench/plate_2d.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# the same particles as a CSV file: cell centres, volume h^2 x thickness
/usr/bin/python3 - "$h" "$work/plate.csv" <<'PY'
import sys
from fractions import Fraction
h = float(Fraction(sys.argv[1]))
n = round(1 / h)
with open(sys.argv[2], "w") as f:
    f.write("x, y, volume\n")
    v = h * h * 0.01
    for j in range(n):
        y = (j + 0.5) * h
        f.write("".join(f"{(i + 0.5) * h!r}, {y!r}, {v!r}\n" for i in range(n)))
PY
sed -e 's|^grid:.*|particles: {file: plate.csv}|' "$scene" > "$work/plate_csv.yaml"
echo "| body | ranks | path | particles | largest rank MB | smallest rank MB | all ranks MB | time s |"
echo "|---|---|---|---|---|---|---|---|"
for body in grid csv; do
  for P in "${ranks[@]}"; do
    for path in old new; do
      if [[ $body == grid ]]; then
        args=("$scene" -peak "$path" -grid_spacing "$h")
      else
        args=("$work/plate_csv.yaml" -peak "$path")
      fi
      out=$(mpiexec --oversubscribe -n "$P" "$exe" "${args[@]}" "$@")
      # "old 1002001 particles, 2 ranks, 1.23 s, peak MB per rank: 120 118"
      /usr/bin/python3 - "$body" "$P" "$path" "$out" <<'PY'
import sys
body, P, path, out = sys.argv[1:5]
head, mem = out.strip().split("peak MB per rank:")
words = head.replace(",", "").split()
n, t = int(words[1]), float(words[5])
mem = [float(m) for m in mem.split()]
label = "whole body" if path == "old" else "owned"
print(f"| {body} | {P} | {label} | {n:,} | {max(mem):.0f} | {min(mem):.0f} | {sum(mem):.0f} | {t:.2f} |")
PY
    done
  done
done
