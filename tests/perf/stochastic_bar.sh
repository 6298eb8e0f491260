#!/usr/bin/env bash
# Issue 27 item 6: a bar in tension (200 x 4 x 4 periodic in y and z as Ganzenmueller's, clamped at
# x = 0, a traction at x = 200; npmb,
# no partial volumes or surface correction) on the stochastic tetrahedral mesh of
# examples/mesh/bar_stochastic.geo (particles.size 3.3, split twice: about 70,000 particles, as
# the paper's finest) with horizon.neighbors 30, against a uniform grid of about the same count
# with one horizon of 2 spacings (a ball of 33 neighbours). Prints particles, bonds, the set-up
# (search and family volumes: summary.json neighbors_s; assembly_s) and the solve (solve_s, CG
# iterations), and the ratios stochastic / uniform.
# Usage: stochastic_bar.sh PERILIN [RANKS]
set -euo pipefail
exe=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
ranks=${2:-1}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
cp "$here/../../examples/mesh/bar_stochastic.geo" "$tmp/"
common='dim: 3
model: {type: npmb}
material: {E: 1.0, rho: 1}
corrections: {partial_volume: none, surface: none}
regions:
  left: {side: x-}
  right: {side: x+}
bc:
  - {region: left, fix: [ux, uy, uz]}
loads:
  - {region: right, traction: [1.0e-3, 0, 0]}
output: {vtk: false}'
printf '%s\nparticles: {mesh: bar_stochastic.geo, size: 3.3, refine: 2, periodic: [false, true, true]}\nhorizon: {neighbors: 30}\n' "$common" > "$tmp/stochastic.yaml"
printf '%s\ngrid: {lower: [0, 0, 0], upper: [200, 4, 4], spacing: 0.3333333333333333, periodic: [false, true, true]}\nhorizon: {m: 2}\n' "$common" > "$tmp/uniform.yaml"
run() { mpiexec --oversubscribe -n "$ranks" "$exe" "$tmp/$1.yaml" -quiet -output_dir "$tmp/$1-out" > /dev/null; }
get() { /usr/bin/python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print(' '.join(str(s.get(k, s['timing'].get(k, s['solver'].get(k)))) for k in sys.argv[2:]))" "$tmp/$1-out/summary.json" "${@:2}"; }
printf "%-10s %9s %9s %11s %10s %8s %6s\n" mesh particles bonds neighbors_s assembly_s solve_s its
for m in stochastic uniform; do
  run $m
  read -r n b ns as ss its <<< "$(get $m particles bonds neighbors_s assembly_s solve_s iterations)"
  printf "%-10s %9s %9s %11.3f %10.3f %8.3f %6s\n" $m "$n" "$b" "$ns" "$as" "$ss" "$its"
  eval "${m}_ns=$ns ${m}_ss=$ss ${m}_as=$as"
done
/usr/bin/python3 -c "import sys; a=list(map(float,sys.argv[1:])); print(f'stochastic / uniform: set-up (search) {a[0]/a[3]:.2f}, assembly {a[1]/a[4]:.2f}, solve {a[2]/a[5]:.2f}')" "$stochastic_ns" "$stochastic_as" "$stochastic_ss" "$uniform_ns" "$uniform_as" "$uniform_ss"
