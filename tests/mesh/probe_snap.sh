#!/usr/bin/env bash
# Issue 28, item 8: a probe inside the body but outside its nearest particle's cell snaps to that
# particle with a note. examples/mesh/plate_hole.yaml coarsened to -particles_size 0.02: hole_edge
# (0, 0.053) lies in the plate (the hole's radius is 0.05, the plate 1.4 x 1 m), in a triangle beside
# the hole whose centroid is farther than the cell's reach. The run must succeed on 1 and 2 ranks,
# print the note once, and record snapped, distance (= |x - particle_x|, at most the horizon) and the
# same particle on both. A point in the hole's centre (0, 0), 0.05 from the plate, farther than the
# horizon (0.039) from every particle, is still an error naming the probe, and nothing is written.
# Usage: probe_snap.sh PERILIN EXAMPLES_DIR
set -u
exe=$1 ex=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
scene=$ex/mesh/plate_hole.yaml
fail=0
check() { # check OUT: the note and summary.json's hole_edge
  local out=$1
  [ "$(grep -c "note: probe 'hole_edge' (0, 0.053)" "$out.log")" = 1 ] || { echo "FAIL: $out: the note is not printed exactly once"; cat "$out.log"; fail=1; }
  python3 - "$out/summary.json" << 'PY' || fail=1
import json, math, sys
s = json.load(open(sys.argv[1]))
p = s["probes"]["hole_edge"]
d = math.dist(p["x"], p["particle_x"])
ok = p.get("snapped") is True and abs(d - p["distance"]) <= 1e-12 and p["x"] == [0, 0.053] and d <= s["horizon"]
print(("ok" if ok else "FAIL") + ": hole_edge snapped to", p["particle_x"], "at", d, "(horizon", s["horizon"], ")")
sys.exit(0 if ok else 1)
PY
}
"$exe" "$scene" -particles_size 0.02 -output_dir "$tmp/one" > "$tmp/one.log" 2>&1 || { echo "FAIL: the coarse run stopped"; cat "$tmp/one.log"; exit 1; }
check "$tmp/one"
mpiexec --oversubscribe -n 2 "$exe" "$scene" -particles_size 0.02 -output_dir "$tmp/two" > "$tmp/two.log" 2>&1 || { echo "FAIL: the coarse run on 2 ranks stopped"; cat "$tmp/two.log"; exit 1; }
check "$tmp/two"
python3 -c 'import json, sys; a, b = (json.load(open(f))["probes"]["hole_edge"]["particle_x"] for f in sys.argv[1:]); sys.exit(a != b)' "$tmp/one/summary.json" "$tmp/two/summary.json" || { echo "FAIL: 1 and 2 ranks sample different particles"; fail=1; }
for launch in "" "mpiexec --oversubscribe -n 2"; do
  # shellcheck disable=SC2086
  if $launch "$exe" "$scene" -particles_size 0.02 -probes_hole_edge 0,0 -output_dir "$tmp/far" > "$tmp/far.log" 2>&1; then
    echo "FAIL: a probe in the hole's centre was accepted (${launch:-1 rank})"
    fail=1
  elif ! grep -q "key 'probes.hole_edge': the point lies outside the body: the nearest particle to (0, 0)" "$tmp/far.log" || [ -e "$tmp/far" ]; then
    echo "FAIL: the hole's centre: no clear error, or an output was left (${launch:-1 rank})"
    cat "$tmp/far.log"
    fail=1
  fi
done
[ $fail = 0 ] && echo "ok: snapped with a note on 1 and 2 ranks; the hole's centre is outside"
exit $fail
