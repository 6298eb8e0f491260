#!/usr/bin/env bash
# The modal analysis' default beyond small bodies (issue 29, item 1): perilin's LOBPCG preconditioned
# by one V-cycle of the geometric multigrid on a matrix-free K of a grid body, else by GAMG on the
# short-range stiffness (analysis.eigensolver: lobpcg, which auto takes from 8,000 DOFs on a grid,
# 300,000 elsewhere), on the 3,600-particle gerstle lamina (examples/lamina/modal.yaml, 10 modes,
# 10,800 DOFs). Its frequencies must equal the factorization's (shift_invert, an independent solver)
# to 1e-8 on 1 and 2 ranks, also with the assembled K; auto must take LOBPCG here and keep
# shift_invert at 900 particles (2,700 DOFs); a LOBPCG that runs out of iterations, and LOBPCG around
# a target, must fail with their cause and write no modes. On a free body it must find the modes
# shift_invert finds.
# Usage: modal_lobpcg.sh PERILIN SCENE FREE_BODY_SCENE MPIRUN...
set -euo pipefail
perilin=$1 scene=$2 bar=$3
shift 3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
common=(-model_type gerstle -analysis_nev 10 -output_vtk false -output_plots false)
"$perilin" "$scene" "${common[@]}" -output_dir auto > auto.log
"$perilin" "$scene" "${common[@]}" -output_dir small -grid_spacing 0.02 > small.log
"$perilin" "$scene" "${common[@]}" -output_dir si -analysis_eigensolver shift_invert > si.log
"$perilin" "$scene" "${common[@]}" -output_dir lob1 -analysis_eigensolver lobpcg > lob1.log
"$@" "$perilin" "$scene" "${common[@]}" -output_dir lob2 -analysis_eigensolver lobpcg > lob2.log
"$perilin" "$scene" "${common[@]}" -output_dir asm -analysis_eigensolver lobpcg -solver_operator assembled > asm.log
"$perilin" "$scene" "${common[@]}" -output_dir gamg -analysis_eigensolver lobpcg -st_pc_type gamg > gamg.log
# a free body (the lps bar, 6 rigid-body modes): LOBPCG on (K + shift M, M), GAMG on the shifted
# short-range stiffness, must give shift_invert's frequencies to 1e-8 and count the same rigid-body
# modes, on 1 and 2 ranks; also on the shifted assembled K (with LU: GAMG on the assembled
# two-horizon lps K stalls near 1e-4, docs/modal.md)
free=(-analysis_nev 8 -output_vtk false -output_plots false)
"$perilin" "$bar" "${free[@]}" -output_dir bsi -analysis_eigensolver shift_invert > bsi.log
"$perilin" "$bar" "${free[@]}" -output_dir blob1 -analysis_eigensolver lobpcg > blob1.log
"$@" "$perilin" "$bar" "${free[@]}" -output_dir blob2 -analysis_eigensolver lobpcg > blob2.log
"$perilin" "$bar" "${free[@]}" -output_dir basm -analysis_eigensolver lobpcg -solver_operator assembled -st_pc_type lu > basm.log
python3 - <<'PY'
import json, sys
s = {d: json.load(open(f"{d}/summary.json")) for d in ("auto", "small", "si", "lob1", "lob2", "asm", "gamg", "bsi", "blob1", "blob2", "basm")}
bad = False
for d, want in (("auto", "lobpcg"), ("small", "shift_invert")):
    got = s[d]["modal"]["eigensolver"]
    bad |= got != want
    print(f"{'FAIL' if got != want else 'ok  '} auto at {s[d]['particles']} particles: {got} (expected {want})")
# the preconditioner: the geometric multigrid's V-cycle (a PCSHELL) on the matrix-free grid lamina,
# GAMG when asked for, on the assembled K and on a free body; LU where the test asks for it
for ref, n, runs in (("si", 10, (("lob1", "matrix_free", "shell"), ("lob2", "matrix_free", "shell"), ("asm", "assembled", "gamg"), ("gamg", "matrix_free", "gamg"))),
                     ("bsi", 8, (("blob1", "matrix_free", "gamg"), ("blob2", "matrix_free", "gamg"), ("basm", "assembled", "lu")))):
    r = s[ref]["modal"]
    for d, op, pc in runs:
        m = s[d]["modal"]
        err = max(abs(a - b) / b for a, b in zip(m["frequencies_hz"], r["frequencies_hz"]))
        ok = len(m["frequencies_hz"]) == len(r["frequencies_hz"]) == n and err <= 1e-8 and m["rigid_modes"] == r["rigid_modes"] and m["eigensolver"] == "lobpcg" and s[d]["solver"]["stiffness"] == op and s[d]["solver"]["pc_type"] == pc
        bad |= not ok
        print(f"{'ok  ' if ok else 'FAIL'} lobpcg, {s[d]['ranks']} rank(s), K {op}, PC {s[d]['solver']['pc_type']}: {len(m['frequencies_hz'])} frequencies, {m['rigid_modes']} rigid modes ({r['rigid_modes']} by shift_invert), largest relative difference {err:.2e} (tolerance 1e-8)")
bad |= s["bsi"]["modal"]["rigid_modes"] != 6
sys.exit(1 if bad else 0)
PY
# failures: non-zero exit, the cause named, no modes written
refused() { # DIR PATTERN WHAT SCENE OPTIONS...
  local dir=$1 pattern=$2 what=$3
  shift 3
  if "$perilin" "$@" -output_dir "$dir" > "$dir.log" 2>&1; then
    echo "FAIL: $what ran"; exit 1
  fi
  grep -qE "$pattern" "$dir.log" || { echo "FAIL: no cause for $what:"; cat "$dir.log"; exit 1; }
  [ ! -e "$dir/modes.csv" ] || { echo "FAIL: $what wrote modes.csv"; exit 1; }
  echo "ok   $what fails: $(grep -oE "$pattern" "$dir.log" | head -1)"
}
# LOBPCG converges its pairs together: after 3 iterations none has
refused short "LOBPCG converged|converged no mode" "LOBPCG out of iterations" "$scene" "${common[@]}" -analysis_eigensolver lobpcg -eps_max_it 3
refused target "nearest analysis.target_hz" "LOBPCG around a target" "$bar" -analysis_nev 8 -output_vtk false -analysis_eigensolver lobpcg -analysis_target_hz 3000
