#!/bin/bash
# The same command twice gives the same numbers, every analysis, 1 and 2 ranks (issue 40, item 7;
# tests/reproducible.py says what is compared).
# usage: reproducible.sh PERILIN REPO [MPIRUN...]
set -u
exe=$1 repo=$2
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1
/usr/bin/python3 "$repo/tests/reproducible.py" "$exe" "$repo/examples" "$repo/tests/scenes" "$tmp" "$@"
