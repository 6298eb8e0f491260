#!/bin/bash
# The 3D PMB plate of issue 14 (items 3 and 6) solved by perilin (1 rank, its default solver) and by
# LAMMPS's `minimize` with min_style cg (serial), on the identical discrete problem:
# tests/perf/lammps/plate_3d.yaml and tests/perf/lammps/plate_3d.in (the same lattice, volumes,
# horizon, partial volumes, clamp and total force; see their headers).
#
#   tests/perf/lammps_3d.sh PERILIN [LMP] [SCALE]
#
# SCALE 1: 160 x 40 x 4 = 25,600 sites; SCALE 2: 320 x 80 x 4 = 102,400 (the load follows the
# cross-section, so the strain stays ~1e-5). Runs LAMMPS and perilin interleaved, RUNS times each
# (default 3), each under /usr/bin/time -f "%e %M", and prints the medians of wall time and peak
# resident memory, the ratios (LAMMPS/perilin time, perilin/LAMMPS memory) and both tip
# displacements with their relative difference. A benchmark, not a test (not in ctest).
#
# Environment: RUNS (3), FTOL (LAMMPS's force tolerance, the 2-norm of the force-density
# vector; default 20 x SCALE: 2e-8 of the applied load's norm at SCALE 1, where the norm levels
# off at ~7 from round-off; the table prints LAMMPS's stopping criterion), MAXITER (LAMMPS's
# iteration limit, 20000; SCALE 1 needs ~330), KEEP=1 keeps the work directory.
# The tip displacement is the mean x-displacement of the loaded layer: LAMMPS averages it over
# the layer's atoms; perilin's is 2 U / F (summary.json's strain_energy U; exact for the linear
# problem, since the load is spread equally over the layer). Both also report the site
# (0, ny/2 a, 2a) (perilin's probe 'tip'). They differ by about -8e-6 relative at SCALE 1: LAMMPS's
# bonds are geometrically nonlinear (the gap halves with the load: -4.2e-6 at sigma 7.5e4; its
# extrapolation to zero load is ~1e-8).
set -euo pipefail

if [ $# -lt 1 ]; then
  echo "usage: $0 PERILIN [LMP] [SCALE]" >&2
  exit 2
fi
PERILIN=$(readlink -f "$1")
LMP=${2:-/usr/bin/lmp}
SCALE=${3:-1}
RUNS=${RUNS:-3}
FTOL=${FTOL:-$((20 * SCALE))}
MAXITER=${MAXITER:-20000}
here=$(cd "$(dirname "$0")" && pwd)
deck=$here/lammps/plate_3d.in
scene=$here/lammps/plate_3d.yaml

nx=$((160 * SCALE)); ny=$((40 * SCALE)); nz=4
# the scene's overrides for this size (a = 1e-3; sites x = -(nx-2)a..a, y = 0..(ny-1)a)
read -r lower0 upper1 force probey < <(python3 -c "
a = 1e-3; nx, ny, nz = $nx, $ny, $nz
print(repr((1.5 - nx) * a), repr((ny - 0.5) * a), repr(1.5e5 * ny * nz * a * a), repr(ny / 2 * a))")

work=$(mktemp -d /tmp/lammps_3d.XXXXXX)
[ "${KEEP:-0}" = 1 ] || trap 'rm -rf "$work"' EXIT
echo "plate ${nx} x ${ny} x ${nz} = $((nx * ny * nz)) sites, $RUNS runs each, LAMMPS ftol $FTOL; work dir $work"
echo "machine load before: $(cut -d' ' -f1-3 /proc/loadavg)"

for r in $(seq 1 "$RUNS"); do
  (cd "$work" && /usr/bin/time -f "%e %M" -o "$work/lmp_$r.time" \
    "$LMP" -in "$deck" -log none -var nx "$nx" -var ny "$ny" -var nz "$nz" \
    -var ftol "$FTOL" -var maxiter "$MAXITER" > "$work/lmp_$r.out" 2>&1) ||
    { echo "LAMMPS run $r failed:" >&2; tail -20 "$work/lmp_$r.out" >&2; exit 1; }
  /usr/bin/time -f "%e %M" -o "$work/peri_$r.time" \
    "$PERILIN" "$scene" -output_dir "$work/peri_$r" -grid_lower_0 "$lower0" -grid_upper_1 "$upper1" \
    -loads_0_force "$force,0,0" -probes_tip "0,$probey,0.002" > "$work/peri_$r.out" 2>&1 ||
    { echo "perilin run $r failed:" >&2; tail -20 "$work/peri_$r.out" >&2; exit 1; }
  echo "run $r: LAMMPS $(cat "$work/lmp_$r.time") | perilin $(cat "$work/peri_$r.time")   (s KB)"
done
echo "machine load after: $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$work" "$RUNS" "$force" <<'PY'
import json, re, statistics, sys
work, runs, force = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
def times(tool):
    t = [tuple(map(float, open(f"{work}/{tool}_{r}.time").read().split()[-2:])) for r in range(1, runs + 1)]
    return statistics.median(x[0] for x in t), statistics.median(x[1] for x in t) / 1024
lt, lm = times("lmp")
pt, pm = times("peri")
out = open(f"{work}/lmp_{runs}.out").read()
grab = lambda key: float(re.search(key + r" (\S+)", out).group(1))
l_tip, l_probe = grab("LAMMPS_TIP_UX"), grab("LAMMPS_PROBE_UX")
its = re.search(r"Iterations, force evaluations = (\d+) (\d+)", out)
stop = re.search(r"Stopping criterion = (.*)", out).group(1).strip()
s = json.load(open(f"{work}/peri_{runs}/summary.json"))
p_tip = 2 * s["strain_energy"] / force
p_probe = s["probes"]["tip"]["u"][0]
print()
print("| code | wall s (median) | peak RSS MB (median) | iterations | tip ux (layer mean) | probe ux |")
print("|---|---|---|---|---|---|")
print(f"| LAMMPS minimize cg | {lt:.2f} | {lm:.0f} | {its.group(1)} ({its.group(2)} force evaluations; {stop}) | {l_tip:.10e} | {l_probe:.10e} |")
print(f"| perilin {s['solver']['ksp_type']} + {s['solver']['pc_type']} ({s['solver'].get('stiffness', 'assembled')} K) | {pt:.2f} | {pm:.0f} | {s['solver']['iterations']} | {p_tip:.10e} | {p_probe:.10e} |")
print()
print(f"time LAMMPS/perilin {lt / pt:.2f}; memory perilin/LAMMPS {pm / lm:.2f}")
print(f"tip relative difference (LAMMPS - perilin)/perilin {(l_tip - p_tip) / p_tip:.3e}; probe {(l_probe - p_probe) / p_probe:.3e}")
t = s["timing"]
print(f"perilin: neighbours {t['neighbors_s']:.2f} s, assembly {t['assembly_s']:.2f} s, solve {t['solve_s']:.2f} s; "
      f"matrix_mb {s['matrix_mb']:.0f}, memory_phases_mb {s['memory_phases_mb']}")
PY
