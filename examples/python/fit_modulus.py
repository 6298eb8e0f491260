"""Young's modulus fitted to a measured displacement field with scipy.optimize, the model solved
in-process at every evaluation (docs/python.md).

The "measurement" is made here: the plate in traction (examples/pmb/plate_traction.yaml, 0.02 m
spacing) solved with a known E_true = 1.3e9 Pa gives u_meas (every particle's ux, uy). The fit
starts from E0 = 2 E_true (a poor guess) and minimizes the misfit ||u(E) - u_meas|| / ||u_meas||
with scipy.optimize.least_squares over s = E / E0 (each evaluation: set('material.E', E), solve()).
It must recover E_true to 1e-6 (relative); it exits 1 otherwise.

usage: /usr/bin/python3 examples/python/fit_modulus.py [SCENE]   (a scene whose loads set u)
"""
import os
import sys

import numpy as np
from scipy.optimize import least_squares

import perilin

scene = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "pmb", "plate_traction.yaml")
E_true = 1.3e9

with perilin.Problem(scene, {"grid.spacing": 0.02, "material.E": E_true, "output.plots": False}) as p:
    u_meas = p.solve().u.ravel().copy()
    scale = np.linalg.norm(u_meas)
    E0 = 2 * E_true
    evaluations = []

    def misfit(s):
        E = s[0] * E0
        p.set("material.E", E)  # the problem is set up again with the new modulus (docs/python.md)
        evaluations.append(E)
        return (p.solve().u.ravel() - u_meas) / scale

    fit = least_squares(misfit, x0=[1.0], bounds=([1e-3], [1e3]), xtol=1e-14, ftol=1e-14, gtol=1e-14)
    E_fit = fit.x[0] * E0
    rel = abs(E_fit - E_true) / E_true
    if p.comm.getRank() == 0:
        print("E_true %.10g Pa, start %.10g Pa, fitted %.10g Pa: relative error %.2g (<= 1e-6)" % (E_true, E0, E_fit, rel))
        print("%d evaluations (solves), final misfit %.2g; %s" % (len(evaluations), np.linalg.norm(fit.fun), fit.message))
        print("ok" if rel <= 1e-6 else "FAIL")
sys.exit(0 if rel <= 1e-6 else 1)
