#!/usr/bin/env bash
# The fuzzing stage of CI (.ci/run; issue 40, item 2): libFuzzer harnesses of perilin's input
# readers (tests/fuzz/fuzz_*.c: the scene, particles.file CSV, the VTU of analysis.initial, the
# -restart checkpoint), under AddressSanitizer and UndefinedBehaviorSanitizer. They are built in the
# sanitizer stage's build directory (build-san, -DPERILIN_FUZZ=ON, which tests/sanitize/run.sh
# configures too): after that stage only the harnesses are compiled. The seeds are made here, at
# run time: the scenes of examples/ and tests/, the CSV files beside them, and the .vtu files and
# the checkpoint of runs of tiny scenes. Each harness runs for a bounded time, two at a time (CI
# has 2 cores); any finding (a crash, a sanitizer report, a leak, a timeout of 10 s on one input,
# more than 2 GB) fails the stage, its input kept in BUILD/fuzz/findings (docs/reliability.md
# "Fuzzing": each finding becomes a bad-input case and a fix).
# Usage: tests/fuzz/fuzz_stage.sh [--long SECONDS] [BUILD_DIR]   (default: 60 s per harness, build-san)
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
seconds=60
if [ "${1:-}" = --long ]; then
  seconds=${2:?--long needs a number of seconds per harness}
  shift 2
fi
build=${1:-$repo/build-san}
case $build in /*) ;; *) build=$PWD/$build ;; esac
harnesses=(scene csv vtu checkpoint)
t_start=$SECONDS

# the sanitizer stage's configuration, so that a build it left is reused as it is
if [ -f "$build/CMakeCache.txt" ] && ! grep -q '^CMAKE_C_COMPILER:.*clang' "$build/CMakeCache.txt"; then rm -rf "$build"; fi
mkdir -p "$build"
cmake -S "$repo" -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPERILIN_SANITIZE=ON -DPERILIN_FUZZ=ON > /dev/null
cmake --build "$build" -j 2 --target perilin fuzz_all > "$build/fuzz-build.log" 2>&1 || {
  tail -50 "$build/fuzz-build.log"
  exit 1
}
echo "fuzz: built in $((SECONDS - t_start)) s"

work=$build/fuzz
findings=$work/findings
rm -rf "$work/seeds" "$work/runs" "$findings"
mkdir -p "$work/seeds" "$work/runs" "$findings"
for h in "${harnesses[@]}"; do mkdir -p "$work/seeds/$h" "$work/corpus/$h"; done

# one file: LSan reads a single suppressions file (Open MPI's, then PETSc's of tests/fuzz/fuzz_lsan.supp)
cat "$repo/tests/sanitize/lsan.supp" "$repo/tests/fuzz/fuzz_lsan.supp" > "$work/lsan.supp"
# the slow unwinder: Debian's PETSc has no frame pointers, and with the fast one a leak's stack
# ends at PetscMallocAlign, where no suppression can match (a finding of 2026-11-29)
export ASAN_OPTIONS="detect_leaks=1:fast_unwind_on_malloc=0"
export LSAN_OPTIONS="suppressions=$work/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# Seeds. Scenes and CSV files: every one of the repository's (the bad-input cases too), named by
# their path. A file name in a seed directory is its content's only label for libFuzzer.
(cd "$repo" && find examples tests -name '*.yaml' -size -64k) | while read -r f; do cp "$repo/$f" "$work/seeds/scene/${f//\//_}"; done
(cd "$repo" && find examples tests -name '*.csv' -size -64k) | while read -r f; do cp "$repo/$f" "$work/seeds/csv/${f//\//_}"; done
# .vtu and .pvtu files of perilin: particles and modes on one rank, the pieces' index on two; the
# checkpoint of the checkpoint harness' own scene.
seedrun() {
  local name=$1 want=$2
  shift 2
  local code=0
  # leaks: the sanitizer stage's business (with its suppressions of Open MPI's); here only the files
  ASAN_OPTIONS=detect_leaks=0 "$@" -output_dir "$work/runs/$name" -output_plots false > "$work/runs/$name.log" 2>&1 < /dev/null || code=$?
  if [ "$code" -ne "$want" ]; then
    echo "fuzz: the seed run $name exited with $code, expected $want"
    tail -20 "$work/runs/$name.log"
    exit 1
  fi
}
seedrun modal 0 "$build/perilin" "$repo/tests/scenes/tiny_modal.yaml" -output_vtk true
seedrun modal_2ranks 0 mpiexec --oversubscribe -n 2 "$build/perilin" "$repo/tests/scenes/tiny_modal.yaml" -output_vtk true
# the checkpoint of the whole run (its last step): a restart from it reads, checks and restores the
# state, and solves nothing more (unless a mutation moves its load factor)
seedrun checkpoint 0 "$build/perilin" "$repo/tests/fuzz/checkpoint.yaml" -quiet
for f in "$work/runs/modal"/*.vtu "$work/runs/modal_2ranks"/*.pvtu "$work/runs/modal_2ranks"/particles/*.vtu; do
  cp "$f" "$work/seeds/vtu/$(basename "$(dirname "$f")")_$(basename "$f")"
done
cp "$work/runs/checkpoint/checkpoint/state.bin" "$work/seeds/checkpoint/state.bin"
# earlier findings, fixed (tests/fuzz/regressions/HARNESS-*): seeds too, so every run replays them
for h in "${harnesses[@]}"; do
  for f in "$repo/tests/fuzz/regressions/$h-"*; do if [ -e "$f" ]; then cp "$f" "$work/seeds/$h/"; fi; done
done
echo "fuzz: seeds made in $((SECONDS - t_start)) s"

# One harness: $seconds of fuzzing from its corpus (kept between runs) and the seeds; its report in
# runs/NAME.log, its findings (crash-*, leak-*, timeout-*, oom-*) in findings/.
fuzz() {
  local h=$1 unwind=1
  # the scene harness reaches PETSc's leak (lsan.supp), whose stack only the slow unwinder sees
  # through PETSc (no frame pointers); it costs the others most of their speed. Their leaks show
  # their stacks when the finding is run again with ASAN_OPTIONS=fast_unwind_on_malloc=0.
  [ "$h" = scene ] && unwind=0
  ASAN_OPTIONS="$ASAN_OPTIONS:fast_unwind_on_malloc=$unwind" "$build/tests/fuzz/fuzz_$h" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
    -close_fd_mask=1 -print_final_stats=1 -artifact_prefix="$findings/$h-" \
    "$work/corpus/$h" "$work/seeds/$h" > "$work/runs/fuzz_$h.log" 2>&1 < /dev/null
}
status=0
for pair in "scene csv" "vtu checkpoint"; do
  pids=()
  for h in $pair; do
    fuzz "$h" &
    pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p" || status=1; done
done

for h in "${harnesses[@]}"; do
  log=$work/runs/fuzz_$h.log
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  found=$(find "$findings" -name "$h-*" | wc -l)
  echo "fuzz: $h: ${runs:-?} inputs in ${seconds} s, corpus $(find "$work/corpus/$h" -type f | wc -l) files, $found finding(s)"
  if [ "$found" -gt 0 ] || ! grep -q '^Done [0-9]* runs' "$log"; then
    grep -E '^==[0-9]+==ERROR|SUMMARY|runtime error|^Done' "$log" | head -10
    status=1
  fi
done
[ $status -eq 0 ] && echo "ok: 4 fuzzers, $seconds s each, no finding ($((SECONDS - t_start)) s in all)"
[ $status -eq 0 ] || echo "fuzz: FAIL: the inputs are in $findings (reproduce: $build/tests/fuzz/fuzz_NAME FILE)"
exit $status
