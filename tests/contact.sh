#!/bin/bash
# Contact and impactors (issue 38, item 3): momentum and energy of an impact, two bars that
# exchange their momentum, 1 and 2 ranks (tests/contact.py says what and why).
# usage: contact.sh PERILIN REPO [MPIRUN...]
set -u
exe=$1 repo=$2
shift 2
source "$repo/tests/vtk_python.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1
"$py" "$repo/tests/contact.py" "$exe" "$repo/tests/scenes" "$tmp" "$@"
