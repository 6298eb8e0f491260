#!/bin/bash
# Restart of dynamic runs (issue 38, item 6): a run stopped after step K as a SIGINT would
# (-peri_stop_after_step K) and continued with -restart ends as the uninterrupted run: summary.json's
# steps, broken bonds, energies and impactor state equal to 1e-12 (relative), history.csv the same
# bytes, particles.pvd the same frames. Kalthoff-Winkler (bonds breaking, contact, an impactor) on 1
# and 2 ranks (there with and without contact between particles); the pulse with the implicit integrator.
# usage: dynamic_restart.sh PERILIN REPO [MPIRUN...]
set -u
exe=$1 repo=$2
shift 2
mpirun=("$@")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1
fail=0
compare() { # name: full/, cont/ of $tmp/name
  /usr/bin/python3 - "$tmp/$1" << 'PY' || fail=1
import json, sys
d = sys.argv[1]
a = json.load(open(d + "/full/summary.json"))["dynamic"]
b = json.load(open(d + "/cont/summary.json"))["dynamic"]
bad = []
for k in ("steps", "broken_bonds", "time", "kinetic_energy", "strain_energy", "dissipated_energy", "work_of_loads", "energy_drift"):
    if abs(a[k] - b[k]) > 1e-12 * max(abs(a[k]), 1e-300):
        bad.append("%s %r != %r" % (k, a[k], b[k]))
for ia, ib in zip(a.get("impactors", []), b.get("impactors", [])):
    for k in ("center", "velocity", "force"):
        if any(abs(x - y) > 1e-12 * max(abs(x), 1e-300) for x, y in zip(ia[k], ib[k])):
            bad.append("impactor %s %r != %r" % (k, ia[k], ib[k]))
if not b.get("restart_step"):
    bad.append("no restart_step in the continued run's summary")
print(("FAIL: " + "; ".join(bad)) if bad else "ok: %s: the restarted run ends as the whole one (step %d of %d, %d bonds broken)" % (d, b["restart_step"], b["steps"], b["broken_bonds"]))
sys.exit(1 if bad else 0)
PY
  cmp -s "$tmp/$1/full/history.csv" "$tmp/$1/cont/history.csv" && echo "ok: $1: history.csv identical" || { echo "FAIL: $1: history.csv differs"; fail=1; }
  if [ -f "$tmp/$1/full/particles.pvd" ]; then
    cmp -s "$tmp/$1/full/particles.pvd" "$tmp/$1/cont/particles.pvd" && echo "ok: $1: particles.pvd identical" || { echo "FAIL: $1: particles.pvd differs"; fail=1; }
  fi
}
case_run() { # name K launcher... -- perilin arguments
  local name=$1 k=$2
  shift 2
  local launch=()
  while [ "$1" != "--" ]; do launch+=("$1"); shift; done
  shift
  "${launch[@]}" "$exe" "$@" -quiet -output_dir "$tmp/$name/full" > "$tmp/$name.full.log" 2>&1 < /dev/null || { echo "FAIL: $name: the whole run exited $?"; cat "$tmp/$name.full.log"; fail=1; return; }
  "${launch[@]}" "$exe" "$@" -quiet -output_dir "$tmp/$name/stop" -peri_stop_after_step "$k" > "$tmp/$name.stop.log" 2>&1 < /dev/null
  st=$?
  [ $st = 130 ] || { echo "FAIL: $name: the stopped run exited $st, not 130 (SIGINT's)"; cat "$tmp/$name.stop.log"; fail=1; return; }
  grep -q '"complete": false' "$tmp/$name/stop/summary.json" || { echo "FAIL: $name: the stopped run is not marked incomplete"; fail=1; }
  "${launch[@]}" "$exe" "$@" -quiet -output_dir "$tmp/$name/cont" -restart "$tmp/$name/stop" > "$tmp/$name.cont.log" 2>&1 < /dev/null || { echo "FAIL: $name: the restarted run exited $?"; cat "$tmp/$name.cont.log"; fail=1; return; }
  compare "$name"
}
kw=("$repo/examples/dynamics/kalthoff_winkler.yaml" -grid_spacing 2e-3)
case_run kw 100 env -- "${kw[@]}"
# 2 ranks: the impactor and the breaking bonds without contact between particles, and with it
# (its candidate pairs rebuilt from the restored positions; the default ghost layer reaches far
# enough for the whole run: docs/contact.md)
grep -v '^contact:' "$repo/examples/dynamics/kalthoff_winkler.yaml" > "$tmp/kw_no_contact.yaml"
[ ${#mpirun[@]} -gt 0 ] && case_run kw_2ranks 60 "${mpirun[@]}" -- "$tmp/kw_no_contact.yaml" -grid_spacing 2.5e-3
[ ${#mpirun[@]} -gt 0 ] && case_run kw_contact_2ranks 60 "${mpirun[@]}" -- "$repo/examples/dynamics/kalthoff_winkler.yaml" -grid_spacing 2.5e-3
case_run pulse_implicit 8 env -- "$repo/examples/dynamics/pulse.yaml" -analysis_integrator implicit -analysis_dt 0.4 -analysis_t_end 6 -output_vtk true
exit $fail
