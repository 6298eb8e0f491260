# Sourced by the tests that read perilin's VTK files with VTK's own Python readers: sets py to a
# python3 that has them (Debian's python3-vtk9; the first python3 on PATH may be another one, a
# pyenv or a venv), or says the test is skipped and exits 77 (ctest's SKIP_RETURN_CODE).
py=""
for p in python3 /usr/bin/python3; do
  if command -v "$p" > /dev/null && "$p" -c "import numpy, vtkmodules.vtkIOXML, vtkmodules.util.numpy_support" 2> /dev/null; then
    py=$p
    break
  fi
done
[ -n "$py" ] || { echo "SKIP: VTK's Python readers are not installed (Debian python3-vtk9; bash .ci/install installs it)"; exit 77; }
