#!/usr/bin/env bash
# Every analysis key is checked before any particle exists (issue 25 item 2): a bad analysis.*
# value on a body of 10^12 particles must be reported at once, naming the key, with no trace of
# the particle phase (no memory estimate, which is its first step, in the -info log) and no
# output directory. Before the analyses' setfromscene phase, these scenes failed on the memory
# estimate ("needs about ... GB") instead, after the model and the grid were read.
# Usage: analysis_keys_first.sh PERILIN
set -u
exe=${1:?usage: analysis_keys_first.sh PERILIN}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
fail=0
# name | analysis section | the message expected (grep -E)
cases=(
  "modal_nev|{type: modal, nev: 0}|analysis.nev.*must lie in \\[1, inf\\)"
  "modal_target|{type: modal, target_hz: -1}|analysis.target_hz.*must lie in \\[0, inf\\)"
  "quasistatic_step|{type: quasistatic, load_factor_max: 1, load_factor_step: 2}|analysis.load_factor_step.*must lie in"
  "quasistatic_fraction|{type: quasistatic, load_factor_max: 1, load_factor_step: 0.1, break: all, break_fraction: 0.5}|analysis.break_fraction.*applies to break: fraction only"
  "anisotropy_m|{type: anisotropy, criteria: [stretch], paths: [[1, 0]], m: [30]}|analysis.m.*must lie in \\[1, 20\\]"
  "unknown_type|{type: dynamics}|unknown analysis 'dynamics'"
)
for entry in "${cases[@]}"; do
  IFS='|' read -r name section expect <<< "$entry"
  cat > "$name.yaml" << YAML
dim: 3
model: {type: pmb}
material: {E: 1.0e9, nu: 0.25, rho: 1000}
grid: {lower: [0, 0, 0], upper: [1, 1, 1], spacing: 2.5e-3}
horizon: {m: 3}
failure: {critical_stretch: 0.01}
regions:
  base: {side: z-}
bc:
  - {region: base, fix: [ux, uy, uz]}
loads:
  - {region: base, force: [0, 0, 1]}
analysis: $section
output: {dir: $name-out}
YAML
  start=$(date +%s)
  timeout 60 "$exe" "$name.yaml" -info > "$name.log" 2>&1 < /dev/null
  code=$?
  secs=$(($(date +%s) - start))
  if [ "$code" -eq 0 ] || [ "$code" -eq 124 ]; then
    echo "FAIL: $name: exit $code (expected an input error)"; fail=1; continue
  fi
  if ! grep -qE "perilin: error: .*$expect" "$name.log"; then
    echo "FAIL: $name: the error does not name the key as expected ($expect):"; grep "perilin: error" "$name.log" | head -3; fail=1; continue
  fi
  if grep -q "memory estimate" "$name.log"; then
    echo "FAIL: $name: the particle phase began (memory estimate in the log) before the analysis key was checked"; fail=1; continue
  fi
  if [ -e "$name-out" ]; then
    echo "FAIL: $name: an output directory was created"; fail=1; continue
  fi
  echo "ok: $name: reported before any particle ($secs s): $(grep -oE "$expect" "$name.log" | head -1)"
done
# the control: with valid keys the same body reaches the particle phase, whose memory estimate
# (logged by -info, and refusing 10^12 particles) the checks above look for
sed 's/^analysis: .*/analysis: {type: modal, nev: 3}/' modal_nev.yaml > control.yaml
timeout 60 "$exe" control.yaml -info > control.log 2>&1 < /dev/null
if grep -q "memory estimate\|needs about" control.log; then
  echo "ok: control: with valid analysis keys the particle phase begins (its memory estimate refuses the body)"
else
  echo "FAIL: control: the valid scene did not reach the memory estimate; the test cannot tell the phases apart"; tail -3 control.log; fail=1
fi
exit $fail
