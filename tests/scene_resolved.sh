#!/bin/bash
# scene.yaml, the resolved scene of every output set (docs/summary.md), reproduces the run: for
# several scenes (with overrides), perilin run again on OUT/scene.yaml (into another directory, with
# no override) gives the same results in summary.json (every number but the costs: timings,
# memory), and its own scene.yaml is the same file (idempotent) but for output.dir and the header
# comments. scene.yaml parses as YAML, holds the overrides, the declared defaults the run used, and
# absolute input paths (the mesh file, read from the output directory).
# usage: scene_resolved.sh PERILIN EXAMPLES_DIR
set -u
exe=$1; ex=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# check NAME SCENE [OPTIONS...]: run, run again from scene.yaml, compare
check() {
  local name=$1 scene=$2
  shift 2
  "$exe" "$scene" "$@" -quiet -output_dir "$tmp/$name-1" > "$tmp/$name.log" 2>&1 || { cat "$tmp/$name.log"; fail "$name: the run failed"; }
  [ -f "$tmp/$name-1/scene.yaml" ] || fail "$name: no scene.yaml in the output set"
  # from another working directory: every path in scene.yaml must be absolute
  (cd "$tmp" && "$exe" "$tmp/$name-1/scene.yaml" -quiet -output_dir "$tmp/$name-2") > "$tmp/$name.log" 2>&1 || { cat "$tmp/$name.log"; fail "$name: perilin on its scene.yaml failed"; }
  python3 - "$tmp/$name-1" "$tmp/$name-2" "$name" <<'PY' || fail "$name: scene.yaml does not reproduce the run"
import json, os, sys, yaml
a, b, name = sys.argv[1:4]
# what is not a result: where and how the run was made, and what it cost
COST = {"scene", "build", "command_line", "timing", "memory_mb", "memory_mb_max_rank", "memory_phases_mb", "matrix_mb"}
def results(d, path=""):
    if isinstance(d, dict):
        out = {}
        for k, v in d.items():
            if (not path and k in COST) or k.endswith("_s"):
                continue
            out[k] = results(v, path + "." + k)
        return out
    return d
ra = results(json.load(open(os.path.join(a, "summary.json"))))
rb = results(json.load(open(os.path.join(b, "summary.json"))))
# The same command run twice is not bitwise reproducible itself (the last digits of a quasi-static
# run vary, one BLAS thread or not): numbers agree to 1e-9 relative, where a number of round-off
# size (an imbalance, a residual) is relative to the largest of its siblings.
num = lambda v: isinstance(v, (int, float)) and not isinstance(v, bool)
def diff(x, y, path="", scale=0.0):
    if isinstance(x, (dict, list)) and type(x) == type(y):
        keys = sorted(set(x) | set(y)) if isinstance(x, dict) else range(max(len(x), len(y)))
        vals = list(x.values()) if isinstance(x, dict) else x
        scale = max([abs(v) for v in vals if num(v)] + [0.0])
        for k in keys:
            if (isinstance(x, dict) and (k not in x or k not in y)) or (isinstance(x, list) and k >= min(len(x), len(y))):
                yield "%s.%s only in one" % (path, k)
            else:
                yield from diff(x[k], y[k], "%s.%s" % (path, k), scale)
    elif num(x) and num(y):
        if abs(x - y) > 1e-9 * max(abs(x), abs(y), 1e-6 * scale) + 1e-300:
            yield "%s: %r != %r" % (path, x, y)
    elif x != y:
        yield "%s: %r != %r" % (path, x, y)
d = list(diff(ra, rb))
assert not d, "results differ:\n  " + "\n  ".join(d[:20])
def body(f):
    return [l for l in open(os.path.join(f, "scene.yaml")) if not l.startswith("#")]
sa, sb = yaml.safe_load("".join(body(a))), yaml.safe_load("".join(body(b)))
assert sa["output"]["dir"] == os.path.abspath(a) and sb["output"]["dir"] == os.path.abspath(b), (sa["output"], sb["output"])
strip = lambda lines: [l for l in lines if not l.startswith("  dir: ")]
assert strip(body(a)) == strip(body(b)), "scene.yaml is not idempotent:\n" + "".join(l for l in body(a) if l not in body(b))
head = [l for l in open(os.path.join(a, "scene.yaml")) if l.startswith("#")]
assert any("given back to perilin, this reproduces the run" in l.lower() for l in head), head
assert any(l.startswith("# command line: ") for l in head), head
leaves = lambda d: sum(leaves(v) for v in d.values()) if isinstance(d, dict) else 1
print("ok: %s: the %d results of summary.json agree, scene.yaml idempotent (%d lines)" % (name, leaves(ra), len(body(a))))
PY
}

check plate "$ex/pmb/plate_traction.yaml" -grid_spacing 0.02 -material_E 2e9
grep -q '^  spacing: 0.02$' "$tmp/plate-1/scene.yaml" || fail "plate: the override -grid_spacing 0.02 is not in scene.yaml"
grep -q '^  E: 2e9$' "$tmp/plate-1/scene.yaml" || fail "plate: the override -material_E 2e9 is not in scene.yaml"
# declared defaults the run used are written (the file has neither)
grep -q '^  rho: 0$' "$tmp/plate-1/scene.yaml" || fail "plate: the default material.rho is not in scene.yaml"
grep -q '^  type: static$' "$tmp/plate-1/scene.yaml" || fail "plate: the default analysis.type is not in scene.yaml"
check modal "$ex/lamina/modal.yaml" -grid_spacing 0.02
check crack "$ex/fracture/edge_crack.yaml" -grid_spacing 0.04
check mesh "$ex/mesh/plate_hole.yaml" -analysis_type setup
grep -q "^  mesh: $(cd "$ex/mesh" && pwd)/plate_hole.geo\$" "$tmp/mesh-1/scene.yaml" || fail "mesh: particles.mesh is not absolute in scene.yaml: $(grep mesh: "$tmp/mesh-1/scene.yaml")"
check pulse "$ex/dynamics/pulse.yaml" -analysis_t_end 10
echo "ok: scene.yaml reproduces every run"
