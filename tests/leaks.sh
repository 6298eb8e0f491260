#!/usr/bin/env bash
# leaks.sh PERILIN EXAMPLES_DIR: runs a static, two modal (factorization, LOBPCG) and a quasi-static example and three failing
# runs (an input error, a solver failure, a LOBPCG out of iterations) under PETSc's -malloc_debug -malloc_dump, and fails when
# any run reports an unfreed block ("[rank] N bytes Function() at file:line"), reports corrupted
# memory, or ends differently than expected. Coarse grids keep the whole test at a few seconds.
set -u
perilin=$1
ex=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

# check NAME EXPECTED_EXIT STDERR_REGEX SCENE [OPTIONS...]
check() {
  local name=$1 want=$2 expect=$3 scene=$4
  shift 4
  local log="$tmp/$name.log" code problem="" t0 t1
  t0=$(date +%s.%N)
  "$perilin" "$ex/$scene" "$@" -output_dir "$tmp/$name-out" -malloc_debug -malloc_dump > "$log" 2>&1 < /dev/null
  code=$?
  t1=$(date +%s.%N)
  if [ "$code" -ne "$want" ]; then
    problem="exit code $code, expected $want"
  elif [ -n "$expect" ] && ! grep -Eq -- "$expect" "$log"; then
    problem="the output does not match '$expect'"
  elif grep -Eq '^\[ *[0-9]+\] [0-9]+ bytes ' "$log"; then
    problem="$(grep -Ec '^\[ *[0-9]+\] [0-9]+ bytes ' "$log") unfreed blocks"
  elif grep -Eiq 'corrupt|PetscMallocValidate' "$log"; then
    problem="corrupted memory"
  fi
  if [ -n "$problem" ]; then
    echo "FAIL $name: $problem"
    # the allocation sites, most frequent first
    grep -E '^\[ *[0-9]+\] [0-9]+ bytes ' "$log" | sed -E 's/^\[ *[0-9]+\] [0-9]+ bytes //' | sort | uniq -c | sort -rn | head -20 | sed 's/^/    /'
    grep -v -E '^\[ *[0-9]+\] [0-9]+ bytes ' "$log" | tail -5 | sed 's/^/    /'
    fail=$((fail + 1))
  else
    printf 'ok   %s (%.1f s)\n' "$name" "$(echo "$t1 - $t0" | bc)"
  fi
}

check static 0 'strain energy' pmb/plate_traction.yaml -grid_spacing 0.02
check modal 0 'modes \(Hz\)' lamina/modal.yaml -grid_spacing 0.05
check modal_lobpcg 0 'modes \(Hz\)' lamina/modal.yaml -grid_spacing 0.05 -model_type gerstle -analysis_eigensolver lobpcg
check modal_lobpcg_failure 1 'converged no mode' lamina/modal.yaml -grid_spacing 0.05 -model_type gerstle -analysis_eigensolver lobpcg -eps_max_it 2
check quasistatic 0 'strain energy' antiplane/cracked_bar.yaml -grid_spacing 0.05 -analysis_min_step 0.25 -quiet
check input_error 1 "unknown model 'nosuch'" pmb/plate_traction.yaml -grid_spacing 0.02 -model_type nosuch
check solver_failure 1 'did not converge' pmb/plate_traction.yaml -grid_spacing 0.02 -ksp_max_it 1

[ "$fail" -eq 0 ] && echo "leaks: all runs freed everything" || echo "leaks: $fail run(s) failed"
[ "$fail" -eq 0 ]
