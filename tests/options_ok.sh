#!/usr/bin/env bash
# options_ok.sh PERILIN SCENE: options that name nothing are errors unless -options_unused_ok
# (docs/scene.md, "Options that name nothing"). Checks that
#   1. with -options_unused_ok a misspelt scene option and a misspelt PETSc option are warnings
#      (printed once, with the suggestion), the run succeeds and writes its results;
#   2. without it, common global options that PETSc reads at the end (-options_left, ...) or at
#      start-up (-log_view, -malloc_dump, ...) and options of the solver used are no error.
set -u
perilin=$1
scene=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

"$perilin" "$scene" -output_dir "$tmp/ok" -options_unused_ok -ksp_rtoll 1e-8 -material_nuu 0.3 > "$tmp/stdout" 2> "$tmp/stderr" < /dev/null
code=$?
if [ "$code" -ne 0 ]; then
  echo "FAIL -options_unused_ok: exit status $code"; fail=1
elif ! grep -q "perilin: warning: unknown option -material_nuu (the scene file has no key 'nuu' in 'material'; did you mean -material_nu?); ignored (-options_unused_ok)" "$tmp/stderr"; then
  echo "FAIL -options_unused_ok: no warning for -material_nuu"; fail=1
elif ! grep -q "perilin: warning: unknown option -ksp_rtoll (did you mean -ksp_rtol?); ignored (-options_unused_ok)" "$tmp/stderr"; then
  echo "FAIL -options_unused_ok: no warning for -ksp_rtoll"; fail=1
elif [ "$(grep -c 'perilin: warning: unknown option' "$tmp/stderr")" -ne 2 ]; then
  echo "FAIL -options_unused_ok: the warnings are not printed once each"; fail=1
elif [ ! -f "$tmp/ok/summary.json" ]; then
  echo "FAIL -options_unused_ok: no summary.json"; fail=1
else
  echo "ok   -options_unused_ok: exit 0, two warnings, results written"
fi
[ "$fail" -ne 0 ] && sed 's/^/    /' "$tmp/stderr"

"$perilin" "$scene" -output_dir "$tmp/global" -options_left -options_view -log_view -malloc_dump -malloc_debug -ksp_monitor -ksp_view -ksp_converged_reason -pc_type gamg -pc_gamg_threshold 0.01 -mg_levels_ksp_type richardson -mat_type aij -info :none > "$tmp/stdout" 2> "$tmp/stderr" < /dev/null
code=$?
if [ "$code" -ne 0 ] || grep -q 'perilin: error' "$tmp/stderr"; then
  echo "FAIL global options: exit status $code"; sed 's/^/    /' "$tmp/stderr" | head -5; fail=1
else
  echo "ok   global options: exit 0"
fi
[ "$fail" -eq 0 ]
