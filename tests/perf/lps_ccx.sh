#!/bin/bash
# Issue 37 item 7: the natural frequencies of the free steel bar (0.5 x 0.1 x 0.05 m, E = 200 GPa,
# rho = 7850 kg/m^3, nu = 0.3 or 0.25) with lps against CalculiX (tests/reference/ccx_free_bar.json:
# C3D20R 80 x 16 x 8, converged to 6e-5; tests/reference/ccx_free_bar.py rebuilds it), at each
# spacing given (default 0.0125 0.01 0.00625 m; m = 3, shift-and-invert on the assembled K).
# Each CalculiX mode is matched to the perilin mode of the same kind nearest in frequency
# (tests/reference/ccx_modes_match.py).
#   tests/perf/lps_ccx.sh PERILIN [NU] [SPACING ...]
# Further perilin options in LPS_CCX_OPTIONS (e.g. "-model_dilatation affine").
set -euo pipefail
exe=$(readlink -f "${1:?usage: lps_ccx.sh PERILIN [NU] [SPACING ...]}")
nu=${2:-0.3}
shift $(($# < 2 ? $# : 2))
spacings=("$@")
[ ${#spacings[@]} -gt 0 ] || spacings=(0.0125 0.01 0.00625)
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d /tmp/lps_ccx.XXXXXX)
for h in "${spacings[@]}"; do
  /usr/bin/time -f "%e s %M KB" "$exe" "$here/scenes/lps_free_bar.yaml" -material_nu "$nu" -grid_spacing "$h" -analysis_nev 16 ${LPS_CCX_OPTIONS:-} -output_dir "$tmp/h$h" > "$tmp/h$h.log" 2>&1
  tail -1 "$tmp/h$h.log" | sed "s/^/dx $h: /"
done
python3 - "$here/reference" "$nu" "$tmp" "${spacings[@]}" << 'PY'
import json, sys
sys.path.insert(0, sys.argv[1])
from ccx_modes_match import reference, match
freqs, types = reference(sys.argv[1] + "/ccx_free_bar.json", sys.argv[2])
tmp, hs = sys.argv[3], sys.argv[4:]
cols = [match(json.load(open(f"{tmp}/h{h}/summary.json"))["modal"]["modes"], freqs, types) for h in hs]
print("| mode | CalculiX (Hz) | " + " | ".join(f"lps dx = {h} m" for h in hs) + " |")
print("|---|---|" + "---|" * len(hs))
for k, (t, f) in enumerate(zip(types, freqs)):
    cells = ["—" if c[k][2] is None else f"{c[k][2]:.1f} ({100 * (c[k][2] / f - 1):+.1f} %)" for c in cols]
    print(f"| {t} | {f:.1f} | " + " | ".join(cells) + " |")
PY
rm -rf "$tmp"
