#!/usr/bin/env bash
# Issue 27 on the stochastic tetrahedral bar (examples/mesh/pulse_stochastic.yaml,
# tests/mesh/stochastic.py): horizon.neighbors gives every particle a horizon holding exactly 30
# neighbours, the same on 1 and 2 ranks; Ganzenmueller's pulse nears c t when the mesh is split.
# Needs python3-vtk9 (else skipped, exit 77).
# Usage: stochastic.sh PERILIN EXAMPLES_DIR
set -u
exe=$1 ex=$2
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=/dev/null
source "$here/../vtk_python.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
scene=$ex/mesh/pulse_stochastic.yaml
"$exe" "$scene" -analysis_type setup -output_vtk true -quiet -output_dir "$tmp/setup1" > /dev/null || exit 1
mpiexec --oversubscribe -n 2 "$exe" "$scene" -analysis_type setup -output_vtk true -quiet -output_dir "$tmp/setup2" > /dev/null || exit 1
"$py" "$here/stochastic.py" neighbors "$tmp/setup1" "$tmp/setup2" 30 || exit 1
"$exe" "$scene" -quiet -output_dir "$tmp/pulse0" > /dev/null || exit 1
"$exe" "$scene" -particles_refine 1 -quiet -output_dir "$tmp/pulse1" > /dev/null || exit 1
"$py" "$here/stochastic.py" pulse "$tmp/pulse0" "$tmp/pulse1"
