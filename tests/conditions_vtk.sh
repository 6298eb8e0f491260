#!/bin/bash
# The conditions in particles.vtu (issue 28 item 7): fixed components, prescribed values, applied
# forces and regions, in a setup run (nothing solved) and a static one, on 1 and 2 ranks, checked
# by tests/conditions_vtk.py against the scene's numbers; overlapping bc items with override: true.
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
# overlapping bc items (item 9): the one with override: true wins on the components it sets, an
# equal value needs none; the corner is the box x, y <= 0.03 of the scene, the left layer x < 0.03
echo "== bc_override"
scene=$repo/tests/scenes/bc_override.yaml
if "$exe" "$scene" -analysis_type setup -quiet -output_dir "$tmp/override" > "$tmp/log" 2>&1; then
  "$py" - "$tmp/override/particles.vtu" <<'PY' || { echo "FAIL: bc_override: the prescribed values"; status=1; }
import sys
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
r = vtkXMLUnstructuredGridReader()
r.SetFileName(sys.argv[1])
r.Update()
g = r.GetOutput()
X = vtk_to_numpy(g.GetPoints().GetData())
pd = g.GetPointData()
fixed, u, left = (vtk_to_numpy(pd.GetArray(n)) for n in ("fixed", "prescribed_displacement", "region_left"))
corner = (X[:, 0] <= 0.03) & (X[:, 1] <= 0.03)
held = left.astype(bool)
assert (corner & held).sum() > 0 and (held & ~corner).sum() > 0
assert (fixed[held] == 1).all() and (fixed[~held] == 0).all()
assert (u[corner & held, 1] == 0.001).all() and (u[held & ~corner, 1] == 0).all() and (u[:, 0] == 0).all()
print("ok: bc_override: uy = 0.001 on the %d corner particles of the left layer, 0 on its other %d" % ((corner & held).sum(), (held & ~corner).sum()))
PY
else
  cat "$tmp/log"; echo "FAIL: bc_override: the run failed"; status=1
fi
exit $status
