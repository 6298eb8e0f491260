#!/usr/bin/env bash
# analysis.type setup (src/analysis/setup.c): the system is set up exactly as for a solve and
# nothing is solved. Checks, on 1 and 2 ranks, against a static run of the same scene: the same
# particles, bonds and edge cut; no solver section, no strain energy, no displacement field; exit 0.
# A scene of another analysis (a quasi-static one: its analysis keys) is accepted by the dry run.
# Usage: analysis_setup.sh PERILIN SCENE [QUASISTATIC_SCENE]
set -euo pipefail
perilin=$1 scene=$2 qs=${3:-}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
for ranks in 1 2; do
  run=("$perilin")
  [[ $ranks == 1 ]] || run=(mpiexec --oversubscribe -n "$ranks" "$perilin")
  "${run[@]}" "$scene" -analysis_type setup -output_dir setup$ranks > setup$ranks.log
  "${run[@]}" "$scene" -output_dir static$ranks > static$ranks.log
  python3 - "$ranks" <<'PY'
import json, sys
r = sys.argv[1]
s, t = (json.load(open(f"{d}{r}/summary.json")) for d in ("setup", "static"))
# one rank writes particles.vtu; several the .pvtu index of one piece per rank (docs/summary.md)
vtu = open(f"setup{r}/particles.vtu", "rb").read() if r == "1" else open(f"setup{r}/particles.pvtu", "rb").read()
checks = {
  "analysis is setup": s["analysis"] == "setup",
  "same particles as the static run": s["particles"] == t["particles"],
  "same bonds as the static run": s["bonds"] == t["bonds"],
  "same edge cut as the static run": s["edge_cut"] == t["edge_cut"],
  "an edge cut on 2 ranks": r == "1" or s["edge_cut"] > 0,
  "no solver section": "solver" not in s,
  "no strain energy": "strain_energy" not in s,
  "no displacement field": b'Name="displacement"' not in vtu,
  "volumes written": b'Name="volume"' in vtu,
}
bad = [k for k, ok in checks.items() if not ok]
if bad:
    sys.exit(f"analysis_setup ({r} rank(s)): failed: {', '.join(bad)}")
print(f"ok: analysis setup on {r} rank(s): {s['particles']} particles, {s['bonds']} bonds, edge cut {s['edge_cut']}, as the static run; nothing solved")
PY
done
if [[ -n $qs ]]; then
  "$perilin" "$qs" -analysis_type setup -grid_spacing 0.04 -output_dir setup_qs > setup_qs.log
  echo "ok: analysis setup accepts a quasi-static scene's keys (exit 0)"
fi
