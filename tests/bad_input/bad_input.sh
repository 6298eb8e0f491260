#!/usr/bin/env bash
# Runs the invalid scenes of one category: bad_input.sh PERILIN DIR CATEGORY runs DIR/CATEGORY/*.yaml.
# Each scene is invalid: perilin must exit with a non-zero status below 128 (or the one of its
# "# exit:" line), print "perilin: error:" exactly once with a message matching its "# expect:"
# line, and leave no output behind. Header lines at the top of a case (all optional but expect):
#   # expect: REGEX        grep -E against stderr
#   # args: OPTIONS        extra options, word-split by the shell; $out in them is the output
#                          directory (a setup may make inputs beside it, "$out.fifo": the runner's
#                          temporary directory holds both and is removed at the end)
#   # ranks: N             run under mpiexec -n N
#   # exit: STATUS         the exact exit status expected
#   # setup: COMMAND       run by bash before perilin, with $out the output directory ($perilin and
#                          $scene: the executable and the case, to make a checkpoint of it)
#   # keep: FILE...        the outputs the case may leave (paths relative to $out, globs allowed)
#   # signal: SIG DELAY [rank|group]   send SIG after DELAY s to perilin (or mpiexec), to one rank,
#                          or to the process group; then the run must write summary.json marked
#                          "complete": false, print no error, and the message is looked for in
#                          stdout and stderr
# Without setup and keep no output directory may be left; with setup it must be exactly as the
# setup left it, apart from the files of keep. Every case runs with stdin from /dev/null and a
# timeout of 60 s; the runner always passes -output_dir "$out".
set -u
if [ $# -ne 3 ]; then
  echo "usage: $0 PERILIN DIR CATEGORY" >&2
  exit 2
fi
perilin=$1
dir=$2
category=$3
timeout_s=60
pass=0
fail=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# header KEY FILE: the value of the first "# KEY: " line of the comment block at the top of FILE.
header() {
  awk -v key="$1" '!/^#/ { exit } index($0, "# " key ": ") == 1 { print substr($0, length(key) + 5); exit }' "$2"
}

# snapshot DIR: one line per path below DIR (type, checksum of files), sorted; empty if DIR is absent.
snapshot() {
  [ -e "$1" ] || return 0
  (cd "$1" && find . -mindepth 1 | LC_ALL=C sort | while IFS= read -r p; do
    if [ -f "$p" ] && [ ! -L "$p" ]; then echo "f ${p#./} $(md5sum < "$p" | cut -c1-32)"
    elif [ -d "$p" ] && [ ! -L "$p" ]; then echo "d ${p#./}"
    else echo "o ${p#./} $(ls -ld "$p" | cut -c1-10)"
    fi
  done)
}

# allowed PATH PATTERNS...: whether PATH (relative to $out) matches one of the keep patterns.
allowed() {
  local p=$1 pat
  shift
  for pat in "$@"; do
    # shellcheck disable=SC2053
    [[ $p == $pat || $p == $pat/* ]] && return 0
  done
  return 1
}

# run_signalled: runs the case in a session of its own and, after the delay of its "# signal:
# SIG DELAY [rank|group]" line, sends SIG to the launched process (perilin, or mpiexec), to one
# perilin rank, or to the whole process group (a terminal's Ctrl-C); sets code.
run_signalled() {
  local sig delay target pid victim waited=0
  read -r sig delay target <<< "$signal"
  # shellcheck disable=SC2086
  setsid "${launcher[@]}" "$perilin" "$scene" -output_dir "$out" $args > "$tmp/stdout" 2> "$tmp/stderr" < /dev/null &
  pid=$!
  sleep "$delay"
  case "$target" in
    rank) victim=$(pgrep -x -s "$pid" perilin | head -n 1); kill -s "$sig" "$victim" ;;
    group) kill -s "$sig" -- "-$pid" ;;
    *) kill -s "$sig" "$pid" ;;
  esac
  while kill -0 "$pid" 2> /dev/null && [ "$waited" -lt "$timeout_s" ]; do
    sleep 1
    waited=$((waited + 1))
  done
  if kill -0 "$pid" 2> /dev/null; then
    kill -s KILL -- "-$pid"
    wait "$pid"
    code=124
  else
    wait "$pid"
    code=$?
  fi
}

shopt -s nullglob
scenes=("$dir/$category"/*.yaml)
shopt -u nullglob
if [ ${#scenes[@]} -eq 0 ]; then
  echo "FAIL bad_input/$category: no cases in $dir/$category"
  exit 1
fi

for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .yaml)
  expect=$(header expect "$scene")
  args=$(header args "$scene")
  out="$tmp/$name-out"
  args=${args//\$out/$out} # inputs the setup made in the run's own directory, removed with it
  ranks=$(header ranks "$scene")
  want_exit=$(header exit "$scene")
  setup=$(header setup "$scene")
  keep=$(header keep "$scene")
  signal=$(header signal "$scene")
  rm -rf "$out"
  problem=""
  if [ -z "$expect" ]; then problem="no '# expect:' line"; fi
  if [ -z "$problem" ] && [ -n "$setup" ]; then
    if ! out="$out" perilin="$perilin" scene="$scene" bash -c "$setup" > "$tmp/setup.log" 2>&1 < /dev/null; then
      problem="setup failed: $(head -c 200 "$tmp/setup.log")"
    fi
  fi
  before=$(snapshot "$out")
  existed=no
  [ -e "$out" ] && existed=yes
  if [ -z "$problem" ]; then
    launcher=()
    if [ -n "$ranks" ]; then
      launcher=(env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpiexec --oversubscribe -n "$ranks")
    fi
    if [ -n "$signal" ]; then
      run_signalled
    else
      # shellcheck disable=SC2086
      timeout -k 5 "$timeout_s" "${launcher[@]}" "$perilin" "$scene" -output_dir "$out" $args \
        > "$tmp/stdout" 2> "$tmp/stderr" < /dev/null
      code=$?
    fi
    after=$(snapshot "$out")
    changed=$(diff <(echo "$before") <(echo "$after") | sed -n 's/^[<>] [fdo] \([^ ]*\).*/\1/p' | LC_ALL=C sort -u)
    left=""
    while IFS= read -r p; do
      [ -z "$p" ] && continue
      # shellcheck disable=SC2086
      if ! allowed "$p" $keep; then left="$left $p"; fi
    done <<< "$changed"
    if [ "$existed" = no ] && [ -z "$keep" ] && [ -e "$out" ]; then left=" (the directory itself)$left"; fi
    nerr=$(grep -c 'perilin: error:' "$tmp/stderr")
    if [ -n "$signal" ]; then
      # an interrupted run is no error: it writes what it has, marked incomplete
      [ "$nerr" -eq 0 ] && nerr=1 || nerr=2
      cat "$tmp/stdout" >> "$tmp/stderr"
      if [ "$code" -ne 124 ] && ! grep -q '"complete": false' "$out/summary.json" 2> /dev/null; then problem="summary.json is missing or not marked \"complete\": false"; fi
      if compgen -G "$out.partial-*" > /dev/null; then problem="a staging directory was left behind: $(echo "$out".partial-*)"; fi
    fi
    if [ -n "$problem" ]; then :
    elif [ "$code" -eq 124 ] || [ "$code" -eq 137 ]; then problem="hang: no exit within $timeout_s s"
    elif [ -n "$want_exit" ] && [ "$code" -ne "$want_exit" ]; then problem="exit status $code, expected $want_exit"
    elif [ -z "$want_exit" ] && [ "$code" -eq 0 ]; then problem="exit status 0"
    elif [ -z "$want_exit" ] && [ "$code" -gt 128 ]; then problem="killed by signal $((code - 128))"
    elif grep -q 'PETSC ERROR: Caught signal' "$tmp/stderr"; then problem="crashed (PETSc caught a signal, exit status $code)"
    elif ! grep -Eq -- "$expect" "$tmp/stderr"; then problem="message does not match '$expect'"
    elif [ -n "$left" ]; then problem="output left behind in $out:$left"
    elif [ "$nerr" -ne 1 ]; then problem="'perilin: error:' printed $nerr times, expected once"
    fi
  fi
  if [ -n "$problem" ]; then
    echo "FAIL $category/$name: $problem"
    [ -f "$tmp/stderr" ] && head -n 20 "$tmp/stderr" | sed 's/^/    /'
    fail=$((fail + 1))
  else
    echo "ok   $category/$name: $(grep -m1 'perilin: error:' "$tmp/stderr" | head -c 200)"
    pass=$((pass + 1))
  fi
  rm -f "$tmp/stderr" "$tmp/stdout"
done
echo "bad_input/$category: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
