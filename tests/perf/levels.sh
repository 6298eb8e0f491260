#!/usr/bin/env bash
# Issue 27 item 6: the cost of the per-particle-horizon search (src/disc/levels.c) from 1e4 to 1e6
# particles on a 2D cloud graded 100:1 (spacing h0 100^(x/L) across x, jittered by 30 %), each
# particle's horizon 3 of its own spacings (horizon.spacing: own), against the one-horizon cell
# list on a uniform jittered cloud of the same count. Prints particles, bonds and the search time
# (summary.json neighbors_s: the search, family volumes and corrections), per particle and per bond.
# Usage: levels.sh PERILIN [N ...]   (default 1e4 1e5 1e6)
set -euo pipefail
exe=$1; shift
sizes=("$@"); [ ${#sizes[@]} -gt 0 ] || sizes=(10000 100000 1000000)
py=/usr/bin/python3
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cloud() { # N RATIO FILE: a jittered cloud of about N particles over [0, 1] x [0, 0.25], graded RATIO:1 along x
  "$py" - "$1" "$2" "$3" <<'PY'
import sys, numpy as np
N, ratio, path = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
L, H = 1.0, 0.25
# columns: h grows geometrically from h0 to ratio h0; choose h0 so that sum H/h over the columns is N
def count(h0):
    x, n = 0.0, 0
    while x < L:
        h = h0 * ratio ** (x / L); n += int(H / h); x += h
    return n
lo, hi = 1e-6, 1.0
for _ in range(60):
    mid = (lo * hi) ** 0.5
    lo, hi = (mid, hi) if count(mid) > N else (lo, mid)
h0, x, rows, rng = hi, 0.0, [], np.random.default_rng(1)
while x < L:
    h = h0 * ratio ** (x / L); m = int(H / h)
    y = (np.arange(m) + 0.5) * h + 0.3 * h * (2 * rng.random(m) - 1)
    xx = x + 0.3 * h * (2 * rng.random(m) - 1)
    rows.append(np.column_stack([xx, y, np.full(m, h * h)])); x += h
np.savetxt(path, np.vstack(rows), delimiter=",", header="x,y,volume", comments="")
PY
}
printf "%-8s %-9s %10s %10s %9s %12s %12s\n" horizon ratio particles bonds search_s us/particle ns/bond
for n in "${sizes[@]}"; do
  for kind in own mean; do
    ratio=100; [ $kind = mean ] && ratio=1
    cloud "$n" $ratio "$tmp/cloud.csv"
    cat > "$tmp/scene.yaml" <<YAML
dim: 2
model: {type: npmb, plane: stress}
material: {E: 1.0, thickness: 1.0}
particles: {file: cloud.csv}
horizon: {m: 3, spacing: $kind}
analysis: {type: setup}
output: {vtk: false}
YAML
    "$exe" "$tmp/scene.yaml" -output_dir "$tmp/out" -quiet > /dev/null
    "$py" - "$tmp/out/summary.json" $kind $ratio <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); n = s["particles"]; b = s["bonds"]; t = s["timing"]["neighbors_s"] if "timing" in s else s["neighbors_s"]
print(f"{sys.argv[2]:<8} {sys.argv[3]:<9} {n:>10} {b:>10} {t:>9.3f} {1e6*t/n:>12.2f} {1e9*t/b:>12.1f}")
PY
    rm -rf "$tmp/out"
  done
done
