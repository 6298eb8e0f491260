#!/usr/bin/env python3
"""Normalize a perilin output directory and compare it with committed expectations (tests/golden).

  golden.py normalize OUTDIR DEST          write the normalized files of OUTDIR into DEST
  golden.py compare GOT EXPECTED [--update] compare two normalized directories; with --update,
                                           replace each expected file that does not compare equal
                                           (files that still compare equal are kept byte for byte,
                                           so the git diff of an update shows only real changes)

Normalized files (see golden.sh for why these are guards against unintended change, not physics tests):
  summary.json   perilin's summary minus the volatile keys (VOLATILE below), with the values of the
                 keys that vary by build and invocation (VARIES: build.perilin, which `git describe`
                 changes at every commit, the PETSc and SLEPc versions, the command line with its
                 temporary paths) replaced by "<varies>", so their presence is still compared
  modes.csv      as written
  steps.csv      minus the `seconds` column
  files.txt      the names of the files in the output directory (hidden ones included)
  arrays.txt     for every .vtu: the set of DataArray (section, name, NumberOfComponents) read from
                 the XML header (the appended binary data is not compared); for every .pvd: the
                 files it indexes

Numbers (summary.json, modes.csv, steps.csv) are equal when
  |a - b| <= 1e-9 max(|a|, |b|)                       (relative)
  or max(|a|, |b|) <= 1e-12 S                         (both round-off zeros of their family)
  or |a - b| <= 1e-12 S                               (a change at round-off of the family's scale:
     a value zero by symmetry that the iterative solve leaves at its tolerance, ~1e-11 S, moves by
     1e-15 S with the machine's BLAS; seen between two machines with the same code)
  or, in a CSV, |a - b| <= one unit of the last printed digit of a or b (modes.csv prints shares
     and effective masses with 6 decimals: a round-off change may flip the last digit).
S, the scale of a family, is the largest magnitude of the family in either file: a CSV column, or
the numbers in one JSON container (path without list indices, e.g. probes.a.u,
modal.modes.energy_share, max_abs_u); a scalar of the top level is its own family. Two families can
be all round-off in the goldens' scenes, so they get a physical floor: modal.modes.effective_mass
(bar_modes: zero for every elastic mode of a free bar) has S >= modal.total_mass, and
modal.modes.energy_share (shares sum to 1) has S >= 1. Forces vanish by balance in several scenes (a
pin's reaction, a self-equilibrated load): the families reactions.*, applied_load and
equilibrium.imbalance have S >= equilibrium.force_scale, and steps.csv's reaction and R_* columns
share the largest of them as S.
1e-12 rather than 1e-14: a refactoring that reorders sums moves a value that is zero by symmetry by
round-off times the condition of the solve, which can reach ~1e-13 of the family scale.

Round-off quantities (ROUNDOFF): a refactoring may change them legitimately, so only their order of
magnitude is guarded: the new value must not exceed 10^(floor(log10(expected)) + 3), i.e. it may
grow by at most two orders of magnitude (it may fall freely).
  solver.residual_norm           true relative residual after the solve
  solver.load_share_removed      share of the load along free rigid motions (round-off when balanced)
  modal.modes.residual, modes.csv residual   eigenpair residuals
  interior_strain                mean strain of the interior particles: zero by antisymmetry in the
                                 only reference scene of the goldens (pure bending), 1e-16
  equilibrium.relative_imbalance, steps.csv relative_imbalance   the reactions' and loads' sum
  equilibrium.moment_imbalance, relative_moment_imbalance        the same for their moments

Degenerate modes: modes whose frequencies agree to 1e-6 (bar_modes: the transverse pairs in y and
z) span a subspace in which the eigensolver's basis is arbitrary, so round-off may rotate it. For
such a group only rotation-invariant quantities are compared: each frequency, the group sums of
energy shares and effective masses, and the set of kinds.
"""
import csv
import json
import math
import os
import re
import shutil
import sys

# Keys that differ between two identical runs, or that name the machine rather than the run:
# checked by running every scene twice; only these differed (and `scene` is the path given).
VOLATILE = [("scene",), ("timing",), ("memory_mb",), ("memory_mb_max_rank",), ("memory_phases_mb",), ("matrix_mb",),
            ("modal", "factorization_s"), ("modal", "eigensolve_s"), ("quasistatic", "checkpoint_s"), ("quasistatic", "unfinished_s")]
VARIES = [("build", "perilin"), ("build", "petsc"), ("build", "slepc"), ("command_line",)]
ROUNDOFF_JSON = {"solver.residual_norm", "solver.load_share_removed", "modal.modes.residual",
                 "interior_strain", "equilibrium.relative_imbalance", "equilibrium.moment_imbalance",
                 "equilibrium.relative_moment_imbalance"}
ROUNDOFF_CSV = {"residual", "relative_imbalance"}
STEPS_VOLATILE = {"seconds"}  # wall time of each step
REL = 1e-9
ZERO = 1e-12
DEGENERATE = 1e-6


# ---------------------------------------------------------------- normalize
def vtu_arrays(path):
    with open(path, "rb") as f:
        head = f.read(1 << 20)
    cut = head.find(b"<AppendedData")
    text = head[: cut if cut >= 0 else len(head)].decode("latin-1")
    stack, out = [], set()
    for m in re.finditer(r"<(/?)([A-Za-z]+)([^>]*?)(/?)>", text):
        close, tag, attrs, empty = m.groups()
        if close:
            if stack and stack[-1] == tag:
                stack.pop()
            continue
        if tag == "DataArray":
            a = dict(re.findall(r'(\w+)="([^"]*)"', attrs))
            out.add("%s %s %s" % (stack[-1] if stack else "-", a.get("Name", "?"),
                                  a.get("NumberOfComponents", "1")))
        if not empty:
            stack.append(tag)
    return sorted(out)


def normalize(outdir, dest):
    os.makedirs(dest, exist_ok=True)
    names = sorted(os.listdir(outdir))
    with open(os.path.join(dest, "files.txt"), "w") as f:
        f.write("".join(n + "\n" for n in names))
    lines = []
    for n in names:
        p = os.path.join(outdir, n)
        if n.endswith(".vtu"):
            lines += ["%s: %s" % (n, a) for a in vtu_arrays(p)]
        elif n.endswith(".pvd"):
            for g in re.findall(r'file="([^"]+)"', open(p).read()):
                lines.append("%s: indexes %s" % (n, g))
    with open(os.path.join(dest, "arrays.txt"), "w") as f:
        f.write("".join(l + "\n" for l in lines))
    s = json.load(open(os.path.join(outdir, "summary.json")))
    for key in VOLATILE:
        d = s
        for k in key[:-1]:
            d = d.get(k, {}) if isinstance(d, dict) else {}
        if isinstance(d, dict):
            d.pop(key[-1], None)
    for key in VARIES:
        d = s
        for k in key[:-1]:
            d = d.get(k, {}) if isinstance(d, dict) else {}
        if isinstance(d, dict) and key[-1] in d:
            d[key[-1]] = "<varies>"
    with open(os.path.join(dest, "summary.json"), "w") as f:
        json.dump(s, f, indent=2)
        f.write("\n")
    if os.path.exists(os.path.join(outdir, "modes.csv")):
        shutil.copyfile(os.path.join(outdir, "modes.csv"), os.path.join(dest, "modes.csv"))
    if os.path.exists(os.path.join(outdir, "steps.csv")):
        rows = list(csv.reader(open(os.path.join(outdir, "steps.csv"), newline="")))
        keep = [i for i, c in enumerate(rows[0]) if c not in STEPS_VOLATILE] if rows else []
        with open(os.path.join(dest, "steps.csv"), "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            for r in rows:
                w.writerow([r[i] for i in keep if i < len(r)])


# ---------------------------------------------------------------- compare
def isnum(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def close(a, b, scale, unit=0.0):
    if a == b:
        return True
    if math.isnan(a) or math.isnan(b):
        return False
    m = max(abs(a), abs(b))
    return abs(a - b) <= REL * m or m <= ZERO * scale or abs(a - b) <= ZERO * scale or abs(a - b) <= unit * (1 + 1e-9)


def roundoff_ok(expected, got):
    if abs(got) <= abs(expected):
        return True
    if expected == 0:
        return abs(got) < 1e-30
    return abs(got) < 10.0 ** (math.floor(math.log10(abs(expected))) + 3)


def strip(path):
    return re.sub(r"\[\d+\]", "", path)


def families(obj, path="", acc=None):
    """largest magnitude per family (the container path without indices)"""
    acc = {} if acc is None else acc
    items = obj.items() if isinstance(obj, dict) else enumerate(obj)
    for k, v in items:
        p = "%s.%s" % (path, k) if isinstance(obj, dict) else "%s[%d]" % (path, k)
        p = p.lstrip(".")
        if isinstance(v, (dict, list)):
            families(v, p, acc)
        elif isnum(v):
            fam = strip(path) if path else p
            acc[fam] = max(acc.get(fam, 0.0), abs(v))
    return acc


def mode_groups(freqs):
    groups, start = [], 0
    for i in range(1, len(freqs) + 1):
        if i == len(freqs) or abs(freqs[i] - freqs[i - 1]) > DEGENERATE * max(abs(freqs[i]), abs(freqs[i - 1])):
            groups.append(list(range(start, i)))
            start = i
    return groups


def invariant_modes(s):
    """replace the basis-dependent members of degenerate groups by group aggregates (in place)"""
    modes = s.get("modal", {}).get("modes") if isinstance(s.get("modal"), dict) else None
    if not modes:
        return
    for g in mode_groups([m.get("f_hz", 0.0) for m in modes]):
        if len(g) < 2:
            continue
        share = {}
        meff = None
        for i in g:
            for k, v in modes[i].get("energy_share", {}).items():
                share[k] = share.get(k, 0.0) + v
            if "effective_mass" in modes[i]:
                e = modes[i]["effective_mass"]
                meff = list(e) if meff is None else [x + y for x, y in zip(meff, e)]
        kinds = "+".join(sorted(str(modes[i].get("kind")) for i in g))
        for i in g:
            if "energy_share" in modes[i]:
                modes[i]["energy_share"] = {k: ("group sum", v) for k, v in share.items()}
            if meff is not None:
                modes[i]["effective_mass"] = [("group sum", v) for v in meff]
            if "kind" in modes[i]:
                modes[i]["kind"] = "group: " + kinds


def compare_json(exp, got, errs):
    scale = families(exp)
    for k, v in families(got).items():
        scale[k] = max(scale.get(k, 0.0), v)
    tm = exp.get("modal", {}).get("total_mass") if isinstance(exp.get("modal"), dict) else None
    if isnum(tm):
        scale["modal.modes.effective_mass"] = max(scale.get("modal.modes.effective_mass", 0.0), abs(tm))
    scale["modal.modes.energy_share"] = max(scale.get("modal.modes.energy_share", 0.0), 1.0)
    # forces: the reactions, the applied load and the imbalance are round-off where they vanish
    # (a pin, a self-equilibrated load); their floor is the run's force scale (sum of particle forces)
    fs = exp.get("equilibrium", {}).get("force_scale") if isinstance(exp.get("equilibrium"), dict) else None
    if isnum(fs):
        for k in list(scale) + ["applied_load", "equilibrium.imbalance"]:
            if k.startswith("reactions.") or k in ("applied_load", "equilibrium.imbalance"):
                scale[k] = max(scale.get(k, 0.0), abs(fs))
    invariant_modes(exp)
    invariant_modes(got)

    def walk(a, b, path, parent):
        if isinstance(a, tuple):  # a degenerate-group aggregate
            a, b = a[1], b[1] if isinstance(b, tuple) else b
        if isinstance(a, dict) and isinstance(b, dict):
            if list(a) != list(b):
                errs.append("%s: keys %s, expected %s" % (path or "summary", list(b), list(a)))
            for k in a:
                if k in b:
                    p = "%s.%s" % (path, k) if path else k
                    walk(a[k], b[k], p, path)
            return
        if isinstance(a, list) and isinstance(b, list):
            if len(a) != len(b):
                errs.append("%s: %d entries, expected %d" % (path, len(b), len(a)))
            for i, (x, y) in enumerate(zip(a, b)):
                walk(x, y, "%s[%d]" % (path, i), path)
            return
        if isnum(a) and isnum(b):
            sp = strip(path)
            if sp in ROUNDOFF_JSON or strip(parent) in ROUNDOFF_JSON:
                if not roundoff_ok(a, b):
                    errs.append("%s: %r, expected at most the order of %r + 2" % (path, b, a))
            elif not close(a, b, scale.get(strip(parent) if parent else path, 0.0)):
                errs.append("%s: %r, expected %r (rel. diff %.2e)" % (path, b, a, abs(a - b) / max(abs(a), abs(b))))
            return
        if a != b or type(a) != type(b):
            errs.append("%s: %r, expected %r" % (path, b, a))

    walk(exp, got, "", "")


def unit_of(text):
    """one unit of the last printed digit of a number written as text"""
    m = re.fullmatch(r"[-+]?(\d*)(?:\.(\d*))?(?:[eE]([-+]?\d+))?", text.strip())
    if not m or (m.group(2) is None and m.group(3) is None):
        return 0.0  # an integer (a count, an iteration number) must agree exactly
    return 10.0 ** (-len(m.group(2) or "") + int(m.group(3) or 0))


def tofloat(text):
    try:
        return float(text)
    except ValueError:
        return None


def read_csv(path):
    rows = list(csv.reader(open(path, newline="")))
    return (rows[0], rows[1:]) if rows else ([], [])


def csv_cells(head, body, modes):
    """rows of {column: (float or str, unit)}, degenerate modes replaced by group aggregates"""
    table = []
    for r in body:
        row = {}
        for c, t in zip(head, r):
            v = tofloat(t)
            row[c] = (v, unit_of(t)) if v is not None else (t, 0.0)
        table.append(row)
    if modes and "f_hz" in head:
        for g in mode_groups([row["f_hz"][0] for row in table]):
            if len(g) < 2:
                continue
            for c in head:
                if c.startswith("share_") or c.startswith("meff_"):
                    tot = (sum(table[i][c][0] for i in g), sum(table[i][c][1] for i in g))
                    for i in g:
                        table[i][c] = tot
            kinds = "group: " + "+".join(sorted(table[i]["kind"][0] for i in g))
            for i in g:
                if "kind" in table[i]:
                    table[i]["kind"] = (kinds, 0.0)
    return table


def compare_csv(name, exp_path, got_path, errs):
    eh, eb = read_csv(exp_path)
    gh, gb = read_csv(got_path)
    if eh != gh:
        errs.append("%s: columns %s, expected %s" % (name, gh, eh))
        return
    if len(eb) != len(gb):
        errs.append("%s: %d rows, expected %d" % (name, len(gb), len(eb)))
    et = csv_cells(eh, eb, name == "modes.csv")
    gt = csv_cells(gh, gb, name == "modes.csv")
    scale = {}
    for t in (et, gt):
        for row in t:
            for c, (v, u) in row.items():
                if isinstance(v, float):
                    scale[c] = max(scale.get(c, 0.0), abs(v))
    # reaction columns: a held component that carries no force is round-off of the largest reaction
    forces = max([scale[c] for c in scale if c.startswith("R_") or c == "reaction"] + [0.0])
    for c in scale:
        if c.startswith("R_") or c == "reaction":
            scale[c] = forces
    for i, (a, b) in enumerate(zip(et, gt)):
        for c in eh:
            (x, ux), (y, uy) = a.get(c, ("", 0.0)), b.get(c, ("", 0.0))
            where = "%s row %d, %s" % (name, i + 1, c)
            if isinstance(x, float) and isinstance(y, float):
                if c in ROUNDOFF_CSV:
                    if not roundoff_ok(x, y):
                        errs.append("%s: %r, expected at most the order of %r + 2" % (where, y, x))
                elif not close(x, y, scale.get(c, 0.0), max(ux, uy)):
                    errs.append("%s: %r, expected %r" % (where, y, x))
            elif x != y:
                errs.append("%s: %r, expected %r" % (where, y, x))


def compare_file(name, exp_path, got_path):
    errs = []
    if not os.path.exists(exp_path):
        return ["%s: not expected, but written" % name]
    if not os.path.exists(got_path):
        return ["%s: expected, but not written" % name]
    if name == "summary.json":
        compare_json(json.load(open(exp_path)), json.load(open(got_path)), errs)
    elif name.endswith(".csv"):
        compare_csv(name, exp_path, got_path, errs)
    else:
        a, b = open(exp_path).read().splitlines(), open(got_path).read().splitlines()
        if a != b:
            errs += ["%s: expected line missing: %s" % (name, l) for l in a if l not in b]
            errs += ["%s: unexpected line: %s" % (name, l) for l in b if l not in a]
            if not errs:
                errs.append("%s: the same lines in another order" % name)
    return errs


def compare(got, exp, update):
    names = sorted(set(os.listdir(got)) | (set(os.listdir(exp)) if os.path.isdir(exp) else set()))
    errs = []
    for n in names:
        e = compare_file(n, os.path.join(exp, n), os.path.join(got, n))
        if e and update:
            os.makedirs(exp, exist_ok=True)
            if os.path.exists(os.path.join(got, n)):
                shutil.copyfile(os.path.join(got, n), os.path.join(exp, n))
                print("  updated %s" % os.path.join(exp, n))
            else:
                os.remove(os.path.join(exp, n))
                print("  removed %s" % os.path.join(exp, n))
            for line in e[:10]:
                print("    " + line)
            continue
        errs += e
    for e in errs[:40]:
        print("  " + e)
    if len(errs) > 40:
        print("  ... and %d more differences" % (len(errs) - 40))
    return 0 if update or not errs else 1


if __name__ == "__main__":
    if len(sys.argv) >= 4 and sys.argv[1] == "normalize":
        normalize(sys.argv[2], sys.argv[3])
    elif len(sys.argv) >= 4 and sys.argv[1] == "compare":
        sys.exit(compare(sys.argv[2], sys.argv[3], "--update" in sys.argv[4:]))
    else:
        sys.exit(__doc__)
