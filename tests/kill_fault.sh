#!/usr/bin/env bash
# SIGKILL of one rank of a 2-rank run (issue 40, item 3): a quasi-static run (the edge crack of
# tests/restart.sh) and a dynamic one (Kalthoff-Winkler without contact, as tests/dynamic_restart.sh
# runs it on 2 ranks) are killed, rank 1 alone by SIGKILL, as soon as their first checkpoint is in
# place. Nothing can be saved then: what is on disk must be the output directory as it was (a
# previous complete set, the same bytes) and the staging directory DIR.partial-XXXXXX, whose
# checkpoint/state.bin is whole. -restart
# from that directory must continue the run to the end of the uninterrupted one: the same broken
# bonds and steps; quasi-static steps.csv as tests/restart.sh compares it (load factors to 1e-12,
# the rest to 1e-8); dynamic energies and impactors to 1e-12 and history.csv the same bytes.
# usage: kill_fault.sh PERILIN REPO MPIEXEC...   (MPIEXEC: the command that runs 2 ranks)
set -u
# shellcheck source=tests/run_scratch.sh
source "$(dirname "$0")/run_scratch.sh"
need python3

# the pid of rank 1 among the processes under mpiexec's pid $1 (Open MPI: OMPI_COMM_WORLD_RANK)
rank1() {
  local p
  for p in $(ps -o pid= --ppid "$1") $(for c in $(ps -o pid= --ppid "$1"); do ps -o pid= --ppid "$c"; done); do
    tr '\0' '\n' < "/proc/$p/environ" 2> /dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1' && { echo "$p"; return; }
  done
}

# killed NAME OPTIONS...: the uninterrupted run (ref), the run whose rank 1 is killed (out), its
# restart from the staging directory it left (cont)
killed() {
  local name=$1 d=$tmp/$1 mpid r1 st partial
  shift
  mkdir -p "$d"
  "${mpi[@]}" "$exe" "$@" -quiet -output_dir "$d/ref" > "$d/ref.log" 2>&1 < /dev/null || { bad "$name: the uninterrupted run exited $?"; cat "$d/ref.log"; return; }
  cp -a "$d/ref" "$d/out" # a previous complete set, which the killed run must leave as it was
  "${mpi[@]}" "$exe" "$@" -quiet -output_dir "$d/out" > "$d/out.log" 2>&1 < /dev/null &
  mpid=$!
  await $mpid "$d/out.partial-*/checkpoint/state.bin"
  r1=$(rank1 $mpid)
  [ -n "$r1" ] && kill -KILL "$r1"
  wait $mpid
  st=$?
  [ -n "$r1" ] || { bad "$name: the run ended (exit $st) before rank 1 could be killed"; return; }
  [ $st -ne 0 ] || bad "$name: mpiexec exited 0 although rank 1 was killed"
  diff -r "$d/ref" "$d/out" > /dev/null || bad "$name: the killed run changed the previous set in $d/out"
  partial=$(compgen -G "$d/out.partial-*")
  [ "$(echo "$partial" | wc -l)" -eq 1 ] && [ -s "$partial/checkpoint/state.bin" ] || { bad "$name: no single staging directory with a checkpoint: '$partial'"; ls -la "$d"; return; }
  "${mpi[@]}" "$exe" "$@" -quiet -restart "$partial" -output_dir "$d/cont" > "$d/cont.log" 2>&1 < /dev/null || { bad "$name: the restart from $partial exited $?"; cat "$d/cont.log"; return; }
  python3 - "$d" "$name" << 'EOF' || fail=1
import csv, json, sys
d, name = sys.argv[1:3]
bad = []
def close(a, b, rel):
    a, b = float(a), float(b)
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)
R = json.load(open(d + "/ref/summary.json"))
C = json.load(open(d + "/cont/summary.json"))
if "quasistatic" in R:
    R, C = R["quasistatic"], C["quasistatic"]
    rows = lambda s: list(csv.DictReader(open(f"{d}/{s}/steps.csv")))
    r, c = rows("ref"), rows("cont")
    if len(r) != len(c):
        bad.append(f"steps.csv: {len(c)} rows, the uninterrupted run {len(r)}")
    exact = ("step", "broken", "broken_total", "softened", "equilibrium_iterations")
    for a, b in zip(r, c):
        for k in a:
            if k in ("seconds", "ksp_iterations"):
                continue
            if not (a[k] == b[k] if k in exact else close(a[k], b[k], 1e-12 if k == "load_factor" else 1e-8)):
                bad.append(f"steps.csv step {a['step']} {k}: {b[k]}, uninterrupted {a[k]}")
    keys, reals = ("broken_bonds", "steps", "failed", "failure_step"), ("critical_load_factor", "peak_load_factor")
else:
    R, C = R["dynamic"], C["dynamic"]
    if open(d + "/ref/history.csv").read() != open(d + "/cont/history.csv").read():
        bad.append("history.csv differs from the uninterrupted run's")
    for ia, ib in zip(R.get("impactors", []), C.get("impactors", [])):
        for k in ("center", "velocity", "force"):
            if any(not close(x, y, 1e-12) for x, y in zip(ia[k], ib[k])):
                bad.append(f"impactor {k} {ib[k]} != {ia[k]}")
    keys, reals = ("steps", "broken_bonds"), ("time", "kinetic_energy", "strain_energy", "dissipated_energy", "work_of_loads", "energy_drift")
for k in keys:
    if R.get(k) != C.get(k):
        bad.append(f"summary.json {k}: {C.get(k)}, uninterrupted {R.get(k)}")
for k in reals:
    if not close(R[k], C[k], 1e-12):
        bad.append(f"summary.json {k}: {C[k]!r}, uninterrupted {R[k]!r}")
if not C.get("restart_step") or C.get("restart_step") >= C.get("steps"):
    bad.append(f"restart_step {C.get('restart_step')} of {C.get('steps')} steps: not killed mid-run")
for b in bad:
    print(f"FAIL: {name}: {b}")
if not bad:
    print(f"ok: {name}: rank 1 killed, restarted from step {C['restart_step']} to step {C['steps']}, {C['broken_bonds']} bonds broken, as uninterrupted")
sys.exit(1 if bad else 0)
EOF
}

killed quasistatic "$repo/examples/fracture/edge_crack.yaml" -grid_spacing 0.025 -analysis_min_step 1.25
grep -v '^contact:' "$repo/examples/dynamics/kalthoff_winkler.yaml" > "$tmp/kw_no_contact.yaml"
killed dynamic "$tmp/kw_no_contact.yaml" -grid_spacing 4e-3
exit $fail
