#!/usr/bin/env bash
# Issue 29, item 1: the 10 lowest modes of the gerstle cantilever lamina (examples/lamina/modal.yaml
# -model_type gerstle) at one spacing, the default eigensolver (auto) against the factorization
# (analysis.eigensolver: shift_invert), interleaved, medians of REPS (default 1), 1 rank. Prints
# each run's wall time and peak memory (/usr/bin/time), the targets' ratios (wall / 40 s and peak /
# 3 GB at 230,400 particles; peak / this machine's memory for the largest size) and the largest
# relative difference of the frequencies. A benchmark, not a test.
# Usage: tests/perf/modes_at_scale.sh build/perilin [SPACING [REPS [SOLVERS [options...]]]]
#   SPACING 0.0025: 57,600 particles; 0.00125: 230,400; 0.000625: 921,600.
#   SOLVERS: "auto shift_invert" (default), or one of them ("auto" alone where the factorization
#   does not fit). Extra options go to every run.
set -euo pipefail
perilin=$(realpath "$1")
dx=${2:-0.0025}
reps=${3:-1}
solvers=${4:-auto shift_invert}
shift $(($# < 4 ? $# : 4))
scene=$(cd "$(dirname "$0")/../.." && pwd)/examples/lamina/modal.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
for r in $(seq "$reps"); do
  for s in $solvers; do
    /usr/bin/time -a -o runs.txt -f "$s %e %M" "$perilin" "$scene" -model_type gerstle -grid_spacing "$dx" -analysis_nev 10 -analysis_eigensolver "$s" \
      -output_dir "$s" -output_vtk false -output_plots false -quiet "$@" > /dev/null
  done
done
python3 - <<'PY'
import json, os, statistics
runs = [line.split() for line in open("runs.txt")]
t = {k: [(float(w), int(kb) / 1048576) for s, w, kb in runs if s == k] for k, _, _ in runs}
mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
f = {}
for k, v in t.items():
    d = json.load(open(f"{k}/summary.json"))
    f[k] = d["modal"]["frequencies_hz"]
    w, gb = statistics.median(x[0] for x in v), statistics.median(x[1] for x in v)
    print(f"{k} ({d['modal']['eigensolver']}, K {d['solver']['stiffness']}), {d['particles']} particles, {len(v)} run(s): wall {w:.1f} s, peak {gb:.2f} GB, "
          f"{d['solver']['iterations']} iterations, largest mode residual {max(m['residual'] for m in d['modal']['modes']):.1e}")
    print(f"  targets: wall / 40 s = {w / 40:.2f}, peak / 3 GB = {gb / 3:.2f}, peak / machine ({mem:.1f} GB) = {gb / mem:.2f}")
if len(f) == 2:
    a, b = f.values()
    print(f"largest relative difference of the {len(a)} frequencies: {max(abs(x - y) / y for x, y in zip(a, b)):.1e} (target 1e-8)")
PY
