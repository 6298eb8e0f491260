#!/usr/bin/env bash
# Issue 29, item 3: perilin's geometric multigrid (src/system/multigrid.c), the default PC of a
# matrix-free K on a grid body. Its solutions must equal a direct factorization's (an independent
# solver: -ksp_type preonly -pc_type cholesky on the assembled K) on a PMB plate (1 and 2 ranks),
# a 3D block and a micropolar lamina: strain energy to 1e-9, every probe's displacement and the
# largest |u| per component to 1e-7 of the largest (the solves stop at a true relative residual of 1e-10). Its CG iterations must
# not grow with the grid (4 sizes of the plate: at most 4 more on the finest than on the coarsest,
# and at most 20). Where it cannot apply it is refused, with the reason, and writes nothing.
# Usage: multigrid.sh PERILIN EXAMPLES MPIRUN...
set -euo pipefail
perilin=$1 ex=$2
shift 2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
common=(-output_vtk false -output_plots false -quiet)
direct=(-solver_operator assembled -ksp_type preonly -pc_type cholesky)
plate=$ex/pmb/plate_traction.yaml
"$perilin" "$plate" "${common[@]}" -output_dir plate_mg
"$@" "$perilin" "$plate" "${common[@]}" -output_dir plate_mg2
"$perilin" "$plate" "${common[@]}" "${direct[@]}" -output_dir plate_lu
# a small 3D body defaults to Jacobi: the multigrid asked for
"$perilin" "$ex/bench/block_3d.yaml" "${common[@]}" -grid_spacing 1/12 -pc_type mg -output_dir block_mg
"$perilin" "$ex/bench/block_3d.yaml" "${common[@]}" -grid_spacing 1/12 "${direct[@]}" -output_dir block_lu
"$perilin" "$ex/lamina/bending.yaml" "${common[@]}" -pc_type mg -output_dir lamina_mg
"$perilin" "$ex/lamina/bending.yaml" "${common[@]}" "${direct[@]}" -output_dir lamina_lu
for h in 0.02 0.01 0.005 0.0025; do # 1,250 to 80,000 particles
  "$perilin" "$plate" "${common[@]}" -grid_spacing $h -output_dir "size_$h"
done
python3 - <<'PY'
import json, sys
load = lambda d: json.load(open(f"{d}/summary.json"))
bad = False
for mg, ref in (("plate_mg", "plate_lu"), ("plate_mg2", "plate_lu"), ("block_mg", "block_lu"), ("lamina_mg", "lamina_lu")):
    a, b = load(mg), load(ref)
    e = abs(a["strain_energy"] - b["strain_energy"]) / abs(b["strain_energy"])
    # every probe's displacement and the largest |u| per component
    ua = [v for n in sorted(b.get("probes", {})) for v in a["probes"][n]["u"]] + [a["max_abs_u"][k] for k in sorted(b["max_abs_u"])]
    ub = [v for n in sorted(b.get("probes", {})) for v in b["probes"][n]["u"]] + [b["max_abs_u"][k] for k in sorted(b["max_abs_u"])]
    scale = max(abs(v) for v in ub)
    du = max(abs(x - y) / scale for x, y in zip(ua, ub))
    ok = a["solver"]["pc_type"] == "mg" and e <= 1e-9 and du <= 1e-7
    bad |= not ok
    print(f"{'ok  ' if ok else 'FAIL'} {mg} ({a['ranks']} rank(s), pc {a['solver']['pc_type']}, {a['solver']['iterations']} its) vs {ref}: energy {e:.1e} (<= 1e-9), probes {du:.1e} (<= 1e-7)")
its = [load(f"size_{h}")["solver"]["iterations"] for h in ("0.02", "0.01", "0.005", "0.0025")]
ok = its[-1] <= its[0] + 4 and max(its) <= 20
bad |= not ok
print(f"{'ok  ' if ok else 'FAIL'} CG iterations at spacing 0.02 .. 0.0025: {its} (finest at most 4 more than the coarsest, all <= 20)")
sys.exit(1 if bad else 0)
PY
# refused where it cannot apply: exit 1, the reason, no summary
refuse() {
  local want=$1
  shift
  if "$perilin" "$@" "${common[@]}" -output_dir refused > refused.log 2>&1; then
    echo "FAIL: $* ran"; exit 1
  fi
  grep -q "$want" refused.log || { echo "FAIL: no '$want' in:"; cat refused.log; exit 1; }
  [[ ! -e refused/summary.json ]] || { echo "FAIL: a refused run wrote refused/summary.json"; exit 1; }
  echo "ok   refused: $want"
}
refuse "does not come from a grid" "$ex/mesh/plate_hole.yaml" -pc_type mg
refuse "K is assembled" "$plate" -pc_type mg -solver_operator assembled
refuse "this grid allows 2 to" "$plate" -pc_type mg -pc_mg_levels 9
