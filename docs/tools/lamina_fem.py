#!/usr/bin/env python3
"""Converged plane-stress FEM frequencies of Diana & Casolo's cantilever lamina (sec. 3.1), the
reference the modal tables of docs/modal.md compare with besides the paper's FEM column.

The body of examples/lamina/modal.yaml above its clamp: 0.6 m wide, 0.57 m high, clamped (ux = uy
= 0) along its bottom edge, E = 70 GPa, rho = 2500 kg/m^3, plane stress. Biquadratic (Q9)
elements, consistent mass, 3 x 3 Gauss points; the mesh is refined until the first three
frequencies change by less than 1e-5 (Richardson's extrapolation is printed too). A mode is
axial or flexural by the rule of perilin's modal analysis (its effective mass along y or across
it; by its kinetic energy when it moves no net mass); f_I is the first flexural, f_II the first
axial, f_III the second flexural, as in docs/modal.md.

    /usr/bin/python3 docs/tools/lamina_fem.py        (needs Debian's python3-scipy; about a minute)

An independent computation: no perilin code or output is used.
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

E, RHO, W, H = 70e9, 2500.0, 0.6, 0.57
G1D = (np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)]), np.array([5.0, 8.0, 5.0]) / 9.0)


def shape_1d(x):
    """Quadratic Lagrange functions on [-1, 1] (nodes -1, 0, 1) and their derivatives."""
    n = np.array([0.5 * x * (x - 1), 1 - x * x, 0.5 * x * (x + 1)])
    d = np.array([x - 0.5, -2 * x, x + 0.5])
    return n, d


def element_matrices(hx, hy, nu):
    """Stiffness and consistent mass of one Q9 element of size hx x hy (unit thickness); DOFs
    ordered (ux, uy) per node, nodes a + 3 b for a, b in 0..2 along x, y."""
    c = E / (1 - nu * nu) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])
    ke, me = np.zeros((18, 18)), np.zeros((18, 18))
    for gx, wx in zip(*G1D):
        for gy, wy in zip(*G1D):
            nx, dx = shape_1d(gx)
            ny, dy = shape_1d(gy)
            n = np.outer(ny, nx).ravel()                   # node a + 3 b: nx[a] ny[b]
            dndx = np.outer(ny, dx).ravel() * 2 / hx
            dndy = np.outer(dy, nx).ravel() * 2 / hy
            b = np.zeros((3, 18))
            b[0, 0::2], b[1, 1::2] = dndx, dndy
            b[2, 0::2], b[2, 1::2] = dndy, dndx
            jw = wx * wy * hx * hy / 4
            ke += jw * b.T @ c @ b
            nn = np.zeros((2, 18))
            nn[0, 0::2], nn[1, 1::2] = n, n
            me += jw * RHO * nn.T @ nn
    return ke, me


def frequencies(ex, ey, nu, nev=8):
    """The nev lowest frequencies (Hz) and kinds of the ex x ey Q9 mesh."""
    nxn, nyn = 2 * ex + 1, 2 * ey + 1
    ke, me = element_matrices(W / ex, H / ey, nu)
    rows, cols, kv, mv = [], [], [], []
    for j in range(ey):
        for i in range(ex):
            nodes = [(2 * j + b) * nxn + 2 * i + a for b in range(3) for a in range(3)]
            dofs = np.array([[2 * n, 2 * n + 1] for n in nodes]).ravel()
            rows.append(np.repeat(dofs, 18))
            cols.append(np.tile(dofs, 18))
            kv.append(ke.ravel())
            mv.append(me.ravel())
    nd = 2 * nxn * nyn
    r, c = np.concatenate(rows), np.concatenate(cols)
    k = sp.csr_matrix((np.concatenate(kv), (r, c)), shape=(nd, nd))
    m = sp.csr_matrix((np.concatenate(mv), (r, c)), shape=(nd, nd))
    free = np.arange(2 * nxn, nd)  # the bottom row of nodes (y = 0) is clamped
    k, m = k[free][:, free], m[free][:, free]
    lam, vec = sla.eigsh(k, nev, m, sigma=0, which="LM")
    order = np.argsort(lam)
    lam, vec = lam[order], vec[:, order]
    kinds = []
    rx, ry = np.zeros(len(free)), np.zeros(len(free))
    rx[0::2], ry[1::2] = 1, 1  # unit translations; the free DOFs keep the (ux, uy) alternation
    total = RHO * W * H
    for q in range(nev):
        v = vec[:, q]
        mv = m @ v
        norm = v @ mv
        ex, ey = (rx @ mv) ** 2 / norm / total, (ry @ mv) ** 2 / norm / total
        ux, uy = v * rx, v * ry
        # as perilin's modal analysis: by effective mass along the axis (y) or across it, else
        # by where the kinetic energy is
        axial = ey > ex if max(ex, ey) > 1e-3 else uy @ (m @ uy) > 0.5 * (v @ mv)
        kinds.append("axial" if axial else "flexural")
    return np.sqrt(lam) / (2 * np.pi), kinds


def three(f, kinds):
    flex = [x for x, k in zip(f, kinds) if k == "flexural"]
    axial = [x for x, k in zip(f, kinds) if k == "axial"]
    return np.array([flex[0], axial[0], flex[1]])


def main():
    print("| nu | mesh (Q9) | f_I | f_II | f_III |")
    print("|---|---|---|---|---|")
    for nu, label in ((-0.5, "-0.5"), (0.0, "0"), (0.1, "0.1"), (0.25, "0.25"), (1 / 3, "1/3")):
        prev = None
        for ex in (10, 20, 40, 80):
            ey = round(ex * H / W)
            f3 = three(*frequencies(ex, ey, nu))
            print(f"| {label} | {ex} x {ey} | {f3[0]:.2f} | {f3[1]:.2f} | {f3[2]:.2f} |")
            if prev is not None and np.max(np.abs(f3 / prev - 1)) < 1e-5:
                break
            prev = f3
        if prev is not None:
            rich = f3 + (f3 - prev) / 15  # fourth order in h for the frequencies of Q9 elements
            print(f"| {label} | extrapolated | {rich[0]:.2f} | {rich[1]:.2f} | {rich[2]:.2f} |")


if __name__ == "__main__":
    main()
