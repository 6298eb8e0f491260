#!/usr/bin/env bash
# A full disk while a run writes its results (issue 40): the output directory lies on a small tmpfs
# (mounted here: root only, else skipped with 77) that holds less than the run's output set.
#  - static (the plate of examples/pmb/plate_traction.yaml): exit 1, the message names the file
#    and "No space left on device", nothing is left (no output, no staging directory);
#  - quasi-static (the edge crack, which writes a checkpoint at each equilibrium): the same
#    message, and the staging directory is kept with the last whole checkpoint, said on stderr;
#    once there is space, -restart from it ends the run complete.
# usage: disk_full_final.sh PERILIN REPO
set -u
# shellcheck source=tests/run_scratch.sh
source "$(dirname "$0")/run_scratch.sh"
mnt=$tmp/small
on_exit='umount "$mnt" 2> /dev/null'
mkdir -p "$mnt"
mount -t tmpfs -o size=64k tmpfs "$mnt" 2> /dev/null || { echo "SKIP: cannot mount a tmpfs here (needs root)"; exit 77; }
umount "$mnt"

# full NAME SIZE_KB SCENE OPTIONS...: the run into $mnt/out on a tmpfs of SIZE_KB
full() {
  local name=$1 size=$2
  shift 2
  mount -t tmpfs -o size="${size}k" tmpfs "$mnt" || { bad "$name: mount"; return 1; }
  "$exe" "$@" -quiet -output_dir "$mnt/out" > "$tmp/$name.log" 2>&1 < /dev/null
  st=$?
  [ $st -eq 1 ] || bad "$name: exit $st, expected 1"
  grep -Eq "perilin: error: .*$mnt/out\.partial-[A-Za-z0-9]+/[^ ]*: No space left on device" "$tmp/$name.log" || bad "$name: the message does not name the file and the cause: $(cat "$tmp/$name.log")"
  [ -e "$mnt/out" ] && bad "$name: an output directory was left"
  return 0
}
# the size of a run's whole output set, in KB
outsize() { "$exe" "$@" -quiet -output_dir "$tmp/whole" > /dev/null 2>&1 && du -sk "$tmp/whole" | cut -f1 && rm -rf "$tmp/whole"; }

plate=("$repo/examples/pmb/plate_traction.yaml")
T=$(outsize "${plate[@]}")
full static $((T / 2)) "${plate[@]}"
[ -z "$(ls -A "$mnt")" ] || bad "static: left behind: $(ls -A "$mnt")"
[ $fail -eq 0 ] && echo "ok: static: $(grep -o 'error: .*device' "$tmp/static.log"); nothing left"
umount "$mnt"

qs=("$repo/examples/fracture/edge_crack.yaml" -grid_spacing 0.025 -analysis_min_step 1.25)
T=$(outsize "${qs[@]}")
full quasistatic $((T * 5 / 6)) "${qs[@]}"
staging=$(compgen -G "$mnt/out.partial-*")
if [ -n "$staging" ] && [ -f "$staging/checkpoint/state.bin" ]; then
  grep -q "perilin: the run's last checkpoint is kept whole in $staging: free space, then continue with -restart $staging" "$tmp/quasistatic.log" || bad "quasistatic: the kept checkpoint is not said: $(cat "$tmp/quasistatic.log")"
  cp -a "$staging" "$tmp/kept"
  umount "$mnt"
  "$exe" "${qs[@]}" -quiet -restart "$tmp/kept" -output_dir "$tmp/cont" > "$tmp/cont.log" 2>&1 < /dev/null || bad "quasistatic: -restart from the kept checkpoint exited $?: $(cat "$tmp/cont.log")"
  grep -q '"complete": true' "$tmp/cont/summary.json" 2> /dev/null || bad "quasistatic: the restarted run is not complete"
  [ $fail -eq 0 ] && echo "ok: quasistatic: $(grep -o 'error: .*device' "$tmp/quasistatic.log"); the staging directory kept with its checkpoint; -restart from it ends complete"
else
  bad "quasistatic: no staging directory with a checkpoint was kept: $(ls -A "$mnt"; cat "$tmp/quasistatic.log")"
fi
exit $fail
