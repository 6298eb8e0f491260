#!/usr/bin/env bash
# The cost of contact (issue 38, item 8; docs/contact.md, docs/performance.md "contact"): the EOI
# at dx = 1.25 mm (51,200 particles) with contact: {} against without, paired runs; and
# Kalthoff-Winkler in 2D at dx = 1 mm on one core (target: 30 s).
# usage: tests/perf/contact_cost.sh [BUILD_DIR]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
exe=${1:-$repo/build}/perilin
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sed "s#^output: .*#output: {dir: $tmp/plain, vtk: false}#" "$repo/examples/dynamics/eoi.yaml" > "$tmp/plain.yaml"
sed "s#^output: .*#output: {dir: $tmp/contact, vtk: false}#" "$repo/examples/dynamics/eoi.yaml" > "$tmp/contact.yaml"
echo "contact: {}" >> "$tmp/contact.yaml"
farm-bench -n 3 --timeout 400 --vs "$exe $tmp/plain.yaml -quiet -grid_spacing 1.25e-3" -- "$exe" "$tmp/contact.yaml" -quiet -grid_spacing 1.25e-3
farm-bench -n 3 --timeout 200 -- "$exe" "$repo/examples/dynamics/kalthoff_winkler.yaml" -output_dir "$tmp/kw" -quiet
