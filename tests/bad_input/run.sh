#!/usr/bin/env bash
# Every scene here is invalid: perilin must exit non-zero, print the message of its "# expect:"
# line (a regular expression), crash on none, and leave no output directory behind.
set -u
perilin=$1
dir=$2
pass=0
fail=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for scene in "$dir"/*.yaml; do
  name=$(basename "$scene" .yaml)
  expect=$(sed -n '1s/^# expect: //p' "$scene")
  out="$tmp/$name-out"
  "$perilin" "$scene" -output_dir "$out" > "$tmp/stdout" 2> "$tmp/stderr" < /dev/null
  code=$?
  problem=""
  if [ "$code" -eq 0 ]; then problem="exit code 0"
  elif [ "$code" -gt 128 ]; then problem="killed by signal $((code - 128))"
  elif ! grep -Eq -- "$expect" "$tmp/stderr"; then problem="message does not match '$expect'"
  elif [ -e "$out" ]; then problem="output left behind in $out"
  elif [ "$(wc -l < "$tmp/stderr")" -gt 3 ]; then problem="more than one message"
  fi
  if [ -n "$problem" ]; then
    echo "FAIL $name: $problem"
    sed 's/^/    /' "$tmp/stderr"
    fail=$((fail + 1))
  else
    echo "ok   $name: $(head -c 200 "$tmp/stderr")"
    pass=$((pass + 1))
  fi
done
echo "bad_input: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
