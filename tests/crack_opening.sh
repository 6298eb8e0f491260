#!/bin/bash
# The static opening of a 3D penny-shaped crack against Sneddon's (tests/crack_opening.py).
# usage: crack_opening.sh PERILIN REPO
set -u
exe=$1 repo=$2
source "$repo/tests/vtk_python.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1
"$py" "$repo/tests/crack_opening.py" "$exe" "$repo/tests/scenes/penny_static.yaml" "$tmp"
