#!/usr/bin/env bash
# Issue 29 item 4: does the default solver pick the fastest? For each scene with a static problem
# (the static examples, the benchmarks and the quasi-static examples' first solve), the tune
# analysis (docs/tuning.md) times the default (-solver_operator auto, no KSP or PC option: what a
# static run does) against {assembled, matrix_free} x {GAMG, Jacobi, hypre BoomerAMG} with CG,
# each the median of REPEAT runs on one rank (after a warm-up configuration), and prints the default's time over the fastest
# converged one's (target <= 1.3) and which that was. Large benchmarks take minutes.
# Usage: defaults.sh PERILIN [REPEAT [SCENE...]]   (default: every scene listed below; a SCENE is
#   examples/SCENE.yaml; options in $DEFAULTS_OPTS go to every run, e.g. -grid_spacing 0.005)
set -euo pipefail
# shellcheck source=tests/perf/args.sh
. "$(dirname "$0")/args.sh"
perf_scenes "$0" "$@"
[ ${#scenes[@]} -gt 0 ] || scenes=(antiplane/bimaterial antiplane/square_bar bench/block_3d bench/lamina_2d bench/lamina_bending_2d bench/plate_2d fracture/edge_crack fracture/micropolar_shear lamina/bending lamina/shear lamina/traction mesh/bar_tet mesh/plate_hole mesh/plate_hole_graded pmb/energy_density pmb/plate_traction torsion/rect_bar torsion/torsion_edge_crack)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"; rm -f "$root"/examples/*/.defaults_tune_*.yaml' EXIT
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
printf "%-28s %9s %9s %6s  %s\n" scene default_s fastest_s ratio "fastest (default: its configuration)"
for s in "${scenes[@]}"; do
  src=$root/examples/$s.yaml
  tune=$(dirname "$src")/.defaults_tune_$(basename "$src") # beside it: meshes and files are relative to the scene
  /usr/bin/python3 - "$src" "$tune" "$repeat" <<'PY'
import sys, yaml
scene = yaml.safe_load(open(sys.argv[1]))
scene.pop("output", None)
configs = ["-ksp_type cg -solver_operator auto", "-solver_operator auto"]  # the first warms up (caches, first allocations) and is left out
for op in ("assembled", "matrix_free"):
    for pc in ("-pc_type gamg", "-pc_type jacobi", "-pc_type hypre -pc_hypre_type boomeramg"):
        configs.append(f"-ksp_type cg {pc} -solver_operator {op}")
if "grid" in scene and not (scene["grid"].get("periodic")):  # the geometric multigrid: grid bodies
    configs.append("-ksp_type cg -pc_type mg -solver_operator matrix_free")
scene["analysis"] = {"type": "tune", "repeat": int(sys.argv[3]), "configurations": configs}
yaml.safe_dump(scene, open(sys.argv[2], "w"), sort_keys=False)
PY
  # shellcheck disable=SC2086
  if ! "$exe" "$tune" ${DEFAULTS_OPTS:-} -quiet -output_vtk false -output_plots false -output_dir "$tmp/$(basename "$s")" > "$tmp/log" 2>&1; then
    printf "%-28s failed: %s\n" "$s" "$(grep -m1 error "$tmp/log" | cut -c1-120)"
    continue
  fi
  /usr/bin/python3 - "$tmp/$(basename "$s")/tune.csv" "$s" ${DEFAULTS_ROWS:+rows} <<'PY'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["configuration"] != "-ksp_type cg -solver_operator auto"]
conv = [r for r in rows if r["converged"] in ("1", "true", "yes", "True")]
default = next(r for r in rows if r["configuration"] == "-solver_operator auto")
others = [r for r in conv if r["configuration"] != "-solver_operator auto"]
best = min(others, key=lambda r: float(r["total_s"]))
d, b = float(default["total_s"]), float(best["total_s"])
mark = "" if d <= 1.3 * b else "  <-- above 1.3"
print(f"{sys.argv[2]:28s} {d:9.4f} {b:9.4f} {d / b:6.2f}  {best['configuration']}{mark}")
if len(sys.argv) > 3:  # DEFAULTS_ROWS=1: every row
    for r in rows:
        print(f"    {r['configuration']:62s} {r['converged']:>5s} {r['iterations']:>6s} {float(r['total_s']):9.4f}")
PY
done
