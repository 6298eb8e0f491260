"""Contact and impactors (issue 38, item 3) checked by conservation laws and a textbook collision,
from the output set (particles.vtu or .pvtu read by VTK, summary.json, history.csv).

usage: contact.py PERILIN SCENES_DIR TMP [MPIRUN...]

1. A free plate struck by a rigid disc (impact_momentum.yaml): no bc and no load, so the momentum of
   the particles and the impactor together is the impactor's initial M v0 at every step, to
   round-off (1e-12 relative): PETSc's velocity Verlet moves both with the same kick; the energy
   balance closes within the default 1 %, and halving dt cuts its drift by at least 3 (second
   order gives 4).
2. Two equal bars cut apart by a crack, the left one moving (contact_bars.yaml): with contact they
   collide and, as two equal elastic bars do (the wave crosses each bar once), the left one gives
   its momentum to the right one: at the end the right bar carries at least 95 % (tolerance: the
   penalty's finite stiffness leaves a few per cent behind) and the total is conserved to 1e-12;
   without contact the left bar keeps all of it (they pass through each other). On 2 ranks the
   same numbers to 1e-10. The implicit integrator at dt 1 (Jacobian-free Newton on the steps with
   contact): the same exchange, the total to 1e-8, the balance within 1 %.
3. A strip pulled at its left end at v = -0.001 (pulled_bar.yaml, bc velocity, issue 38 item 2):
   the grip has moved by v t exactly (1e-12); behind the wave front (c = 1) the particles move at
   v within 2 %, ahead of it (x > 40 at t = 30) they are at rest (|v| < 1 % of v); the balance,
   with the supports' work, closes within 1 %. On 2 ranks the same field to 1e-12. The implicit
   integrator (dt 0.5) the same, its balance to 1e-9 (the trapezoid of the reactions is exact).
4. Kalthoff-Winkler at dx = 2 mm (examples/dynamics/kalthoff_winkler.yaml, coarse): no bc, so the
   plate's and the punch's momentum stays the punch's M v0 (1e-12); the setup is symmetric about
   y = 0, so the two cracks leave their notch tips at angles within 3 degrees of each other, and
   forward (between 20 and 80 degrees from the notch; the experiment's is about 70, perilin's 44:
   docs/contact.md says why that is a miss); the balance within its default 1 % (the run fails
   otherwise). The same with the elastic projectile (kalthoff_winkler_elastic.yaml: a second body
   of the grid, grid.holes beside it, a crack between): the two bodies' momentum is the
   projectile's rho V v0 (1e-12); the cracks symmetric within 3 degrees and forward.
"""
import json
import os
import subprocess
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader

failures = 0


def check(ok, what):
    global failures
    print(("ok: " if ok else "FAIL: ") + what)
    failures += not ok


def run(exe, scene, out, mpirun=(), *opts):
    cmd = list(mpirun) + [exe, scene, "-output_dir", out, "-output_vtk", "true", "-quiet"] + list(opts)
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode:
        print(r.stdout)
        raise SystemExit("FAIL: %s exited %d" % (" ".join(cmd), r.returncode))
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def particles(out):
    """Positions, volumes and velocities of the output set's particles.vtu (or .pvtu)."""
    path = os.path.join(out, "particles.vtu")
    r = vtkXMLUnstructuredGridReader() if os.path.exists(path) else vtkXMLPUnstructuredGridReader()
    r.SetFileName(path if os.path.exists(path) else os.path.join(out, "particles.pvtu"))
    r.Update()
    g = r.GetOutput()
    a = lambda n: vtk_to_numpy(g.GetPointData().GetArray(n))
    return vtk_to_numpy(g.GetPoints().GetData()), a("volume"), a("velocity")


def momentum(out, rho, where=None):
    X, V, v = particles(out)
    keep = np.ones(len(V), bool) if where is None else where(X)
    return (rho * V[keep, None] * v[keep]).sum(axis=0)


def impact(exe, scenes, tmp):
    s = run(exe, os.path.join(scenes, "impact_momentum.yaml"), os.path.join(tmp, "impact"))
    imp = s["dynamic"]["impactors"][0]
    p = momentum(os.path.join(tmp, "impact"), s["material"]["rho"])[:2] + imp["mass"] * np.array(imp["velocity"])
    p0 = imp["mass"] * np.array([0.05, 0.01])
    err = np.abs(p - p0).max() / np.abs(p0).max()
    check(err < 1e-12, "impact: particles' + impactor's momentum %s, initial %s (relative error %.2g < 1e-12)" % (p, p0, err))
    check(np.abs(imp["velocity"][0] - 0.05) > 0.01, "impact: the impactor was slowed: v_x %.4g of 0.05" % imp["velocity"][0])
    d1 = s["dynamic"]["energy_drift"]
    s2 = run(exe, os.path.join(scenes, "impact_momentum.yaml"), os.path.join(tmp, "impact2"), (), "-analysis_dt", str(s["dynamic"]["dt"] / 2))
    d2 = s2["dynamic"]["energy_drift"]
    check(d1 <= 0.01 and d2 * 3 <= d1, "impact: energy drift %.3g at dt %g, %.3g at dt/2 (<= 1 %%, falls by >= 3)" % (d1, s["dynamic"]["dt"], d2))


def bars(exe, scenes, tmp, mpirun):
    scene = os.path.join(scenes, "contact_bars.yaml")
    left = lambda X: X[:, 0] < 20
    right = lambda X: X[:, 0] > 20
    total = 80 * 0.01
    s = run(exe, scene, os.path.join(tmp, "bars"))
    pl, pr = (momentum(os.path.join(tmp, "bars"), 1, w)[0] for w in (left, right))
    check(abs(pl + pr - total) < 1e-12 * total, "bars: total momentum %.15g, initial %g" % (pl + pr, total))
    check(pr >= 0.95 * total and pl <= 0.05 * total, "bars with contact: the right bar carries %.4g, the left %.4g of %g (an exchange)" % (pr, pl, total))
    check(s["dynamic"]["contact"]["list_builds"] >= 2, "bars: the candidate list followed the motion (%d builds)" % s["dynamic"]["contact"]["list_builds"])
    nocontact = os.path.join(tmp, "nocontact.yaml")
    with open(scene) as f, open(nocontact, "w") as g:
        g.write("".join(line for line in f if not line.startswith("contact:")))
    run(exe, nocontact, os.path.join(tmp, "through"))
    pl0 = momentum(os.path.join(tmp, "through"), 1, left)[0]
    check(abs(pl0 - total) < 1e-12, "bars without contact: the left bar keeps %.15g of %g (they pass through)" % (pl0, total))
    # implicit (dt 1, 0.9 explicit limits): contact has no Jacobian op, so the step's Newton is
    # Jacobian-free (differences of the residual, preconditioned by the bonds' J); the momentum is
    # conserved to the steps' tolerance and exchanged as in the explicit run. The momentum's error
    # is the Newton residual's impulse: 2.3e-8 at the default -snes_rtol 1e-8 (2e-9 before the
    # spring form's rounding), 3.8e-10 at 1e-9, 4.9e-12 at 1e-10, 9e-15 at 1e-11 (2026-11-29), so
    # the check runs at 1e-10 and asks for 1e-10
    s = run(exe, scene, os.path.join(tmp, "bars_implicit"), (), "-analysis_integrator", "implicit", "-analysis_dt", "1", "-snes_rtol", "1e-10")
    ql, qr = (momentum(os.path.join(tmp, "bars_implicit"), 1, w)[0] for w in (left, right))
    check(abs(ql + qr - total) < 1e-10 * total and qr >= 0.95 * total and s["dynamic"]["energy_drift"] <= 0.01,
          "bars, implicit dt 1: the right bar carries %.4g, the left %.4g of %g (total to %.2g); drift %.2g" % (qr, ql, total, abs(ql + qr - total) / total, s["dynamic"]["energy_drift"]))
    if mpirun:
        run(exe, scene, os.path.join(tmp, "bars2"), mpirun)
        ql, qr = (momentum(os.path.join(tmp, "bars2"), 1, w)[0] for w in (left, right))
        check(abs(ql - pl) < 1e-10 and abs(qr - pr) < 1e-10, "bars on 2 ranks: %.12g, %.12g; 1 rank %.12g, %.12g" % (ql, qr, pl, pr))
        # to t = 300 the bars move 2.6 apart, beyond the ghosts of the bonds' reach alone (a rank
        # would miss pairs: refused, naming contact.ghosts) but within the default contact.ghosts
        # (a horizon more): the same numbers as on one rank
        long = ("-analysis_t_end", "300")
        run(exe, scene, os.path.join(tmp, "bars300"), (), *long)
        run(exe, scene, os.path.join(tmp, "bars300_2"), mpirun, *long)
        a, b = (momentum(os.path.join(tmp, d), 1, right)[0] for d in ("bars300", "bars300_2"))
        check(abs(a - b) < 1e-10, "bars to t = 300 on 2 ranks (default contact.ghosts): the right bar's momentum %.12g, 1 rank %.12g" % (b, a))
        r = subprocess.run(list(mpirun) + [exe, scene, "-output_dir", os.path.join(tmp, "bars300_g0"), "-quiet", "-contact_ghosts", "0", *long], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        check(r.returncode != 0 and "contact.ghosts" in r.stdout and not os.path.exists(os.path.join(tmp, "bars300_g0")), "bars to t = 300 on 2 ranks with contact.ghosts 0: refused (%s)" % ([l for l in r.stdout.splitlines() if "perilin: error" in l] or ["no message"])[0][:200])


def motion(out):
    """Positions, displacements and velocities of the output set's particles.vtu."""
    X, _, vel = particles(out)
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(os.path.join(out, "particles.vtu"))
    r.Update()
    return X, vtk_to_numpy(r.GetOutput().GetPointData().GetArray("displacement")), vel


def pulled_one(exe, scene, out, what, drift, args=()):
    v, t = -0.001, 30
    s = run(exe, scene, out, (), *args)
    X, u, vel = motion(out)
    grip = X[:, 0] < 3
    check(np.abs(u[grip, 0] - v * t).max() < 1e-12 and np.abs(u[grip, 1]).max() == 0, "%s: the grip moved by %.15g (v t = %g)" % (what, u[grip, 0].mean(), v * t))
    behind = (X[:, 0] > 5) & (X[:, 0] < 15)
    ahead = X[:, 0] > 40
    check(abs(vel[behind, 0].mean() / v - 1) < 0.02, "%s: behind the front the particles move at %.5g (v = %g)" % (what, vel[behind, 0].mean(), v))
    check(np.abs(vel[ahead]).max() < 0.01 * abs(v), "%s: ahead of the front at most %.2g (< 1 %% of |v|)" % (what, np.abs(vel[ahead]).max()))
    check(s["dynamic"]["energy_drift"] <= drift and s["dynamic"]["work_of_loads"] > 0, "%s: energy drift %.3g (<= %g) with the supports' work %.4g" % (what, s["dynamic"]["energy_drift"], drift, s["dynamic"]["work_of_loads"]))
    return X, vel


def amplitudes(exe, scene, tmp):
    """bc.<k>.amplitude: the grip's velocity v a(t), its displacement v times a's integral."""
    v, t = -0.001, 30
    cases = (("ramp", "{shape: ramp, rise_time: 6}", v * (t - 3), v, (1e-12, 1e-12)),
             ("sine", "{shape: sine, period: 40}", v * 40 / (2 * np.pi) * (1 - np.cos(2 * np.pi * t / 40)), v * np.sin(2 * np.pi * t / 40), (5e-3, 5e-3)))
    for name, amp, u_exact, v_exact, (tol_u, tol_v) in cases:
        path = os.path.join(tmp, "pulled_%s.yaml" % name)
        with open(scene) as f, open(path, "w") as g:
            g.write(f.read().replace("velocity: [-0.001, 0]}", "velocity: [-0.001, 0], amplitude: %s}" % amp))
        for integ, args, drift, tu, tv in (("explicit", (), 0.01, tol_u, tol_v), ("implicit", ("-analysis_integrator", "implicit", "-analysis_dt", "0.5"), 1e-9, 1e-12, 1e-9 if name == "ramp" else 1e-3)):
            out = os.path.join(tmp, "pulled_%s_%s" % (name, integ))
            s = run(exe, path, out, (), *args)
            X, u, vel = motion(out)
            u, vel = u[X[:, 0] < 3, 0], vel[X[:, 0] < 3, 0]
            eu, ev = np.abs(u - u_exact).max() / abs(u_exact), np.abs(vel - v_exact).max() / abs(v_exact)
            check(eu <= tu and ev <= tv and s["dynamic"]["energy_drift"] <= drift,
                  "pulled, %s amplitude, %s: the grip at %.12g (exact %.12g, rel. error %.2g <= %g), moving at %.8g (exact %.8g, %.2g <= %g), drift %.2g <= %g"
                  % (name, integ, u.mean(), u_exact, eu, tu, vel.mean(), v_exact, ev, tv, s["dynamic"]["energy_drift"], drift))


def pulled(exe, scenes, tmp, mpirun):
    scene = os.path.join(scenes, "pulled_bar.yaml")
    X, vel = pulled_one(exe, scene, os.path.join(tmp, "pulled"), "pulled", 0.01)
    # implicit (average acceleration, dt 0.5): the grip's u = v t is in the residual, and the
    # change of the held DOFs' kinetic energy plus the trapezoid of the body's pull on them is the
    # supports' exact work in this scheme: the balance closes to the steps' solver tolerance
    # (measured 6e-13)
    pulled_one(exe, scene, os.path.join(tmp, "pulled_implicit"), "pulled, implicit", 1e-9, ("-analysis_integrator", "implicit", "-analysis_dt", "0.5"))
    amplitudes(exe, scene, tmp)
    if mpirun:
        run(exe, os.path.join(scenes, "pulled_bar.yaml"), os.path.join(tmp, "pulled2"), mpirun)
        X2, _, vel2 = particles(os.path.join(tmp, "pulled2"))
        a, b = np.lexsort(X.T[::-1]), np.lexsort(X2.T[::-1])
        check(np.abs(vel[a] - vel2[b]).max() < 1e-12, "pulled on 2 ranks: the velocities equal 1 rank's to %.2g" % np.abs(vel[a] - vel2[b]).max())


def kalthoff(exe, repo, tmp):
    out = os.path.join(tmp, "kw")
    s = run(exe, os.path.join(repo, "examples", "dynamics", "kalthoff_winkler.yaml"), out, (), "-grid_spacing", "2e-3")
    imp = s["dynamic"]["impactors"][0]
    p = momentum(out, s["material"]["rho"])[:2] + imp["mass"] * np.array(imp["velocity"])
    p0 = np.array([imp["mass"] * 32.0, 0.0])
    check(np.abs(p - p0).max() < 1e-12 * p0[0], "kalthoff: plate's + punch's momentum %s, M v0 %s" % (p, p0))
    r = subprocess.run([sys.executable, os.path.join(repo, "docs", "tools", "kw_angle.py"), out], cwd=repo, stdout=subprocess.PIPE, text=True)
    angles = [float(line.split()[-2]) for line in r.stdout.splitlines() if "angle" in line]
    check(len(angles) == 2 and abs(angles[0] - angles[1]) < 3 and all(20 < a < 80 for a in angles), "kalthoff: crack angles %s (symmetric within 3 degrees, forward)" % angles)


def kalthoff_elastic(exe, repo, tmp):
    """The elastic projectile (a second body of the same grid, cut off by a crack): the two
    bodies' momentum stays the projectile's rho V v0 (1e-12), the cracks are symmetric and forward."""
    out = os.path.join(tmp, "kwe")
    s = run(exe, os.path.join(repo, "examples", "dynamics", "kalthoff_winkler_elastic.yaml"), out, (), "-grid_spacing", "2e-3",
            # the holes' edges and the notches between rows of particles at 2 mm (y = 0.025 is one)
            "-grid_holes_0_lower", "-0.06,0.026", "-grid_holes_1_upper", "0,-0.026", "-cracks_1_from", "-0.001,0.026",
            "-cracks_1_to", "0.05,0.026", "-cracks_2_from", "-0.001,-0.026", "-cracks_2_to", "0.05,-0.026")
    X, V, _ = particles(out)
    p = momentum(out, s["material"]["rho"])[:2]
    p0 = np.array([s["material"]["rho"] * V[X[:, 0] < 0].sum() * 32.0, 0.0])
    check(np.abs(p - p0).max() < 1e-12 * p0[0], "kalthoff, elastic projectile: the two bodies' momentum %s, the projectile's rho V v0 %s" % (p, p0))
    r = subprocess.run([sys.executable, os.path.join(repo, "docs", "tools", "kw_angle.py"), out, "0.026"], cwd=repo, stdout=subprocess.PIPE, text=True)
    angles = [float(line.split()[-2]) for line in r.stdout.splitlines() if "angle" in line]
    check(len(angles) == 2 and abs(angles[0] - angles[1]) < 3 and all(20 < a < 80 for a in angles), "kalthoff, elastic projectile: crack angles %s (symmetric within 3 degrees, forward)" % angles)


def main():
    exe, scenes, tmp = sys.argv[1:4]
    mpirun = sys.argv[4:]
    impact(exe, scenes, tmp)
    bars(exe, scenes, tmp, mpirun)
    pulled(exe, scenes, tmp, mpirun)
    kalthoff(exe, os.path.dirname(os.path.dirname(os.path.abspath(scenes))), tmp)
    kalthoff_elastic(exe, os.path.dirname(os.path.dirname(os.path.abspath(scenes))), tmp)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
