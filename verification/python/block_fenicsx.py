"""Clamped neo-Hookean block under 10 % compression, solved by DOLFINx (SNES Newton)
-> verification/data/block_fenicsx.json.

Full block [0, 20] x [0, 20] x [0, 10] mm (no symmetry planes, so palpa can run it as is).
Bottom face z = 0 clamped (u = 0); top face z = H glued to a rigid plate moved by (0, 0, -H/10).
Compressible neo-Hookean  Psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,
mu = 0.33 MPa, lambda = 0.495 MPa (nu = 0.3, E = 0.858 MPa).
"""

import os
import sys
import time

for _k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_k] = "1"

import numpy as np  # noqa: E402

import common  # noqa: E402
import fenicsx_util as fx  # noqa: E402  (imports mpi4py before dolfinx)
from fenicsx_util import MPI, PETSc, dolfinx, fem, mesh, ufl  # noqa: E402

LX, LY, H = 0.020, 0.020, 0.010  # m
MU = 3.3e5  # Pa
LAMBDA = 4.95e5  # Pa  (nu = lambda / (2 (lambda + mu)) = 0.3)
STRAIN = 0.10  # plate displacement = -STRAIN * H
LOAD_STEPS = 1  # path independent (hyperelastic); Newton converges in 4 iterations from u = 0
LEVELS = [(4, 4, 2), (8, 8, 4), (16, 16, 8)]  # Q1 meshes palpa compares against (full data)
Q1_FINE = (32, 32, 16)  # Q1, scalars only
Q2_REF = (16, 16, 8)  # Q2 (27-node) reference, scalars only


def solve_block(msh, degree, qdeg):
    V = fem.functionspace(msh, ("Lagrange", degree, (3,)))
    u = fem.Function(V, name="u")
    v = ufl.TestFunction(V)
    d = 3
    I = ufl.Identity(d)
    F = I + ufl.grad(u)
    C = F.T * F
    J = ufl.det(F)
    lnJ = ufl.ln(J)
    psi = MU / 2 * (ufl.tr(C) - 3) - MU * lnJ + LAMBDA / 2 * lnJ**2
    dx = ufl.dx(metadata={"quadrature_degree": qdeg})
    Pi = psi * dx
    R = ufl.derivative(Pi, u, v)

    tdim = msh.topology.dim
    fdim = tdim - 1
    bottom_f = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[2], 0.0))
    top_f = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[2], H))
    bottom = fem.locate_dofs_topological(V, fdim, bottom_f)
    top = fem.locate_dofs_topological(V, fdim, top_f)
    plate = fem.Constant(msh, np.zeros(3))
    bcs = [fem.dirichletbc(np.zeros(3), bottom, V), fem.dirichletbc(plate, top, V)]

    opts = {
        "snes_type": "newtonls", "snes_linesearch_type": "basic",
        "snes_rtol": 1e-12, "snes_atol": 1e-11, "snes_stol": 0.0, "snes_max_it": 30,
        "ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps",
    }
    problem = fem.petsc.NonlinearProblem(R, u, bcs=bcs, petsc_options=opts,
                                         petsc_options_prefix=f"block{degree}_{id(msh)}_")
    its = []
    for s in range(1, LOAD_STEPS + 1):
        plate.value[:] = (0.0, 0.0, -STRAIN * H * s / LOAD_STEPS)
        problem.solve()
        reason = problem.solver.getConvergedReason()
        if reason <= 0:
            raise SystemExit(f"Newton failed at load step {s} (SNES reason {reason})")
        its.append(problem.solver.getIterationNumber())
    u.x.scatter_forward()

    # Reaction: the residual assembled without boundary conditions, summed over the top dofs.
    r = fem.assemble_vector(fem.form(R)).array.reshape(-1, 3)
    top_reaction = r[top].sum(axis=0)
    bottom_reaction = r[bottom].sum(axis=0)
    return V, u, r, top, bottom, top_reaction, bottom_reaction, its


def value_at(V, u, point):
    x = V.tabulate_dof_coordinates()
    k = np.flatnonzero(np.abs(x - np.asarray(point)).max(axis=1) < 1e-12)
    if len(k) != 1:
        raise SystemExit(f"no unique dof at {point}")
    return u.x.array.reshape(-1, 3)[k[0]]


BULGE_POINT = (LX, LY / 2, H / 2)  # mid-height midpoint of the face x = LX


def main():
    out = common.out_dir_from_args("block_fenicsx.json")
    levels = []
    t_all = time.time()
    for div in LEVELS:
        t0 = time.time()
        nodes, cells = common.box_mesh((LX, LY, H), div)
        msh = fx.mesh_from_vtk_hex(nodes, cells)
        V, u, r, top, bottom, Rt, Rb, its = solve_block(msh, 1, 3)
        n_of_d = fx.input_node_of_dof(msh, V, nodes)
        d_of_n = np.empty_like(n_of_d)
        d_of_n[n_of_d] = np.arange(len(n_of_d))
        U = u.x.array.reshape(-1, 3)[d_of_n]
        Rn = r[d_of_n]
        top_nodes = np.sort(n_of_d[top])
        bot_nodes = np.sort(n_of_d[bottom])
        bulge = value_at(V, u, BULGE_POINT)
        print(f"Q1 {div}: Fz(top) = {Rt[2]:.10g} N, bulge ux = {bulge[0]:.10g} m, "
              f"Newton its {its}, {time.time() - t0:.1f} s", flush=True)
        idx = common.node_index_grid(div)
        levels.append({
            "name": "%dx%dx%d" % div,
            "divisions": list(div),
            "element": "hex8 (Q1), 2x2x2 Gauss",
            "mesh": {
                "element": "hex8", "node_order": "VTK_HEXAHEDRON",
                "numbering": "structured, node = i + (nx+1)*(j + (ny+1)*k), x_i = LX*i/nx etc.",
                "nodes": common.exact_list(nodes),
                "cells": common.int_list(cells),
            },
            "boundary_conditions": {
                "bottom_clamped": {"nodes": common.int_list(bot_nodes),
                                   "displacement": [0.0, 0.0, 0.0]},
                "top_plate": {"nodes": common.int_list(top_nodes),
                              "displacement": [0.0, 0.0, -STRAIN * H]},
            },
            "bulge_node": int(idx(div[0], div[1] // 2, div[2] // 2)),
            "solution": {
                "displacement": common.rnd_array(U),
                "top_reaction_force": common.rnd_array(Rt),
                "bottom_reaction_force": common.rnd_array(Rb),
                "reaction_force_z": common.rnd(Rt[2]),
                "bulge_displacement_x": common.rnd(bulge[0]),
                "top_nodal_reactions": {"nodes": common.int_list(top_nodes),
                                        "values": common.rnd_array(Rn[top_nodes])},
            },
            "newton_iterations_per_step": its,
        })

    refs = []
    for degree, div, qdeg in ((1, Q1_FINE, 3), (2, Q2_REF, 5)):
        t0 = time.time()
        if degree == 1:
            nodes, cells = common.box_mesh((LX, LY, H), div)
            msh = fx.mesh_from_vtk_hex(nodes, cells)
        else:
            msh = mesh.create_box(MPI.COMM_WORLD, [np.zeros(3), np.array([LX, LY, H])], list(div),
                                  cell_type=mesh.CellType.hexahedron)
        V, u, r, top, bottom, Rt, Rb, its = solve_block(msh, degree, qdeg)
        bulge = value_at(V, u, BULGE_POINT)
        ndof = V.dofmap.index_map.size_local * 3
        print(f"Q{degree} {div}: Fz(top) = {Rt[2]:.10g} N, bulge ux = {bulge[0]:.10g} m, "
              f"{ndof} dofs, Newton its {its}, {time.time() - t0:.1f} s", flush=True)
        refs.append({
            "name": "Q%d %dx%dx%d" % ((degree,) + div),
            "divisions": list(div),
            "element": "hex8 (Q1), 2x2x2 Gauss" if degree == 1 else "hex27 (Q2), 3x3x3 Gauss",
            "dofs": ndof,
            "reaction_force_z": common.rnd(Rt[2]),
            "bulge_displacement_x": common.rnd(bulge[0]),
            "newton_iterations_per_step": its,
        })

    # Observed convergence of the Q1 sequence against the Q2 reference (h halves each level).
    ref = refs[-1]
    conv = {}
    for q in ("reaction_force_z", "bulge_displacement_x"):
        vals = [lv["solution"][q] for lv in levels] + [refs[0][q]]
        errs = [abs(v - ref[q]) / abs(ref[q]) for v in vals]
        rates = [np.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]
        conv[q] = {"q1_levels": [lv["name"] for lv in levels] + [refs[0]["name"]],
                   "relative_error_vs_reference": [common.rnd(e) for e in errs],
                   "observed_rate": [common.rnd(x) for x in rates]}
        print(q, "rel. errors", ["%.3e" % e for e in errs], "rates", ["%.2f" % x for x in rates])

    import ffcx  # noqa: F401
    doc = {
        "schema": common.SCHEMA,
        "problem": "clamped_block_neo_hookean",
        "description": (
            "Full block [0,0.02]x[0,0.02]x[0,0.01] m (no symmetry planes). Bottom face z=0 clamped "
            "(all components zero); top face z=0.01 glued to a rigid plate displaced (0,0,-0.001) m "
            "(10 % compression, x and y fixed). Quasi-static, no body force, compressible "
            "neo-Hookean. Reaction force = force the plate exerts on the block (top face, "
            "z component, negative in compression). Bulge = x displacement of the point "
            "(0.02, 0.01, 0.005), mid-height midpoint of the face x = 0.02 (a node on every mesh)."),
        "generator": common.generator(__file__, "FEniCSx/DOLFINx", dolfinx.__version__, fx.versions(
            {"nonlinear_solver": "dolfinx.fem.petsc.NonlinearProblem (PETSc SNES newtonls, basic "
                                 "line search, rtol 1e-12, atol 1e-11), LU (MUMPS)",
             "load_steps": LOAD_STEPS})),
        "units": {"length": "m", "force": "N", "stress": "Pa"},
        "geometry": {"lx": LX, "ly": LY, "h": H},
        "material": {
            "law": "neo_hookean_compressible",
            "strain_energy": "Psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2",
            "mu": MU, "lambda": LAMBDA,
            "E": MU * (3 * LAMBDA + 2 * MU) / (LAMBDA + MU),
            "nu": LAMBDA / (2 * (LAMBDA + MU)),
        },
        "loading": {"plate_displacement": [0.0, 0.0, -STRAIN * H], "compression": STRAIN},
        "bulge_point": list(BULGE_POINT),
        "levels": levels,
        "references": refs,
        "reference": {"name": ref["name"], "reaction_force_z": ref["reaction_force_z"],
                      "bulge_displacement_x": ref["bulge_displacement_x"]},
        "convergence": conv,
    }
    print(f"total {time.time() - t_all:.1f} s")
    common.write_json(out, doc)


if __name__ == "__main__":
    sys.exit(main())
