#!/usr/bin/env bash
# Kalthoff-Winkler's crack angle under refinement (docs/contact.md, "The notch's width"): the
# elastic-projectile plate with notches 2 mm wide at dx = 1, 0.5 and 0.25 mm (m = 3), each run's
# angles by docs/tools/kw_angle.py. At 0.25 mm the horizon (0.75 mm) no longer reaches across the
# notch's 2 mm gap, so the notch cracks, which would cut no bond (an input error), are dropped and
# the gap is the boxes alone ([24, 26] mm: at 1 and 0.5 mm the same rows as the example's). About
# 6 s, 50 s and 5 min on one core.
# usage: tests/perf/kalthoff_winkler_angles.sh [BUILD_DIR] [SPACINGS_M...]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
exe=${1:-$repo/build}/perilin
shift || true
spacings=${*:-1e-3 0.5e-3 0.25e-3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
scene=$repo/examples/dynamics/kalthoff_winkler_elastic.yaml
grep -v "from: \[-0.001, -\?0.025\]" "$scene" | sed 's/0\.02425/0.024/g; s/0\.02575/0.026/g' > "$tmp/boxes_only.yaml"
for h in $spacings; do
  # the example's own notch cracks while the horizon (3 dx) reaches across the gap
  if python3 -c "import sys; sys.exit(0 if 3 * $h > 2e-3 else 1)"; then s=$scene; else s=$tmp/boxes_only.yaml; fi
  start=$(date +%s.%N)
  "$exe" "$s" -quiet -grid_spacing "$h" -output_dir "$tmp/h$h"
  echo "== dx $h m ($(basename "$s")), wall $(python3 -c "import time; print('%.1f' % (time.time() - $start))") s"
  (cd "$repo" && /usr/bin/python3 docs/tools/kw_angle.py "$tmp/h$h")
done
