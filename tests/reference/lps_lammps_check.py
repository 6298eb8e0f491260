#!/usr/bin/python3
"""Independent re-computation of the LPS force densities and dilatations of a LAMMPS dump
written by tests/perf/lammps/lps_forces.in, from the formulas of docs/references/lammps_lps.md.

  tests/reference/lps_lammps_check.py lps_forces.dump [--E 200e9 --nu 0.3 --a 1e-3 --m 3.015]

Evaluates on the dump's lattice, with its displacement field:
  nonlinear: LAMMPS's own form (e = |xi + eta| - |xi|, force along the deformed bond);
  linear:    the linearized LPS (e = xi.eta/|xi|, force along the reference bond xi) that a
             small-displacement code (perilin) computes;
and prints the largest difference of each from the dump's theta and (fx, fy, fz), relative to
the largest |theta| and the largest |f| of the dump. The nonlinear form should agree to
roundoff (~1e-8, set by the absolute coordinates LAMMPS stores), the linear one to O(strain)
(about 1.4 times the largest displacement gradient). With --pe (LAMMPS's thermo pe of the run)
it also prints the energy sums that pe is compared with. Needs numpy (Debian's python3-numpy).
"""

import argparse
import sys

import numpy as np


def read_dump(path):
    with open(path) as f:
        lines = f.read().splitlines()
    head = next(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
    cols = lines[head].split()[2:]
    data = np.array([[float(v) for v in l.split()] for l in lines[head + 1:] if l.strip()])
    return {c: data[:, k] for k, c in enumerate(cols)}


def lps(X, U, a, delta, K, G, V, linear):
    """X, U: (nx, ny, nz, 3) reference positions and displacements on a simple-cubic lattice.
    Returns theta (nx,ny,nz), f (nx,ny,nz,3) force densities, m (nx,ny,nz)."""
    shape = X.shape[:3]
    Y = X + U
    nmax = int(np.floor(delta / a))
    offsets = []
    for i in range(-nmax, nmax + 1):
        for j in range(-nmax, nmax + 1):
            for k in range(-nmax, nmax + 1):
                if (i, j, k) == (0, 0, 0):
                    continue
                if (i * i + j * j + k * k) * a * a <= delta * delta * (1 + 1e-12):
                    offsets.append((i, j, k))

    def pairs(o):
        src = []
        dst = []
        for d in range(3):
            n = shape[d]
            lo = max(0, -o[d])
            hi = n - max(0, o[d])
            src.append(slice(lo, hi))
            dst.append(slice(lo + o[d], hi + o[d]))
        return tuple(src), tuple(dst)

    m = np.zeros(shape)
    tsum = np.zeros(shape)
    bonds = []
    for o in offsets:
        s, d = pairs(o)
        xi = X[d] - X[s]
        r0 = np.sqrt((xi * xi).sum(-1))
        vfs = np.where(np.abs(r0 - delta) <= 0.5 * a, (delta + 0.5 * a - r0) / a, 1.0)
        w = 1.0 / r0
        y = Y[d] - Y[s]
        r = np.sqrt((y * y).sum(-1))
        if linear:
            eta = U[d] - U[s]
            e = (xi * eta).sum(-1) / r0
            M = xi / r0[..., None]
        else:
            e = r - r0
            M = y / r[..., None]
        m[s] += w * r0 * r0 * V * vfs
        tsum[s] += w * r0 * e * V * vfs
        bonds.append((s, d, r0, vfs, w, e, M))
    theta = 3.0 * tsum / m
    f = np.zeros(shape + (3,))
    wdev = np.zeros(shape)
    for (s, d, r0, vfs, w, e, M) in bonds:
        ed = e - theta[s] * r0 / 3.0
        wdev[s] += 15.0 * G / (2.0 * m[s]) * w * ed * ed * V * vfs
        mi = m[s]
        mj = m[d]
        ti = theta[s]
        tj = theta[d]
        # t[x_i]<xi> - t[x_j]<-xi>, both along M, with w(xi) = w(-xi)
        mag = V * vfs * w * ((3 * K - 5 * G) * (ti / mi + tj / mj) * r0 + 15 * G * (1 / mi + 1 / mj) * e)
        f[s] += mag[..., None] * M
    # LPS strain energy density W_i = K theta^2 / 2 + (15 G / 2 m) sum w (e^d)^2 V vfs
    return theta, f, m, 0.5 * K * theta * theta, wdev


def main():
    p = argparse.ArgumentParser()
    p.add_argument("dump")
    p.add_argument("--E", type=float, default=200e9)
    p.add_argument("--nu", type=float, default=0.3)
    p.add_argument("--a", type=float, default=1e-3)
    p.add_argument("--m", type=float, default=3.015, help="horizon / a")
    p.add_argument("--pe", type=float, help="LAMMPS's thermo pe of the same run, to compare")
    args = p.parse_args()
    d = read_dump(args.dump)
    a = args.a
    K = args.E / (3 * (1 - 2 * args.nu))
    G = args.E / (2 * (1 + args.nu))
    delta = args.m * a
    V = a ** 3
    ijk = np.rint(np.stack([d["v_x0"], d["v_y0"], d["v_z0"]], 1) / a).astype(int)
    ijk -= ijk.min(0)
    shape = tuple(ijk.max(0) + 1)
    if np.prod(shape) != len(ijk):
        sys.exit("not a full box lattice: %s sites for shape %s" % (len(ijk), shape))
    X = np.zeros(shape + (3,))
    U = np.zeros(shape + (3,))
    F = np.zeros(shape + (3,))
    T = np.zeros(shape)
    idx = (ijk[:, 0], ijk[:, 1], ijk[:, 2])
    X[idx] = np.stack([d["v_x0"], d["v_y0"], d["v_z0"]], 1)
    U[idx] = np.stack([d["c_dsp[1]"], d["c_dsp[2]"], d["c_dsp[3]"]], 1)
    F[idx] = np.stack([d["fx"], d["fy"], d["fz"]], 1)
    T[idx] = d["c_dil"]
    print("lattice %s, a = %g, delta = %g a, K = %.6g, G = %.6g, max |u| = %.3g m" %
          (shape, a, args.m, K, G, np.abs(U).max()))
    for linear in (False, True):
        theta, f, m, wvol, wdev = lps(X, U, a, delta, K, G, V, linear)
        if not linear:
            wv, wd = wvol.sum(), wdev.sum()
        dt = np.abs(theta - T).max() / np.abs(T).max()
        df = np.abs(f - F).max() / np.abs(F).max()
        print("  %-9s max |theta - lammps| / max |theta| = %.3e,  max |f - lammps| / max |f| = %.3e"
              % ("linear" if linear else "nonlinear", dt, df))
    interior = tuple(np.array(shape) // 2)
    print("  m at the centre site %s = %.12g a^4; at the corner = %.12g a^4 (m in m^4; the full"
          " family of 122 bonds, delta = 3.015a: 230.933410618 a^4)" %
          (interior, m[interior] / a ** 4, m[0, 0, 0] / a ** 4))
    print("  max |f| = %.6g N/m^3, max |theta| = %.6g" % (np.abs(F).max(), np.abs(T).max()))
    print("  sum_i W_i (LPS energy densities, J/m^3) = %.12g = %.12g (dilatational) + %.12g "
          "(deviatoric); sum_i W_i V_i = %.6g J" % (wv + wd, wv, wd, (wv + wd) * V))
    print("  sum of the dilatational part and half the deviatoric part = %.12g" % (wv + 0.5 * wd))
    if args.pe is not None:
        print("  LAMMPS pe = %.12g" % args.pe)


if __name__ == "__main__":
    main()
