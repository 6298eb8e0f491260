#!/usr/bin/env bash
# Zero-energy modes of lps (issue 37, item 6): a free lps body has exactly the rigid-body modes,
# 6 in 3D and 3 in 2D, shown by the modal analysis (summary.json modal.rigid_modes: the
# eigenvalues below 1e-6 of the scale, at most the free rigid motions), with the lowest elastic
# mode far above them (a spurious zero-energy mode would sit there): the free steel bar of
# tests/scenes/lps_free_bar.yaml at m = 1.5, 2, 3 and 5 (first bending 1000 +- 100 Hz, CalculiX
# 1003.6 Hz), at m = 3 with model.calibration: lattice (first bending 800-1100 Hz: measured 905.7,
# the lattice calibration's thickness modes are soft at this spacing, docs/models/lps.md), and a
# free plane-stress plate 0.2 x 0.1 (3 rigid modes, first mode above 1 kHz).
# Usage: lps_modes.sh PERILIN REPO
set -u
exe=${1:?usage: lps_modes.sh PERILIN REPO}
repo=${2:?usage: lps_modes.sh PERILIN REPO}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
fail=0
run() { # name, args...
  local name=$1
  shift
  "$exe" "$@" -output_dir "$tmp/$name" > "$tmp/$name.log" 2>&1 < /dev/null || { echo "FAIL: $name exited $?"; tail -3 "$tmp/$name.log"; fail=1; }
}
bar=$repo/tests/scenes/lps_free_bar.yaml
for m in 1.5 2 3 5; do run bar_m$m "$bar" -horizon_m $m; done
run bar_lattice "$bar" -model_calibration lattice
run plate "$bar" -dim 2 -grid_lower 0,0 -grid_upper 0.2,0.1 -grid_spacing 0.005 -material_thickness 0.01
[ $fail = 0 ] || exit 1
python3 - "$tmp" << 'PY'
import json, sys
tmp = sys.argv[1]
bad = 0
for name, rigid, lo, hi in (("bar_m1.5", 6, 900, 1100), ("bar_m2", 6, 900, 1100), ("bar_m3", 6, 900, 1100), ("bar_m5", 6, 900, 1100), ("bar_lattice", 6, 800, 1100), ("plate", 3, 1000, 1e9)):
    m = json.load(open(f"{tmp}/{name}/summary.json"))["modal"]
    f1 = m["frequencies_hz"][0]
    ok = m["rigid_modes"] == rigid and lo < f1 < hi
    bad |= not ok
    print(("ok: " if ok else "FAIL: ") + f"lps free body {name}: {m['rigid_modes']} rigid modes (expected {rigid}), lowest elastic {f1:.1f} Hz (expected in ({lo}, {hi:g}))")
sys.exit(bad)
PY
