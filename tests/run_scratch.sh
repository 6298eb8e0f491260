# shellcheck shell=bash disable=SC2034,SC2154 # exe, repo, mpi and the helpers serve the sourcing test; on_exit is its
# Sourced by the tests of runs and their faults (restart, kill_fault, disk_full, disk_full_final,
# disk_full_writers, fracture_curve) with their arguments: PERILIN, the repository (restart.sh: its
# scene), then the command that runs 2 ranks where a test takes it, as exe, repo and mpi (empty:
# one rank only). A scratch directory $tmp removed at exit (with the command in $on_exit first,
# when set), PETSc options of the caller's environment dropped, one thread per BLAS, and helpers:
# bad MESSAGE prints a failure and marks the test failed ($fail); need PROGRAM skips the test
# (77) without it; split_run LAUNCHER... -- OPTIONS... sets $launch (env, or mpiexec -n 2) and
# $run; await PID GLOB waits until a file matches GLOB (false when PID ends first, or after 20 s).
exe=$1 repo=$2
mpi=("${@:3}")
tmp=$(mktemp -d)
trap 'eval "${on_exit:-}"; rm -rf "$tmp"' EXIT
unset PETSC_OPTIONS
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
fail=0
bad() { echo "FAIL: $*"; fail=1; }
need() { command -v "$1" > /dev/null || { echo "SKIP: no $1"; exit 77; }; }
split_run() {
  launch=() run=()
  while [ "$1" != "--" ]; do launch+=("$1"); shift; done
  shift
  run=("$@")
}
await() {
  local t0=$SECONDS
  until compgen -G "$2" > /dev/null; do
    kill -0 "$1" 2> /dev/null && [ $((SECONDS - t0)) -lt 20 ] || return 1
    sleep 0.01
  done
}
