#!/bin/bash
# Outputs are one set describing one state: a quasi-static run's summary, fields and steps.csv
# agree on the last equilibrium; snapshot and mode-shape series have a .pvd index whose files
# exist; a second run replaces the whole set (no stale snapshot survives); a failing run leaves
# the previous set untouched; no staging directory is left.
# usage: output_set.sh PERILIN EXAMPLES_DIR
set -u
exe=$1; ex=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
out="$tmp/run"
fail() { echo "FAIL: $*"; exit 1; }

"$exe" "$ex/fracture/edge_crack.yaml" -grid_spacing 0.04 -quiet -output_every 1 -output_dir "$out" > "$tmp/log" 2>&1 || { cat "$tmp/log"; fail "the quasi-static run failed"; }
python3 - "$out" <<'PY' || fail "the quasi-static set is not one state"
import csv, json, os, re, sys
out = sys.argv[1]
s = json.load(open(os.path.join(out, "summary.json")))
q = s["quasistatic"]
rows = list(csv.DictReader(open(os.path.join(out, "steps.csv"))))
assert q["state"] == "last equilibrium", q
assert q["broken_bonds"] == int(rows[-1]["broken_total"]), (q["broken_bonds"], rows[-1])
assert abs(q["peak_load_factor"] - float(rows[-1]["load_factor"])) <= 1e-9 * q["peak_load_factor"]
assert q["steps"] == len(rows)
# the control probe in summary.json is steps.csv's last control_u
# (along the control component: uy, the direction of the load)
assert q["control_component"] == "uy", q["control_component"]
u = s["probes"][q["control_probe"]]["u"][["ux", "uy"].index(q["control_component"])]
assert abs(u - float(rows[-1]["control_u"])) <= 1e-9 * abs(u), (u, rows[-1]["control_u"])
if q["failed"]:
    assert q["failure_step"] == len(rows) + 1
    assert os.path.exists(os.path.join(out, "failed_trial.vtu"))
files = re.findall(r'file="([^"]+)"', open(os.path.join(out, "particles.pvd")).read())
assert len(files) == len(rows), (len(files), len(rows))
for f in files:
    assert os.path.exists(os.path.join(out, f)), f
print("ok: quasi-static set: %d steps, %d broken bonds at the last equilibrium, %d snapshots indexed" % (len(rows), q["broken_bonds"], len(files)))
PY
[ -n "$(ls "$out"/particles_*.vtu)" ] || fail "no snapshots"

# a second run into the same directory replaces the set: no snapshot of the first survives
"$exe" "$ex/fracture/edge_crack.yaml" -grid_spacing 0.04 -quiet -output_dir "$out" > "$tmp/log" 2>&1 || { cat "$tmp/log"; fail "the second run failed"; }
ls "$out" | grep -q '^particles_' && fail "stale snapshots survived the second run: $(ls "$out")"
# (particles.pvd is written by default: the second run's, whose one frame is particles.vtu, no
# bond having broken before its last equilibrium)
grep -q 'particles_' "$out/particles.pvd" && fail "a stale particles.pvd survived: $(cat "$out/particles.pvd")"
grep -q 'file="particles.vtu"' "$out/particles.pvd" || fail "the second run's particles.pvd does not index particles.vtu"
echo "ok: a second run replaced the whole set"

# a failing run leaves the previous set as it was
before=$(cd "$out" && md5sum -- * .perilin-output)
"$exe" "$ex/fracture/edge_crack.yaml" -grid_spacing 0.04 -quiet -output_dir "$out" -ksp_type preonly -pc_type jacobi > "$tmp/log" 2>&1 && fail "a solver failure exited 0"
[ "$before" = "$(cd "$out" && md5sum -- * .perilin-output)" ] || fail "a failing run changed the previous results"
echo "ok: a failing run left the previous set untouched"

# mode shapes: one file per mode, indexed by modes.pvd
"$exe" "$ex/lamina/modal.yaml" -grid_spacing 0.02 -output_dir "$tmp/modes" > "$tmp/log" 2>&1 || { cat "$tmp/log"; fail "the modal run failed"; }
python3 - "$tmp/modes" <<'PY' || fail "the mode series is wrong"
import json, os, re, sys
out = sys.argv[1]
s = json.load(open(os.path.join(out, "summary.json")))
files = re.findall(r'file="([^"]+)"', open(os.path.join(out, "modes.pvd")).read())
assert len(files) == len(s["modal"]["modes"]), (files, len(s["modal"]["modes"]))
for f in files:
    assert os.path.exists(os.path.join(out, f)), f
print("ok: %d mode shapes indexed by modes.pvd" % len(files))
PY
ls -d "$tmp"/*.partial-* > /dev/null 2>&1 && fail "a staging directory was left behind"
echo "ok: no staging directory left"
