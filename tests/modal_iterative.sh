#!/usr/bin/env bash
# The modal analysis with iterative inner solves (issue 14, item 5): the free-DOF stiffness now
# carries the rigid modes as its near-null space, so GAMG can precondition it. On the cantilever
# lamina (examples/lamina/modal.yaml, dx 0.02), Krylov-Schur with CG + GAMG inner solves and
# LOBPCG with a GAMG preconditioner must give the default's (MUMPS Cholesky) frequencies to 1e-8.
# Usage: modal_iterative.sh PERILIN SCENE
set -euo pipefail
perilin=$1 scene=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
common=(-grid_spacing 0.02 -output_vtk false)
"$perilin" "$scene" "${common[@]}" -output_dir direct > direct.log
"$perilin" "$scene" "${common[@]}" -output_dir ks -st_ksp_type cg -st_pc_type gamg -st_ksp_rtol 1e-10 > ks.log
"$perilin" "$scene" "${common[@]}" -output_dir lobpcg -eps_type lobpcg -eps_smallest_real -st_type precond -st_pc_type gamg -eps_tol 1e-10 > lobpcg.log
python3 - <<'PY'
import json, sys
f = {d: json.load(open(f"{d}/summary.json"))["modal"]["frequencies_hz"] for d in ("direct", "ks", "lobpcg")}
bad = False
for d in ("ks", "lobpcg"):
    err = max(abs(a - b) / b for a, b in zip(f[d], f["direct"]))
    ok = len(f[d]) == len(f["direct"]) and err <= 1e-8
    bad |= not ok
    print(f"{'ok  ' if ok else 'FAIL'} {d}: {len(f[d])} frequencies, largest relative difference from the direct solve {err:.2e} (tolerance 1e-8)")
sys.exit(1 if bad else 0)
PY
