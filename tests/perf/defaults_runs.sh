#!/usr/bin/env bash
# Issue 29 item 4 for the quasi-static examples: defaults.sh times their first solve, but a user
# waits for the whole run, whose solves reuse (or rebuild) the preconditioner as bonds break. Here
# each whole run is timed under the default (no solver option) and under CG with {GAMG, Jacobi,
# hypre BoomerAMG} x {assembled, matrix-free} K and the geometric multigrid, interleaved, the
# median of REPEAT runs (wall, /usr/bin/time), one rank. Prints each configuration's median, the
# default's over the fastest finished one's (target <= 1.3), and per run its load steps and final
# strain energy (a configuration that ends in another crack state says so). A benchmark, not a test.
# Usage: defaults_runs.sh PERILIN [REPEAT [SCENE...]]   (SCENE: examples/SCENE.yaml; default: the
#   quasi-static examples)
set -euo pipefail
# shellcheck source=tests/perf/args.sh
. "$(dirname "$0")/args.sh"
perf_scenes "$0" "$@"
[ ${#scenes[@]} -gt 0 ] || scenes=(fracture/edge_crack fracture/micropolar_shear antiplane/cracked_bar)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
configs=("default|"
  "GAMG, assembled|-ksp_type cg -pc_type gamg -solver_operator assembled"
  "Jacobi, assembled|-ksp_type cg -pc_type jacobi -solver_operator assembled"
  "BoomerAMG, assembled|-ksp_type cg -pc_type hypre -pc_hypre_type boomeramg -solver_operator assembled"
  "GAMG, matrix-free|-ksp_type cg -pc_type gamg -solver_operator matrix_free"
  "Jacobi, matrix-free|-ksp_type cg -pc_type jacobi -solver_operator matrix_free"
  "BoomerAMG, matrix-free|-ksp_type cg -pc_type hypre -pc_hypre_type boomeramg -solver_operator matrix_free"
  "multigrid, matrix-free|-ksp_type cg -pc_type mg -solver_operator matrix_free")
for s in "${scenes[@]}"; do
  : > "$tmp/runs"
  for _ in $(seq "$repeat"); do
    for k in "${!configs[@]}"; do
      opts=${configs[$k]#*|}
      out=$tmp/o$k
      # shellcheck disable=SC2086
      if /usr/bin/time -o "$tmp/t" -f "%e" "$exe" "$root/examples/$s.yaml" $opts -quiet -output_vtk false -output_plots false -output_dir "$out" > "$tmp/log" 2>&1; then
        echo "$k $(cat "$tmp/t") ok" >> "$tmp/runs"
      else
        echo "$k 0 $(grep -m1 -o 'error: .*' "$tmp/log" | cut -c8-90)" >> "$tmp/runs"
      fi
    done
  done
  /usr/bin/python3 - "$s" "$tmp" "${configs[@]}" <<'PY'
import json, os, statistics, sys
scene, tmp, configs = sys.argv[1], sys.argv[2], [c.split("|")[0] for c in sys.argv[3:]]
runs = [(line.split(None, 2) + [""])[:3] for line in open(os.path.join(tmp, "runs"))]
print(f"{scene}:")
best, med = None, {}
for k, name in enumerate(configs):
    mine = [r for r in runs if int(r[0]) == k]
    if any(r[2].strip() != "ok" for r in mine):
        print(f"  {name:24s} failed: {mine[0][2].strip()}")
        continue
    med[k] = statistics.median(float(r[1]) for r in mine)
    d = json.load(open(os.path.join(tmp, f"o{k}", "summary.json")))
    q = d.get("quasistatic", {})
    steps = f"{q.get('steps')} steps, {q.get('broken_bonds')} broken bonds"
    print(f"  {name:24s} {med[k]:7.2f} s  ({d['solver']['pc_type']}, {d['solver']['stiffness']}; {steps}, final strain energy {d.get('strain_energy', float('nan')):.4g})")
fast = min(med, key=med.get)
if 0 in med:
    print(f"  default / fastest = {med[0] / med[fast]:.2f} (fastest: {configs[fast]}; target <= 1.3)")
PY
done
