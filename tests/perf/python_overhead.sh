#!/usr/bin/env bash
# Issue 39, item 6: the cost of a run from Python (tests/perf/python_run.py: import perilin, set up,
# solve, write the output set) against the same run from the command line (perilin SCENE
# -output_dir DIR), whole processes, in pairs taken in turn (CLI, Python, CLI, ...) so that a drift
# of the machine's speed falls on both; prints each pair and the medians of the wall times and of
# the pairs' ratios. A benchmark, not a test (docs/python.md, docs/performance.md).
# Usage: tests/perf/python_overhead.sh BUILD [PAIRS [SPACING]]
#   BUILD: the build directory (BUILD/perilin, BUILD/python); PAIRS default 7; SPACING of
#   examples/bench/plate_2d.yaml, default 1/401 (160,801 particles)
set -euo pipefail
build=$(realpath "$1")
pairs=${2:-7}
h=${3:-1/401}
root=$(cd "$(dirname "$0")/../.." && pwd)
scene=$root/examples/bench/plate_2d.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
stamps=()
for ((k = 0; k <= pairs; k++)); do # pair 0 warms the caches, not counted
  t0=$(now)
  "$build/perilin" "$scene" -grid_spacing "$h" -quiet -output_dir "$work/cli" > /dev/null
  t1=$(now)
  PYTHONPATH=$build/python /usr/bin/python3 "$root/tests/perf/python_run.py" "$scene" "$work/py" grid.spacing="$h" > /dev/null
  t2=$(now)
  [[ $k -gt 0 ]] && stamps+=("$t0,$t1,$t2")
done
/usr/bin/python3 - "${stamps[@]}" << 'PY'
import statistics, sys
cli, py = [], []
for k, s in enumerate(sys.argv[1:]):
    t0, t1, t2 = (float(v) for v in s.split(","))
    cli.append(t1 - t0)
    py.append(t2 - t1)
    print("pair %d: command line %.3f s, Python %.3f s" % (k + 1, cli[-1], py[-1]))
r = [b / a for a, b in zip(cli, py)]
print("medians: command line %.3f s, Python %.3f s; Python / command line, median of the pairs' ratios %.3f (min %.3f, max %.3f)" % (statistics.median(cli), statistics.median(py), statistics.median(r), min(r), max(r)))
PY
