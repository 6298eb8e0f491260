#!/bin/bash
# Ctrl-C in the middle of a quasi-static run: perilin must stop after the current solve, write
# steps.csv, particles.vtu and summary.json with "complete": false, and exit with 130.
# usage: interrupt.sh PERILIN SCENE
set -u
exe=$1; scene=$2
out=$(mktemp -d)
timeout --preserve-status -s INT 5 "$exe" "$scene" -grid_spacing 0.01 -output_dir "$out/run" -quiet > "$out/log" 2>&1
rc=$?
fail() { echo "FAIL: $*"; cat "$out/log"; rm -rf "$out"; exit 1; }
[ "$rc" -eq 130 ] || fail "exit status $rc, expected 130 (interrupted)"
for f in steps.csv particles.vtu summary.json; do [ -s "$out/run/$f" ] || fail "no $f"; done
grep -q '"complete": false' "$out/run/summary.json" || fail "summary.json is not marked incomplete"
ls "$out/run" | grep -q '\.tmp$' && fail "a temporary file was left behind"
echo "ok: interrupted run wrote its results, marked incomplete, exit 130"
rm -rf "$out"
