#!/usr/bin/env bash
# Issue 15, item 1: what model.calibration: lattice costs against continuum, 1 rank, on the
# benchmark scenes. The two calibrations run interleaved REPS times (default 5); prints the median
# wall time and peak resident memory of each and the ratio lattice/continuum. The solve is the same
# size either way; the difference is the calibration's setup (moments, one small solve per
# particle) and the bond factors in the assembly. A benchmark, not a test.
# Usage: tests/perf/lattice.sh build/perilin [REPS]
set -euo pipefail
perilin=$(realpath "$1")
reps=${2:-5}
root=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
cases=(
  "plate_2d_pmb|$root/examples/bench/plate_2d.yaml"
  "lamina_2d_gerstle|$root/examples/bench/lamina_2d.yaml -grid_spacing 1/301"
  "block_3d_npmb|$root/examples/bench/block_3d.yaml -grid_spacing 1/30"
)
printf "%-18s %10s %10s %10s %10s %7s\n" case cont_s latt_s cont_MB latt_MB ratio
for c in "${cases[@]}"; do
  name=${c%%|*}
  args=${c#*|}
  for r in $(seq "$reps"); do
    for cal in continuum lattice; do
      # shellcheck disable=SC2086
      /usr/bin/time -f "%e %M" -o t.txt "$perilin" $args -model_calibration $cal -corrections_surface none -output_dir out -output_vtk false -quiet > /dev/null
      echo "$cal $(cat t.txt)" >> "$name.txt"
    done
  done
  python3 - "$name" <<'PY'
import statistics, sys
name = sys.argv[1]
rows = [l.split() for l in open(f"{name}.txt")]
med = {c: (statistics.median(float(r[1]) for r in rows if r[0] == c),
           statistics.median(float(r[2]) / 1024 for r in rows if r[0] == c)) for c in ("continuum", "lattice")}
(ct, cm), (lt, lm) = med["continuum"], med["lattice"]
print(f"{name:18s} {ct:10.2f} {lt:10.2f} {cm:10.0f} {lm:10.0f} {lt / ct:7.2f}")
PY
done
