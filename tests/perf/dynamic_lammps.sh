#!/bin/bash
# Issue 26 item 7 (explicit part): perilin's explicit dynamic step (velocity Verlet,
# src/analysis/dynamic.c) against LAMMPS's PERI package (pair_style peri/pmb, fix nve, run N:
# velocity Verlet) on the identical 3D lattice of tests/perf/lammps (plate_3d: 160 x 40 x 4 =
# 25,600 sites, delta = 3.015a, the same volumes and partial volumes, 1,072,620 bonds in both):
# tests/perf/lammps/dynamic_3d.yaml and tests/perf/lammps/dynamic_3d.in. The free plate starts at
# rest from a Gaussian x-displacement (no failure, no load); the same dt and number of steps.
#
#   tests/perf/dynamic_lammps.sh PERILIN [LMP] [STEPS]
#
# For each rank count in RANKS ("1 2"; 2 ranks: mpiexec --oversubscribe, LAMMPS with its own MPI)
# it runs LAMMPS, perilin with its defaults (since issue 26's second part: the matrix-free K and
# the energy balance every step), perilin checking the energy only at the end (as the deck's
# thermo output) and the same with the assembled BAIJ K, in turn, RUNS times
# (default 3), each rank under /usr/bin/time -f "%e %M", and prints medians:
#   - per step: LAMMPS's "Loop time" / STEPS (the steps alone, no set-up); perilin's
#     timing.solve_s / STEPS (the analysis' time loop: the steps plus the per-step energy
#     monitor, which since issue 37 takes K q from the step's own force evaluation (kick-drift-
#     kick); plus the stability bound) and -log_view's TSStep event
#     / STEPS (the velocity Verlet steps alone). Set-up (neighbours, assembly) is printed apart.
#   - ns per step per particle (25,600 particles, or 102,400 with SCALE=2), the ratios LAMMPS/perilin;
#   - wall time of the whole process, and peak RSS summed over ranks (perilin/LAMMPS ratio);
#   - the x-displacement of the site (-70a, 20a, 2a) after the run in both, and their relative
#     difference (LAMMPS's bonds are geometrically nonlinear: ~1e-7 at this strain, ~1e-6).
# LAMMPS is Debian's `lammps` package (apt-get install lammps; not installed by .ci/install: a
# benchmark, not a test). -analysis_energy_every k checks the balance every k steps only (it
# cost a second product per step before the kick-drift-kick step). Environment: RUNS (3), RANKS ("1 2"), DT (1e-7 s;
# perilin's limit here is 3.5e-7), KEEP=1 keeps the work directory, SCALE=2 the plate scaled up
# in x and y (320 x 80 x 4 = 102,400 sites, issue 37 item 5; 1 by default).
set -euo pipefail

if [ $# -lt 1 ]; then
  echo "usage: $0 PERILIN [LMP] [STEPS]" >&2
  exit 2
fi
PERILIN=$(readlink -f "$1")
LMP=${2:-/usr/bin/lmp}
STEPS=${3:-400}
RUNS=${RUNS:-3}
RANKS=${RANKS:-1 2}
DT=${DT:-1e-7}
SCALE=${SCALE:-1}
N=$((25600 * SCALE * SCALE))
xlo=-$((160 * SCALE - 2)).5 # the plate's faces in units of a: x from xlo to 1.5, y from -0.5 to yhi
yhi=$((40 * SCALE - 1)).5
grid="-grid_lower ${xlo}e-3,-0.5e-3,-0.5e-3 -grid_upper 1.5e-3,${yhi}e-3,3.5e-3"
here=$(cd "$(dirname "$0")" && pwd)
deck=$here/lammps/dynamic_3d.in
scene=$here/lammps/dynamic_3d.yaml
tend=$(python3 -c "print(repr($STEPS * $DT))")
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1

work=$(mktemp -d /tmp/dynamic_lammps.XXXXXX)
[ "${KEEP:-0}" = 1 ] || trap 'rm -rf "$work"' EXIT
echo "$N sites, $STEPS steps of $DT s, $RUNS runs each, ranks: $RANKS; work dir $work"
echo "machine load before: $(cut -d' ' -f1-3 /proc/loadavg)"

# timed NAME P CMD...: every rank under /usr/bin/time (wall, peak RSS) -> NAME.rank*.time
timed() {
  local name=$1 np=$2
  shift 2
  if [ "$np" = 1 ]; then
    /usr/bin/time -f "%e %M" -o "$work/$name.rank0.time" "$@" > "$work/$name.out" 2>&1
  else
    mpiexec --oversubscribe -n "$np" sh -c '/usr/bin/time -f "%e %M" -o "$0.rank$OMPI_COMM_WORLD_RANK.time" "$@"' \
      "$work/$name" "$@" > "$work/$name.out" 2>&1
  fi || { echo "$name failed:" >&2; tail -20 "$work/$name.out" >&2; exit 1; }
}

for np in $RANKS; do
  for r in $(seq 1 "$RUNS"); do
    (cd "$work" && timed "lmp_${np}_$r" "$np" "$LMP" -in "$deck" -log none -var steps "$STEPS" -var dt "$DT" -var xlo "$xlo" -var yhi "$yhi")
    timed "peri_${np}_$r" "$np" "$PERILIN" "$scene" $grid -output_dir "$work/peri_${np}_$r" \
      -analysis_dt "$DT" -analysis_t_end "$tend" -log_view ":$work/peri_${np}_$r.log"
    timed "lean_${np}_$r" "$np" "$PERILIN" "$scene" $grid -output_dir "$work/lean_${np}_$r" -analysis_energy_every "$STEPS" \
      -analysis_dt "$DT" -analysis_t_end "$tend" -log_view ":$work/lean_${np}_$r.log"
    timed "asm_${np}_$r" "$np" "$PERILIN" "$scene" $grid -output_dir "$work/asm_${np}_$r" -analysis_energy_every "$STEPS" -solver_operator assembled \
      -analysis_dt "$DT" -analysis_t_end "$tend" -log_view ":$work/asm_${np}_$r.log"
    echo "ranks $np run $r done: $(cut -d' ' -f1-3 /proc/loadavg)"
  done
done
echo "machine load after: $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$work" "$RUNS" "$STEPS" "$RANKS" "$N" <<'PY'
import glob, json, re, statistics, sys
work, runs, steps, ranks = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4].split()
N = int(sys.argv[5])
med = statistics.median
def proc(name):  # wall of the slowest rank, RSS summed over ranks (MB)
    t = [tuple(map(float, open(f).read().split()[-2:])) for f in glob.glob(f"{work}/{name}.rank*.time")]
    return max(x[0] for x in t), sum(x[1] for x in t) / 1024
def event(log, ev):  # -log_view: max time over ranks
    m = re.search(rf"^{ev}\s+(\d+)\s+\S+\s+(\S+)", open(log).read(), re.M)
    return float(m.group(2))
rows, probe = {}, {}
for np in ranks:
    L = [dict(zip(("wall", "rss"), proc(f"lmp_{np}_{r}"))) for r in range(1, runs + 1)]
    for r, d in enumerate(L, 1):
        out = open(f"{work}/lmp_{np}_{r}.out").read()
        d["step"] = float(re.findall(r"Loop time of (\S+) on \d+ procs for (\d+) steps", out)[-1][0]) / steps
        d["ux"] = float(re.search(r"LAMMPS_PROBE_UX (\S+)", out).group(1))
    rows[("LAMMPS", np)] = L
    for tag in ("peri", "lean", "asm"):
        P = []
        for r in range(1, runs + 1):
            d = dict(zip(("wall", "rss"), proc(f"{tag}_{np}_{r}")))
            s = json.load(open(f"{work}/{tag}_{np}_{r}/summary.json"))
            assert s["dynamic"]["steps"] == steps, s["dynamic"]["steps"]
            d["step"] = s["timing"]["solve_s"] / steps
            d["tsstep"] = event(f"{work}/{tag}_{np}_{r}.log", "TSStep") / steps
            d["setup"] = s["timing"]["neighbors_s"] + s["timing"]["assembly_s"]
            d["matrix_mb"] = s["matrix_mb"]
            d["ux"] = s["probes"]["site"]["u"][0]
            d["drift"] = s["dynamic"]["energy_drift"]
            P.append(d)
        rows[(tag, np)] = P
name = {"LAMMPS": "LAMMPS peri/pmb, fix nve", "peri": "perilin explicit, defaults (matrix-free K, energy every step)", "lean": "perilin, energy at the end only (as LAMMPS's thermo)", "asm": "perilin, assembled BAIJ K, energy at the end"}
print()
print("| ranks | code | ms per step | ns per step per particle | steps alone (TSStep) ns/step/particle | set-up s | whole process s | peak RSS MB (sum over ranks) | site ux after the run |")
print("|---|---|---|---|---|---|---|---|---|")
for np in ranks:
    for tag in ("LAMMPS", "peri", "lean", "asm"):
        R = rows[(tag, np)]
        st = med(d["step"] for d in R)
        ts = f"{med(d['tsstep'] for d in R) / N * 1e9:.0f}" if tag != "LAMMPS" else "(loop time)"
        su = f"{med(d['setup'] for d in R):.2f}" if tag != "LAMMPS" else "—"
        print(f"| {np} | {name[tag]} | {st * 1e3:.2f} | {st / N * 1e9:.0f} | {ts} | {su} | {med(d['wall'] for d in R):.2f} | {med(d['rss'] for d in R):.0f} | {R[-1]['ux']:.12e} |")
print()
for np in ranks:
    L = rows[("LAMMPS", np)]
    ls, lm, lu = med(d["step"] for d in L), med(d["rss"] for d in L), L[-1]["ux"]
    for tag in ("peri", "lean", "asm"):
        P = rows[(tag, np)]
        print(f"{np} rank(s), {name[tag]}: per step LAMMPS/perilin {ls / med(d['step'] for d in P):.2f} "
              f"(steps alone {ls / med(d['tsstep'] for d in P):.2f}); memory perilin/LAMMPS {med(d['rss'] for d in P) / lm:.2f} "
              f"(matrix {P[-1]['matrix_mb']:.0f} MB); site ux (LAMMPS - perilin)/perilin {(lu - P[-1]['ux']) / P[-1]['ux']:.2e}; "
              f"energy drift {P[-1]['drift']:.1e}")
PY
