#!/usr/bin/env bash
# Issue 17: the particle data is distributed, so each rank's memory shrinks as 1/P. Checks, on the
# 2D PMB plate (examples/bench/plate_2d.yaml, 251,001 particles at spacing 1/501), that the largest
# rank's peak resident memory on P = 4 ranks, above the runtime floor F_P (PETSc, MPI and the
# libraries: the same run on a 21 x 21 grid), is at most 1.2 times the 1-rank run's peak above its
# floor F_1, divided by P:
#     max_rank(P) - F_P <= 1.2 (single - F_1) / P
# which is the issue's max_rank <= 1.2 single / P + C with the constant C the floor. Checked at the
# end of the set-up (particles, ghosts, bonds, corrections, calibration) and after the assembly
# (the matrix-free operator), from summary.json's memory_phases_mb (each the largest rank's peak).
# A replicated array of 8 bytes per particle on every rank (2 MB here) moves the ratio by 0.05;
# the whole-body arrays this issue removed (about 280 bytes per particle) by 1.8.
# The whole run (the solve's phase included) is checked against the 2-rank run instead: from 1 to
# 2 ranks GAMG switches from PETSc's serial matrix products and coarsening to the parallel ones,
# which keep about 3.5 times as much in all (docs/distributed.md), so the 1-rank run is not the
# reference for that phase; from 2 ranks on it shares out as 1/P:
#     max_rank(P) - F_P <= 1.2 (max_rank(2) - F_2) 2 / P
# Usage: memory_ranks.sh PERILIN REPO [P]
set -euo pipefail
perilin=$1 repo=$2 P=${3:-4}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
scene=$repo/examples/bench/plate_2d.yaml
run() { # ranks spacing dir
  mpiexec --oversubscribe -n "$1" "$perilin" "$scene" -grid_spacing "$2" -output_dir "$3" -output_vtk false -quiet > /dev/null
}
run 1 1/20 floor1
run 2 1/20 floor2
run "$P" 1/20 floorP
run 1 1/501 single
run 2 1/501 two
run "$P" 1/501 many
/usr/bin/python3 - "$P" <<'PY'
import json, sys
P = int(sys.argv[1])
ph = {d: json.load(open(d + "/summary.json"))["memory_phases_mb"] for d in ("floor1", "floor2", "floorP", "single", "two", "many")}
bad = []
for phase, ref, floor, n in (("setup", "single", "floor1", 1), ("assembly", "single", "floor1", 1), ("run", "single", "floor1", 1), ("run", "two", "floor2", 2)):
    share = (ph[ref][phase] - ph[floor]["setup"]) * n / P
    mine = ph["many"][phase] - ph["floorP"]["setup"]
    ratio = mine / share
    line = f"{phase}: largest rank {ph['many'][phase]:.0f} MB on {P} ranks (floor {ph['floorP']['setup']:.0f}), {n} rank(s) {ph[ref][phase]:.0f} MB (floor {ph[floor]['setup']:.0f}): {mine:.0f} MB above the floor against a share of {share:.0f} MB, ratio {ratio:.2f}"
    if phase == "run" and n == 1:
        print("info: " + line + " (GAMG's serial algorithms on 1 rank: not the reference)")
    elif ratio <= 1.2:
        print("ok: " + line + " <= 1.2")
    else:
        bad.append(line)
for b in bad:
    print("FAIL: " + b + " > 1.2")
sys.exit(1 if bad else 0)
PY
