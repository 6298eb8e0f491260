#!/usr/bin/env bash
# Restart of a quasi-static run (issue 28, item 4), on 1 and 2 ranks: the edge crack run without a
# stop is the reference; the same run stopped after equilibrium step 7 (-peri_stop_after_step: the
# path of a SIGINT, exit 130, "complete": false) and continued with -restart from its output
# directory must end where the reference did: the same steps.csv rows (all but the timing and the
# KSP iteration columns: the continued run builds its preconditioner anew, so its solves agree to
# the solver's tolerance), the same broken bonds, critical and peak load factor to 1e-12, the same
# particles.pvd frames (the stopped run's snapshots taken over). Then what -restart refuses, each
# with exit 1 and no output: a directory without a checkpoint, another scene, another rank count,
# an analysis without checkpoints.
# usage: restart.sh PERILIN SCENE MPIEXEC...   (MPIEXEC: the command that runs 2 ranks)
set -u
# shellcheck source=tests/run_scratch.sh
source "$(dirname "$0")/run_scratch.sh"
need python3
scene=$repo
opts=(-grid_spacing 0.025 -analysis_min_step 1.25 -quiet) # bonds break at steps 7 and 8: before and after the stop; a coarser bracket, a shorter test

# run NAME EXPECTED_STATUS [launcher...] -- options...
run() {
  local name=$1 want=$2 rc
  shift 2
  local launch=() run=()
  split_run "$@"
  "${launch[@]}" "$exe" "$scene" "${opts[@]}" "${run[@]}" -output_dir "$tmp/$name" > "$tmp/$name.log" 2>&1 < /dev/null
  rc=$?
  [ "$rc" -eq "$want" ] || { bad "$name: exit $rc, expected $want"; cat "$tmp/$name.log"; }
}

compare() { # REFERENCE CONTINUED STOPPED LABEL
  python3 - "$@" << 'EOF' || fail=1
import csv, json, sys
ref, cont, stop, label = sys.argv[1:5]
bad = []
def rows(d):
    with open(d + "/steps.csv") as f:
        return list(csv.DictReader(f))
def qs(d):
    with open(d + "/summary.json") as f:
        return json.load(f)
def close(a, b, rel):
    a, b = float(a), float(b)
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)
r, c, s = rows(ref), rows(cont), rows(stop)
if len(s) != 7:
    bad.append(f"the stopped run has {len(s)} steps, expected 7")
if len(r) != len(c) or list(r[0]) != list(c[0]):
    bad.append(f"steps.csv: {len(c)} rows with columns {list(c[0])}, the uninterrupted run {len(r)} with {list(r[0])}")
exact = ("step", "broken", "broken_total", "softened", "equilibrium_iterations")
skip = ("seconds", "ksp_iterations")
for a, b in zip(r, c):
    for k in a:
        ok = a[k] == b[k] if k in exact else True if k in skip else close(a[k], b[k], 1e-12 if k == "load_factor" else 1e-8)
        if not ok:
            bad.append(f"steps.csv step {a['step']} {k}: {b[k]}, uninterrupted {a[k]}")
R, C, S = qs(ref)["quasistatic"], qs(cont)["quasistatic"], qs(stop)["quasistatic"]
for k in ("broken_bonds", "steps", "failed", "failure_step"):
    if R.get(k) != C.get(k):
        bad.append(f"summary.json quasistatic.{k}: {C.get(k)}, uninterrupted {R.get(k)}")
for k in ("critical_load_factor", "peak_load_factor"):
    if not close(R[k], C[k], 1e-12):
        bad.append(f"summary.json quasistatic.{k}: {C[k]!r}, uninterrupted {R[k]!r}")
if S["complete"] or not C["complete"] or C.get("restart_step") != 7:
    bad.append(f"complete: stopped {S['complete']}, continued {C['complete']}; restart_step {C.get('restart_step')}, expected 7")
if R["broken_bonds"] <= S["broken_bonds"] or S["broken_bonds"] == 0:
    bad.append(f"bonds must break before and after the stop: {S['broken_bonds']} at the stop, {R['broken_bonds']} at the end")
if open(ref + "/particles.pvd").read() != open(cont + "/particles.pvd").read():
    bad.append("particles.pvd differs from the uninterrupted run's")
for b in bad:
    print(f"FAIL: {label}: {b}")
if not bad:
    print(f"ok: {label}: stopped at step 7 ({S['broken_bonds']} bonds broken), continued to step {C['steps']}: "
          f"{C['broken_bonds']} bonds, critical load factor {C.get('critical_load_factor')}, steps.csv as uninterrupted")
sys.exit(1 if bad else 0)
EOF
}

for np in 1 2; do
  launch=()
  [ $np -eq 2 ] && launch=("${mpi[@]}")
  run ref$np 0 "${launch[@]}" --
  run stop$np 130 "${launch[@]}" -- -peri_stop_after_step 7
  [ -s "$tmp/stop$np/checkpoint/state.bin" ] || bad "$np rank(s): the stopped run wrote no checkpoint/state.bin"
  run cont$np 0 "${launch[@]}" -- -restart "$tmp/stop$np"
  compare "$tmp/ref$np" "$tmp/cont$np" "$tmp/stop$np" "$np rank(s)"
done

# refused: exit 1, the cause named, no output set and no staging directory left
refused() { # NAME PATTERN [launcher...] -- options...
  local name=$1 pattern=$2
  shift 2
  run "$name" 1 "$@"
  grep -q "$pattern" "$tmp/$name.log" || bad "$name: the message does not say '$pattern': $(cat "$tmp/$name.log")"
  for f in "$tmp/$name" "$tmp/$name".partial-*; do [ -e "$f" ] && bad "$name: left $f"; done
  [ $fail -eq 0 ] && echo "ok: $name refused: $(tail -1 "$tmp/$name.log")"
}
refused no_checkpoint "no checkpoint there" -- -restart "$tmp/nothing"
refused other_scene "another scene" -- -failure_G 1.1 -restart "$tmp/stop1"
refused other_ranks "written on 2 ranks" -- -restart "$tmp/stop2"
refused setup "writes none" -- -analysis_type setup -restart "$tmp/stop1"
exit $fail
