# shellcheck shell=bash disable=SC2034  # sourced: the variables it sets are its callers'
# Sourced by the benchmarks of tests/perf: `perf_args NAME "$@"` puts the words before "--" into
# the array NAME and the words after it into the array PERF_REST (options for every run).
perf_args() {
  local -n list=$1
  shift
  list=()
  while [[ $# -gt 0 && $1 != -- ]]; do
    list+=("$1")
    shift
  done
  [[ $# -gt 0 ]] && shift
  PERF_REST=("$@")
}

# `perf_scenes "$0" "$@"` for the scripts called as SCRIPT PERILIN [REPEAT [SCENE...]]: sets exe
# (PERILIN, absolute), repeat (default 3), root (the repository) and the array scenes (the rest).
perf_scenes() {
  local script=$1
  shift
  exe=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
  repeat=${2:-3}
  shift $(($# < 2 ? $# : 2))
  root=$(cd "$(dirname "$script")/../.." && pwd)
  scenes=("$@")
}
