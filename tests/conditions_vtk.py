"""The conditions in particles.vtu (issue 28 item 7), read by VTK's own readers and checked against
values computed here from the scene file alone: the arrays fixed (UInt8, one component per DOF,
named ux, uy), prescribed_displacement, applied_force and region_<name> (UInt8).

usage: conditions_vtk.py plate|grip SCENE OUTPUT_DIR
  plate: examples/pmb/plate_traction.yaml (a roller layer on the left, a pin box, a traction on
         the right): the sum of applied_force is traction x face area x thickness, only on the
         right layer; ux fixed exactly on the left layer's particles, uy on the pin's;
  grip:  tests/scenes/reaction_qs.yaml (a clamped left layer, a displaced right one): the
         prescribed values on exactly the right layer's particles.
The grid (cell-centred particles, the first at lower + dx/2) and the regions (a layer one horizon,
m dx, deep; a box) are rebuilt here from the scene's numbers.
"""
import os
import sys

import numpy as np
import yaml
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader

kind, scene_file, out = sys.argv[1:4]
scene = yaml.safe_load(open(scene_file))
failures = 0


def check(ok, what):
    global failures
    print(("ok: " if ok else "FAIL: ") + what)
    failures += not ok


def read(out):
    path = os.path.join(out, "particles.pvtu")
    reader = vtkXMLPUnstructuredGridReader() if os.path.exists(path) else vtkXMLUnstructuredGridReader()
    reader.SetFileName(path if os.path.exists(path) else os.path.join(out, "particles.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    pd = grid.GetPointData()
    arrays = {pd.GetArrayName(k): pd.GetArray(k) for k in range(pd.GetNumberOfArrays())}
    return vtk_to_numpy(grid.GetPoints().GetData()), arrays


x, arrays = read(out)
value = {name: vtk_to_numpy(a) for name, a in arrays.items()}
g = scene["grid"]
dx = float(g["spacing"])
lower, upper = np.array(g["lower"], float), np.array(g["upper"], float)
shape = np.rint((upper - lower) / dx).astype(int)
check(len(x) == shape.prod(), "%d particles, the grid's %s" % (len(x), shape))
depth = float(scene["horizon"]["m"]) * dx


def layer(side):
    axis, sign = "xyz".index(side[0]), side[1]
    return x[:, axis] < lower[axis] + depth if sign == "-" else x[:, axis] > upper[axis] - depth


def box(r):
    lo, hi = np.array(r["lower"], float), np.array(r["upper"], float)
    return np.all((x[:, :2] >= lo) & (x[:, :2] <= hi), axis=1)


regions = {name: layer(r["side"]) if "side" in r else box(r) for name, r in scene["regions"].items()}
for name, inside in regions.items():
    a = arrays.get("region_" + name)
    check(a is not None and a.GetDataTypeAsString() == "unsigned char", "region_%s is a UInt8 array" % name)
    check(a is not None and np.array_equal(value["region_" + name] == 1, inside), "region_%s is 1 on exactly its %d particles" % (name, inside.sum()))
fixed = arrays["fixed"]
check(fixed.GetDataTypeAsString() == "unsigned char" and [fixed.GetComponentName(c) for c in range(2)] == ["ux", "uy"], "fixed is UInt8 with components ux, uy")
expect = np.zeros((len(x), 2), bool)
for bc in scene["bc"]:
    comps = bc["fix"] if "fix" in bc else list(bc["value"])
    for c in comps:
        expect[regions[bc["region"]], ["ux", "uy"].index(c)] = True
check(np.array_equal(value["fixed"] == 1, expect), "fixed: ux on %d particles, uy on %d, as the bc items' regions" % tuple(expect.sum(axis=0)))
f = value["applied_force"]
p = value["prescribed_displacement"]
if kind == "plate":
    load = scene["loads"][0]
    t = np.array(load["traction"], float)
    height = upper[1] - lower[1]  # the right face's length
    total = t * height * float(scene["material"]["thickness"])
    check(np.allclose(f[:, :2].sum(axis=0), total, rtol=1e-12, atol=1e-9 * abs(total).max()), "sum of applied_force %s = traction x face area %s" % (f[:, :2].sum(axis=0), total))
    check(not f[~regions[load["region"]]].any(), "applied_force is 0 off the loaded layer")
    check(not p.any(), "prescribed_displacement is 0 (fix only)")
else:
    v = np.zeros((len(x), 3))
    for bc in scene["bc"]:
        for c, val in bc.get("value", {}).items():
            v[regions[bc["region"]], ["ux", "uy"].index(c)] = float(val)
    check(np.array_equal(p, v), "prescribed_displacement is the bc values on their regions (ux %g on %d particles)" % (v[:, 0].max(), (v[:, 0] != 0).sum()))
    check(not f.any(), "applied_force is 0 (no loads)")
sys.exit(1 if failures else 0)
