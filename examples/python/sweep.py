"""The speed/accuracy trade of the horizon ratio m and the spacing dx on the plate in uniaxial
traction (examples/pmb/plate_traction.yaml), from Python: each point is a Problem set up and solved
in this process, timed, and its error measured against the closed form (docs/python.md).

The reference: away from its ends the plate is in uniform uniaxial stress sigma = 1e6 Pa
(loads.0.traction), so the continuum's strain between the probes a (x = 0.305) and b (x = 0.705)
on the mid-line is eps_xx = sigma / E = 1e-3 (plane stress, E = 1e9 Pa). The error of a run is
|eps - sigma/E| / (sigma/E) with eps = (u_x(b) - u_x(a)) / (x_b - x_a) at the particles the
probes sample (summary.json's probes: the nearest particle).

usage: /usr/bin/python3 examples/python/sweep.py [FIGURE]   (default /tmp/perilin-sweep.png)
Prints a table (dx, m, particles, seconds, strain, error) and writes the figure: error against
wall time, one line per m, each point a spacing.
"""
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")  # a file, no display
import matplotlib.pyplot as plt

import perilin

figure = sys.argv[1] if len(sys.argv) > 1 else "/tmp/perilin-sweep.png"
plate = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "pmb", "plate_traction.yaml")
spacings = (0.02, 0.01, 0.005, 0.0025)
ratios = (2, 3, 4, 6)

points = []  # (dx, m, particles, seconds, strain, error)
with perilin.Problem(plate, {"output.plots": False}) as p:
    exact = p.get("loads.0.traction")[0] / p.get("material.E")
    rank0 = p.comm.getRank() == 0
if rank0:
    print("reference: eps_xx = sigma / E = %.6g between probes a and b" % exact)
    print("%8s %3s %9s %9s %12s %9s" % ("dx", "m", "particles", "seconds", "strain", "error"))
for m in ratios:
    for dx in spacings:
        t0 = time.perf_counter()
        with perilin.Problem(plate, {"grid.spacing": dx, "horizon.m": m, "output.plots": False}) as p:
            r = p.solve()  # the set-up (particles, bonds) and the solve, timed together
        seconds = time.perf_counter() - t0
        a, b = r.summary["probes"]["a"], r.summary["probes"]["b"]
        strain = (b["u"][0] - a["u"][0]) / (b["particle_x"][0] - a["particle_x"][0])
        points.append((dx, m, r.summary["particles"], seconds, strain, abs(strain - exact) / exact))
        if rank0:
            print("%8g %3d %9d %9.3f %12.6g %9.2e" % points[-1], flush=True)

if rank0:
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for m in ratios:
        mine = [q for q in points if q[1] == m]
        ax.loglog([q[3] for q in mine], [q[5] for q in mine], "o-", label="m = %d" % m)
        for q in mine:
            ax.annotate("%g" % q[0], (q[3], q[5]), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlabel("wall time of set-up and solve (s)")
    ax.set_ylabel("relative error of eps_xx against sigma/E")
    ax.set_title("plate in traction (pmb); labels: dx (m)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(figure, dpi=120)
    print("figure: %s" % figure)
