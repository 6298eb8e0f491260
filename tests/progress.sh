#!/usr/bin/env bash
# The status line of long runs (issue 16, item 6; src/sys/progress.c):
#   - on a terminal (a pseudo-terminal from util-linux `script`) a line "perilin: N s | ..." with
#     the phase and the KSP iteration appears, overwritten with '\r', and is erased at the end;
#   - in a pipe, under -quiet, under -progress false, and under mpiexec into a pipe (Open MPI gives
#     the ranks a pseudo-terminal of their own), stdout has no '\r' and no status;
#   - the ordinary lines are the same on the terminal as in the pipe (numbers masked: timings).
# The static solve runs with Jacobi so that it lasts a few seconds (the line is drawn after 1 s).
# Usage: progress.sh PERILIN EXAMPLES_DIR [MPIEXEC...]. Exit 77 (skipped) without `script`.
set -u
exe=$1 ex=$2
shift 2
mpi=("$@")
command -v script > /dev/null || { echo "SKIP: util-linux 'script' is not installed: no terminal to test on"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
unset PETSC_OPTIONS
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
args="$ex/pmb/plate_traction.yaml -grid_spacing 1/400 -pc_type jacobi -output_vtk false"
fail=0

# stdout of a run on a pseudo-terminal: script's own output, '\r\n' from the terminal's line
# discipline; stdin from /dev/null so that script does not wait for input
tty_run() { script -qec "$exe $args $* -output_dir $tmp/out" /dev/null < /dev/null; }

tty_run > tty.txt 2>&1 || { echo "FAIL: perilin on a terminal exited $?"; cat tty.txt; exit 1; }
$exe $args -output_dir "$tmp/out" > pipe.txt 2> /dev/null < /dev/null || { echo "FAIL: perilin into a pipe exited $?"; exit 1; }
tty_run -quiet > quiet.txt 2>&1 || fail=1
tty_run -progress false > off.txt 2>&1 || fail=1
if [ ${#mpi[@]} -gt 0 ]; then
  "${mpi[@]}" $exe $args -output_dir "$tmp/out2" > mpi.txt 2> /dev/null < /dev/null || { echo "FAIL: mpiexec run exited $?"; fail=1; }
fi

python3 - "$fail" << 'PY'
import re, sys
fail = int(sys.argv[1])
# a drawing: the elapsed time, then the slots (none when a phase has just cleared them, which a
# redraw at that moment shows: seen on a loaded machine)
status = re.compile(r"\rperilin: \d+ s(?: \|[^\r\n]*)? *(?=[\r\n]|$)")
def read(name):
    with open(name, "rb") as f:
        return f.read().decode("utf-8", "replace")
def lines(text):
    """The ordinary lines: status drawings and their erasure removed, numbers masked."""
    text = text.replace("\r\n", "\n")
    text = status.sub("", text)
    text = re.sub(r"\r *\r?", "", text)
    return [re.sub(r"\d[\d.e+-]*", "#", l) for l in text.split("\n") if l.strip()]
def check(ok, what):
    global fail
    print(("ok: " if ok else "FAIL: ") + what)
    fail |= not ok
tty, pipe = read("tty.txt"), read("pipe.txt")
# a drawing shorter than the one before is written, blanked to the old length, and written again
# (src/sys/progress.c, Draw): one drawing
draws = status.findall(re.sub(r"\r(perilin: \d+ s[^\r\n]*?) +\r\1(?=[\r\n]|$)", r"\r\1", tty))
check(len(draws) >= 2, "%d status drawings on the terminal (at least 2: the solve lasts over 2 s)" % len(draws))
check(any("| solve | KSP iteration" in d and "residual norm" in d for d in draws), "the line shows the phase, the KSP iteration and the residual norm: %r" % (draws[-1] if draws else None))
check(all(len(d) <= 81 for d in draws), "every drawing fits an 80-column terminal")
times = [int(re.match(r"\rperilin: (\d+) s", d).group(1)) for d in draws]
check(times == sorted(set(times)), "at most one drawing per second (elapsed %s)" % times)
check("\r" not in pipe and "perilin: " in pipe and " s |" not in pipe, "a pipe gets no '\\r' and no status line")
check(lines(tty) == lines(pipe), "the terminal shows the pipe's lines, and nothing else, once the status is erased")
if lines(tty) != lines(pipe):  # what differed, and the terminal's raw bytes, to tell why
    import difflib
    print("\n".join(difflib.unified_diff(lines(pipe), lines(tty), "pipe", "terminal", lineterm="")))
    print("terminal, raw: %r" % tty)
for name, what in (("quiet.txt", "-quiet"), ("off.txt", "-progress false")):
    t = read(name)
    check(not status.search(t), "%s: no status line on the terminal" % what)
import os
if os.path.exists("mpi.txt"):
    m = read("mpi.txt")
    check("\r" not in m and not status.search(m) and "on 2 rank(s)" in m, "mpiexec -n 2 into a pipe: no status line (the ranks' pseudo-terminal is not the user's)")
sys.exit(1 if fail else 0)
PY
