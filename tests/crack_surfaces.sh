#!/bin/bash
# 3D cracks (polygon, disc, surface: STL ASCII and binary, Gmsh .msh) on 1 and 2 ranks against
# the cut bonds counted by tests/crack_surfaces.py from particles.vtu (its header says how).
# usage: crack_surfaces.sh PERILIN REPO
set -u
exe=$1; repo=$2
source "$repo/tests/vtk_python.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$py" "$repo/tests/crack_surfaces.py" "$exe" "$tmp"
