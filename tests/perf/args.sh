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
