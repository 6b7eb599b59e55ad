"""Shared helpers for the palpa reference scripts (scikit-fem and FEniCSx venvs alike).

Only the standard library and numpy are used here, so the same module runs under the
scikit-fem venv (Python 3.11) and the FEniCSx venv (Python 3.12).

Conventions used by every reference file:
  * SI units throughout (m, N, Pa).
  * Hexahedra are stored in VTK_HEXAHEDRON order with reference corners
      0:(-,-,-) 1:(+,-,-) 2:(+,+,-) 3:(-,+,-) 4:(-,-,+) 5:(+,-,+) 6:(+,+,+) 7:(-,+,+).
  * Structured meshes number their nodes x fastest: n = i + (nx+1) * (j + (ny+1) * k).
  * The files contain no date, and every float is written by ``repr`` after a fixed rounding,
    so regenerating a file on the same software stack gives the same bytes.
"""

import argparse
import math
import os
import random
import sys

import numpy as np

SCHEMA = "palpa-reference/1"

# Reference corners of VTK_HEXAHEDRON, as (0|1) per axis.
VTK_HEX_CORNERS = [
    (0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
    (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1),
]
# scikit-fem MeshHex1 reference corners (skfem/mesh/mesh_hex_1.py, ``doflocs``).
SKFEM_HEX_CORNERS = [
    (0, 0, 0), (0, 0, 1), (0, 1, 0), (1, 0, 0),
    (0, 1, 1), (1, 0, 1), (1, 1, 0), (1, 1, 1),
]
# DOLFINx / basix tensor-product hexahedron: vertex v sits at (v & 1, (v >> 1) & 1, (v >> 2) & 1).
DOLFINX_HEX_CORNERS = [(v & 1, (v >> 1) & 1, (v >> 2) & 1) for v in range(8)]


def _perm(target_corners):
    """Column permutation p such that cells_target = cells_vtk[:, p]."""
    return [VTK_HEX_CORNERS.index(c) for c in target_corners]


VTK_TO_SKFEM = _perm(SKFEM_HEX_CORNERS)      # [0, 4, 3, 1, 7, 5, 2, 6]
VTK_TO_DOLFINX = _perm(DOLFINX_HEX_CORNERS)  # [0, 1, 3, 2, 4, 5, 7, 6]


def cells_to_skfem(cells_vtk):
    """(ncell, 8) VTK connectivity -> (8, ncell) scikit-fem ``t`` array."""
    return np.ascontiguousarray(np.asarray(cells_vtk, dtype=np.int64)[:, VTK_TO_SKFEM].T)


def cells_to_dolfinx(cells_vtk):
    """(ncell, 8) VTK connectivity -> (ncell, 8) DOLFINx (basix) ordered connectivity."""
    return np.ascontiguousarray(np.asarray(cells_vtk, dtype=np.int64)[:, VTK_TO_DOLFINX])


def box_mesh(lengths, divisions, origin=(0.0, 0.0, 0.0)):
    """Structured hex8 mesh of a box, VTK order, nodes numbered x fastest.

    Returns (nodes (nnode, 3) float64, cells (ncell, 8) int64)."""
    nx, ny, nz = divisions
    axes = [
        [origin[a] + lengths[a] * i / divisions[a] for i in range(divisions[a] + 1)]
        for a in range(3)
    ]
    nodes = np.array(
        [[axes[0][i], axes[1][j], axes[2][k]]
         for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)],
        dtype=np.float64,
    )

    def nid(i, j, k):
        return i + (nx + 1) * (j + (ny + 1) * k)

    cells = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                cells.append([nid(i + di, j + dj, k + dk) for (di, dj, dk) in VTK_HEX_CORNERS])
    return nodes, np.array(cells, dtype=np.int64)


def node_index_grid(divisions):
    """Function (i, j, k) -> node id for ``box_mesh`` numbering."""
    nx, ny, _ = divisions
    return lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)


def hex_corner_jacobians(nodes, cells_vtk):
    """det(dX/dxi) of the trilinear map at the 8 corners and the centre of each VTK hex.

    Returns an array (ncell, 9); all entries positive means a valid, positively oriented mesh."""
    x = np.asarray(nodes)[np.asarray(cells_vtk)]  # (ncell, 8, 3)
    corners = np.array(VTK_HEX_CORNERS, dtype=np.float64) * 2.0 - 1.0  # (8, 3) in [-1, 1]
    pts = np.vstack([corners, np.zeros((1, 3))])
    out = np.empty((x.shape[0], pts.shape[0]))
    for q, (a, b, c) in enumerate(pts):
        dn = np.empty((8, 3))
        for n, (s, t, u) in enumerate(corners):
            dn[n, 0] = s * (1 + t * b) * (1 + u * c) / 8
            dn[n, 1] = t * (1 + s * a) * (1 + u * c) / 8
            dn[n, 2] = u * (1 + s * a) * (1 + t * b) / 8
        jac = np.einsum("enj,nk->ejk", x, dn)  # dX_j / dxi_k
        out[:, q] = np.linalg.det(jac)
    return out


def distorted_cube_mesh(edge, n, max_fraction, seed, decimals=12):
    """Cube [0, edge]^3 with n^3 hexes; nodes moved by up to max_fraction * h per axis, tangentially
    on the boundary (see below), so every element and every boundary face is distorted.

    Uses Python's ``random.Random(seed)`` (Mersenne Twister, reproducible across Python versions)
    so the scikit-fem and FEniCSx venvs build bit-identical meshes. Coordinates are rounded to
    ``decimals`` decimal places (1e-12 m), so the JSON ``repr`` rebuilds exactly the solved mesh."""
    nodes, cells = box_mesh((edge, edge, edge), (n, n, n))
    h = edge / n
    rng = random.Random(seed)
    idx = node_index_grid((n, n, n))
    for k in range(n + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                nid = idx(i, j, k)
                ijk = (i, j, k)
                for a in range(3):
                    r = 2.0 * rng.random() - 1.0  # always drawn: the stream does not depend on n
                    # Coordinate a moves only where the node is not on a face normal to axis a:
                    # interior nodes move freely, face nodes slide in their face, edge nodes along
                    # their edge, corners stay. The domain stays the cube.
                    d = r * max_fraction * h if 0 < ijk[a] < n else 0.0
                    nodes[nid, a] = round(float(nodes[nid, a]) + d, decimals)
    jac = hex_corner_jacobians(nodes, cells)
    if not (jac > 0).all():
        raise SystemExit(f"distorted mesh has a non-positive Jacobian (min {jac.min()})")
    return nodes, cells, jac


def boundary_nodes_of_box(nodes, lo, hi, tol=1e-12):
    """Ids of the nodes on the surface of the box [lo, hi] (sorted)."""
    x = np.asarray(nodes)
    on = np.zeros(x.shape[0], dtype=bool)
    for a in range(3):
        on |= np.abs(x[:, a] - lo[a]) < tol
        on |= np.abs(x[:, a] - hi[a]) < tol
    return np.flatnonzero(on)


# ----------------------------------------------------------------------------------------------
# Deterministic JSON output.
# ----------------------------------------------------------------------------------------------

RESULT_DIGITS = 15  # significant digits kept for computed (solver) results


def rnd(x, digits=RESULT_DIGITS):
    """Round a computed float to ``digits`` significant digits (and -0.0 to 0.0)."""
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"non-finite value {x}")
    if x == 0.0:
        return 0.0
    y = float(f"{x:.{digits - 1}e}")
    return 0.0 if y == 0.0 else y


def rnd_array(a, digits=RESULT_DIGITS):
    """Nested lists of rounded floats from an array-like."""
    a = np.asarray(a, dtype=np.float64)
    if a.ndim == 0:
        return rnd(a, digits)
    return [rnd_array(r, digits) for r in a]


def exact_list(a):
    """Nested lists of floats without rounding (inputs: coordinates, parameters)."""
    a = np.asarray(a, dtype=np.float64)
    if a.ndim == 0:
        v = float(a)
        return 0.0 if v == 0.0 else v
    return [exact_list(r) for r in a]


def int_list(a):
    a = np.asarray(a)
    if a.ndim == 0:
        return int(a)
    return [int_list(r) for r in a]


def _scalar(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if v is None:
        return "null"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if not math.isfinite(v):
            raise ValueError("non-finite float in reference output")
        return repr(0.0 if v == 0.0 else v)
    if isinstance(v, str):
        import json
        return json.dumps(v, ensure_ascii=True)
    raise TypeError(f"cannot serialise {type(v)}")


def _is_flat(lst):
    return all(not isinstance(v, (list, tuple, dict)) for v in lst)


def dumps(obj, indent=0):
    """JSON text: dicts keep insertion order, flat lists on one line, lists of flat lists one
    row per line. Deterministic for deterministic input."""
    pad = "  " * indent
    pad1 = "  " * (indent + 1)
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = [f"{pad1}{_scalar(str(k))}: {dumps(v, indent + 1)}" for k, v in obj.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, (list, tuple)):
        if not obj:
            return "[]"
        if _is_flat(obj):
            return "[" + ", ".join(_scalar(v) for v in obj) + "]"
        rows = [f"{pad1}{dumps(v, indent + 1)}" for v in obj]
        return "[\n" + ",\n".join(rows) + "\n" + pad + "]"
    return _scalar(obj)


def write_json(path, obj):
    text = dumps(obj) + "\n"
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write(text)
    print(f"wrote {path} ({len(text)} bytes)")


def out_dir_from_args(default_name):
    """Parse ``--out DIR`` (default: verification/data next to this directory)."""
    here = os.path.dirname(os.path.abspath(__file__))
    p = argparse.ArgumentParser(description=f"writes {default_name}")
    p.add_argument("--out", default=os.path.join(here, "..", "data"),
                   help="directory for the JSON file (default: verification/data)")
    args = p.parse_args()
    return os.path.normpath(os.path.join(args.out, default_name))


def generator(script, solver, solver_version, extra=None):
    g = {
        "script": "verification/python/" + os.path.basename(script),
        "solver": solver,
        "solver_version": solver_version,
        "python": "%d.%d" % sys.version_info[:2],
        "numpy": np.__version__,
    }
    if extra:
        g.update(extra)
    return g


def lame(E, nu):
    """(lambda, mu) exactly as palpa's material::law::lame computes them."""
    mu = E / (2.0 * (1.0 + nu))
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    return lam, mu


# ----------------------------------------------------------------------------------------------
# Problem definitions shared by the scikit-fem and FEniCSx scripts.
# ----------------------------------------------------------------------------------------------

PATCH = {
    "edge": 0.1,          # m, cube [0, 0.1]^3
    "divisions": 3,       # 3 x 3 x 3 hexahedra
    "max_fraction": 0.2,  # interior nodes move by up to 20 % of the spacing, per axis
    "seed": 20240611,
    "E": 1.0e6,           # Pa
    "nu": 0.3,
    # u = A X + b. A is symmetric (a pure, general constant strain: no infinitesimal rotation).
    "A": [[1.0e-3, 4.0e-4, -2.0e-4],
          [4.0e-4, -5.0e-4, 3.0e-4],
          [-2.0e-4, 3.0e-4, 8.0e-4]],
    "b": [1.0e-5, -2.0e-5, 3.0e-5],  # m
}


def patch_definition():
    """Mesh, material and Dirichlet data of the distorted-hex patch test (identical in both venvs)."""
    P = PATCH
    nodes, cells, jac = distorted_cube_mesh(P["edge"], P["divisions"], P["max_fraction"], P["seed"])
    A = np.array(P["A"])
    b = np.array(P["b"])
    exact = nodes @ A.T + b
    bnodes = boundary_nodes_of_box(nodes, (0.0, 0.0, 0.0), (P["edge"],) * 3)
    lam, mu = lame(P["E"], P["nu"])
    eps = 0.5 * (A + A.T)
    sigma = lam * np.trace(eps) * np.eye(3) + 2.0 * mu * eps
    return {
        "nodes": nodes, "cells": cells, "jacobians": jac, "A": A, "b": b, "exact": exact,
        "boundary_nodes": bnodes, "lambda": lam, "mu": mu, "stress": sigma,
    }


def patch_json(defn, generator_info, u, reactions):
    """Reference document of the patch test from a solver's displacement and nodal reactions."""
    P = PATCH
    exact = defn["exact"]
    bn = defn["boundary_nodes"]
    err = float(np.abs(u - exact).max())
    scale = float(np.abs(exact).max())
    # Reactions: the sum over boundary nodes must vanish (self-equilibrated), interior ones ~0.
    interior = np.setdiff1d(np.arange(len(u)), bn)
    return {
        "schema": SCHEMA,
        "problem": "patch_test_distorted_hex",
        "description": (
            "Distorted-hexahedron patch test, small-strain linear elasticity, no body force. "
            "Cube [0, 0.1]^3 m, 3x3x3 hex8, nodes randomly perturbed (boundary nodes only "
            "tangentially, so the domain stays the cube); every boundary "
            "node prescribed u = A X + b, whose exact solution is u = A X + b everywhere with "
            "uniform stress. Reaction forces are K u at the boundary nodes."),
        "generator": generator_info,
        "units": {"length": "m", "force": "N", "stress": "Pa"},
        "mesh": {
            "element": "hex8",
            "node_order": "VTK_HEXAHEDRON",
            "construction": {
                "edge": P["edge"], "divisions": [P["divisions"]] * 3,
                "max_perturbation_fraction_of_spacing": P["max_fraction"],
                "seed": P["seed"], "rng": "python random.Random(seed).random() drawn for x,y,z of every node, nodes "
                "looped k,j,i (x fastest); coordinate a moves by (2r-1)*fraction*h unless the node "
                "lies on a face normal to a (faces slide in-plane, edges along the edge, corners "
                "fixed); coordinates rounded to 1e-12 m",
            },
            "min_corner_jacobian": rnd(defn["jacobians"].min()),
            "nodes": exact_list(defn["nodes"]),
            "cells": int_list(defn["cells"]),
        },
        "material": {
            "law": "linear_elastic_small_strain",
            "E": P["E"], "nu": P["nu"],
            "lambda": defn["lambda"], "mu": defn["mu"],
        },
        "quadrature": "scikit-fem and DOLFINx: 2x2x2 Gauss-Legendre (the patch test passes for any "
                      "rule that integrates grad N exactly, which 2x2x2 does)",
        "boundary_conditions": {
            "dirichlet": {
                "nodes": int_list(bn),
                "values": exact_list(exact[bn]),
            },
        },
        "loads": {"body_force": [0.0, 0.0, 0.0]},
        "exact": {
            "A": exact_list(defn["A"]),
            "b": exact_list(defn["b"]),
            "displacement": "u = A X + b",
            "stress": rnd_array(defn["stress"]),
        },
        "solution": {
            "displacement": rnd_array(u),
            "reaction_forces": {
                "nodes": int_list(bn),
                "values": rnd_array(reactions[bn]),
            },
        },
        "checks": {
            # Round-off level numbers (not byte-stable across BLAS builds); the comparison script
            # only checks that they stay below 1e-9.
            "max_abs_displacement_error": rnd(err, 3),
            "max_rel_displacement_error": rnd(err / scale, 3),
            "max_abs_interior_residual": rnd(np.abs(reactions[interior]).max(), 3),
            "max_abs_reaction_sum": rnd(np.abs(reactions[bn].sum(axis=0)).max(), 3),
        },
    }
