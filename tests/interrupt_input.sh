#!/bin/bash
# SIGTERM, or a closed terminal or ssh session (SIGHUP), while perilin still reads its scene: the
# scene comes from a pipe that never ends (a generator that stalls), so the read blocks. perilin
# must notice the signal, say so naming it, exit with 128 + the signal (143, 129) and write nothing.
# usage: interrupt_input.sh PERILIN SCENE
set -u
exe=$1; scene=$2
tmp=$(mktemp -d)
writer=""
cleanup() {
  [ -n "$writer" ] && kill "$writer" 2> /dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; cat "$tmp/log"; exit 1; }
mkfifo "$tmp/scene.yaml"
for sig in TERM HUP; do
  # the first lines of a valid scene, then the writer keeps the pipe open without writing
  { head -n 3 "$scene"; exec sleep 60; } > "$tmp/scene.yaml" &
  writer=$!
  "$exe" "$tmp/scene.yaml" -output_dir "$tmp/out" > "$tmp/log" 2>&1 &
  pid=$!
  # the signal once perilin reads the pipe (its start takes seconds under AddressSanitizer), and 1 s more
  for _ in $(seq 100); do
    ls -l "/proc/$pid/fd" 2> /dev/null | grep -q "$tmp/scene.yaml" && break
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.2
  done
  sleep 1
  kill -0 "$pid" 2> /dev/null || fail "SIG$sig: perilin did not wait for the pipe"
  kill -s $sig "$pid"
  for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.2; done
  kill -0 "$pid" 2> /dev/null && { kill -s KILL "$pid"; fail "SIG$sig: still reading 10 s after the signal"; }
  wait "$pid"
  rc=$?
  kill "$writer" 2> /dev/null
  wait "$writer" 2> /dev/null
  writer=""
  want=$((128 + $(kill -l $sig)))
  [ "$rc" -eq $want ] || fail "SIG$sig: exit status $rc, expected $want"
  grep -q "perilin: error: interrupted by SIG$sig while reading the scene $tmp/scene.yaml: nothing was written" "$tmp/log" || fail "SIG$sig: the message does not name the signal and the scene"
  [ "$(grep -c 'perilin: error:' "$tmp/log")" -eq 1 ] || fail "SIG$sig: 'perilin: error:' not printed exactly once"
  ls "$tmp" | grep -qv '^scene.yaml$\|^log$' && fail "SIG$sig: something was written: $(ls "$tmp")"
  echo "ok: SIG$sig while the scene is read: exit $rc, $(grep -m1 'perilin: error:' "$tmp/log")"
done
