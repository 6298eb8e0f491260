#!/usr/bin/env bash
# lps wave speeds (issue 37, item 7): pulses in the bar of examples/dynamics/pulse.yaml (periodic
# in y and z: a plane wave; K = 1, rho = 1, dx = 1, delta = 2.5), shortened to 200, width 20
# (a wavelength of 8 horizons: little lattice dispersion), explicit. The pulse's speed is the slope
# of history.csv's pulse_position (the centroid of u^2 of the particles displaced by more than half
# the largest) once the pulse has left the free end:
#   1. longitudinal (analysis.pulse along x, displacing along x): sqrt((K + 4G/3)/rho), nu = 0.3,
#      t = 50..94, within 1 %;
#   2. shear (displacing along y: analysis.pulse.direction): sqrt(G/rho), nu = 0.3, t = 50..94, and
#      nu = 0.45 (G = 0.103: slower, so t = 200..400), within 1 %.
# Usage: lps_waves.sh PERILIN REPO
set -u
exe=${1:?usage: lps_waves.sh PERILIN REPO}
repo=${2:?usage: lps_waves.sh PERILIN REPO}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
bar=("$repo/examples/dynamics/pulse.yaml" -model_type lps -grid_upper 200,4,4 -analysis_pulse_width 20)
fail=0
run() { # name, args...
  local name=$1
  shift
  "$exe" "$@" -output_dir "$tmp/$name" > "$tmp/$name.log" 2>&1 < /dev/null || { echo "FAIL: $name exited $?"; tail -3 "$tmp/$name.log"; fail=1; }
}
run p30 "${bar[@]}" -material_nu 0.3
run s30 "${bar[@]}" -material_nu 0.3 -analysis_pulse_direction y
run s45 "${bar[@]}" -material_nu 0.45 -analysis_pulse_direction y -analysis_t_end 400
[ $fail = 0 ] || exit 1
python3 - "$tmp" << 'PY'
import csv, math, sys
tmp = sys.argv[1]
bad = 0
def speed(name, t0, t1):
    pts = [(float(r["time"]), float(r["pulse_position"])) for r in csv.DictReader(open(f"{tmp}/{name}/history.csv")) if t0 <= float(r["time"]) <= t1 + 1e-9]
    n = len(pts); sx = sum(p[0] for p in pts); sy = sum(p[1] for p in pts)
    sxx = sum(p[0] ** 2 for p in pts); sxy = sum(p[0] * p[1] for p in pts)
    return (n * sxy - sx * sy) / (n * sxx - sx * sx)
for name, nu, kind, t0, t1 in (("p30", 0.3, "P", 50, 94), ("s30", 0.3, "S", 50, 94), ("s45", 0.45, "S", 200, 400)):
    G = 3 * (1 - 2 * nu) / (2 * (1 + nu))  # K = 1
    c = math.sqrt(1 + 4 * G / 3) if kind == "P" else math.sqrt(G)
    s = speed(name, t0, t1)
    ok = abs(s / c - 1) < 0.01
    bad |= not ok
    print(("ok: " if ok else "FAIL: ") + f"lps {kind} wave at nu = {nu}: {s:.5f} against {'sqrt((K + 4G/3)/rho)' if kind == 'P' else 'sqrt(G/rho)'} = {c:.5f} ({100 * (s / c - 1):+.2f} %, tolerance 1 %)")
sys.exit(bad)
PY
