#!/bin/bash
# Ctrl-C (SIGINT), or a closed terminal or ssh session (SIGHUP), in the middle of a quasi-static
# run: perilin must stop after the current solve, write steps.csv, particles.vtu and summary.json
# with "complete": false and the signal's name, and exit with 128 + the signal (130, 129).
# usage: interrupt.sh PERILIN SCENE
set -u
exe=$1; scene=$2
out=$(mktemp -d)
fail() { echo "FAIL: $*"; cat "$out/log"; rm -rf "$out"; exit 1; }
for sig in INT HUP; do
  rm -rf "$out/run"
  timeout --preserve-status -s $sig 5 "$exe" "$scene" -grid_spacing 0.01 -output_dir "$out/run" -quiet > "$out/log" 2>&1
  rc=$?
  want=$((128 + $(kill -l $sig)))
  [ "$rc" -eq $want ] || fail "SIG$sig: exit status $rc, expected $want (interrupted)"
  for f in steps.csv particles.vtu summary.json; do [ -s "$out/run/$f" ] || fail "SIG$sig: no $f"; done
  grep -q '"complete": false' "$out/run/summary.json" || fail "SIG$sig: summary.json is not marked incomplete"
  grep -q "\"interrupted_by\": \"SIG$sig\"" "$out/run/summary.json" || fail "SIG$sig: summary.json does not name the signal"
  ls "$out/run" | grep -q '\.tmp$' && fail "SIG$sig: a temporary file was left behind"
  echo "ok: SIG$sig: the interrupted run wrote its results, marked incomplete, exit $rc"
done
rm -rf "$out"
