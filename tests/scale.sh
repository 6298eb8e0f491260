#!/usr/bin/env bash
# scale.sh PERILIN EXAMPLES_DIR [E...]: static linear elasticity is scale-invariant, so the plate
# of pmb/plate_traction.yaml with Young's modulus E must move exactly 1/E times as far as with
# E = 1: every component of max_abs_u in summary.json times E must equal E = 1's to 1e-8
# (relative). Default moduli: 1e-40 1e-20 1e20 1e40 (units the solver must not notice).
set -u
perilin=$1
ex=$2
shift 2
moduli=${*:-1e-40 1e-20 1e20 1e40}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

run() {
  "$perilin" "$ex/pmb/plate_traction.yaml" -material_E "$1" -output_vtk false -output_dir "$tmp/E$1" > "$tmp/E$1.log" 2>&1 < /dev/null
}

run 1 || {
  echo "FAIL E = 1 did not run"
  cat "$tmp/E1.log"
  exit 1
}
for E in $moduli; do
  if ! run "$E"; then
    echo "FAIL E = $E: $(grep -m1 error "$tmp/E$E.log")"
    fail=$((fail + 1))
    continue
  fi
  if python3 - "$tmp/E1/summary.json" "$tmp/E$E/summary.json" "$E" << 'EOF'; then echo "ok   E = $E"; else fail=$((fail + 1)); fi
import json, sys
ref = json.load(open(sys.argv[1]))["max_abs_u"]
got = json.load(open(sys.argv[2]))["max_abs_u"]
E = float(sys.argv[3])
bad = 0
for c in ref:
    rel = abs(got[c] * E - ref[c]) / abs(ref[c])
    if not rel < 1e-8:
        print(f"FAIL E = {E:g}: max |{c}| * E = {got[c] * E:.15g}, at E = 1 {ref[c]:.15g} (relative difference {rel:.2e})")
        bad = 1
sys.exit(bad)
EOF
done
[ "$fail" -eq 0 ] && echo "scale: displacements scale as 1/E" || echo "scale: $fail modulus value(s) failed"
[ "$fail" -eq 0 ]
