#!/usr/bin/env bash
# What the README's first command shows a new user (issue 28, item 10): the default example, a
# plate of E = 1 GPa pulled by 1 MPa, prints what it solved, the largest displacements, the
# displacements at the scene's four probes and the files of its output set, which exist; the
# printed numbers are summary.json's, and the probes' stretch ux(b) - ux(a) over their 0.4 m is
# the uniaxial strain sigma / E = 1e-3 (to 10 %: surface effects, a discrete body).
# usage: first_run.sh PERILIN REPO_DIR
set -u
exe=$1 repo=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
unset PETSC_OPTIONS
"$exe" "$repo/examples/pmb/plate_traction.yaml" -output_dir "$tmp/out" > "$tmp/log" 2>&1 < /dev/null || { cat "$tmp/log"; echo "FAIL: the default example exited $?"; exit 1; }
cat "$tmp/log"
python3 - "$tmp/log" "$tmp/out" <<'PY'
import json, os, re, sys
log, out = open(sys.argv[1]).read(), sys.argv[2]
s = json.load(open(os.path.join(out, "summary.json")))
fail = []
def check(ok, what):
    if not ok:
        fail.append(what)
def near(a, b):
    return abs(a - b) <= 1e-5 * abs(b) + 1e-300
check(re.search(r"^perilin: static, model pmb, 5000 particles", log, re.M), "the line of what was solved")
m = re.search(r"^perilin: largest displacement \|ux\| (\S+), \|uy\| (\S+)$", log, re.M)
check(m and near(float(m[1]), s["max_abs_u"]["ux"]) and near(float(m[2]), s["max_abs_u"]["uy"]), "the largest displacements as summary.json's max_abs_u")
printed = {}
for name, x, y, ux, uy in re.findall(r"^perilin: probe (\w+) at \((\S+), (\S+)\): ux (\S+) uy (\S+)$", log, re.M):
    printed[name] = (float(ux), float(uy))
    p = s["probes"][name]
    check(near(float(x), p["particle_x"][0]) and near(float(y), p["particle_x"][1]), "probe %s's position" % name)
    check(near(printed[name][0], p["u"][0]) and near(printed[name][1], p["u"][1]), "probe %s's displacement" % name)
check(sorted(printed) == ["a", "b", "c", "d"], "the four probes of the scene: %s" % sorted(printed))
if "a" in printed and "b" in printed:
    strain = (printed["b"][0] - printed["a"][0]) / 0.4  # probes a and b lie 0.4 m apart along x
    check(abs(strain / 1e-3 - 1) < 0.1, "the strain between probes a and b, %g, is not sigma / E = 1e-3" % strain)
m = re.search(r"^perilin: strain energy \S+; results in (\S+)/: (.+) \(docs/summary\.md\)$", log, re.M)
check(m and os.path.samefile(m[1], out), "the last line names the output directory")
files = m[2].split(", ") if m else []
check("summary.json" in files and "particles.vtu" in files, "the last line names summary.json and particles.vtu: %s" % files)
for f in files:
    check(os.path.exists(os.path.join(out, f)), "%s is named but not written" % f)
for f in fail:
    print("FAIL: " + f)
if not fail:
    print("first_run: the default example shows what it solved, its displacements and its files")
sys.exit(1 if fail else 0)
PY
