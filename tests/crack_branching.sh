#!/usr/bin/env bash
# Crack branching in soda-lime glass (issue 38, item 7; docs/dynamics.md "Crack branching in
# glass"): examples/dynamics/crack_branching.yaml at dx = 0.5 mm (m = 2, delta = 1 mm as in the
# example; 16,000 particles, about 5 s). What is asserted, and why:
#   1. the crack grows: history.csv's damage front (damage > 0.35, only x >= 0, the pre-crack's tip)
#      passes 10 mm by 43 us (it reaches about 39 mm at dx = 1/3 and 0.5 mm);
#   2. its speed stays below the Rayleigh speed of the model's solid (plane stress, nu = 1/3:
#      c_R = 3058 m/s, from E and rho) over the whole run (summary's fitted damage_front_speed), and
#      over the last 5 us before branching lies in 900..2000 m/s, 0.3..0.65 c_R: measured 1495 and
#      1497 m/s at dx = 1/3 and 0.5 mm; the terminal crack speed in soda-lime glass is about
#      1500 m/s (docs/dynamics.md gives the sources and what is uncertain); the band allows a
#      third either way, the spread of a threshold-based tip over 5 us at this dx;
#   3. the energy balance closes within 1 % (energy_drift; measured 0.16 %);
#   4. it branches: docs/tools/branch_point.py finds two damaged branches, one on each side of the
#      crack line, over at least 1 mm of columns, starting 5..30 mm ahead of the pre-crack's tip
#      (measured 15.2 and 17.2 mm at dx = 1/3 and 0.5 mm; the band only asks that the crack first
#      runs straight for several horizons and branches within the plate's right half), and both
#      branches reach x > 30 mm at |y| > 5 mm (the right edge region);
#   5. analysis.fronts.direction: with `both` the pre-crack's own damage (0.40 > 0.35 at its
#      particles) sets the front before the crack runs (3 us) to its far end, 49.75 mm; with `positive` it is 0.
#   6. the screen of the every-step failure check (bonds well below s_c skipped by their stretch)
#      changes nothing: with -peri_failure_screen false history.csv is the same bytes;
# Usage: crack_branching.sh PERILIN REPO
set -u
exe=${1:?usage: crack_branching.sh PERILIN REPO}
repo=${2:?usage: crack_branching.sh PERILIN REPO}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
scene=("$repo/examples/dynamics/crack_branching.yaml" -grid_spacing 5e-4 -regions_top_depth 2.5e-4 -regions_bottom_depth 2.5e-4)
fail=0
run() { # name, args...
  local name=$1
  shift
  "$exe" "$@" -output_dir "$tmp/$name" > "$tmp/$name.log" 2>&1 < /dev/null || { echo "FAIL: $name exited $?"; tail -3 "$tmp/$name.log"; fail=1; }
}
run branch "${scene[@]}"
run both "${scene[@]}" -analysis_fronts_direction both -analysis_t_end 3e-6 -output_vtk false
run positive "${scene[@]}" -analysis_t_end 3e-6 -output_vtk false
run unscreened "${scene[@]}" -peri_failure_screen false -output_vtk false
[ $fail = 0 ] || exit 1
python3 "$repo/docs/tools/branch_point.py" "$tmp/branch" > "$tmp/branch.txt" || { echo "FAIL: branch_point.py"; exit 1; }
cat "$tmp/branch.txt"
python3 - "$tmp" "$repo" << 'PY'
import csv, json, math, re, sys
tmp, repo = sys.argv[1], sys.argv[2]
sys.path.insert(0, repo + "/src/output")
from draw_plots import read_particles
bad = 0
def check(ok, what):
    global bad
    print(("ok  " if ok else "FAIL") + ": " + what)
    bad |= not ok
# the model's Rayleigh speed: plane stress, nu = 1/3, E = 72 GPa, rho = 2440
E, nu, rho = 7.2e10, 1 / 3, 2440
cT, cL = math.sqrt(E / (2 * rho * (1 + nu))), math.sqrt(E / (rho * (1 - nu * nu)))
f = lambda x: (2 - x * x) ** 2 - 4 * math.sqrt(1 - x * x) * math.sqrt(1 - x * x * cT * cT / (cL * cL))
a, b = 0.5, 0.999999
for _ in range(100):
    m = (a + b) / 2
    a, b = (a, m) if f(a) * f(m) <= 0 else (m, b)
cR = m * cT
d = json.load(open(f"{tmp}/branch/summary.json"))["dynamic"]
rows = list(csv.DictReader(open(f"{tmp}/branch/history.csv")))
front = float(rows[-1]["damage_front"])
check(front > 0.010, "damage front at %.2f us: %.2f mm > 10 mm" % (1e6 * float(rows[-1]["time"]), 1e3 * front))
check(0 < d["damage_front_speed"] < cR, "fitted damage front speed %.0f m/s below c_R = %.0f m/s" % (d["damage_front_speed"], cR))
txt = open(f"{tmp}/branch.txt").read()
late = re.search(r"last \S+ us before branching (\d+) m/s", txt)
v = float(late.group(1)) if late else -1
check(900 <= v <= 2000 and v < cR, "speed over the last 5 us before branching %.0f m/s in 900..2000 (%.2f c_R)" % (v, v / cR))
check(d["energy_drift"] <= 0.01, "energy drift %.2g <= 0.01" % d["energy_drift"])
bp = re.search(r"branch point x = ([-\d.]+) mm", txt)
x_b = float(bp.group(1)) if bp else -1
check(5 <= x_b <= 30, "branch point %.2f mm ahead of the pre-crack's tip, in 5..30 mm" % x_b)
P = read_particles(f"{tmp}/branch", ["damage"])
up = sum(1 for x, dm in zip(P["Points"], P["damage"]) if dm[0] > 0.35 and x[0] > 0.03 and x[1] > 0.005)
lo = sum(1 for x, dm in zip(P["Points"], P["damage"]) if dm[0] > 0.35 and x[0] > 0.03 and x[1] < -0.005)
check(up > 0 and lo > 0, "damaged particles at x > 30 mm: %d above y = 5 mm, %d below y = -5 mm" % (up, lo))
f_both = float(list(csv.DictReader(open(f"{tmp}/both/history.csv")))[-1]["damage_front"])
f_pos = float(list(csv.DictReader(open(f"{tmp}/positive/history.csv")))[-1]["damage_front"])
check(abs(f_both - 0.04975) < 1e-9, "direction both: the pre-crack's damage sets the front to %.3f mm (49.75)" % (1e3 * f_both))
check(f_pos == 0, "direction positive: front %.3f mm (0) before the crack runs" % (1e3 * f_pos))
same = open(f"{tmp}/branch/history.csv", "rb").read() == open(f"{tmp}/unscreened/history.csv", "rb").read()
check(same, "-peri_failure_screen false (every live bond evaluated in full each step): history.csv the same bytes as the screened run's")
sys.exit(1 if bad else 0)
PY
