#!/usr/bin/env bash
# Characterization guards ("goldens", ARCHITECTURE.md section 11, step 0).
#
# usage: golden.sh PERILIN REPO_DIR [--update]
#
# Runs eight one-rank scenes, each into a fresh output directory, and compares what perilin writes
# with the expectations committed in tests/golden/expected/<name>/, plus `perilin -help` with
# expected/help.txt. The expectations are perilin's own output, by design: these are guards
# against UNINTENDED change during the refactoring, not physics tests. The physics is asserted by
# the other tests, against exact solutions and the papers. A green golden says "nothing changed",
# not "this is right".
#
# Compared (the rules, and why some keys are left out, are in golden.py's header):
#   summary.json     minus the volatile keys (timing, memory_mb, memory_mb_max_rank, scene,
#                    modal.factorization_s, modal.eigensolve_s, quasistatic.checkpoint_s and unfinished_s), the values of build.* and
#                    command_line as "<varies>"; numbers to 1e-9 relative;
#                    round-off quantities (residual norms, load_share_removed, the mean interior
#                    strain of the bending scene) by order of magnitude only
#   modes.csv        same numeric rule, column names exactly
#   steps.csv        minus the `seconds` column, same numeric rule
#   *.vtu, *.pvd     the set of DataArray names and NumberOfComponents (XML header only, not the
#                    appended binary data); the files a .pvd indexes
#   the names of the files in the output directory
#   perilin -help    exactly (expected/help.txt: perilin's usage, options and scene keys; PETSc's
#                    generic list is printed only under -help petsc, so this does not depend on
#                    the installed PETSc)
#
# --update regenerates the expectations, for a step that changes an output on purpose: files
# that still compare equal are left untouched, so `git diff tests/golden/expected` shows exactly
# what changed. Review that diff before committing it.
set -u
exe=${1:?usage: golden.sh PERILIN REPO_DIR [--update]}
repo=${2:?usage: golden.sh PERILIN REPO_DIR [--update]}
update=""
[ "${3:-}" = "--update" ] && update="--update"
here=$(cd "$(dirname "$0")" && pwd)
expected="$here/expected"
py="$here/golden.py"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# the environment must not change a run: no options from outside, no threaded BLAS
unset PETSC_OPTIONS SLEPC_OPTIONS
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
cd "$tmp" || exit 1

# name | scene (relative to REPO_DIR) | options (each run takes about a second or less)
scenes=(
  "plate_traction|examples/pmb/plate_traction.yaml|"
  "lamina_bending|examples/lamina/bending.yaml|"
  "bar_modes|examples/pmb/bar_modes.yaml|"
  "tiny_modal|tests/scenes/tiny_modal.yaml|"
  "edge_crack|examples/fracture/edge_crack.yaml|-grid_spacing 0.04 -quiet"
  "square_bar|examples/antiplane/square_bar.yaml|"
  "torsion_rect_bar|examples/torsion/rect_bar.yaml|"
  "softening_bar|tests/scenes/softening_bar.yaml|"
)

fail=0
# elapsed seconds since a `date +%s%N` stamp, to 0.1 s
since() { local d=$((($(date +%s%N) - $1) / 100000000)); echo "$((d / 10)).$((d % 10))"; }
t0=$(date +%s%N)
for entry in "${scenes[@]}"; do
  IFS='|' read -r name scene opts <<< "$entry"
  out="$tmp/$name-out"
  s0=$(date +%s%N)
  # shellcheck disable=SC2086
  "$exe" "$repo/$scene" $opts -output_dir "$out" > "$tmp/$name.log" 2>&1 < /dev/null
  code=$?
  secs=$(since "$s0")
  if [ "$code" -ne 0 ]; then
    echo "FAIL: $name: perilin $scene${opts:+ $opts} exited $code"
    tail -n 20 "$tmp/$name.log"
    fail=1
    continue
  fi
  python3 "$py" normalize "$out" "$tmp/$name-norm" || { echo "FAIL: $name: cannot read the output"; fail=1; continue; }
  if python3 "$py" compare "$tmp/$name-norm" "$expected/$name" $update > "$tmp/$name.cmp" 2>&1; then
    [ -n "$update" ] && cat "$tmp/$name.cmp"
    echo "ok: $name ($scene${opts:+ $opts}, ${secs} s)"
  else
    echo "FAIL: $name ($scene${opts:+ $opts}) differs from tests/golden/expected/$name:"
    cat "$tmp/$name.cmp"
    fail=1
  fi
done

"$exe" -help > "$tmp/help.txt" 2>&1 < /dev/null
code=$?
if [ "$code" -ne 0 ]; then
  echo "FAIL: perilin -help exited $code"
  fail=1
elif ! diff -u "$expected/help.txt" "$tmp/help.txt" > "$tmp/help.diff" 2>&1; then
  if [ -n "$update" ]; then
    mkdir -p "$expected" && cp "$tmp/help.txt" "$expected/help.txt"
    echo "  updated $expected/help.txt"
    echo "ok: perilin -help"
  else
    echo "FAIL: perilin -help differs from tests/golden/expected/help.txt:"
    cat "$tmp/help.diff"
    fail=1
  fi
else
  echo "ok: perilin -help"
fi

total=$(since "$t0")
if [ -n "$update" ] && [ "$fail" -eq 0 ]; then
  echo "golden: expectations updated where they differed (${total} s); review git diff tests/golden/expected"
  exit 0
fi
[ "$fail" -eq 0 ] && echo "golden: all outputs as expected (${total} s)" || echo "golden: differences found (${total} s); if intended, rerun with --update and review git diff tests/golden/expected"
exit "$fail"
