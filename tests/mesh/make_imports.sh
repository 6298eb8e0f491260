#!/usr/bin/env bash
# Regenerates the Abaqus and Exodus test meshes of tests/mesh/ from the committed Gmsh meshes, so
# that test_mesh can compare each with the same mesh read as .msh (ctest mesh_import_*):
#   square_tri.inp, block_tet.inp, square_quad.inp: written by Gmsh itself (-format inp): one
#     *ELSET per physical group; a node set appended here, left_nodes: the nodes on x = 0 (to 1e-9);
#   square_tri.exo, block_tet.exo: the .inp read and written by meshio (Exodus II through netCDF);
#     meshio writes neither block names nor the node set's name from Gmsh's sets, so the element
#     blocks get Exodus' eb_names (each the physical group that covers the block), as Cubit writes.
# Needs gmsh, python3-meshio and python3-netcdf4. Usage: bash tests/mesh/make_imports.sh
set -euo pipefail
cd "$(dirname "$0")"
py=/usr/bin/python3
for m in square_tri block_tet square_quad; do
  gmsh "$m.msh" -0 -format inp -o "$m.inp" > /dev/null
  "$py" - "$m.inp" << 'PY'
import sys, meshio
m = meshio.read(sys.argv[1])
text = open(sys.argv[1]).read().split("*NODE\n")[1].split("*")[0]
ids = [int(line.split(",")[0]) for line in text.splitlines() if line.strip()]  # meshio's order
left = [ids[i] for i, p in enumerate(m.points) if abs(p[0]) < 1e-9]
with open(sys.argv[1], "a") as f:
    f.write("*NSET,NSET=left_nodes\n")
    for k in range(0, len(left), 10):
        f.write(", ".join(map(str, left[k:k + 10])) + "\n")
PY
done
for m in square_tri block_tet; do
  "$py" - "$m.inp" "$m.exo" << 'PY'
import sys, meshio, netCDF4, numpy
m = meshio.read(sys.argv[1])
names = []
for b, block in enumerate(m.cells):  # the physical group (not Gmsh's entity set) that is the whole block
    whole = [n for n, v in m.cell_sets.items() if len(v[b]) == len(block.data) and sum(len(a) for a in v) == len(block.data)]
    names.append([n for n in whole if not n.startswith(("Line", "Surface", "Volume"))][0])
m.cell_sets = {}
m.write(sys.argv[2], file_format="exodus")
with netCDF4.Dataset(sys.argv[2], "a") as nc:
    v = nc.createVariable("eb_names", "S1", ("num_el_blk", "len_string"))
    v[:] = numpy.array([netCDF4.stringtochar(numpy.array([n], "S%d" % len(nc.dimensions["len_string"])))[0] for n in names])
PY
done
