"""Issue 39, item 6: a sweep of E on the 160,801-particle plate (examples/bench/plate_2d.yaml at its
default spacing) in one Problem: each point a set("material.E", E), which keeps the particles and
bonds, and a solve(). Prints, per point, the set()'s and the solve()'s wall time and their sum
against the bare solve (the first Problem's solve() alone, its set-up not counted), the median and
the worst of points 2..N; then, for reference, the first point's whole set-up (Problem()). Checks
that u scales as 1/E (bound 1e-10). A benchmark, not a test (docs/python.md, "Sweeps").

usage: /usr/bin/python3 tests/perf/python_sweep.py BUILD [POINTS [SPACING]]
  BUILD: the build directory (BUILD/python); POINTS default 12; SPACING default 1/401
"""
import os
import statistics
import sys
import time

build = os.path.abspath(sys.argv[1])
points = int(sys.argv[2]) if len(sys.argv) > 2 else 12
h = sys.argv[3] if len(sys.argv) > 3 else "1/401"
sys.path.insert(0, os.path.join(build, "python"))
import numpy as np  # noqa: E402
import perilin  # noqa: E402 (from the build named on the command line)

scene = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "bench", "plate_2d.yaml")
t0 = time.perf_counter()
p = perilin.Problem(scene, {"grid.spacing": h})
t1 = time.perf_counter()
r = p.solve()
t2 = time.perf_counter()
E0, u0, bare = p.get("material.E"), r.u.copy(), t2 - t1
print("%d particles: Problem() %.3f s (set-up), bare solve %.3f s" % (len(r.u), t1 - t0, bare))
print("point  E          set() s  solve() s  (set+solve)/bare  rebuilt  |u E/E0 - u0|/|u0|")
ratios = []
for k, E in enumerate(np.linspace(0.5, 2.0, points) * E0, start=2):
    a = time.perf_counter()
    p.set("material.E", E)
    b = time.perf_counter()
    u = p.solve().u
    c = time.perf_counter()
    err = np.abs(u * E / E0 - u0).max() / np.abs(u0).max()
    ratios.append((c - a) / bare)
    print("%5d  %.3e  %7.3f  %9.3f  %16.3f  %7s  %.2g" % (k, E, b - a, c - b, ratios[-1], p.rebuilt, err))
    if err > 1e-10 or p.rebuilt:
        sys.exit("FAILED: point %d: error %.2g, rebuilt %s" % (k, err, p.rebuilt))
p.close()
print("points 2..%d: (set+solve)/bare median %.3f, worst %.3f (target <= 1.2)" % (points + 1, statistics.median(ratios), max(ratios)))
