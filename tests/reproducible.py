"""The same command twice gives the same numbers (issue 40, item 7): every analysis, on 1 and 2
ranks. Each case runs twice into two output directories; every number of summary.json but the
costs (timings, memory, seconds, the command line) must be equal bit for bit, and particles.vtu
(or particles.pvtu and its pieces) the same bytes, and the analysis' tables (steps.csv, modes.csv,
history.csv, anisotropy_polar.csv) the same but for the seconds a step took.

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


def same_files(a, b):
    bad = [f for f in TABLES if os.path.exists(os.path.join(a, f)) and not same_table(os.path.join(a, f), os.path.join(b, f))]
    pieces = os.path.join(a, "particles")
    if os.path.isdir(pieces):
        bad += ["particles/" + f for f in os.listdir(pieces) if not filecmp.cmp(os.path.join(pieces, f), os.path.join(b, "particles", f), shallow=False)]
    return bad


def case(name, cmd, tmp):
    global failures
    outs = [os.path.join(tmp, "%s_%d" % (name, k)) for k in (1, 2)]
    for o in outs:
        r = subprocess.run(cmd + ["-output_dir", o, "-quiet"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if r.returncode:
            print("FAIL: %s exited %d\n%s" % (name, r.returncode, r.stdout[-2000:]))
            failures += 1
            return
    s = [dict(numbers(json.load(open(os.path.join(o, "summary.json"))))) for o in outs]
    diff = [k for k in s[0] if s[0][k] != s[1].get(k)] + [k for k in s[1] if k not in s[0]]
    files = same_files(*outs)
    ok = not diff and not files
    print(("ok: " if ok else "FAIL: ") + "%s: %d summary values equal%s" % (name, len(s[0]), "" if ok else "; differ: %s %s" % (diff[:5], files)))
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
            case(name + "_2ranks", mpirun + [exe] + args, tmp)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
