#!/bin/bash
# Issue 37, item 6: lps near incompressibility. The block of examples/bench/block_3d.yaml as lps at
# Δx = 1/15 (4,096 particles), static, defaults (CG + Jacobi, handing over to GAMG past its
# budget), at each ν: the iterations, the preconditioned operator's condition estimate (CG's
# extreme singular values, -ksp_view_singularvalues: one line per solver tried), and the CG
# solution against a direct solve of the assembled K (Cholesky): the largest displacement
# difference relative to the largest displacement, and the strain energies.
#   tests/perf/lps_near_incompressible.sh PERILIN [SPACING]
set -euo pipefail
exe=$(readlink -f "${1:?usage: lps_near_incompressible.sh PERILIN [SPACING]}")
h=${2:-1/15}
here=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d /tmp/lps_nu.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
sed 's/material: {K: 1.0e9}/material: {E: 1.0e9, nu: 0.3}/; s/type: npmb/type: lps/' "$here/examples/bench/block_3d.yaml" > "$tmp/block.yaml"
echo "| ν | solver | iterations | condition estimate | solve (s) | CG against Cholesky: max \|Δu\| / max \|u\| | strain energy |"
echo "|---|---|---|---|---|---|---|"
for nu in 0.3 0.45 0.49 0.499 0.4999; do
  "$exe" "$tmp/block.yaml" -grid_spacing "$h" -material_nu "$nu" -output_vtk true -output_dir "$tmp/cg$nu" -ksp_view_singularvalues > "$tmp/cg$nu.log" 2>&1
  "$exe" "$tmp/block.yaml" -grid_spacing "$h" -material_nu "$nu" -output_vtk true -output_dir "$tmp/lu$nu" -solver_operator assembled -ksp_type preonly -pc_type cholesky > "$tmp/lu$nu.log" 2>&1
  /usr/bin/python3 - "$tmp" "$nu" << 'PY'
import json, re, sys
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
tmp, nu = sys.argv[1:3]
def disp(o):
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(o + "/particles.vtu")
    r.Update()
    return vtk_to_numpy(r.GetOutput().GetPointData().GetArray("displacement"))
cg, lu = (json.load(open(f"{tmp}/{k}{nu}/summary.json")) for k in ("cg", "lu"))
a, b = disp(f"{tmp}/cg{nu}"), disp(f"{tmp}/lu{nu}")
cond = " then ".join("%.3g" % float(c) for c in re.findall(r"max/min ([0-9.e+]+)", open(f"{tmp}/cg{nu}.log").read()))
s = cg["solver"]
print(f"| {nu} | CG + {s['pc_type']} | {s['iterations']} | {cond} | {cg['timing']['solve_s']:.2f} | {abs(a - b).max() / abs(b).max():.1e} | {cg['strain_energy']:.12g} (Cholesky {lu['strain_energy']:.12g}) |")
PY
done
