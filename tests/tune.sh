#!/usr/bin/env bash
# analysis.type tune (src/analysis/tune.c, docs/tuning.md). Checks
#   1. examples/tuning/plate_tune.yaml (coarsened), 1 and 2 ranks: tune.csv has one row per
#      configuration of the scene; every converged row's solution (max |u|) is the static run's
#      within 1e-6; the direct solve on the matrix-free operator and CG stopped at 2 iterations
#      are rows not converged with a reason, and the run succeeds; the winner is rank 1 and its
#      solution is the output (strain energy of the static run); 2 ranks converge the same set;
#   2. the micropolar lamina (mppd, matrix-free since issue 29): the built-in list has matrix_free
#      configurations; a matrix_free one given converges; an option of a configuration that
#      nothing reads makes its row not converged; the solutions agree with the static run's;
#   3. an unknown -pc_type in a configuration is an input error before any particle exists, and
#      no configuration converging is an error; neither leaves an output directory.
# Usage: tune.sh PERILIN REPO
set -euo pipefail
perilin=$1
repo=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
plate=$repo/examples/tuning/plate_tune.yaml
coarse=(-grid_spacing 0.02 -analysis_repeat 1)

"$perilin" "$plate" "${coarse[@]}" -output_dir tune1 > tune1.log
mpiexec --oversubscribe -n 2 "$perilin" "$plate" "${coarse[@]}" -output_dir tune2 > tune2.log
# the same plate as a static run (examples/pmb/plate_traction.yaml, with probes besides)
"$perilin" "$repo/examples/pmb/plate_traction.yaml" -grid_spacing 0.02 -output_dir static > static.log

# the lamina: its scene with a tune section appended
lamina=$repo/examples/lamina/traction.yaml
cp "$lamina" lamina_tune.yaml
cat >> lamina_tune.yaml << 'EOF'
analysis:
  type: tune
  configurations:
    - "-ksp_type cg -pc_type gamg"
    - "-ksp_type preonly -pc_type cholesky"
    - "-ksp_type cg -pc_type jacobi -solver_operator matrix_free"
    - "-ksp_type cg -pc_type jacobi -ksp_rtoll 1e-3"
EOF
"$perilin" lamina_tune.yaml -output_dir lamina > lamina.log
"$perilin" "$lamina" -analysis_type tune -output_dir lamina_default > lamina_default.log
"$perilin" "$lamina" -output_dir lamina_static > lamina_static.log

python3 - "$plate" << 'PY'
import csv, json, re, sys
fail = 0
def check(ok, what):
    global fail
    fail += not ok
    print(("ok   " if ok else "FAIL ") + what)
def rows(d):
    return list(csv.DictReader(open(f"{d}/tune.csv")))
def umax(d):
    return max(json.load(open(f"{d}/summary.json"))["max_abs_u"].values())
configs = re.findall(r'^\s*- "(.*)"\s*$', open(sys.argv[1]).read(), re.M)
for d in ("tune1", "tune2"):
    r, s = rows(d), json.load(open(f"{d}/summary.json"))
    check(sorted(x["configuration"] for x in r) == sorted(configs), f"{d}: one row per configuration ({len(r)} rows, {len(configs)} configurations)")
    ref = umax("static")
    conv = [x for x in r if x["converged"] == "true"]
    check(all(abs(float(x["u_max"]) - ref) <= 1e-6 * ref for x in conv), f"{d}: the {len(conv)} converged solutions' max |u| are the static run's {ref:.10g} within 1e-6")
    check(all(float(x["residual"]) <= float(x["residual_tol"]) and not x["reason"] for x in conv), f"{d}: converged rows have a true residual within tolerance and no reason")
    mf = next(x for x in r if x["configuration"] == "-ksp_type preonly -pc_type cholesky -solver_operator matrix_free")
    check(mf["converged"] == "false" and "true relative residual" in mf["reason"], f"{d}: the direct solve on the matrix-free operator is not converged: {mf['reason']}")
    it = next(x for x in r if "-ksp_max_it 2" in x["configuration"])
    check(it["converged"] == "false" and "DIVERGED_ITS" in it["reason"], f"{d}: CG stopped at 2 iterations is not converged: {it['reason']}")
    check(r[0]["rank"] == "1" and s["tune"]["winner"] == r[0]["configuration"] and r[0]["converged"] == "true", f"{d}: the winner is rank 1: {r[0]['configuration']}")
    check(abs(s["strain_energy"] - json.load(open("static/summary.json"))["strain_energy"]) <= 1e-6 * s["strain_energy"], f"{d}: the output is the static solution (strain energy {s['strain_energy']:.8g})")
    check(len(s["tune"]["configurations"]) == len(r), f"{d}: summary.json's tune has every row")
check({x["configuration"] for x in rows("tune1") if x["converged"] == "true"} == {x["configuration"] for x in rows("tune2") if x["converged"] == "true"}, "1 and 2 ranks converge the same configurations")
r = rows("lamina")
ref = umax("lamina_static")
by = {x["configuration"]: x for x in r}
mf = by["-ksp_type cg -pc_type jacobi -solver_operator matrix_free"]
check(mf["converged"] == "true", f"lamina: matrix_free converges: {mf['reason']}")
unread = by["-ksp_type cg -pc_type jacobi -ksp_rtoll 1e-3"]
check(unread["converged"] == "false" and "-ksp_rtoll was read by nothing" in unread["reason"], f"lamina: the unread option's row is not converged: {unread['reason']}")
conv = [x for x in r if x["converged"] == "true"]
check(len(conv) == 3 and all(abs(float(x["u_max"]) - ref) <= 1e-6 * ref for x in conv), f"lamina: GAMG, Cholesky and matrix-free Jacobi converge to the static solution (max |u| {ref:.10g})")
d = rows("lamina_default")
check(len(d) >= 4 and any("matrix_free" in x["configuration"] for x in d), f"lamina: the built-in list ({len(d)} configurations) has a matrix_free one")
check(all(abs(float(x["u_max"]) - ref) <= 1e-6 * ref for x in d if x["converged"] == "true"), "lamina: the built-in list's converged solutions agree with the static run")
sys.exit(1 if fail else 0)
PY

fail=0
sed 's/"-ksp_type cg -pc_type gamg -solver_operator assembled"/"-ksp_type cg -pc_type nonsense"/' "$plate" > bogus.yaml
if "$perilin" bogus.yaml -output_dir bogus > bogus.log 2> bogus.err; then
  echo "FAIL unknown pc type: the run succeeded"; fail=1
elif ! grep -q "bogus.yaml:[0-9]*: key 'analysis.configurations.0': configuration '-ksp_type cg -pc_type nonsense' cannot be set up: Unable to find requested PC type nonsense" bogus.err || [ -e bogus ] || grep -q particles bogus.log; then
  echo "FAIL unknown pc type: wrong message, or output left, or particles made"; cat bogus.err; fail=1
else
  echo "ok   unknown pc type: an input error naming the configuration, before any particle"
fi
python3 - "$plate" > none.yaml << 'PY'
import re, sys
t = open(sys.argv[1]).read()
print(re.sub(r'configurations:\n(\s*- ".*"\n)+', 'configurations:\n    - "-ksp_type cg -pc_type jacobi -ksp_max_it 3"\n', t))
PY
if "$perilin" none.yaml -grid_spacing 0.02 -output_dir none > none.log 2> none.err; then
  echo "FAIL none converged: the run succeeded"; fail=1
elif ! grep -q "no configuration of the 1 converged" none.err || [ -e none ]; then
  echo "FAIL none converged: wrong message or output left"; cat none.err; fail=1
else
  echo "ok   none converged: an error, nothing written"
fi
exit $fail
