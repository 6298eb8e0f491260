#!/usr/bin/env bash
# Issue 14, item 5: the modes of the cantilever lamina (examples/lamina/modal.yaml, 10 modes) in
# static runs' worth of wall time: the same body loaded at its free edge and solved once
# statically is the unit. Interleaved runs, medians of REPS (default 3), 1 rank. Prints the wall
# times, the peaks and the ratio; extra options (e.g. -model_type gerstle, or an inner solver)
# after the spacing go to both runs. A benchmark, not a test.
# Usage: tests/perf/modal_scale.sh build/perilin [SPACING [REPS [options...]]]
#   SPACING 0.0025: 57,600 particles; 0.00125: 230,400.
set -euo pipefail
perilin=$(realpath "$1")
dx=${2:-0.0025}
reps=${3:-3}
shift $(($# < 3 ? $# : 3))
scene=$(cd "$(dirname "$0")/../.." && pwd)/examples/lamina/modal.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
# the static twin: no analysis section, a traction on the free edge
python3 - "$scene" > static.yaml <<'PY'
import sys
out = []
for line in open(sys.argv[1]):
    if line.startswith("analysis:"):
        continue
    out.append(line)
    if line.startswith("  base:"):
        out.append("  top: {side: y+}\n")
out.append("loads:\n  - {region: top, traction: [1.0e6, 0]}\n")
print("".join(out), end="")
PY
for r in $(seq "$reps"); do
  /usr/bin/time -f "%e %M" -o s.txt "$perilin" static.yaml -grid_spacing "$dx" -output_dir st -output_vtk false -quiet "$@" > /dev/null
  echo "static $(cat s.txt)" >> times.txt
  /usr/bin/time -f "%e %M" -o m.txt "$perilin" "$scene" -grid_spacing "$dx" -analysis_nev 10 -output_dir mo -output_vtk false -quiet "$@" > /dev/null
  echo "modal $(cat m.txt)" >> times.txt
done
python3 - <<'PY'
import json, statistics
t = {}
for line in open("times.txt"):
    k, w, kb = line.split()
    t.setdefault(k, []).append((float(w), int(kb) / 1048576))
med = {k: (statistics.median(x[0] for x in v), statistics.median(x[1] for x in v)) for k, v in t.items()}
d = json.load(open("mo/summary.json"))
f = d["modal"]["frequencies_hz"][:3]
print(f"{d['particles']} particles, {d['model']} model")
print(f"static: wall {med['static'][0]:.2f} s, peak {med['static'][1]:.2f} GB")
print(f"modal (10 modes): wall {med['modal'][0]:.2f} s, peak {med['modal'][1]:.2f} GB, first frequencies {', '.join(f'{x:.6f}' for x in f)}")
print(f"modal / static: {med['modal'][0] / med['static'][0]:.1f} static runs' worth")
PY
