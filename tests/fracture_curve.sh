#!/usr/bin/env bash
# The load-displacement curve of the fracture examples as users meet it (issue 28, items 1-3):
#   1. edge_crack (tractions along y): steps.csv's control_u is uy (the direction of the load, not
#      the model's first component), and its force column applied_load is lambda x the applied
#      load (1 N per unit load factor: 1 Pa on the 1 m top face); at a coarse spacing where no
#      bond breaks before the last equilibrium, the log and summary say so;
#   2. edge_crack at its own spacing: bonds break in an equilibrium before the failure, and that
#      equilibrium's particles.vtu carries them (damage > 0, read by VTK when python3-vtk9 is
#      there); particles.pvd is written without output.every and indexes snapshots that exist;
#      its steps.csv counts every attempt of a step in attempts and seconds (item 6);
#   3. micropolar_shear (displacement control) goes on past the first load drop by default
#      (runaway_fraction 1) to load_factor_max, many steps after the peak;
#   4. docs/tools/plot_load_displacement.py writes a PNG for every quasi-static example and test
#      scene with a curve, and refuses a static run's output with a message, not a traceback.
# usage: fracture_curve.sh PERILIN REPO_DIR
set -u
# shellcheck source=tests/run_scratch.sh
source "$(dirname "$0")/run_scratch.sh"
run() { # name scene options...
  local name=$1 scene=$2
  shift 2
  "$exe" "$repo/$scene" "$@" -output_dir "$tmp/$name" > "$tmp/$name.log" 2>&1 < /dev/null || { bad "perilin $scene $* exited $?"; cat "$tmp/$name.log"; }
}
# a python3 with matplotlib (the first on PATH may be a pyenv or venv without it)
py=""
for p in python3 /usr/bin/python3; do
  command -v "$p" > /dev/null && "$p" -c "import matplotlib" 2> /dev/null && { py=$p; break; }
done
pyany=${py:-python3}

# 1. the edge crack's columns
run ec "examples/fracture/edge_crack.yaml" -grid_spacing 0.04
grep -q "load control: control_u is uy of probe top_left (the direction of the largest applied load); force column applied_load" "$tmp/ec.log" || bad "the log does not say the control component and force column: $(grep control "$tmp/ec.log")"
grep -Fq "runaway_fraction 0.01 (the default of load control" "$tmp/ec.log" || bad "the log does not say load control's runaway_fraction"
grep -q "note: no bond broke before the last equilibrium" "$tmp/ec.log" || bad "the log does not say that the last equilibrium is before any break"
"$pyany" - "$tmp/ec" <<'PY' || bad "edge_crack's steps.csv"
import csv, json, os, sys
out = sys.argv[1]
q = json.load(open(os.path.join(out, "summary.json")))["quasistatic"]
rows = list(csv.DictReader(open(os.path.join(out, "steps.csv"))))
assert q["control_component"] == "uy", q["control_component"]
assert q["control"] == "load" and q["force_column"] == "applied_load", q
assert abs(q["applied_load_per_load_factor"] - 1) < 1e-12, q["applied_load_per_load_factor"]
assert "no bond broke before the last equilibrium" in q.get("note", ""), q
assert "applied_load" in rows[0], list(rows[0])
for r in rows:
    lam, F = float(r["load_factor"]), float(r["applied_load"])
    assert abs(F - lam * 1.0) <= 1e-9 * lam, (lam, F)
    assert float(r["control_u"]) > 0, r  # the top-left corner moves up with the load
print("ok: edge_crack: control_u is uy, applied_load = lambda x 1 N over %d steps" % len(rows))
PY

# 2. the crack in the last equilibrium's particles.vtu, and particles.pvd by default
run ec_fine "examples/fracture/edge_crack.yaml" -quiet
"$pyany" - "$tmp/ec_fine" <<'PY' || bad "edge_crack's last equilibrium and series"
import csv, json, os, re, sys
out = sys.argv[1]
q = json.load(open(os.path.join(out, "summary.json")))["quasistatic"]
rows = list(csv.DictReader(open(os.path.join(out, "steps.csv"))))
assert q["failed"] and int(rows[-1]["broken_total"]) > 0, (q["failed"], rows[-1])
assert "note" not in q, q["note"]
pvd = os.path.join(out, "particles.pvd")
assert os.path.exists(pvd), "no particles.pvd without output.every"
files = re.findall(r'file="([^"]+)"', open(pvd).read())
broke = ["particles_%04d.vtu" % (k + 1) for k, r in enumerate(rows) if int(r["broken"]) > 0]
assert broke and all(f in files for f in broke), (broke, files)
assert files[-1] == "particles.vtu" or files[-1] == "particles_%04d.vtu" % len(rows), files
for f in files:
    assert os.path.exists(os.path.join(out, f)), f
print("ok: edge_crack: %d bonds broke before the last equilibrium; particles.pvd indexes %s" % (int(rows[-1]["broken_total"]), files))
PY
# the same run's per-step times (issue 28, item 6): every attempt of a step counts. The attempts
# follow from the load factors alone by the halving rule of docs/failure.md (a failed trial halves
# the step down to min_step; after an equilibrium the step is halved when more than 1 % of the
# bonds broke, kept when some did, doubled up to load_factor_step when none did), and the rows'
# seconds with unfinished_s (the failing step's bracketing) make up the loop's own timer, solve_s.
"$pyany" - "$tmp/ec_fine" "$repo/examples/fracture/edge_crack.yaml" <<'PY' || bad "edge_crack's per-step times and attempts"
import csv, json, os, sys
out = sys.argv[1]
d = json.load(open(os.path.join(out, "summary.json")))
q = d["quasistatic"]
rows = list(csv.DictReader(open(os.path.join(out, "steps.csv"))))
step, min_step = 20.0, 0.25  # the example's load_factor_step and min_step


def tries(dl, accepted):  # the trials from dl, halved (not below min_step) until accepted
    n = 1
    while dl > accepted * (1 + 1e-9):
        dl, n = max(dl / 2, min_step), n + 1
    return n


dl, lam = step, 0.0
for r in rows:
    inc = float(r["load_factor"]) - lam
    want = tries(dl, inc)
    assert int(r["attempts"]) == want, ("step", r["step"], "tried", dl, "accepted", inc, r["attempts"], want)
    broken = int(r["broken"])
    dl = max(inc / 2, min_step) if broken > d["bonds"] / 100 else inc if broken else min(2 * inc, step)
    lam = float(r["load_factor"])
# the failing step: tried from dl, halved to min_step, every trial failed
want = tries(dl, min_step)
assert q["failed"] and q["unfinished_attempts"] == want, (q["unfinished_attempts"], want)
assert max(int(r["attempts"]) for r in rows) > 1, "no step was retried"
total = sum(float(r["seconds"]) for r in rows) + q["unfinished_s"]
solve = d["timing"]["solve_s"]
assert abs(total - solve) <= 0.02 * solve + 1e-3 * len(rows), (total, solve)
retried = sum(float(r["seconds"]) for r in rows if int(r["attempts"]) > 1)
print("ok: edge_crack: attempts of %d rows and of the failing step (%d) as the halving rule says; seconds + unfinished_s = %.3f s, solve_s %.3f s (retried steps %.3f s)" % (len(rows), want, total, solve, retried))
PY
# shellcheck source=/dev/null
vtkpy=""
for p in python3 /usr/bin/python3; do
  command -v "$p" > /dev/null && "$p" -c "import numpy, vtkmodules.vtkIOXML" 2> /dev/null && { vtkpy=$p; break; }
done
if [ -n "$vtkpy" ]; then
  "$vtkpy" - "$tmp/ec_fine/particles.vtu" <<'PY' || bad "the last equilibrium's particles.vtu shows no broken bond"
import sys
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
r = vtkXMLUnstructuredGridReader()
r.SetFileName(sys.argv[1])
r.Update()
pd = r.GetOutput().GetPointData()
d = vtk_to_numpy(pd.GetArray("damage_tension"))
assert d.max() > 0, d.max()
print("ok: particles.vtu of the last equilibrium: damage_tension > 0 at %d particles" % (d > 0).sum())
PY
else
  echo "note: VTK's Python readers are not installed: particles.vtu's damage not read"
fi

# 3. displacement control past the load drop
run ms "examples/fracture/micropolar_shear.yaml" -grid_spacing 0.01
grep -Eq "runaway_fraction 1\.? \(the default of displacement control" "$tmp/ms.log" || bad "the log does not say displacement control's runaway_fraction: $(grep runaway "$tmp/ms.log")"
"$pyany" - "$tmp/ms" <<'PY' || bad "micropolar_shear stops at the load drop"
import csv, json, os, sys
out = sys.argv[1]
q = json.load(open(os.path.join(out, "summary.json")))["quasistatic"]
rows = list(csv.DictReader(open(os.path.join(out, "steps.csv"))))
F = [float(r["reaction"]) for r in rows]
peak = F.index(max(F))
assert q["control"] == "displacement" and q["control_component"] == "ux" and q["runaway_fraction"] == 1, q
assert not q["failed"] and abs(float(rows[-1]["load_factor"]) - 2) < 1e-12, (q["ending"], rows[-1])
assert len(rows) - 1 - peak >= 10, "only %d steps after the peak (step %d)" % (len(rows) - 1 - peak, peak + 1)
assert min(F[peak:]) < 0.8 * F[peak], "no load drop after the peak"
print("ok: micropolar_shear: peak at step %d, %d steps after it, to load factor 2" % (peak + 1, len(rows) - 1 - peak))
PY

# 4. the plot tool on every quasi-static example, and on a static run
if [ -z "$py" ]; then
  echo "note: no python3 with matplotlib (Debian python3-matplotlib): the plot tool is not run"
else
  run cb "examples/antiplane/cracked_bar.yaml" -grid_spacing 0.04 -quiet
  run qs "tests/scenes/reaction_qs.yaml" -quiet
  run soft "tests/scenes/softening_bar.yaml" -quiet
  run tor "examples/torsion/torsion_edge_crack.yaml" -grid_spacing 0.05 -quiet
  for name in ec ec_fine ms cb qs soft; do
    rm -f "$tmp/$name/load_displacement.png" # the run's own (output.plots): the tool must write it again
    "$py" "$repo/docs/tools/plot_load_displacement.py" "$tmp/$name" > "$tmp/plot_$name.log" 2>&1 || { bad "the plot tool failed on $name: $(cat "$tmp/plot_$name.log")"; continue; }
    "$py" - "$tmp/$name/load_displacement.png" <<'PY' || bad "$name: load_displacement.png is not a 960 x 720 PNG"
import struct, sys
b = open(sys.argv[1], "rb").read()
assert b[:8] == b"\x89PNG\r\n\x1a\n" and b[12:16] == b"IHDR", b[:16]
w, h = struct.unpack(">II", b[16:24])
assert (w, h) == (960, 720), (w, h)  # the size of the run's own picture (src/output/draw_plots.py)
PY
  done
  grep -q "without failure" "$tmp/ms/summary.json" && bad "micropolar_shear's ending says 'without failure' after its bonds broke"
  if "$py" "$repo/docs/tools/plot_load_displacement.py" "$tmp/tor" > "$tmp/plot_tor.log" 2>&1; then
    bad "the plot tool accepted a static run's output"
  else
    grep -q "not a quasi-static one" "$tmp/plot_tor.log" || bad "the plot tool's message on a static run: $(cat "$tmp/plot_tor.log")"
    grep -q "Traceback" "$tmp/plot_tor.log" && bad "the plot tool printed a traceback on a static run"
  fi
  [ "$fail" -eq 0 ] && echo "ok: the plot tool wrote a PNG for each quasi-static run and refused the static one"
fi
[ "$fail" -eq 0 ] && echo "fracture_curve: all checks passed"
exit "$fail"
