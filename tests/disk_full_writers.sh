#!/usr/bin/env bash
# A full disk while one file of the final output set is written (issue 40), without root (the tmpfs
# of disk_full_final.sh needs it): as soon as the run's staging directory appears, the temporary
# name of one output (summary.json.tmp, particles.vtu.tmp, scene.yaml.tmp, particles.pvtu.tmp,
# history.csv.tmp) is made a symbolic link to /dev/full, as disk_full.sh does for a checkpoint, so
# that file's writes fail with ENOSPC. Each run must exit 1 with one message naming that file and
# "No space left on device", and write no output directory:
#  - static (the plate of examples/pmb/plate_traction.yaml at 2.5 mm, 1 s): no staging directory
#    left either, and a previous output set stays the same bytes; particles.pvtu on 2 ranks too;
#  - dynamic (Kalthoff-Winkler at 4 mm, which writes checkpoints): the staging directory is kept
#    with its whole checkpoint and said with -restart; -restart from it ends the run complete.
# usage: disk_full_writers.sh PERILIN REPO MPIEXEC...   (MPIEXEC: the command that runs 2 ranks)
set -u
# shellcheck source=tests/run_scratch.sh
source "$(dirname "$0")/run_scratch.sh"
[ -w /dev/full ] || { echo "SKIP: no /dev/full"; exit 77; }

# full NAME FILE launcher... -- SCENE OPTIONS...: the run into $tmp/NAME with FILE's temporary
# name on /dev/full; sets $partial (the staging directory) and checks the exit and the message
full() {
  local name=$1 file=$2 d=$tmp/$1 pid st launch=() run=()
  shift 2
  split_run "$@" -quiet
  "${launch[@]}" "$exe" "${run[@]}" -output_dir "$d" > "$d.log" 2>&1 < /dev/null &
  pid=$!
  await $pid "$d.partial-*"
  partial=$(compgen -G "$d.partial-*")
  [ -n "$partial" ] && ln -s /dev/full "$partial/$file.tmp"
  wait $pid
  st=$?
  [ -n "$partial" ] || { bad "$name: no staging directory appeared (exit $st): $(cat "$d.log")"; return 1; }
  [ $st -eq 1 ] || bad "$name: exit $st, expected 1"
  grep -q "^perilin: error: Error writing $partial/$file.tmp: No space left on device" "$d.log" || bad "$name: the message does not name $file.tmp and the cause: $(cat "$d.log")"
  [ "$(grep -c '^perilin: error:' "$d.log")" -eq 1 ] || bad "$name: not one error message: $(cat "$d.log")"
  [ -L "$partial/$file.tmp" ] && bad "$name: the link $file.tmp was left"
  return 0
}

plate=("$repo/examples/pmb/plate_traction.yaml" -grid_spacing 0.0025)
# a previous complete set in the output directory of the first case: it must stay as it was
"$exe" "${plate[@]}" -quiet -output_dir "$tmp/static_summary" > /dev/null 2>&1 < /dev/null || bad "the plate's complete run failed"
before=$(cd "$tmp/static_summary" && md5sum summary.json particles.vtu scene.yaml)
for file in summary.json particles.vtu scene.yaml; do
  name=static_${file%%.*}
  full "$name" "$file" env -- "${plate[@]}" || continue
  [ -e "$partial" ] && bad "$name: the staging directory $partial was left"
  if [ "$file" = summary.json ]; then
    [ "$(cd "$tmp/$name" && md5sum summary.json particles.vtu scene.yaml)" = "$before" ] || bad "$name: the previous output set changed"
  else
    [ -e "$tmp/$name" ] && bad "$name: an output directory was written"
  fi
done
if [ ${#mpi[@]} -gt 0 ] && full static_pvtu_2ranks particles.pvtu "${mpi[@]}" -- "${plate[@]}"; then
  [ -e "$partial" ] && bad "static_pvtu_2ranks: the staging directory $partial was left"
  [ -e "$tmp/static_pvtu_2ranks" ] && bad "static_pvtu_2ranks: an output directory was written"
fi
[ $fail -eq 0 ] && echo "ok: static: summary.json, particles.vtu, scene.yaml (and particles.pvtu on 2 ranks) on a full disk: exit 1 naming the file and ENOSPC, nothing left, a previous set kept"

kw=("$repo/examples/dynamics/kalthoff_winkler.yaml" -grid_spacing 4e-3)
for file in history.csv summary.json; do
  name=dynamic_${file%%.*}
  full "$name" "$file" env -- "${kw[@]}" || continue
  [ -e "$tmp/$name" ] && bad "$name: an output directory was written"
  [ -f "$partial/checkpoint/state.bin" ] || { bad "$name: the staging directory with its checkpoint was not kept: $(ls -A "$partial" 2>&1)"; continue; }
  grep -q "^perilin: the run's last checkpoint is kept whole in $partial: free space, then continue with -restart $partial" "$tmp/$name.log" || bad "$name: the kept checkpoint is not said: $(cat "$tmp/$name.log")"
  [ "$file" = history.csv ] || continue
  "$exe" "${kw[@]}" -quiet -restart "$partial" -output_dir "$tmp/$name.cont" > "$tmp/$name.cont.log" 2>&1 < /dev/null || bad "$name: -restart $partial exited $?: $(cat "$tmp/$name.cont.log")"
  grep -q '"complete": true' "$tmp/$name.cont/summary.json" 2> /dev/null || bad "$name: the restarted run is not complete"
  [ -s "$tmp/$name.cont/history.csv" ] || bad "$name: the restarted run wrote no history.csv"
done
[ $fail -eq 0 ] && echo "ok: dynamic: history.csv, summary.json on a full disk: exit 1 naming the file and ENOSPC, the staging directory kept with its checkpoint; -restart from it ends complete"
exit $fail
