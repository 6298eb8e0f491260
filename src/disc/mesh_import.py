#!/usr/bin/env python3
"""Converts an Abaqus .inp or an Exodus II mesh into a Gmsh MSH 4.1 file for particles.mesh
(src/disc/mesh.c runs it in a child process; docs/mesh.md, "Abaqus and Exodus meshes").

  mesh_import.py IN OUT.msh

meshio reads the file (Debian python3-meshio; Exodus through python3-netcdf4). Gmsh then reads what
this writes, so perilin's particles, volumes and groups come from the one Gmsh reader. Named sets
become physical groups of the same name:
  - an element set (Abaqus *ELSET, an Exodus element block): a group of its elements' dimension;
  - a node set (Abaqus *NSET, an Exodus node set): a boundary group (dimension - 1) of the faces of
    the mesh's boundary whose corners all lie in the set, or a group of points when no face does;
    a node set named as an element set is skipped (Gmsh writes each physical group as both).
Elements overlapping several sets go into one Gmsh entity per combination of sets, so every element
is written once. Element tags are 1, 2, ... in the file's order. Any error: one line on stderr,
exit 1, and OUT is not written.
"""
import os
import sys

GMSH_TYPE = {"vertex": 15, "line": 1, "triangle": 2, "quad": 3, "tetra": 4, "hexahedron": 5,
             "wedge": 6, "pyramid": 7, "line3": 8, "triangle6": 9, "quad9": 10, "tetra10": 11,
             "hexahedron27": 12, "quad8": 16, "hexahedron20": 17}
DIM = {"vertex": 0, "line": 1, "line3": 1, "triangle": 2, "triangle6": 2, "quad": 2, "quad8": 2,
       "quad9": 2, "tetra": 3, "tetra10": 3, "hexahedron": 3, "hexahedron20": 3,
       "hexahedron27": 3, "wedge": 3, "pyramid": 3}
# the sides of the linear elements (corner indices), as boundary faces of a node set
SIDES = {"triangle": ("line", [(0, 1), (1, 2), (2, 0)]),
         "quad": ("line", [(0, 1), (1, 2), (2, 3), (3, 0)]),
         "tetra": ("triangle", [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]),
         "hexahedron": ("quad", [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5),
                                 (2, 3, 7, 6), (3, 0, 4, 7)])}


def fail(msg):
    sys.stderr.write(msg + "\n")
    sys.exit(1)


def exodus_block_names(path):
    """Exodus element blocks' names (eb_names), in meshio's block order; 'block_<id>' if unnamed
    (meshio 5 reads the blocks but not their names)."""
    import netCDF4
    names = []
    with netCDF4.Dataset(path) as nc:
        ids = nc.variables["eb_prop1"][:] if "eb_prop1" in nc.variables else None
        given = []
        if "eb_names" in nc.variables:
            nc.variables["eb_names"].set_auto_mask(False)
            given = [b"".join(c).decode("utf-8").strip("\0 ") for c in nc.variables["eb_names"][:]]
        for key in nc.variables:  # meshio's order: the connect variables as the file lists them
            if key.startswith("connect"):
                k = int(key[7:]) - 1
                name = given[k] if k < len(given) else ""
                names.append(name or "block_%d" % (int(ids[k]) if ids is not None else k + 1))
    return names


def element_sets(mesh, path):
    """{name: [per block: element indices]}: the cell sets, or the Exodus blocks."""
    if os.path.splitext(path)[1].lower() == ".inp":
        return {n: [list(a) for a in v] for n, v in mesh.cell_sets.items()}
    sets = {}
    for k, name in enumerate(exodus_block_names(path)):
        sets.setdefault(name, [[] for _ in mesh.cells])[k] = list(range(len(mesh.cells[k].data)))
    return sets


def boundary_faces(mesh, top, nodes):
    """The faces (type, corners) of the boundary of the top-dimension elements with every corner in
    nodes."""
    count, first = {}, {}
    for block in mesh.cells:
        if DIM.get(block.type) != top or block.type not in SIDES:
            continue
        ftype, sides = SIDES[block.type]
        for cell in block.data:
            for s in sides:
                face = tuple(int(cell[i]) for i in s)
                key = frozenset(face)
                count[key] = count.get(key, 0) + 1
                first.setdefault(key, (ftype, face))
    return [first[k] for k, c in count.items() if c == 1 and k <= nodes]


def groups(mesh, path, top):
    """Physical groups [(dim, name)] and the elements to write [(dim, type, corners, group ids)]."""
    names, members = [], {}
    for name, per_block in element_sets(mesh, path).items():
        dims = {DIM[mesh.cells[b].type] for b, idx in enumerate(per_block) if len(idx)}
        if len(dims) > 1:
            fail("element set '%s' mixes elements of dimensions %s" % (name, sorted(dims)))
        names.append((dims.pop() if dims else top, name))
        for b, idx in enumerate(per_block):
            for i in idx:
                members.setdefault((b, int(i)), []).append(len(names))
    elements = []
    for b, block in enumerate(mesh.cells):
        if block.type not in GMSH_TYPE:
            fail("elements of type '%s', which perilin does not read" % block.type)
        for i, cell in enumerate(block.data):
            elements.append((DIM[block.type], block.type, [int(v) for v in cell], members.get((b, i), [])))
    taken = {n for _, n in names}
    for name, nodes in mesh.point_sets.items():
        if name in taken:  # Gmsh writes each physical group as an *ELSET and an *NSET: the elements say more
            continue
        nodes = {int(v) for v in nodes}
        faces = boundary_faces(mesh, top, nodes)
        names.append((top - 1 if faces else 0, name))
        for ftype, face in faces or [("vertex", (v,)) for v in sorted(nodes)]:
            elements.append((DIM[ftype], ftype, list(face), [len(names)]))
    return names, elements


def write_msh(out, points, names, elements):
    """MSH 4.1 ASCII: one entity per (dimension, combination of groups); the nodes on the first
    entity of the highest dimension."""
    entities = {}
    for d, _, _, tags in elements:
        entities.setdefault((d, tuple(tags)), len([e for e in entities if e[0] == d]) + 1)
    top = max(d for d, _ in entities)
    lines = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names))]
    lines += ['%d %d "%s"' % (d, k + 1, n) for k, (d, n) in enumerate(names)]
    lines += ["$EndPhysicalNames", "$Entities", " ".join(str(sum(1 for e in entities if e[0] == d)) for d in range(4))]
    for (d, tags), tag in sorted(entities.items(), key=lambda e: (e[0][0], e[1])):
        box = "0 0 0" if d == 0 else "0 0 0 0 0 0"
        lines.append("%d %s %d %s%s" % (tag, box, len(tags), " ".join(map(str, tags)), "" if d == 0 else " 0"))
    lines += ["$EndEntities", "$Nodes", "1 %d 1 %d" % (len(points), len(points))]
    lines.append("%d %d 0 %d" % (top, entities[min((e for e in entities if e[0] == top), key=entities.get)], len(points)))
    lines += [str(k + 1) for k in range(len(points))]
    lines += ["%.17g %.17g %.17g" % tuple(p) for p in points]
    blocks = {}
    for d, t, corners, tags in elements:
        blocks.setdefault((d, entities[(d, tuple(tags))], GMSH_TYPE[t]), []).append(corners)
    lines += ["$EndNodes", "$Elements", "%d %d 1 %d" % (len(blocks), len(elements), len(elements))]
    tag = 0
    for (d, e, t), cells in blocks.items():
        lines.append("%d %d %d %d" % (d, e, t, len(cells)))
        for c in cells:
            tag += 1
            lines.append("%d %s" % (tag, " ".join(str(v + 1) for v in c)))
    lines.append("$EndElements")
    tmp = out + ".part"
    with open(tmp, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, out)


def main():
    if len(sys.argv) != 3:
        fail("usage: mesh_import.py IN OUT.msh")
    path, out = sys.argv[1:]
    try:
        import meshio
    except ImportError:
        fail("meshio is not installed (Debian: python3-meshio, and python3-netcdf4 for Exodus)")
    try:
        mesh = meshio.read(path, file_format="abaqus" if path.lower().endswith(".inp") else "exodus")
    except ImportError as e:
        fail("meshio needs %s to read %s (Debian: python3-netcdf4)" % (e.name, path))
    except Exception as e:  # meshio's errors are of many types; its message says what
        fail("meshio: %s" % (str(e).strip() or type(e).__name__))
    points = [list(p) + [0.0] * (3 - len(p)) for p in mesh.points.tolist()]
    top = max((DIM.get(b.type, 0) for b in mesh.cells), default=0)
    names, elements = groups(mesh, path, top)
    write_msh(out, points, names, elements)


if __name__ == "__main__":
    main()
