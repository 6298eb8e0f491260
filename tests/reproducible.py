"""The same command twice gives the same numbers (issue 40, item 7): every analysis, on 1 and 2
ranks. Each case runs twice into two output directories; every number of summary.json but the
costs (timings, memory, seconds, the command line) must be equal bit for bit, and particles.vtu
(or particles.pvtu and its pieces) the same bytes, and the analysis' tables (steps.csv, modes.csv,
history.csv, anisotropy_polar.csv) the same but for the seconds a step took.

One exception, measured (docs/reliability.md, "Reproducible results"): MUMPS on more than one
rank does not give the same last digits twice (ten 2-rank shift-and-invert modal runs of
examples/lamina/modal.yaml gave ten different modes.csv, frequencies within 6e-16 relative,
while SuperLU_DIST and one rank gave the same bytes every time). The 2-rank modal case is
therefore run twice as it is, compared to round-off (NEAR_RTOL of each value, residuals to
NEAR_ATOL), and twice more with SuperLU_DIST, compared bit for bit.

usage: reproducible.py PERILIN EXAMPLES_DIR SCENES_DIR TMP [MPIRUN...]
"""
import csv
import filecmp
import json
import os
import subprocess
import sys

COST = ("timing", "memory", "seconds", "_s", "command_line", "build", "wall", "scene")
TABLES = ("steps.csv", "modes.csv", "history.csv", "anisotropy_polar.csv", "particles.vtu", "particles.pvtu")
NEAR_RTOL = 1e-12  # relative, of every value and of each particle array's largest entry
NEAR_ATOL = 1e-12  # absolute: residuals, and shares and mass fractions that are zero but for round-off
failures = 0


def numbers(d, path=""):
    """Every value of the summary but the costs, by its path."""
    if isinstance(d, dict):
        for k, v in d.items():
            if any(c in k for c in COST):
                continue
            yield from numbers(v, path + "." + k)
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from numbers(v, "%s[%d]" % (path, i))
    else:
        yield path, d


def same_table(a, b):
    """Two files the same bytes; a CSV table less its costs (a column named seconds)."""
    if not a.endswith(".csv"):
        return filecmp.cmp(a, b, shallow=False)
    rows = []
    for path in (a, b):
        with open(path) as f:
            table = list(csv.reader(f))
        keep = [k for k, name in enumerate(table[0]) if name != "seconds"]
        rows.append([[r[k] for k in keep if k < len(r)] for r in table])
    return rows[0] == rows[1]


def same_files(a, b, same=same_table):
    bad = [f for f in TABLES if os.path.exists(os.path.join(a, f)) and not same(os.path.join(a, f), os.path.join(b, f))]
    pieces = os.path.join(a, "particles")
    if os.path.isdir(pieces):
        bad += ["particles/" + f for f in os.listdir(pieces) if not same(os.path.join(pieces, f), os.path.join(b, "particles", f))]
    return bad


def near(a, b):
    """Two numbers equal to round-off: relative NEAR_RTOL, or NEAR_ATOL for values that are 0 to
    round-off (an effective mass of 1e-30) or are themselves round-off (a residual of 1e-12)."""
    if not isinstance(a, float) or not isinstance(b, float):
        return a == b
    return abs(a - b) <= NEAR_RTOL * max(abs(a), abs(b)) + NEAR_ATOL


def near_table(a, b):
    """Two CSV tables or particle files equal to round-off (near() entry by entry; each particle
    array to NEAR_RTOL of its largest entry)."""
    if a.endswith(".csv"):
        rows = [list(csv.reader(open(p))) for p in (a, b)]
        if len(rows[0]) != len(rows[1]):
            return False
        for r, s in zip(*rows):
            for x, y in zip(r, s):
                try:
                    if not near(float(x), float(y)):
                        return False
                except ValueError:
                    if x != y:
                        return False
        return True
    if not a.endswith("vtu"):
        return filecmp.cmp(a, b, shallow=False)
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader
    grids = []
    for p in (a, b):
        reader = vtkXMLPUnstructuredGridReader() if p.endswith(".pvtu") else vtkXMLUnstructuredGridReader()
        reader.SetFileName(p)
        reader.Update()
        pd = reader.GetOutput().GetPointData()
        grids.append({pd.GetArrayName(k): vtk_to_numpy(pd.GetArray(k)) for k in range(pd.GetNumberOfArrays())})
    if grids[0].keys() != grids[1].keys():
        return False
    for k, x in grids[0].items():
        y = grids[1][k]
        scale = max(abs(x).max(), abs(y).max()) if x.size else 0
        if x.shape != y.shape or (x.size and abs(x - y).max() > NEAR_RTOL * scale + NEAR_ATOL):
            return False
    return True


def case(name, cmd, tmp, exact=True):
    global failures
    outs = [os.path.join(tmp, "%s_%d" % (name, k)) for k in (1, 2)]
    for o in outs:
        r = subprocess.run(cmd + ["-output_dir", o, "-quiet"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if r.returncode:
            print("FAIL: %s exited %d\n%s" % (name, r.returncode, r.stdout[-2000:]))
            failures += 1
            return
    s = [dict(numbers(json.load(open(os.path.join(o, "summary.json"))))) for o in outs]
    same = (lambda x, y: x == y) if exact else near
    diff = [k for k in s[0] if k not in s[1] or not same(s[0][k], s[1][k])] + [k for k in s[1] if k not in s[0]]
    files = same_files(*outs, same=same_table if exact else near_table)
    ok = not diff and not files
    print(("ok: " if ok else "FAIL: ") + "%s: %d summary values equal%s%s" % (name, len(s[0]), "" if exact else " to round-off", "" if ok else "; differ: %s %s" % (diff[:5], files)))
    failures += not ok


def main():
    exe, ex, sc, tmp = sys.argv[1:5]
    mpirun = sys.argv[5:]
    runs = [
        ("static", [os.path.join(ex, "pmb/plate_traction.yaml")]),
        ("modal", [os.path.join(sc, "tiny_modal.yaml"), "-output_vtk", "true"]),
        ("quasistatic", [os.path.join(ex, "fracture/edge_crack.yaml"), "-grid_spacing", "0.04"]),
        ("quasistatic_os", [os.path.join(ex, "antiplane/cracked_bar.yaml"), "-grid_spacing", "0.05"]),
        ("dynamic", [os.path.join(ex, "dynamics/kalthoff_winkler.yaml"), "-grid_spacing", "4e-3"]),
        ("anisotropy", [os.path.join(ex, "failure/anisotropy.yaml"), "-analysis_m", "2", "-analysis_orientations", "11", "-analysis_criteria", "stretch,sliding"]),
    ]
    for name, args in runs:
        case(name, [exe] + args, tmp)
        if mpirun and name != "anisotropy":  # the unit-cell study is serial
            case(name + "_2ranks", mpirun + [exe] + args, tmp, exact=name != "modal")
        if mpirun and name == "modal":  # MUMPS's last digits vary on 2 ranks; SuperLU_DIST's do not
            case("modal_2ranks_superlu_dist", mpirun + [exe] + args + ["-st_pc_type", "lu", "-st_pc_factor_mat_solver_type", "superlu_dist"], tmp)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
