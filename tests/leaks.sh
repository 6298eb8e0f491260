#!/usr/bin/env bash
# leaks.sh PERILIN EXAMPLES_DIR: runs a static, two modal (factorization, LOBPCG) and a quasi-static example and failing
# runs (an input error, a solver failure, a LOBPCG out of iterations, refusals of bad_input cases) under PETSc's -malloc_debug -malloc_dump, and fails when
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
  case $scene in /*) ;; *) scene=$ex/$scene ;; esac # a scene of the examples, or one written here
  "$perilin" "$scene" "$@" -output_dir "$tmp/$name-out" -malloc_debug -malloc_dump > "$log" 2>&1 < /dev/null
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

# Refusals that stop a run after its solver, pieces or regions were made (issue 40, item 5: each
# leaked before): a bad_input case, its expected message and options from its header.
refused() { # CATEGORY/NAME
  local f="$ex/../tests/bad_input/$1.yaml"
  # shellcheck disable=SC2046 # the header's options, word-split as bad_input.sh does
  check "refused_${1#*/}" 1 "$(sed -n 's/^# expect: //p' "$f")" "../tests/bad_input/$1.yaml" $(sed -n 's/^# args: //p' "$f")
}
refused physics/rigid_free                # the static solve: loads unbalanced along a free motion
refused physics/crack_loaded_piece        # the pieces cut off by cracks
refused physics/chain_unheld              # particles their bonds cannot hold
refused sizes/empty_region                # a region without particles
refused ranges/mu_by_region_zero          # a shear modulus by region <= 0
refused solver/tune_none_converged        # no tune configuration converges
refused solver/modal_st_jacobi            # an inexact inner solve: stopped inside SLEPc's EPSSolve
# unknown solver types: PETSc 3.18's own refusal (inside KSPSetFromOptions, PCSetFromOptions,
# STSetFromOptions) leaked its 16-byte copy of the name; perilin refuses them first (option_types.c)
refused solver/ksp_nonsense
refused solver/pc_nonexistent
refused solver/modal_st_type_nonsense
refused solver/tune_pc_type_unknown
# a tune configuration's -solver_operator outside its choices: PETSc's PetscOptionsGetEList leaked
# 48 bytes on its refusal; tune.c matches the value itself
refused solver/tune_operator_unknown
# analysis.initial from another body (src/system/readback.c): the file read, then refused
cat > "$tmp/pushed.yaml" << 'EOF'
dim: 2
model: {type: pmb, plane: stress}
material: {E: 1.0e4, rho: 1, thickness: 1}
grid: {lower: [0, 0], upper: [1, 0.5], spacing: 0.1}
horizon: {m: 3}
loads:
  - {region: all, force: [1, 0]}
analysis: {type: dynamic, t_end: 0.002}
output: {vtk: true, plots: false}
EOF
check dynamic 0 'explicit dynamics' "$tmp/pushed.yaml"
# -restart from a damaged checkpoint (the dynamic run's own, cut short): refused after the run's set-up
cp -r "$tmp/dynamic-out" "$tmp/cut"
truncate -s -30 "$tmp/cut/checkpoint/state.bin"
check refused_restart_cut 1 'state\.bin is cut short' "$tmp/pushed.yaml" -restart "$tmp/cut"
# a quasi-static checkpoint whose first step's load factor is a NaN (offset 100, as the case
# filesystem/restart_nan_steps): refused while the steps are read (found by the checkpoint fuzzer)
check checkpoint_scene 0 'strain energy' "$ex/../tests/fuzz/checkpoint.yaml" -quiet
printf '\177\370\0\0\0\0\0\0' | dd of="$tmp/checkpoint_scene-out/checkpoint/state.bin" bs=1 seek=100 conv=notrunc 2> /dev/null
check refused_restart_nan 1 'is damaged: its steps' "$ex/../tests/fuzz/checkpoint.yaml" -restart "$tmp/checkpoint_scene-out"
sed "s|t_end: 0.002|t_end: 0.002, initial: {file: $tmp/dynamic-out/particles.vtu}|" "$tmp/pushed.yaml" > "$tmp/pushed_initial.yaml"
check refused_initial_other_body 1 'holds 50 particles, the body 200: the file must come from the same body' "$tmp/pushed_initial.yaml" -grid_spacing 0.05

[ "$fail" -eq 0 ] && echo "leaks: all runs freed everything" || echo "leaks: $fail run(s) failed"
[ "$fail" -eq 0 ]
