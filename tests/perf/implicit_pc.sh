#!/bin/bash
# The implicit step's default preconditioner (docs/dynamics.md, "The implicit step's
# preconditioner"): the pulse of examples/dynamics/pulse.yaml integrated implicitly at dt 0.4
# (0.47 explicit limits, 100 steps) and at dt 16 (18.7 limits, 40 steps) with the default (CG +
# Jacobi below 20 limits) against -pc_type gamg (built once), paired runs A B A B ... by farm-bench.
# usage: tests/perf/implicit_pc.sh [PERILIN] [RUNS]
set -eu
exe=${1:-build/perilin}
runs=${2:-3}
scene=$(dirname "$0")/../../examples/dynamics/pulse.yaml
for case in "0.4 40" "16 640"; do
  set -- $case
  echo "== dt $1, t_end $2: default (Jacobi) against -pc_type gamg"
  farm-bench -n "$runs" --timeout 900 --vs "$exe $scene -analysis_integrator implicit -analysis_dt $1 -analysis_t_end $2 -pc_type gamg -output_dir /tmp/implicit_pc_b -quiet" \
    -- "$exe" "$scene" -analysis_integrator implicit -analysis_dt "$1" -analysis_t_end "$2" -output_dir /tmp/implicit_pc_a -quiet
done
