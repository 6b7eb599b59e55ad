"""Cantilever tip deflection, small-strain linear elasticity, scikit-fem
-> verification/data/cantilever_skfem.json.

Beam [0, 0.1] x [0, 0.01] x [0, 0.01] m, E = 1 MPa, nu = 0 (so beam theory has no Poisson
coupling and the clamp adds no anticlastic constraint). Face x = 0 clamped (all components).
Face x = L carries a uniform shear traction t = (0, 0, -P/A), total P = 1e-3 N, applied as the
Q1-consistent nodal forces that are stored in the file (palpa applies exactly these).
Q1 hexahedra with full 2x2x2 integration lock in bending: the coarse meshes are far too stiff.
"""

import os

for _k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_k] = "1"

import numpy as np  # noqa: E402
import scipy  # noqa: E402
import skfem  # noqa: E402
from skfem import (Basis, ElementHex1, ElementHex2, ElementVector, FacetBasis,  # noqa: E402
                   LinearForm, MeshHex, asm, condense, solve)
from skfem.models.elasticity import linear_elasticity  # noqa: E402

import common  # noqa: E402

L, B, HT = 0.1, 0.01, 0.01  # m: length (x), width (y), height (z)
E, NU = 1.0e6, 0.0
P = 1.0e-3  # N, total tip load, in -z
Q1_MESHES = [(10, 1, 1), (20, 2, 2), (40, 4, 4)]
Q2_MESHES = [(20, 2, 2), (40, 4, 4)]  # 3-D reference (27-node hexahedra, 3x3x3 Gauss)


def solve_cantilever(mesh, element, intorder):
    lam, mu = common.lame(E, NU)
    basis = Basis(mesh, ElementVector(element), intorder=intorder)
    K = asm(linear_elasticity(lam, mu), basis)
    tip = mesh.facets_satisfying(lambda x: np.isclose(x[0], L))
    fb = FacetBasis(mesh, ElementVector(element), facets=tip, intorder=intorder)
    traction = np.array([0.0, 0.0, -P / (B * HT)])

    @LinearForm
    def load(v, w):
        return traction[0] * v[0] + traction[1] * v[1] + traction[2] * v[2]

    f = asm(load, fb)
    # Dofs off the loaded face pick up ~1e-20 round-off from the facet quadrature: zero them.
    f[~np.isclose(basis.doflocs[0], L)] = 0.0
    D = basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all()
    u = solve(*condense(K, f, D=D))
    return basis, u, f, K


def centre_dof_value(basis, u, comp, point):
    """Value of component ``comp`` at a point that carries nodes (vertex or higher-order node)."""
    x = basis.doflocs  # (3, N); ElementVector puts the 3 components of a node in component order
    dofs = np.sort(np.flatnonzero(np.abs(x - np.asarray(point)[:, None]).max(axis=0) < 1e-12))
    if len(dofs) != 3:
        raise SystemExit(f"no unique node at {point}")
    return u[dofs[comp]]


def q1_face_forces(nodes, div):
    """(nnode, 3) nodal forces of the traction (0, 0, -P/A) on x = L, consistent with Q1."""
    nx, ny, nz = div
    idx = common.node_index_grid(div)
    dy, dz = B / ny, HT / nz
    F = np.zeros((len(nodes), 3))
    for k in range(nz + 1):
        wz = dz * (0.5 if k in (0, nz) else 1.0)
        for j in range(ny + 1):
            wy = dy * (0.5 if j in (0, ny) else 1.0)
            F[idx(nx, j, k), 2] = -P / (B * HT) * wy * wz
    return F


def main():
    out = common.out_dir_from_args("cantilever_skfem.json")
    lam, mu = common.lame(E, NU)
    G = mu
    I_ = B * HT**3 / 12.0
    A = B * HT
    kappa = 10.0 * (1.0 + NU) / (12.0 + 11.0 * NU)  # Cowper's factor, rectangle
    d_eb = P * L**3 / (3.0 * E * I_)
    d_sh = P * L / (kappa * G * A)
    d_timo = d_eb + d_sh
    centre = np.array([L, B / 2, HT / 2])

    meshes = []
    for div in Q1_MESHES:
        nodes, cells = common.box_mesh((L, B, HT), div)
        mesh = MeshHex(np.ascontiguousarray(nodes.T), common.cells_to_skfem(cells))
        assert np.array_equal(mesh.t, common.cells_to_skfem(cells))
        basis, u, f, K = solve_cantilever(mesh, ElementHex1(), 3)
        nd = basis.nodal_dofs
        F = f[nd].T
        # Q1-consistent nodal forces of a uniform traction on the structured end face, in closed
        # form (tributary area: each face cell gives a quarter of its area to each corner).
        F_exact = q1_face_forces(nodes, div)
        if np.abs(F - F_exact).max() > 1e-15 * P:
            raise SystemExit("FacetBasis load differs from the closed-form Q1 nodal forces")
        F = F_exact
        f = np.zeros(basis.N)
        for c in range(3):
            f[nd[c]] = F[:, c]
        D = basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all()
        u = solve(*condense(K, f, D=D))
        U = u[nd].T
        loaded = np.flatnonzero(np.abs(F).max(axis=1) > 0)
        clamped = np.flatnonzero(np.isclose(nodes[:, 0], 0.0))
        R = (K @ u - f)[nd].T
        idx = common.node_index_grid(div)
        nx, ny, nz = div
        # uz at the centre of the end face from the Q1 field (bilinear in the face).
        js = [ny // 2] if ny % 2 == 0 else [ny // 2, ny // 2 + 1]
        ks = [nz // 2] if nz % 2 == 0 else [nz // 2, nz // 2 + 1]
        tip_nodes = [idx(nx, j, k) for j in js for k in ks]
        uz_c = float(np.mean(U[tip_nodes, 2]))
        uz_w = float(F[:, 2] @ U[:, 2]) / -P  # load-weighted mean uz: sum f_z u_z / sum f_z
        print(f"Q1 {div}: tip uz centre {uz_c:.6e} m, load-weighted {uz_w:.6e} m, "
              f"ratio to Timoshenko {uz_c / -d_timo:.4f}")
        meshes.append({
            "name": "%dx%dx%d" % div,
            "divisions": list(div),
            "element": "hex8 (Q1), 2x2x2 Gauss",
            "mesh": {
                "element": "hex8", "node_order": "VTK_HEXAHEDRON",
                "numbering": "structured, node = i + (nx+1)*(j + (ny+1)*k), x_i = L*i/nx etc.",
                "nodes": common.exact_list(nodes),
                "cells": common.int_list(cells),
            },
            "boundary_conditions": {
                "clamped": {"nodes": common.int_list(clamped), "displacement": [0.0, 0.0, 0.0]},
            },
            "loads": {
                "nodal_forces": {"nodes": common.int_list(loaded),
                                 "values": common.rnd_array(F[loaded])},
            },
            "tip_centre_nodes": tip_nodes,
            "solution": {
                "displacement": common.rnd_array(U),
                "reaction_forces": {"nodes": common.int_list(clamped),
                                    "values": common.rnd_array(R[clamped])},
                "tip_uz_centre": common.rnd(uz_c),
                "tip_uz_load_weighted": common.rnd(uz_w),
                "ratio_to_timoshenko": common.rnd(uz_c / -d_timo),
            },
        })

    q2 = []
    for div in Q2_MESHES:
        mesh = MeshHex.init_tensor(*[np.linspace(0.0, l, n + 1) for l, n in zip((L, B, HT), div)])
        basis, u, f, K = solve_cantilever(mesh, ElementHex2(), 5)
        uz_c = float(centre_dof_value(basis, u, 2, centre))
        uz_w = float(f @ u) / -P
        print(f"Q2 {div}: tip uz centre {uz_c:.6e} m, load-weighted {uz_w:.6e} m, {basis.N} dofs")
        q2.append({"name": "Q2 %dx%dx%d" % div, "divisions": list(div),
                   "element": "hex27 (Q2), 3x3x3 Gauss", "dofs": int(basis.N),
                   "tip_uz_centre": common.rnd(uz_c), "tip_uz_load_weighted": common.rnd(uz_w)})

    print(f"beam theory: Euler-Bernoulli {-d_eb:.6e} m, Timoshenko {-d_timo:.6e} m")
    doc = {
        "schema": common.SCHEMA,
        "problem": "cantilever_tip_load",
        "description": (
            "Cantilever [0,0.1]x[0,0.01]x[0,0.01] m, small-strain linear elasticity, E = 1 MPa, "
            "nu = 0. Face x = 0 clamped (all components). Face x = L: uniform traction "
            "(0, 0, -P/A), P = 1e-3 N, given as Q1-consistent nodal forces per mesh. Tip "
            "deflection = uz at the centre (L, 0.005, 0.005) of the loaded face (from the FE field; "
            "for odd divisions the mean of the 4 nodes around it) and the load-weighted mean "
            "f.u / P. Fully integrated Q1 hexahedra shear-lock: compare palpa's formulations with "
            "these per-mesh values and with beam theory."),
        "generator": common.generator(__file__, "scikit-fem", skfem.__version__, {
            "scipy": scipy.__version__,
            "linear_solver": "scipy.sparse.linalg.spsolve (SuperLU)"}),
        "units": {"length": "m", "force": "N", "stress": "Pa"},
        "geometry": {"length": L, "width_y": B, "height_z": HT},
        "material": {"law": "linear_elastic_small_strain", "E": E, "nu": NU,
                     "lambda": lam, "mu": mu},
        "load": {"total_force": [0.0, 0.0, -P], "traction": [0.0, 0.0, -P / (B * HT)]},
        "closed_form": {
            "second_moment_area": I_,
            "shear_coefficient": kappa,
            "euler_bernoulli_tip_uz": -d_eb,
            "timoshenko_tip_uz": -d_timo,
            "formulas": "EB: P L^3 / (3 E I); Timoshenko: P L^3 / (3 E I) + P L / (kappa G A), "
                        "kappa = 10(1+nu)/(12+11nu) (Cowper), I = b h^3 / 12",
        },
        "meshes": meshes,
        "reference_q2": q2,
    }
    common.write_json(out, doc)


if __name__ == "__main__":
    main()
