#!/usr/bin/env bash
# The sanitizer stage of CI (.ci/run; issue 40, item 1): builds perilin and its tests with
# AddressSanitizer and UndefinedBehaviorSanitizer in build-san (-DPERILIN_SANITIZE=ON) and runs a
# subset of the tests under them (built with clang, see docs/build.md "Sanitizers"): every analysis
# once, 1 and 2 ranks, mesh input, restart, signals,
# and the error paths of the bad-input corpus. Every sanitizer report fails the stage, whatever the
# test itself decided: the reports go to files (log_path), not to the tests' stderr, because many
# tests expect perilin to fail and would take a sanitizer's exit status for the expected one.
# Usage: tests/sanitize/run.sh [BUILD_DIR]   (default build-san in the repository)
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$repo/build-san}
case $build in /*) ;; *) build=$PWD/$build ;; esac

# The ctest subset (anchored names), and below it direct runs of what the other tests reach only
# through scenes too large for a sanitized build: every analysis once, 1 and 2 ranks.
tests=(
  plate_traction plate_traction_2ranks             # static, matrix-free, 1 and 2 ranks
  affine_npmb_3d_2ranks                            # 3D, assembled, 2 ranks
  model_contract                                   # every model type
  lammps_lps_2ranks affine_lps_2d_stress           # lps: the state term matrix-free and assembled (B^T D B), 2 ranks
  mesh_read_tet_2ranks mesh_import_inp_tri         # Gmsh meshes; meshio's readers (a child process)
  csv_particles_npmb_2ranks                        # CSV particles
  analysis_setup                                   # the setup analysis, 1 and 2 ranks
  interrupt interrupt_input                        # SIGINT, SIGTERM, SIGHUP (and the signals cases below)
  contact                                          # contact, impactors, bc velocity; 1 and 2 ranks
  bad_input_syntax bad_input_filesystem            # the error paths of the readers and the output
)
ex=$repo/examples
# name, expected exit status, ranks, then perilin's arguments (the output directory is added)
scenarios=(
  "quasistatic_stop 130 2 $ex/antiplane/cracked_bar.yaml -grid_spacing 0.05 -quiet -peri_stop_after_step 3"
  "quasistatic_restart 0 2 $ex/antiplane/cracked_bar.yaml -grid_spacing 0.05 -quiet -restart @quasistatic_stop"
  "quasistatic_events 0 1 $ex/fracture/edge_crack.yaml -grid_spacing 0.04 -quiet -analysis_stepping events"
  "modal 0 1 $repo/tests/scenes/tiny_modal.yaml"
  "modal_2ranks 0 2 $ex/lamina/modal.yaml -grid_spacing 0.05"
  "dynamic_explicit 0 2 $ex/dynamics/pulse.yaml -analysis_t_end 40"
  "dynamic_implicit 0 1 $ex/dynamics/pulse.yaml -analysis_integrator implicit -analysis_dt 0.4 -analysis_t_end 10"
  "anisotropy 0 1 $ex/failure/anisotropy.yaml -analysis_m 2 -analysis_orientations 11 -analysis_criteria stretch,sliding"
  "tune 0 1 $ex/tuning/plate_tune.yaml -grid_spacing 0.02 -analysis_repeat 1"
  "mesh_2ranks 0 2 $ex/mesh/bar_tet.yaml"
  "dynamic_stop 130 2 $ex/dynamics/kalthoff_winkler.yaml -grid_spacing 4e-3 -quiet -peri_stop_after_step 40"
  "dynamic_restart 0 2 $ex/dynamics/kalthoff_winkler.yaml -grid_spacing 4e-3 -quiet -restart @dynamic_stop"
)

# clang (Debian's clang, .ci/install): its runtime holds both sanitizers, and writes UBSan's reports to
# log_path too; with gcc's separate libubsan they go to stderr, where a test may not look.
if [ -f "$build/CMakeCache.txt" ] && ! grep -q '^CMAKE_C_COMPILER:.*clang' "$build/CMakeCache.txt"; then rm -rf "$build"; fi
cmake -S "$repo" -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPERILIN_SANITIZE=ON -DPERILIN_FUZZ=ON > /dev/null
cmake --build "$build" -j 2 > "$build/build.log" 2>&1 || {
  tail -50 "$build/build.log"
  exit 1
}

logs=$build/sanitizer-logs
rm -rf "$logs"
mkdir -p "$logs"
# detect_leaks stays on: perilin pauses the leak check around MPI's start and end (PeriInitialize),
# lsan.supp names what else Open MPI keeps; fast_unwind_on_malloc=0 unwinds through the libraries
# built without frame pointers, so that the suppressions match (0.4 s more per process).
export ASAN_OPTIONS="log_path=$logs/asan:detect_leaks=1:fast_unwind_on_malloc=0"
export LSAN_OPTIONS="suppressions=$repo/tests/sanitize/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="log_path=$logs/ubsan:print_stacktrace=1:halt_on_error=1"

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

status=0
runs=$build/sanitizer-runs
rm -rf "$runs"
mkdir -p "$runs"
for sc in "${scenarios[@]}"; do
  read -r name want np args <<< "$sc"
  args=${args//@/$runs/} # @NAME: the output directory of an earlier scenario
  launch=()
  [ "$np" -gt 1 ] && launch=(mpiexec --oversubscribe -n "$np")
  t0=$SECONDS
  code=0
  # shellcheck disable=SC2086
  timeout -k 5 300 "${launch[@]}" "$build/perilin" $args -output_dir "$runs/$name" -output_plots false > "$runs/$name.log" 2>&1 < /dev/null || code=$?
  if [ "$code" -ne "$want" ]; then
    echo "FAIL: sanitize run $name: exit status $code, expected $want"
    tail -20 "$runs/$name.log"
    status=1
  else
    echo "ok: sanitize run $name ($np rank(s), exit $code, $((SECONDS - t0)) s)"
  fi
done

# The signals cases (tests/bad_input/signals), but those that signal mpiexec or the process group
# during a quasi-static run: mpiexec kills its ranks 1 s after forwarding the signal
# (docs/reliability.md, "Limits"), before a sanitized rank has written its set. Raising
# OMPI_MCA_odls_base_sigkill_timeout instead makes every failing 2-rank run wait that long.
mkdir -p "$runs/cases/signals"
for f in "$repo"/tests/bad_input/signals/*.yaml; do
  case $(basename "$f") in quasistatic_*_group.yaml | quasistatic_*_mpiexec.yaml) continue ;; esac
  cp "$f" "$runs/cases/signals/"
done
t0=$SECONDS
bash "$repo/tests/bad_input/bad_input.sh" "$build/perilin" "$runs/cases" signals > "$runs/signals.log" 2>&1 || {
  grep FAIL "$runs/signals.log"
  status=1
}
echo "$(tail -1 "$runs/signals.log") ($((SECONDS - t0)) s)"

regex="^($(
  IFS='|'
  echo "${tests[*]}"
))\$"
ctest --test-dir "$build" --output-on-failure -j 2 -R "$regex" || status=1
ran=$(ctest --test-dir "$build" -N -R "$regex" | grep -c 'Test *#' || true)
if [ "$ran" -ne "${#tests[@]}" ]; then
  echo "sanitize: the subset names ${#tests[@]} tests, ctest found $ran: a test was renamed or removed"
  status=1
fi
reports=$(find "$logs" -type f | sort)
if [ -n "$reports" ]; then
  echo "sanitize: $(echo "$reports" | wc -l) sanitizer report(s):"
  for f in $reports; do
    echo "==== $f"
    head -60 "$f"
  done
  status=1
fi
[ $status -eq 0 ] && echo "ok: ${#tests[@]} tests, ${#scenarios[@]} runs and the signals cases under AddressSanitizer and UndefinedBehaviorSanitizer, no report"
exit $status
