"""One run of a scene from Python, as the command line does it: set up, solve, write the output set
(docs/python.md, "Overhead"). The Python half of tests/perf/python_overhead.sh.

usage: /usr/bin/python3 tests/perf/python_run.py SCENE OUTDIR [key=value ...]
"""
import sys

import perilin

scene, out = sys.argv[1:3]
overrides = dict(a.split("=", 1) for a in sys.argv[3:])
with perilin.Problem(scene, overrides) as p:
    p.solve()
    p.write(out)
