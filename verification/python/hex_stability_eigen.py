"""Critical time step of lumped-mass hexahedral meshes against the estimate L / c.

    python hex_stability_eigen.py

Assembles the small-strain stiffness K of a regular mesh of unit cubes (one-point mean-gradient
integration without hourglass control, or 2x2x2 Gauss integration), lumps the mass (rho h^3 / 8
per element corner), and prints dt_crit / (h / c) = 2 / sqrt(max eig(M^-1 K)) / (h / c),
c = sqrt((lambda + 2 mu) / rho), for a range of Poisson ratios, next to the fitted factor
kappa = sqrt(M / (M + beta lambda)) of `solver::element::surface_mode_factor` (beta = 0.475).
The table in that function's doc comes from this script. Needs numpy only.
"""
import itertools
import math

import numpy as np

CORNERS = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
           (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
BETA = 0.475


def b_matrix(x, y, z, h):
    """Strain-displacement matrix (Voigt xx yy zz xy yz zx) at natural point (x, y, z)."""
    b = np.zeros((6, 24))
    for a, (xi, et, ze) in enumerate(CORNERS):
        g = np.array([xi * (1 + et * y) * (1 + ze * z),
                      et * (1 + xi * x) * (1 + ze * z),
                      ze * (1 + xi * x) * (1 + et * y)]) / 8 * 2 / h
        b[0, 3 * a] = g[0]
        b[1, 3 * a + 1] = g[1]
        b[2, 3 * a + 2] = g[2]
        b[3, 3 * a], b[3, 3 * a + 1] = g[1], g[0]
        b[4, 3 * a + 1], b[4, 3 * a + 2] = g[2], g[1]
        b[5, 3 * a], b[5, 3 * a + 2] = g[2], g[0]
    return b


def ratio(nx, ny, nz, nu, fix_base=True, full=False):
    """dt_crit / (h / c) of an nx x ny x nz mesh of unit cubes (E = rho = 1)."""
    h = 1.0
    lam = nu / ((1 + nu) * (1 - 2 * nu))
    mu = 1 / (2 * (1 + nu))
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[:3, :3] += 2 * mu * np.eye(3)
    d[3:, 3:] = mu * np.eye(3)
    nid = lambda i, j, k: (k * (ny + 1) + j) * (nx + 1) + i
    n = (nx + 1) * (ny + 1) * (nz + 1)
    k_glob = np.zeros((3 * n, 3 * n))
    m = np.zeros(3 * n)
    if full:
        gp = 1 / math.sqrt(3)
        ke = sum(b_matrix(*p, h).T @ d @ b_matrix(*p, h) * (h / 2) ** 3
                 for p in itertools.product([-gp, gp], repeat=3))
    else:
        b = b_matrix(0, 0, 0, h)
        ke = b.T @ d @ b * h ** 3
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        nodes = [nid(i + (c[0] + 1) // 2, j + (c[1] + 1) // 2, k + (c[2] + 1) // 2) for c in CORNERS]
        dofs = [3 * q + r for q in nodes for r in range(3)]
        k_glob[np.ix_(dofs, dofs)] += ke
        for q in nodes:
            m[3 * q:3 * q + 3] += h ** 3 / 8
    free = np.ones(3 * n, bool)
    if fix_base:
        for i, j in itertools.product(range(nx + 1), range(ny + 1)):
            q = nid(i, j, 0)
            free[3 * q:3 * q + 3] = False
    kf = k_glob[np.ix_(free, free)]
    mf = m[free]
    w2 = np.linalg.eigvalsh(kf / np.sqrt(np.outer(mf, mf))).max()
    c = math.sqrt(lam + 2 * mu)
    return 2 / math.sqrt(w2) / (h / c)


def kappa(nu):
    lam = nu / ((1 + nu) * (1 - 2 * nu))
    mu = 1 / (2 * (1 + nu))
    p = lam + 2 * mu
    return math.sqrt(p / (p + BETA * lam))


def main():
    print("nu      1pt-free  1pt-base-fixed  2x2x2-free  kappa   min/kappa")
    for nu in [0.0, 0.1, 0.2, 0.3, 0.35, 0.4, 0.45, 0.48, 0.49, 0.495, 0.499, 0.4999]:
        a = ratio(5, 4, 4, nu, fix_base=False)
        b = ratio(6, 5, 3, nu, fix_base=True)
        c = ratio(4, 4, 3, nu, fix_base=False, full=True)
        k = kappa(nu)
        print(f"{nu:<7.4f} {a:8.4f}  {b:14.4f}  {c:10.4f}  {k:.4f}  {min(a, b, c) / k:.4f}")


if __name__ == "__main__":
    main()
