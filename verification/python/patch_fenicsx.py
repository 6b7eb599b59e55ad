"""Distorted-hex patch test, linear elasticity, solved by DOLFINx -> verification/data/patch_fenicsx.json."""

import os

for _k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_k] = "1"

import numpy as np  # noqa: E402

import common  # noqa: E402
import fenicsx_util as fx  # noqa: E402  (imports mpi4py before dolfinx)
from fenicsx_util import dolfinx, fem, ufl  # noqa: E402


def main():
    out = common.out_dir_from_args("patch_fenicsx.json")
    d = common.patch_definition()
    nodes, cells = d["nodes"], d["cells"]

    msh = fx.mesh_from_vtk_hex(nodes, cells)
    V = fem.functionspace(msh, ("Lagrange", 1, (3,)))
    node_of_dof = fx.input_node_of_dof(msh, V, nodes)  # P1 dof block -> input node id
    dof_of_node = np.empty_like(node_of_dof)
    dof_of_node[node_of_dof] = np.arange(len(node_of_dof))

    lam, mu = d["lambda"], d["mu"]
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    def sigma(w):
        return lam * ufl.tr(eps(w)) * ufl.Identity(3) + 2.0 * mu * eps(w)

    dx = ufl.dx(metadata={"quadrature_degree": 3})  # 2x2x2 Gauss on hexahedra
    a = ufl.inner(sigma(u), eps(v)) * dx
    zero = fem.Constant(msh, np.zeros(3))
    L = ufl.inner(zero, v) * dx

    bn = d["boundary_nodes"]
    g = fem.Function(V)
    garr = g.x.array.reshape(-1, 3)
    garr[dof_of_node[bn]] = d["exact"][bn]
    bc = fem.dirichletbc(g, dof_of_node[bn].astype(np.int32))

    problem = fem.petsc.LinearProblem(
        a, L, bcs=[bc], petsc_options_prefix="patch_",
        petsc_options={"ksp_type": "preonly", "pc_type": "lu",
                       "pc_factor_mat_solver_type": "mumps"})
    uh = problem.solve()
    if isinstance(uh, (tuple, list)):
        uh = uh[0]
    reason = problem.solver.getConvergedReason()
    if reason <= 0:
        raise SystemExit(f"DOLFINx linear solve failed (KSP reason {reason})")

    # Reactions K u: assemble the internal-force form at u_h without boundary conditions.
    r_form = fem.form(ufl.inner(sigma(uh), eps(v)) * dx)
    r = fem.assemble_vector(r_form).array.reshape(-1, 3)

    u_nodes = uh.x.array.reshape(-1, 3)[dof_of_node]
    r_nodes = r[dof_of_node]

    gen = common.generator(__file__, "FEniCSx/DOLFINx", dolfinx.__version__, fx.versions(
        {"element": "Lagrange degree 1 on hexahedron, quadrature_degree=3 (2x2x2 Gauss)",
         "linear_solver": "PETSc KSP preonly + LU (MUMPS)"}))
    doc = common.patch_json(d, gen, u_nodes, r_nodes)
    print("patch test (DOLFINx): max |u - u_exact| =", doc["checks"]["max_abs_displacement_error"],
          "m; relative", doc["checks"]["max_rel_displacement_error"])
    if doc["checks"]["max_rel_displacement_error"] > 1e-10:
        raise SystemExit("patch test failed in DOLFINx: the reference is wrong")
    common.write_json(out, doc)


if __name__ == "__main__":
    main()
