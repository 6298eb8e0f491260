#!/usr/bin/env bash
# A full disk during a checkpoint write (issue 40, item 3): once the quasi-static edge crack (or the
# dynamic Kalthoff-Winkler plate) has written its first checkpoint, checkpoint/state.bin.tmp in its staging directory is made a
# symbolic link to /dev/full (every write fails with ENOSPC), so the next checkpoint cannot be
# written. The run must stop with exit 1 and a message naming the file and "No space left on
# device", leave no output directory, and keep the staging directory with the previous checkpoint
# whole: -restart from it runs to the end. On 1 and 2 ranks (rank 0 writes the file).
# usage: disk_full.sh PERILIN REPO MPIEXEC...   (MPIEXEC: the command that runs 2 ranks)
set -u
# shellcheck source=tests/run_scratch.sh
source "$(dirname "$0")/run_scratch.sh"
[ -w /dev/full ] || { echo "SKIP: no /dev/full"; exit 77; }

full() { # NAME launcher... -- SCENE OPTIONS...
  local name=$1 d=$tmp/$1 pid st partial launch=() run=()
  shift
  split_run "$@" -quiet
  "${launch[@]}" "$exe" "${run[@]}" -output_dir "$d" > "$d.log" 2>&1 < /dev/null &
  pid=$!
  await $pid "$d.partial-*/checkpoint/state.bin"
  partial=$(compgen -G "$d.partial-*")
  # not while a checkpoint is being written (then state.bin.tmp exists): the link would be
  # renamed into place as if it were the written file
  until [ -z "$partial" ] || ln -s /dev/full "$partial/checkpoint/state.bin.tmp" 2> /dev/null; do
    kill -0 $pid 2> /dev/null || break
    sleep 0.002
  done
  wait $pid
  st=$?
  [ -n "$partial" ] || { bad "$name: no staging directory with a checkpoint appeared (exit $st)"; cat "$d.log"; return; }
  [ $st -eq 1 ] || bad "$name: exit $st, expected 1"
  grep -q "perilin: error: cannot write the checkpoint $partial/checkpoint/state.bin.tmp: No space left on device" "$d.log" || bad "$name: the message does not name the file and the cause: $(cat "$d.log")"
  grep -q -- "-restart $partial" "$d.log" || bad "$name: the message does not say -restart $partial"
  [ -e "$d" ] && bad "$name: an output directory $d was left"
  [ -e "$partial/checkpoint/state.bin.tmp" ] && bad "$name: the link state.bin.tmp was left"
  [ -f "$partial/checkpoint/state.bin" ] && [ ! -L "$partial/checkpoint/state.bin" ] || { bad "$name: state.bin is no longer the previous checkpoint"; ls -la "$partial/checkpoint"; return; }
  "${launch[@]}" "$exe" "${run[@]}" -restart "$partial" -output_dir "$d.cont" > "$d.cont.log" 2>&1 < /dev/null || { bad "$name: -restart $partial exited $?"; cat "$d.cont.log"; return; }
  grep -q '"complete": true' "$d.cont/summary.json" || bad "$name: the restarted run is not complete"
  [ $fail -eq 0 ] && echo "ok: $name: $(grep -o 'cannot write.*device' "$d.log"); restarted from the previous checkpoint to the end"
}

qs=("$repo/examples/fracture/edge_crack.yaml" -grid_spacing 0.025 -analysis_min_step 1.25)
full quasistatic env -- "${qs[@]}"
[ ${#mpi[@]} -gt 0 ] && full quasistatic_2ranks "${mpi[@]}" -- "${qs[@]}"
full dynamic env -- "$repo/examples/dynamics/kalthoff_winkler.yaml" -grid_spacing 4e-3
exit $fail
