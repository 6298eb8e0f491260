"""set() without rebuilding (issue 39 items 1-3, docs/python.md "set()"): material, loads, bc,
analysis and solver keys keep the particles and bonds (the same bond storage, self.rebuilt False)
and give the same u as a new Problem with that override; geometry keys and scenes whose bonds a run
breaks build them anew; a failed set() leaves the problem as it was. Exits 77 (skipped) when
/usr/bin/python3 cannot import perilin.

usage: python_set.py REPO
"""
import os
import sys

try:
    import numpy as np
    import perilin
except ImportError as e:
    print("SKIP: cannot import perilin (%s)" % e)
    sys.exit(77)

repo = sys.argv[1]
plate = os.path.join(repo, "examples/pmb/plate_traction.yaml")
small = {"grid.spacing": 0.02}
failures = []


def check(what, ok, value=""):
    print("%-72s %s %s" % (what, "ok" if ok else "FAILED", value))
    if not ok:
        failures.append(what)


def rel(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


def fresh_u(scene, overrides):
    with perilin.Problem(scene, overrides) as q:
        return q.solve().u, q.scene()


# material.E: u halves, the bonds are the same storage
p = perilin.Problem(plate, small)
u1 = p.solve().u
bonds = p._bonds()
E = p.get("material.E")
p.set("material.E", 2 * E)
check("set('material.E', 2E): no rebuild", not p.rebuilt and p._bonds() == bonds)
d = rel(2 * p.solve().u, u1)
check("set('material.E', 2E): u halves (bound 1e-12)", d <= 1e-12, "%.2g" % d)
u_fresh, scene_fresh = fresh_u(plate, dict(small, **{"material.E": 2 * E}))
d = rel(p.solve().u, u_fresh)
check("... and equals a new Problem's with that override (bound 1e-12)", d <= 1e-12, "%.2g" % d)
check("... and its resolved scene is the new Problem's", p.scene() == scene_fresh)

# a load value
p.set("loads.0.traction", [3.0e6, 0])
u_fresh, scene_fresh = fresh_u(plate, dict(small, **{"material.E": 2 * E, "loads.0.traction": [3.0e6, 0]}))
d = rel(p.solve().u, u_fresh)
check("set('loads.0.traction', ..): no rebuild; u of a new Problem (bound 1e-12)", not p.rebuilt and p._bonds() == bonds and d <= 1e-12, "%.2g" % d)
check("... and its resolved scene is the new Problem's", p.scene() == scene_fresh)

# a failing set() changes nothing: the next one still reuses the same bonds
before = p.solve().u
try:
    p.set("material.E", -1)
    check("set('material.E', -1) raises", False)
except perilin.Error as e:
    check("set('material.E', -1) raises perilin.Error naming the key", "material.E" in str(e))
p.set("solver.residual_tol", 1e-7)
d = rel(p.solve().u, before)
check("after it, set('solver.residual_tol'): same bonds, same u (bound 1e-10)", not p.rebuilt and p._bonds() == bonds and d <= 1e-10, "%.2g" % d)

# a geometry key builds the particles and bonds anew
p.set("grid.spacing", 0.01)
check("set('grid.spacing', ..) rebuilds", p.rebuilt and p._bonds()[1] != bonds[1])
p.close()

# a bc value: the plate pulled by a prescribed ux on its right side instead of a load
scene = {
    "dim": 2,
    "model": {"type": "pmb", "plane": "stress"},
    "material": {"E": 1.0e9, "thickness": 0.01},
    "grid": {"lower": [0, 0], "upper": [1.0, 0.5], "spacing": 0.02},
    "horizon": {"m": 3},
    "regions": {"left": {"side": "x-"}, "right": {"side": "x+"}, "pin": {"lower": [0, 0.23], "upper": [0.05, 0.27]}},
    "bc": [{"region": "left", "fix": ["ux"]}, {"region": "pin", "fix": ["uy"]}, {"region": "right", "value": {"ux": 1.0e-4}}],
}
p = perilin.Problem(scene)
p.solve()
bonds = p._bonds()
p.set("bc.2.value.ux", 3.0e-4)
u_fresh, scene_fresh = fresh_u(scene, {"bc.2.value.ux": 3.0e-4})
d = rel(p.solve().u, u_fresh)
check("set('bc.2.value.ux', ..): no rebuild; u of a new Problem (bound 1e-12)", not p.rebuilt and p._bonds() == bonds and d <= 1e-12, "%.2g" % d)
# the scene dict goes to a temporary file of its own per Problem: its default output.dir differs
mine, theirs = p.scene(), scene_fresh
mine["output"].pop("dir"), theirs["output"].pop("dir")
check("... and its resolved scene is the new Problem's (output.dir aside)", mine == theirs)
p.close()

# modal: material.rho four times: the frequencies halve, the bonds stay
lamina = os.path.join(repo, "examples/lamina/modal.yaml")
with perilin.Problem(lamina, {"grid.spacing": 0.02}) as q:
    f1 = q.modes().frequencies
    bonds = q._bonds()
    q.set("material.rho", 4 * q.get("material.rho"))
    f2 = q.modes().frequencies
    d = np.abs(2 * f2 - f1).max() / f1.max()
    check("modal: set('material.rho', 4 rho): no rebuild, frequencies halve (bound 1e-8)", not q.rebuilt and q._bonds() == bonds and d <= 1e-8, "%.2g" % d)

# a scene with failure (its bonds break in the run) builds them anew
bar = os.path.join(repo, "examples/antiplane/cracked_bar.yaml")
with perilin.Problem(bar, {"grid.spacing": 0.025}) as q:
    q.solve()
    q.set("material.mu", 2 * q.get("material.mu"))
    check("failure scene: set() rebuilds (its bonds carry the run's breaks)", q.rebuilt)

print("%d checks failed" % len(failures) if failures else "all checks passed")
sys.exit(1 if failures else 0)
