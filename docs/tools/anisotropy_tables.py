#!/usr/bin/env python3
"""Diana & Casolo, Tables 7 and 8 (failure anisotropy of the unit cell), recomputed independently
of perilin: the groundwork for issue 15, item 4, which asks perilin itself to write them.

A unit cell of the square lattice (the family of one particle: the bonds n = (i, j) with
|n| <= m, no partial-volume extension) under the homogeneous stretch F = Q diag(1 + s1, 1 + s2) Q^T
(eq. 68-70), rotated by Theta. The error of one orientation is the load factor at which the first
bond reaches its limit over the factor at which the principal measure does, minus one; e_max is its
largest value over the orientations. What reproduces Table 7 to every printed digit:
  - the linearized bond stretch s = e . (F - I) e;
  - the compressive limit s0c = -3 s0t (the rows with s1 = -3);
  - Theta in steps of 0.9 degrees over [0, 90] (101 orientations; the paper says "one hundred").
Table 8 (maximum sliding, nu = 0: gamma0 = s0t / 2) with the linearized shear angle
e_perp . (F - I) e gives 41.42 / 11.38 / 5.15 / 5.15 / 2.92 % where the paper prints
41.48 / 11.46 / 5.23 / 5.23 / 3.00 %: its sliding measure differs from the linearized one by
about 0.06-0.08 percentage points (a finite-deformation measure is the likely cause; not settled).

    python3 docs/tools/anisotropy_tables.py
"""
import math

M = (2, 3, 3.2, 4, 5)
STEP = 0.9  # degrees
S0C = -3.0  # compressive stretch limit, in units of s0t


def directions(m):
    r = int(math.floor(m))
    return sorted({math.atan2(j, i) for i in range(-r, r + 1) for j in range(-r, r + 1) if (i or j) and i * i + j * j <= m * m + 1e-12})


def factor(values):
    """the load factor at which the first of these stretches reaches s0t = 1 or S0C"""
    lam = math.inf
    for v in values:
        if v > 1e-15:
            lam = min(lam, 1.0 / v)
        elif v < -1e-15:
            lam = min(lam, S0C / v)
    return lam


def e_max_stretch(s1, s2, m):
    exact, worst = factor([s1, s2]), 0.0
    for k in range(int(round(90 / STEP)) + 1):
        th = -math.radians(k * STEP)
        worst = max(worst, factor([s1 * math.cos(p - th) ** 2 + s2 * math.sin(p - th) ** 2 for p in directions(m)]) / exact - 1)
    return 100 * worst


def e_max_sliding(s1, s2, m):
    exact, worst = abs(s2 - s1) / 2, 0.0
    for k in range(int(round(90 / STEP)) + 1):
        th = -math.radians(k * STEP)
        seen = max(abs((s2 - s1) * math.sin(p - th) * math.cos(p - th)) for p in directions(m))
        worst = max(worst, exact / seen - 1)
    return 100 * worst


def main():
    print("Table 7 (maximum stretch), e_max in % for m =", ", ".join(map(str, M)))
    for s1, s2 in ((1, 1), (0.5, 1), (0, 1), (-1, 1), (-2, 1), (-3, 1), (-3, 0), (-3, -1.5), (-3, -3)):
        print(f"  {s1:5g} {s2:5g}  " + "  ".join(f"{e_max_stretch(s1, s2, m):6.2f}" for m in M))
    print("Table 8 (maximum sliding, linearized shear angle), e_max in %")
    for s1, s2 in ((0.5, 1), (0, 1), (-0.33, 0.66), (-0.5, 0.5), (-0.66, 0.33), (-1, 0), (-1, -0.5)):
        print(f"  {s1:5g} {s2:5g}  " + "  ".join(f"{e_max_sliding(s1, s2, m):6.2f}" for m in M))


if __name__ == "__main__":
    main()
