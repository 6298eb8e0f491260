"""Issue 39, item 6, within one Python session: the wall time of a run in-process (Problem(), solve(),
write(): the import of perilin, petsc4py and numpy paid once, before) against the same run by the
command line as a whole process, in pairs taken in turn (command line, Python, ...); prints each
pair and the medians. A benchmark, not a test (docs/python.md, "Overhead").

usage: /usr/bin/python3 tests/perf/python_inprocess.py BUILD [PAIRS [SPACING]]
  BUILD: the build directory (BUILD/perilin, BUILD/python); PAIRS default 7; SPACING of
  examples/bench/plate_2d.yaml, default 1/401 (160,801 particles)
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

build = os.path.abspath(sys.argv[1])
pairs = int(sys.argv[2]) if len(sys.argv) > 2 else 7
h = sys.argv[3] if len(sys.argv) > 3 else "1/401"
sys.path.insert(0, os.path.join(build, "python"))
import perilin  # noqa: E402 (from the build named on the command line)

scene = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "bench", "plate_2d.yaml")
work = tempfile.mkdtemp()
cli, py = [], []
for k in range(pairs + 1):  # pair 0 warms the caches, not counted
    t0 = time.perf_counter()
    subprocess.run([os.path.join(build, "perilin"), scene, "-grid_spacing", h, "-quiet", "-output_dir", os.path.join(work, "cli")], check=True, stdout=subprocess.DEVNULL)
    t1 = time.perf_counter()
    with perilin.Problem(scene, {"grid.spacing": h}) as p:
        p.solve()
        p.write(os.path.join(work, "py"))
    t2 = time.perf_counter()
    if k:
        cli.append(t1 - t0)
        py.append(t2 - t1)
        print("pair %d: command line (whole process) %.3f s, in-process run %.3f s" % (k, cli[-1], py[-1]), flush=True)
r = [b / a for a, b in zip(cli, py)]
print("medians: command line %.3f s, in-process %.3f s; in-process / command line, median of the pairs' ratios %.3f (min %.3f, max %.3f)" % (statistics.median(cli), statistics.median(py), statistics.median(r), min(r), max(r)))
subprocess.run(["rm", "-rf", work])
