#!/bin/bash
# The conditions in particles.vtu (issue 28 item 7): fixed components, prescribed values, applied
# forces and regions, in a setup run (nothing solved) and a static one, on 1 and 2 ranks, checked
# by tests/conditions_vtk.py against the scene's numbers.
# usage: conditions_vtk.sh PERILIN REPO
set -u
exe=$1; repo=$2
source "$repo/tests/vtk_python.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mpi=(env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpiexec --oversubscribe -n 2)
plate=$repo/examples/pmb/plate_traction.yaml
grip=$repo/tests/scenes/reaction_qs.yaml
status=0
# run NAME KIND SCENE [RUNNER...] -- [perilin OPTIONS...]: run, then check
run() {
  local name=$1 kind=$2 scene=$3 runner=()
  shift 3
  while [ "$1" != "--" ]; do runner+=("$1"); shift; done
  shift
  echo "== $name"
  "${runner[@]}" "$exe" "$scene" "$@" -quiet -output_dir "$tmp/$name" > "$tmp/log" 2>&1 || { cat "$tmp/log"; echo "FAIL: $name: the run failed"; status=1; return; }
  "$py" "$repo/tests/conditions_vtk.py" "$kind" "$scene" "$tmp/$name" || status=1
}
run setup_1rank plate "$plate" -- -analysis_type setup
run setup_2ranks plate "$plate" "${mpi[@]}" -- -analysis_type setup
run static_2ranks plate "$plate" "${mpi[@]}" --
run grip_setup grip "$grip" -- -analysis_type setup -output_vtk true
exit $status
