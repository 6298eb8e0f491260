# Sourced by the tests of runs and their faults (restart, kill_fault, disk_full, disk_full_final,
# disk_full_writers, fracture_curve): a scratch directory $tmp removed at exit (with the command in
# $on_exit first, when set), PETSc options of the caller's environment dropped, one thread per BLAS, and
# bad MESSAGE, which prints a failure and marks the test failed ($fail).
tmp=$(mktemp -d)
trap 'eval "${on_exit:-}"; rm -rf "$tmp"' EXIT
unset PETSC_OPTIONS
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
fail=0
bad() { echo "FAIL: $*"; fail=1; }
