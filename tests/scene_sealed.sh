#!/usr/bin/env bash
# Settings are read once (issue 39, item 1): with -peri_scene_sealed any read of the scene after
# the set-up is an error naming the key, so each analysis type runs here to its end with it on:
# static (the multigrid's coarse levels from their own view of the scene), modal, quasi-static,
# dynamic explicit (loads with their own amplitudes, contact, a moving boundary) and implicit,
# tune and anisotropy.
# usage: scene_sealed.sh PERILIN REPO
set -u
exe=$1 repo=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
fail=0
n=0
run() { # scene options...
  n=$((n + 1))
  if "$exe" "$@" -peri_scene_sealed -quiet -output_plots false -output_dir "$tmp/$n" > "$tmp/$n.log" 2>&1 < /dev/null; then
    echo "ok: sealed: $*"
  else
    echo "FAIL: sealed: $*: $(grep 'error' "$tmp/$n.log")"
    fail=1
  fi
}
ex=$repo/examples sc=$repo/tests/scenes
run "$ex/pmb/plate_traction.yaml"
run "$ex/bench/block_3d.yaml" -grid_spacing 0.05
run "$ex/lamina/modal.yaml" -grid_spacing 0.02
run "$ex/fracture/edge_crack.yaml" -grid_spacing 0.025
run "$sc/timed_loads.yaml"
run "$sc/contact_bars.yaml"
run "$sc/pulled_bar.yaml"
run "$ex/dynamics/pulse.yaml" -grid_upper 100,4,4 -analysis_t_end 10 -analysis_integrator implicit -analysis_dt 0.5
run "$ex/tuning/plate_tune.yaml"
run "$ex/failure/anisotropy.yaml"
exit $fail
