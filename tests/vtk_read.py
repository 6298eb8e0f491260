"""perilin's VTK output read by VTK's own readers (issue 16, item 7), checked against the run's
other outputs: summary.json, steps.csv, modes.csv.

usage: vtk_read.py static|modal|quasistatic OUTPUT_DIR

VTK has no PVD reader outside ParaView (vtkPVDReader is ParaView's), so a .pvd collection is
parsed with Python's xml module, as its format is plain XML, and every .vtu it names is opened
with vtkXMLUnstructuredGridReader. The expectations come from files VTK does not read: a .vtu
that VTK reads differently from what perilin meant (byte order, offsets, header type, the
appended block) fails here.
"""
import csv
import json
import os
import sys
import xml.etree.ElementTree as ET

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

failures = 0


def check(ok, what):
    global failures
    print(("ok: " if ok else "FAIL: ") + what)
    failures += not ok


def close(a, b, rel=1e-12):
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def read_vtu(path):
    """The grid as VTK reads it; an error (a malformed file) is a failure, not a crash."""
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    if r.GetErrorCode():
        raise RuntimeError("VTK cannot read %s (error code %d)" % (path, r.GetErrorCode()))
    return r.GetOutput()


def array(grid, name):
    a = grid.GetPointData().GetArray(name)
    if a is None:
        raise KeyError("%s: no point array %r" % (grid, name))
    return vtk_to_numpy(a)


def read_pvd(path):
    """The (time, file) frames of a ParaView collection, in file order."""
    root = ET.parse(path).getroot()
    assert root.get("type") == "Collection", path
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def check_frames(out, pvd, times, files, summary, rel):
    frames = read_pvd(os.path.join(out, pvd))
    check([f for _, f in frames] == files, "%s names %s" % (pvd, files))
    t = [x for x, _ in frames]
    check(all(b > a for a, b in zip(t, t[1:])), "%s: the times increase strictly (ParaView needs it)" % pvd)
    check(len(t) == len(times) and all(close(a, b, rel) for a, b in zip(t, times)), "%s: the times %s equal %s (to %g)" % (pvd, t, times, rel))
    for _, f in frames:
        g = read_vtu(os.path.join(out, f))
        check(g.GetNumberOfPoints() == summary["particles"] and g.GetNumberOfCells() == summary["particles"], "%s: %d points and vertex cells, summary.json particles %d" % (f, g.GetNumberOfPoints(), summary["particles"]))
    return frames


def static(out, summary):
    g = read_vtu(os.path.join(out, "particles.vtu"))
    n = summary["particles"]
    check(g.GetNumberOfPoints() == n and g.GetNumberOfCells() == n, "particles.vtu: %d points, %d cells; summary.json particles %d" % (g.GetNumberOfPoints(), g.GetNumberOfCells(), n))
    u = array(g, "displacement")
    check(u.shape == (n, 3), "displacement: %s values, 3 components" % (u.shape,))
    for c, name in enumerate(("ux", "uy", "uz")):
        if name in summary["max_abs_u"]:
            m = float(abs(u[:, c]).max())
            check(close(m, summary["max_abs_u"][name]), "max |%s| = %.17g, summary.json max_abs_u.%s %.17g" % (name, m, name, summary["max_abs_u"][name]))
    W, V = array(g, "strain_energy_density"), array(g, "volume")
    e = float((W * V).sum())
    check(close(e, summary["strain_energy"], 1e-10), "sum W V = %.12g, summary.json strain_energy %.12g" % (e, summary["strain_energy"]))


def modal(out, summary):
    with open(os.path.join(out, "modes.csv")) as f:
        rows = list(csv.DictReader(f))
    f_csv = [float(r["f_hz"]) for r in rows]
    f_json = [m["f_hz"] for m in summary["modal"]["modes"]]
    check(all(close(a, b, 1e-9) for a, b in zip(f_csv, f_json)), "modes.csv f_hz equals summary.json modal.modes[].f_hz")
    order = sorted(range(len(f_json)), key=lambda k: f_json[k])[:12]
    frames = check_frames(out, "modes.pvd", [f_json[k] for k in order], ["mode_%02d.vtu" % (k + 1) for k in order], summary, 1e-11)
    whole = read_vtu(os.path.join(out, "particles.vtu"))
    for _, f in frames:
        k = int(f[5:7])
        u = array(read_vtu(os.path.join(out, f)), "displacement")
        check(close(float(abs(u).max()), 1.0), "%s: the shape is scaled to max |u| = 1" % f)
        check((u == array(whole, "mode_%d" % k)).all(), "%s: its displacement is particles.vtu's mode_%d" % (f, k))


def quasistatic(out, summary):
    with open(os.path.join(out, "steps.csv")) as f:
        steps = list(csv.DictReader(f))
    every = int(sys.argv[3])
    lam = {int(s["step"]): float(s["load_factor"]) for s in steps}
    last = len(steps)
    files = ["particles_%04d.vtu" % k for k in range(every, last + 1, every)]
    times = [lam[k] for k in range(every, last + 1, every)]
    if last % every:
        files.append("particles.vtu")
        times.append(lam[last])
    check(close(times[-1], summary["quasistatic"]["peak_load_factor"], 1e-9), "the last frame is the last equilibrium: load factor %g, summary.json peak_load_factor %g" % (times[-1], summary["quasistatic"]["peak_load_factor"]))
    # steps.csv has 10 digits; equal load factors are 1e-12 apart in the series
    frames = check_frames(out, "particles.pvd", times, files, summary, 1e-9)
    final, end = read_vtu(os.path.join(out, frames[-1][1])), read_vtu(os.path.join(out, "particles.vtu"))
    check((array(final, "displacement") == array(end, "displacement")).all() and (array(final, "damage") == array(end, "damage")).all(), "the last frame shows particles.vtu's displacement and damage")
    if "ux" in summary.get("max_abs_u", {}):
        check(close(float(abs(array(end, "displacement")[:, 0]).max()), summary["max_abs_u"]["ux"]), "particles.vtu max |ux| equals summary.json max_abs_u.ux")


def main():
    kind, out = sys.argv[1], sys.argv[2]
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    {"static": static, "modal": modal, "quasistatic": quasistatic}[kind](out, summary)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
