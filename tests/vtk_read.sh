#!/usr/bin/env bash
# perilin's particles.vtu and .pvd series read by VTK's own Python readers (issue 16, item 7;
# tests/vtk_read.py): a static, a modal, a quasi-static and a dynamic run, each checked against its
# summary.json, modes.csv and steps.csv; then the same runs on 2 ranks (with MPIRUN), whose
# particles.pvtu, mode_NN.pvtu and particles_NNNN.pvtu (one piece per rank, issue 17 item 4) are
# read with VTK's parallel reader, checked the same way and against the one-rank run's arrays. A
# square clamped plate has degenerate modes: modes.pvd's times still increase strictly and equal
# the frequencies to 1e-11 (the .pvd equal-time rule; tests/unit/test_output.c checks the nudge of
# exactly equal times). Needs Debian's python3-vtk9 (.ci/install installs it): without it the
# test says so and exits 77, which ctest reports as skipped.
# Usage: vtk_read.sh PERILIN EXAMPLES_DIR [MPIRUN...]  (MPIRUN: the launcher of 2 ranks)
set -u
exe=$1 ex=$2
shift 2
mpirun=("$@")
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=/dev/null
source "$here/vtk_python.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
unset PETSC_OPTIONS
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
fail=0
run() { # name kind scene options... : runs perilin and the reader's checks of its output; then,
  # with a launcher, the same on 2 ranks, also checked against the one-rank run
  local name=$1 kind=$2 scene=$3
  shift 3
  [[ $scene == /* ]] || scene=$ex/$scene
  echo "== $name: perilin $scene $*"
  "$exe" "$scene" "$@" -output_dir "$tmp/$name" > "$tmp/$name.log" 2>&1 < /dev/null || { echo "FAIL: perilin exited $?"; cat "$tmp/$name.log"; fail=1; return; }
  DEGENERATE=${degenerate:-} "$py" "$here/vtk_read.py" "$kind" "$tmp/$name" "${every:-1}" 1 || fail=1
  [ ${#mpirun[@]} -gt 0 ] || return
  echo "== $name on 2 ranks"
  "${mpirun[@]}" "$exe" "$scene" "$@" -output_dir "$tmp/$name-2" > "$tmp/$name-2.log" 2>&1 < /dev/null || { echo "FAIL: perilin on 2 ranks exited $?"; cat "$tmp/$name-2.log"; fail=1; return; }
  DEGENERATE=${degenerate:-} "$py" "$here/vtk_read.py" "$kind" "$tmp/$name-2" "${every:-1}" 2 ${compare:+"$tmp/$name"} || fail=1
}
echo "VTK $("$py" -c 'import vtkmodules.vtkCommonCore as c; print(c.vtkVersion.GetVTKVersion())') ($py)"
compare=1 run static static pmb/plate_traction.yaml
compare=1 run modal modal lamina/modal.yaml
# degenerate pairs of modes: their shapes are any basis of the pair's plane, not comparable
# between runs; the frames' times are (vtk_read.py checks them)
degenerate=1 run square_modes modal "$here/scenes/square_modes.yaml"
# with a target the modes come by distance to it: the frames must still ascend in frequency
run modal_target modal lamina/modal.yaml -analysis_target_hz 3000
# every 3 of 10 steps: particles.vtu closes the series; with events, two equilibria per break
# (the peak and the state after its cascade) at nearly the same load factor
every=3 compare=1 run quasistatic quasistatic fracture/edge_crack.yaml -grid_spacing 0.04 -quiet -output_every 3
every=2 compare=1 run quasistatic_events quasistatic antiplane/cracked_bar.yaml -grid_spacing 0.04 -quiet -output_every 2 -analysis_stepping events
# a transient run: 25 frames by default, each with its velocity (issue 38, item 5); then every 7
every=0 compare=1 run dynamic dynamic dynamics/pulse.yaml -analysis_t_end 10 -output_vtk true
every=7 run dynamic_every dynamic dynamics/pulse.yaml -analysis_t_end 10 -output_vtk true -output_every 7
exit $fail
