#!/usr/bin/env bash
# The run's pictures (issue 28 item 3, output.plots; docs/summary.md, "Pictures"):
#   1. a quasi-static, a modal (2D, shapes from particles.vtu) and the smallest anisotropy run each
#      write their PNG files into the output set: the PNG signature, a first IHDR chunk of
#      960 x 720 pixels (the size src/output/draw_plots.py sets) with a valid CRC, an IEND chunk;
#      summary.json's plots.files names exactly the PNG files in the set;
#   2. the same modal run on 2 ranks (the shapes from particles.pvtu's pieces);
#   3. -output_plots false writes none, and summary.json says enabled false;
#   4. no matplotlib (PERILIN_PYTHON naming an interpreter that is not there) and a plotter that
#      fails after writing half a file: the run still exits 0 with its other files, warns, writes
#      no PNG and no scratch directory, and summary.json's plots.error says why.
# usage: plots.sh PERILIN REPO_DIR MPIRUN...
set -u
exe=$1 repo=$2
shift 2
mpirun=("$@")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
unset PETSC_OPTIONS PERILIN_PYTHON PERILIN_PLOTS_SCRIPT
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
fail=0
bad() { echo "FAIL: $*"; fail=1; }
run() { # name scene options...
  local name=$1 scene=$2
  shift 2
  "$exe" "$repo/$scene" "$@" -output_dir "$tmp/$name" > "$tmp/$name.log" 2>&1 < /dev/null || { bad "perilin $scene $* exited $?"; cat "$tmp/$name.log"; }
}
# check OUTDIR "expected PNG names" (empty: none) [error]: the set's PNG files against summary.json
check() {
  python3 - "$@" <<'PY' || bad "$1"
import json, os, struct, sys, zlib
out, want = sys.argv[1], sorted(sys.argv[2].split())
error = sys.argv[3] if len(sys.argv) > 3 else None
have = sorted(f for f in os.listdir(out) if f.endswith(".png"))
assert have == want, "PNG files %s, expected %s" % (have, want)
assert not [f for f in os.listdir(out) if f.startswith("plots.tmp") or f.endswith(".tmp")], os.listdir(out)
for f in have:
    b = open(os.path.join(out, f), "rb").read()
    assert b[:8] == b"\x89PNG\r\n\x1a\n", "%s: no PNG signature" % f
    n, kind = struct.unpack(">I4s", b[8:16])
    assert kind == b"IHDR" and n == 13, (f, kind, n)
    w, h = struct.unpack(">II", b[16:24])
    assert (w, h) == (960, 720), "%s is %d x %d, not 960 x 720" % (f, w, h)
    assert struct.unpack(">I", b[29:33])[0] == zlib.crc32(b[12:29]), "%s: bad IHDR CRC" % f
    assert b[-8:-4] == b"IEND", "%s: no IEND at the end" % f
p = json.load(open(os.path.join(out, "summary.json")))["plots"]
assert sorted(p["files"]) == want, (p["files"], want)
assert p["enabled"] == (want != [] or error is not None), p
if error:
    assert error in p.get("error", ""), p
else:
    assert "error" not in p, p
print("ok: %s: %s" % (os.path.basename(out), ", ".join(want) or "no pictures"))
PY
}
an_small=(-analysis_m 2 -analysis_orientations 11 -analysis_criteria stretch,sliding)

# 1. one run of each kind
run qs examples/fracture/edge_crack.yaml -grid_spacing 0.04 -quiet
check "$tmp/qs" "load_displacement.png"
run modal tests/scenes/tiny_modal.yaml -output_vtk true
check "$tmp/modal" "modes.png"
run an examples/failure/anisotropy.yaml "${an_small[@]}"
check "$tmp/an" "anisotropy_envelope.png anisotropy_polar.png"
for f in anisotropy_polar.csv anisotropy_envelope.csv; do [ -s "$tmp/an/$f" ] || bad "no $f"; done
run dyn examples/dynamics/pulse.yaml -analysis_t_end 5 -output_vtk true
check "$tmp/dyn" "dynamics.png"

# 2. two ranks: rank 0 draws the shapes from the pieces
if [ ${#mpirun[@]} -gt 0 ]; then
  "${mpirun[@]}" "$exe" "$repo/examples/lamina/modal.yaml" -output_dir "$tmp/modal2" > "$tmp/modal2.log" 2>&1 < /dev/null || { bad "modal on 2 ranks exited $?"; cat "$tmp/modal2.log"; }
  check "$tmp/modal2" "modes.png"
fi

# 3. switched off
run off tests/scenes/tiny_modal.yaml -output_vtk true -output_plots false
check "$tmp/off" ""

# 4. no plotting library, and a plotter that fails half-way: a warning, never a failed run
PERILIN_PYTHON=/nonexistent/python3 run nopy examples/fracture/edge_crack.yaml -grid_spacing 0.04 -quiet
check "$tmp/nopy" "" "cannot run /nonexistent/python3"
grep -q "perilin: warning: no pictures drawn (output.plots): cannot run /nonexistent/python3" "$tmp/nopy.log" || bad "no warning without python: $(cat "$tmp/nopy.log")"
[ -s "$tmp/nopy/steps.csv" ] || bad "the run without python lost steps.csv"
cat > "$tmp/half.py" <<'PY'
import sys
open(sys.argv[3] + "/modes.png", "wb").write(b"\x89PNG\r\n")
sys.exit("drawing failed half-way")
PY
PERILIN_PLOTS_SCRIPT=$tmp/half.py run half tests/scenes/tiny_modal.yaml
check "$tmp/half" "" "drawing failed half-way"
[ -s "$tmp/half/modes.csv" ] || bad "the run whose plotter failed lost modes.csv"

exit $fail
