"""No leak across Problems (issue 39, docs/python.md): in one process, 100 problems of a small plate
(examples/pmb/plate_traction.yaml at 0.02 m, 1,250 particles) are created, solved, their K,
matrix-free operator, f and mass matrix taken and used in petsc4py arithmetic (whose temporaries
Python drops without destroy(): close() has petsc4py free them), and closed, each beside a Problem
that fails on a misspelt key; after a warm-up of 10 the resident memory (/proc/self/statm) must
stay within 5 % of what it was (a problem that kept one 2,500-DOF vector would add 2 %; before
close() cleaned petsc4py's garbage, this loop grew 10 %). Exits 77 (skipped) when /usr/bin/python3
cannot import perilin.

usage: python_leak.py REPO
"""
import os
import sys
import time

try:
    import perilin
except ImportError as e:
    print("SKIP: cannot import perilin (%s)" % e)
    sys.exit(77)

repo = sys.argv[1]
plate = os.path.join(repo, "examples/pmb/plate_traction.yaml")
overrides = {"grid.spacing": 0.02, "material.rho": 7800}
page_mb = os.sysconf("SC_PAGE_SIZE") / 2**20


def resident_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * page_mb


def one():
    with perilin.Problem(plate, overrides) as p:
        r = p.solve()
        K, A, f, M = p.stiffness(), p.operator(), p.rhs(), p.mass(as_matrix=True)
        y = A * f + K * f + M * f
        assert r.u.shape == (1250, 2) and y.norm() > 0
    try:
        perilin.Problem(plate, {"materal.E": 1})
    except perilin.Error:
        pass


t0 = time.time()
for _ in range(10):
    one()
warm = resident_mb()
for k in range(100):
    one()
    if k == 49:
        half = resident_mb()
end = resident_mb()
growth = (end - warm) / warm
print("resident memory after 10 problems (warm-up) %.1f MB, after 60 %.1f MB, after 110 %.1f MB: %+.2f %% (bound 5 %%), %.1f s" % (warm, half, end, 100 * growth, time.time() - t0))
print("ok" if growth <= 0.05 else "FAIL")
sys.exit(0 if growth <= 0.05 else 1)
