#!/usr/bin/env bash
# perilin's particles.vtu and .pvd series read by VTK's own Python readers (issue 16, item 7;
# tests/vtk_read.py): a static, a modal and a quasi-static run, each checked against its
# summary.json, modes.csv and steps.csv. Needs Debian's python3-vtk9 (.ci/install installs it):
# without it the test says so and exits 77, which ctest reports as skipped.
# Usage: vtk_read.sh PERILIN EXAMPLES_DIR
set -u
exe=$1 ex=$2
here=$(cd "$(dirname "$0")" && pwd)
# python3-vtk9 is Debian's: the first python3 on PATH may be another one (pyenv, a venv)
py=""
for p in python3 /usr/bin/python3; do
  if command -v "$p" > /dev/null && "$p" -c "import vtkmodules.vtkIOXML, vtkmodules.util.numpy_support" 2> /dev/null; then
    py=$p
    break
  fi
done
[ -n "$py" ] || { echo "SKIP: VTK's Python readers are not installed (Debian python3-vtk9; bash .ci/install installs it)"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
unset PETSC_OPTIONS
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
fail=0
run() { # name kind scene options... : runs perilin and the reader's checks of its output
  local name=$1 kind=$2 scene=$3
  shift 3
  echo "== $name: perilin $scene $*"
  "$exe" "$ex/$scene" "$@" -output_dir "$tmp/$name" > "$tmp/$name.log" 2>&1 < /dev/null || { echo "FAIL: perilin exited $?"; cat "$tmp/$name.log"; fail=1; return; }
  "$py" "$here/vtk_read.py" "$kind" "$tmp/$name" "${every:-1}" || fail=1
}
echo "VTK $("$py" -c 'import vtkmodules.vtkCommonCore as c; print(c.vtkVersion.GetVTKVersion())') ($py)"
run static static pmb/plate_traction.yaml
run modal modal lamina/modal.yaml
# with a target the modes come by distance to it: the frames must still ascend in frequency
run modal_target modal lamina/modal.yaml -analysis_target_hz 3000
# every 3 of 10 steps: particles.vtu closes the series; with events, two equilibria per break
# (the peak and the state after its cascade) at nearly the same load factor
every=3 run quasistatic quasistatic fracture/edge_crack.yaml -grid_spacing 0.04 -quiet -output_every 3
every=2 run quasistatic_events quasistatic antiplane/cracked_bar.yaml -grid_spacing 0.04 -quiet -output_every 2 -analysis_stepping events
exit $fail
