#!/usr/bin/env bash
# The anisotropy analysis (src/analysis/anisotropy.c) on examples/failure/anisotropy.yaml against
# Diana & Casolo's Table 7 (maximum stretch: every printed value, to within 0.005 percentage points,
# half the printed 0.01) and Table 8 (maximum sliding: the linearized shear angle gives the paper's
# values less 0.06-0.08 points, docs/failure.md; asserted to the closed form 1/cos^2 or 1/sin of the
# widest gap between the family's directions, sampled as the paper did, within 0.005).
# Usage: tests/anisotropy.sh PERILIN REPO
set -euo pipefail
perilin=$1
repo=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$perilin" "$repo/examples/failure/anisotropy.yaml" -output_dir "$work/out" > "$work/log"
python3 - "$work/out/anisotropy.csv" <<'PY'
import csv, sys
rows = {(r["criterion"], float(r["s1"]), float(r["s2"]), float(r["m"])): float(r["e_max_percent"]) for r in csv.DictReader(open(sys.argv[1]))}
M = (2, 3, 3.2, 4, 5)
table7 = {(1, 1): (0.00, 0.00, 0.00, 0.00, 0.00), (0.5, 1): (7.90, 2.62, 1.24, 1.24, 0.71), (0, 1): (17.16, 5.39, 2.51, 2.51, 1.44),
          (-1, 1): (41.42, 11.38, 5.15, 5.15, 2.92), (-2, 1): (78.36, 18.11, 7.92, 7.92, 4.44), (-3, 1): (24.26, 7.31, 3.37, 3.37, 1.93),
          (-3, 0): (17.16, 5.39, 2.51, 2.51, 1.44), (-3, -1.5): (7.90, 2.62, 1.24, 1.24, 0.71), (-3, -3): (0.00, 0.00, 0.00, 0.00, 0.00)}
table8 = (41.48, 11.46, 5.23, 5.23, 3.00)
linear8 = (41.42, 11.38, 5.15, 5.15, 2.92)  # docs/tools/anisotropy_tables.py, independent of perilin
bad = 0
for (s1, s2), want in table7.items():
    for m, w in zip(M, want):
        got = rows[("stretch", s1, s2, m)]
        ok = abs(got - w) <= 0.005 + 1e-9
        bad += not ok
        print(f"{'ok' if ok else 'FAIL'}: Table 7 s1={s1:g} s2={s2:g} m={m:g}: e_max {got:.4f} %, paper {w:.2f} % (tolerance 0.005)")
for s1, s2 in ((0.5, 1), (0, 1), (-0.33, 0.66), (-0.5, 0.5), (-0.66, 0.33), (-1, 0), (-1, -0.5)):
    for m, w, lin in zip(M, table8, linear8):
        got = rows[("sliding", s1, s2, m)]
        ok = abs(got - lin) <= 0.005 + 1e-9 and 0.05 <= w - got <= 0.09
        bad += not ok
        print(f"{'ok' if ok else 'FAIL'}: Table 8 s1={s1:g} s2={s2:g} m={m:g}: e_max {got:.4f} %, linearized {lin:.2f} % (tolerance 0.005), paper {w:.2f} % (gap {w - got:.3f}, expected 0.05-0.09)")
sys.exit(1 if bad else 0)
PY

# SIGTERM and SIGHUP stop the study within 10 s (issue 40, item 5): exit 143 / 129, summary.json
# "complete": false with the rows complete by then, each row of the three CSV files equal to the
# uninterrupted run's, no staging directory left.
for sig in TERM HUP; do
  rm -rf "$work/int" "$work/int".partial-*
  setsid "$perilin" "$repo/examples/failure/anisotropy.yaml" -output_dir "$work/int" > "$work/int.log" 2>&1 < /dev/null &
  pid=$!
  sleep 1
  kill -s "$sig" "$pid"
  waited=0
  while kill -0 "$pid" 2> /dev/null && [ $waited -lt 10 ]; do
    sleep 1
    waited=$((waited + 1))
  done
  if kill -0 "$pid" 2> /dev/null; then
    kill -s KILL "$pid"
    echo "FAIL: SIG$sig: the anisotropy run did not stop within 10 s"
    exit 1
  fi
  code=0
  wait "$pid" || code=$?
  want=$((128 + $(kill -l "$sig")))
  [ "$code" -eq "$want" ] || {
    echo "FAIL: SIG$sig: exit status $code, expected $want"
    cat "$work/int.log"
    exit 1
  }
  if compgen -G "$work/int.partial-*" > /dev/null; then
    echo "FAIL: SIG$sig: a staging directory was left behind"
    exit 1
  fi
  python3 - "$work/out" "$work/int" "SIG$sig" <<'PY'
import csv, json, sys
full, part, sig = sys.argv[1:]
s = json.load(open(f"{part}/summary.json"))
assert s["complete"] is False and s["interrupted_by"] == sig, (s["complete"], s.get("interrupted_by"))
n = s["anisotropy"]["rows"]
total = json.load(open(f"{full}/summary.json"))["anisotropy"]["rows"]
assert 0 < n < total, f"rows {n} of {total}: the signal should fall inside the study"
for name in ("anisotropy", "anisotropy_polar", "anisotropy_envelope"):
    a = list(csv.reader(open(f"{full}/{name}.csv")))
    b = list(csv.reader(open(f"{part}/{name}.csv")))
    assert b == a[: len(b)], f"{name}.csv: the interrupted run's rows differ from the full run's"
    if name == "anisotropy":
        assert len(b) == n + 1, f"anisotropy.csv has {len(b) - 1} rows, summary.json says {n}"
    if name == "anisotropy_polar":
        assert len(b) == n * s["anisotropy"]["orientations"] + 1, f"anisotropy_polar.csv has {len(b) - 1} rows"
print(f"ok: {sig} stopped the anisotropy run after {n} of {total} rows, marked incomplete, each row the full run's")
PY
done
