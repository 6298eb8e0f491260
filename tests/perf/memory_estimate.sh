#!/bin/bash
# The pre-run memory estimate (src/system/memory.c, -peri_memory_check) against the measured peak
# (summary.json memory_mb) on scenes of every analysis and layout, one rank: the ratio should stay
# at or a little above 1 (an estimate that errs high refuses too early; one that errs low lets a
# run in that then fails for memory). The estimate is read from -info.
#   tests/perf/memory_estimate.sh PERILIN
exe=$(readlink -f "${1:?usage: memory_estimate.sh PERILIN}")
here=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d /tmp/memory_estimate.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
cd "$here" || exit 1
run() {
  local name=$1
  shift
  est=$("$exe" "$@" -output_dir "$tmp/$name" -output_vtk false -info 2>&1 | grep -o "memory estimate: [0-9.e+]*" | awk '{print $3}')
  peak=$(python3 -c "import json; print(json.load(open('$tmp/$name/summary.json'))['memory_mb'])" 2> /dev/null)
  python3 -c "
e, p = float('${est:-0}') / 2**20, float('${peak:-0}' or 0)
print('| %s | %.1f | %.1f | %.2f |' % ('$name', e, p, e / p if p else 0))"
}
plate="-grid_lower -318.5e-3,-0.5e-3,-0.5e-3 -grid_upper 1.5e-3,79.5e-3,3.5e-3"
echo "| run | estimate (MiB) | peak (MiB) | estimate / peak |"
echo "|---|---|---|---|"
# shellcheck disable=SC2086
run "explicit pmb plate 102,400" tests/perf/lammps/dynamic_3d.yaml $plate -analysis_dt 1e-7 -analysis_t_end 2e-6
# shellcheck disable=SC2086
run "the same, vector form, geometry kept" tests/perf/lammps/dynamic_3d.yaml $plate -analysis_dt 1e-7 -analysis_t_end 2e-6 -peri_operator_springs false -peri_release_bond_geometry false
run "static pmb plate 3D 25,600" tests/perf/lammps/plate_3d.yaml
run "static pmb plate 2D 80,000 (multigrid)" examples/pmb/plate_traction.yaml -grid_spacing 1/400
run "static npmb block 64,000 (multigrid)" examples/bench/block_3d.yaml
run "explicit EOI 2.5 mm (failure)" examples/dynamics/eoi.yaml -grid_spacing 2.5e-3
run "explicit Kalthoff-Winkler (contact)" examples/dynamics/kalthoff_winkler_elastic.yaml -analysis_t_end 1e-5
run "static lps plate with a hole" examples/lps/plate_hole_3d.yaml
run "modal mppd lamina, shift-invert" examples/lamina/modal.yaml -analysis_eigensolver shift_invert
run "the same, 14,400 particles" examples/lamina/modal.yaml -analysis_eigensolver shift_invert -grid_spacing 0.005
run "modal npmb periodic bar" examples/pmb/bar_modes.yaml
run "implicit lps wave in a bar" examples/lps/wave_in_bar.yaml -analysis_integrator implicit -analysis_dt 2e-7 -analysis_t_end 4e-6
