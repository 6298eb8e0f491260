"""perilin's VTK output read by VTK's own readers (issue 16, item 7), checked against the run's
other outputs: summary.json, steps.csv, modes.csv; and a run on several ranks (VTK's parallel
format, issue 17 item 4) against the same run on one.

usage: vtk_read.py static|modal|quasistatic|dynamic OUTPUT_DIR EVERY RANKS [ONE_RANK_OUTPUT_DIR]

VTK has no PVD reader outside ParaView (vtkPVDReader is ParaView's), so a .pvd collection is
parsed with Python's xml module, as its format is plain XML, and every file it names is opened
with vtkXMLUnstructuredGridReader (.vtu: one rank) or vtkXMLPUnstructuredGridReader (.pvtu: one
piece per rank). The expectations come from files VTK does not read: a file that VTK reads
differently from what perilin meant (byte order, offsets, header type, the appended block, the
pieces) fails here. On RANKS > 1 every piece must hold exactly its rank's particles (each rank
wrote its own, nothing was gathered), and with ONE_RANK_OUTPUT_DIR every array must equal the
one-rank run's after sorting the particles by position (the partition renumbers them).
"""
import csv
import json
import os
import re
import sys
import xml.etree.ElementTree as ET

from vtkmodules.util.numpy_support import vtk_to_numpy
import numpy as np
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader

failures = 0
RANKS = 1
EXT = "vtu"
# Arrays that differ between partitions by design: the owner, and particle numbers.
NUMBERING = ("rank", "mirror_of")
# The scene's conditions, written with every state (src/system/bc_fields.c): no part of a mode shape.
CONDITIONS = ("fixed", "prescribed_displacement", "applied_force", "region_")
# How far a run on several ranks may differ from the same run on one, relative to each array's
# largest value. Static and quasi-static: every solve ends at a true relative residual of 1e-10
# (perilin's default -ksp_rtol, src/system/solve.c) from a different ordering of the same sums, so
# the fields agree to a small multiple of it; 1e-8 leaves the conditioning of K a factor 100.
# Modal: the shapes come from shift-and-invert solved by a direct factorization and converge to
# SLEPc's default tolerance 1e-8 in the residual, which bounds a shape's error by about that over
# the relative gap to the next frequency (a few per cent in lamina/modal.yaml): 1e-6.
RTOL = {"static": 1e-8, "quasistatic": 1e-8, "modal": 1e-6, "dynamic": 1e-8}


def check(ok, what):
    global failures
    print(("ok: " if ok else "FAIL: ") + what)
    failures += not ok


def close(a, b, rel=1e-12):
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def read_vtu(path):
    """The grid as VTK reads it (a .pvtu with its pieces); an error (a malformed file) is a
    failure, not a crash."""
    r = vtkXMLPUnstructuredGridReader() if path.endswith(".pvtu") else vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    if r.GetErrorCode():
        raise RuntimeError("VTK cannot read %s (error code %d)" % (path, r.GetErrorCode()))
    if path.endswith(".pvtu"):
        check_pieces(path, r.GetOutput().GetNumberOfPoints())
    return r.GetOutput()


def check_pieces(path, npoints):
    """A .pvtu's pieces: one per rank, piece r read alone holds rank r's particles only."""
    sources = [p.get("Source") for p in ET.parse(path).getroot().iter("Piece")]
    counts, own = [], True
    for r, src in enumerate(sources):
        g = read_vtu(os.path.join(os.path.dirname(path), src))
        counts.append(g.GetNumberOfPoints())
        own = own and bool((array(g, "rank") == r).all())
    name = os.path.basename(path)
    check(len(sources) == RANKS, "%s: %d pieces for %d ranks" % (name, len(sources), RANKS))
    check(own and sum(counts) == npoints, "%s: piece r holds rank r's particles only (%s, %d in all)" % (name, counts, npoints))


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
    g = read_vtu(os.path.join(out, "particles." + EXT))
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
    if os.environ.get("DEGENERATE"):
        f = sorted(f_json[:12])
        gap = min((b - a) / b for a, b in zip(f, f[1:]))
        check(gap <= 1e-9, "degenerate modes: the closest frequencies are %.2g apart (relative), at most 1e-9" % gap)
    frames = check_frames(out, "modes.pvd", [f_json[k] for k in order], ["mode_%02d.%s" % (k + 1, EXT) for k in order], summary, 1e-11)
    whole = read_vtu(os.path.join(out, "particles." + EXT))
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
    files = ["particles_%04d.%s" % (k, EXT) for k in range(every, last + 1, every)]
    times = [lam[k] for k in range(every, last + 1, every)]
    if last % every:
        files.append("particles." + EXT)
        times.append(lam[last])
    check(close(times[-1], summary["quasistatic"]["peak_load_factor"], 1e-9), "the last frame is the last equilibrium: load factor %g, summary.json peak_load_factor %g" % (times[-1], summary["quasistatic"]["peak_load_factor"]))
    # steps.csv has 10 digits; equal load factors are 1e-12 apart in the series
    frames = check_frames(out, "particles.pvd", times, files, summary, 1e-9)
    final, end = read_vtu(os.path.join(out, frames[-1][1])), read_vtu(os.path.join(out, "particles." + EXT))
    check((array(final, "displacement") == array(end, "displacement")).all() and (array(final, "damage") == array(end, "damage")).all(), "the last frame shows particles.vtu's displacement and damage")
    if "ux" in summary.get("max_abs_u", {}):
        check(close(float(abs(array(end, "displacement")[:, 0]).max()), summary["max_abs_u"]["ux"]), "particles.vtu max |ux| equals summary.json max_abs_u.ux")


def by_position(g):
    """The point arrays of g in the order of the points sorted by position (x, then y, then z)."""
    x = vtk_to_numpy(g.GetPoints().GetData())
    order = np.lexsort(x.T[::-1])
    pd = g.GetPointData()
    arrays = {pd.GetArrayName(k): vtk_to_numpy(pd.GetArray(k))[order] for k in range(pd.GetNumberOfArrays())}
    return x[order], arrays


def mode_group(name, k):
    """Which mode shape the array k of file name belongs to (its sign is one per mode), or None."""
    if name.startswith("mode_"):
        return None if k in ("volume", "neighbors") + NUMBERING or k.startswith(CONDITIONS) else name
    m = re.match(r"mode_(\d+)", k)
    return m.group(0) if m else None


def compare(out, ref, name, rtol):
    """Every array of out/name against the one-rank run's ref/name (same name, .vtu), to rtol of
    the array's largest magnitude; a mode shape up to its sign (one per mode: no solver fixes it)."""
    xp, ap = by_position(read_vtu(os.path.join(out, name)))
    xs, as1 = by_position(read_vtu(os.path.join(ref, os.path.splitext(name)[0] + ".vtu")))
    check(xp.shape == xs.shape and (xp == xs).all(), "%s: the same particle positions on %d ranks as on one" % (name, RANKS))
    names = sorted(set(ap) | set(as1))
    check(sorted(ap) == sorted(as1), "%s: the same arrays on %d ranks as on one (%s)" % (name, RANKS, ", ".join(names)))
    common = [k for k in names if k not in NUMBERING and k in ap and k in as1]
    sign = {}
    for k in common:  # a mode's sign: from its largest array (the translations, named first)
        g = mode_group(name, k)
        if g and g not in sign:
            sign[g] = 1.0 if float((ap[k].astype(float) * as1[k]).sum()) >= 0 else -1.0
    worst = {}
    for k in common:
        a, b = ap[k].astype(float) * sign.get(mode_group(name, k), 1.0), as1[k].astype(float)
        worst[k] = float(abs(a - b).max()) / max(float(abs(b).max()), 1e-300)
    bad = {k: v for k, v in worst.items() if not v <= rtol}
    check(not bad, "%s: every array equals the one-rank run's to %g of its largest value (worst %s)" % (name, rtol, max(worst.items(), key=lambda kv: kv[1]) if worst else None))
    if bad:
        print("    beyond %g: %s" % (rtol, bad))

def dynamic(out, summary):
    """A transient run's series: a frame every EVERY steps and at the last (EVERY 0: perilin's
    default of 25 frames over t_end), each frame's velocity against history.csv's kinetic energy
    of its time (1/2 sum rho V |v|^2: the field is the state the energies describe), the last
    frame equal to particles.vtu."""
    with open(os.path.join(out, "history.csv")) as f:
        hist = {float(r["time"]): float(r["kinetic"]) for r in csv.DictReader(f)}
    steps, dt = summary["dynamic"]["steps"], summary["dynamic"]["dt"]
    every = int(sys.argv[3]) or -(-steps // 25)
    ks = list(range(0, steps + 1, every)) + ([steps] if steps % every else [])
    frames = check_frames(out, "particles.pvd", [k * dt for k in ks], ["particles_%04d.%s" % (n, EXT) for n in range(len(ks))], summary, 1e-9)
    rho = summary["material"]["rho"]
    for t, f in frames:
        g = read_vtu(os.path.join(out, f))
        v, V = array(g, "velocity"), array(g, "volume")
        T = 0.5 * rho * float((V * (v * v).sum(axis=1)).sum())
        ref = min(hist, key=lambda h: abs(h - t))
        check(close(T, hist[ref], 1e-8), "%s: 1/2 sum rho V |v|^2 = %.10g, history.csv kinetic at t = %g: %.10g" % (f, T, ref, hist[ref]))
    end, last = read_vtu(os.path.join(out, "particles." + EXT)), read_vtu(os.path.join(out, frames[-1][1]))
    check((array(end, "velocity") == array(last, "velocity")).all() and (array(end, "displacement") == array(last, "displacement")).all(), "the last frame shows particles.vtu's displacement and velocity")


def compare_run(kind, out, ref, rtol):
    """The particle file and every frame of the run's series."""
    names = ["particles." + EXT]
    pvd = {"modal": "modes.pvd", "quasistatic": "particles.pvd", "dynamic": "particles.pvd"}.get(kind)
    if pvd and os.path.exists(os.path.join(out, pvd)):
        names += [f for _, f in read_pvd(os.path.join(out, pvd)) if f not in names]
    for n in names:
        compare(out, ref, n, rtol)


def main():
    global RANKS, EXT
    kind, out = sys.argv[1], sys.argv[2]
    RANKS = int(sys.argv[4]) if len(sys.argv) > 4 else 1
    EXT = "pvtu" if RANKS > 1 else "vtu"
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    other = os.path.join(out, "particles." + ("vtu" if RANKS > 1 else "pvtu"))
    check(not os.path.exists(other), "%d rank(s): no %s" % (RANKS, os.path.basename(other)))
    {"static": static, "modal": modal, "quasistatic": quasistatic, "dynamic": dynamic}[kind](out, summary)
    if len(sys.argv) > 5:
        compare_run(kind, out, sys.argv[5], RTOL[kind])
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
