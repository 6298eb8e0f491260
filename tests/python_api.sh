#!/bin/bash
# The Python module perilin (issue 39; tests/python_api.py says what is checked), on 1 and 2 ranks,
# against the command line's run of the same scene on as many ranks; then the example
# examples/python/slepc_modes.py (slepc4py on perilin's K and M gives perilin's frequencies) and
# examples/python/fit_modulus.py (scipy.optimize recovers E to 1e-6).
# Debian's /usr/bin/python3, with the module from the build tree; skipped (77) without the module or
# VTK's readers. usage: python_api.sh PERILIN REPO PYTHON_DIR
set -u
exe=$1 repo=$2 pydir=$3
py=/usr/bin/python3
export PYTHONPATH=$pydir
if ! [ -x "$py" ] || ! "$py" -c "import perilin, vtkmodules.vtkIOXML" 2> /dev/null; then
  echo "SKIP: $py cannot import perilin (python3-petsc4py, python3-slepc4py, python3-mpi4py: bash .ci/install) or VTK's readers (python3-vtk9)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
mpi=(env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpiexec --oversubscribe -n 2)
plate=$repo/examples/pmb/plate_traction.yaml
version=$("$exe" -version | head -1)
status=0
for n in 1 2; do
  run=()
  [ $n = 2 ] && run=("${mpi[@]}")
  echo "== $n rank(s)"
  mkdir -p "$tmp/py$n"
  "${run[@]}" "$exe" "$plate" -quiet -output_dir "$tmp/cli$n" > "$tmp/log" 2>&1 || { cat "$tmp/log"; echo "FAIL: the command line's run on $n rank(s)"; status=1; continue; }
  # the small quasi-static and dynamic scenes of python_api.py's check 9, with its overrides
  "${run[@]}" "$exe" "$repo/examples/antiplane/cracked_bar.yaml" -grid_spacing 0.025 -output_plots false -quiet -output_dir "$tmp/qs$n" > "$tmp/log" 2>&1 || { cat "$tmp/log"; echo "FAIL: the command line's quasi-static run on $n rank(s)"; status=1; continue; }
  "${run[@]}" "$exe" "$repo/examples/dynamics/pulse.yaml" -grid_upper 100,4,4 -analysis_t_end 10 -output_plots false -quiet -output_dir "$tmp/dyn$n" > "$tmp/log" 2>&1 || { cat "$tmp/log"; echo "FAIL: the command line's dynamic run on $n rank(s)"; status=1; continue; }
  "${run[@]}" "$py" "$repo/tests/python_api.py" "$repo" "$tmp/cli$n" "$version" "$tmp/py$n" "$tmp/qs$n" "$tmp/dyn$n" > "$tmp/pylog" 2>&1 || status=1
  grep -E "^(ok|FAIL)" "$tmp/pylog" || cat "$tmp/pylog"
done
echo "== examples/python/slepc_modes.py"
"$py" "$repo/examples/python/slepc_modes.py" "$repo/examples/lamina/modal.yaml" || status=1
echo "== examples/python/fit_modulus.py"
"$py" "$repo/examples/python/fit_modulus.py" || status=1
exit $status
