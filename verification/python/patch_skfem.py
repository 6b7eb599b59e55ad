"""Distorted-hex patch test, linear elasticity, solved by scikit-fem -> verification/data/patch_skfem.json."""

import os

for _k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_k] = "1"

import numpy as np  # noqa: E402
import scipy  # noqa: E402
import skfem  # noqa: E402
from skfem import Basis, ElementHex1, ElementVector, MeshHex, asm, condense, solve  # noqa: E402
from skfem.models.elasticity import linear_elasticity  # noqa: E402

import common  # noqa: E402


def main():
    out = common.out_dir_from_args("patch_skfem.json")
    d = common.patch_definition()
    nodes, cells = d["nodes"], d["cells"]

    mesh = MeshHex(np.ascontiguousarray(nodes.T), common.cells_to_skfem(cells))
    assert np.array_equal(mesh.t, common.cells_to_skfem(cells)), "scikit-fem reordered the cells"
    basis = Basis(mesh, ElementVector(ElementHex1()), intorder=3)  # 2x2x2 Gauss
    assert basis.X.shape[1] == 8
    K = asm(linear_elasticity(d["lambda"], d["mu"]), basis)

    nd = basis.nodal_dofs  # (3, nnode): dof of component c at node n
    bn = d["boundary_nodes"]
    u_dofs = np.zeros(basis.N)
    for c in range(3):
        u_dofs[nd[c, bn]] = d["exact"][bn, c]
    D = nd[:, bn].ravel()
    u_dofs = solve(*condense(K, np.zeros(basis.N), x=u_dofs, D=D))

    u = u_dofs[nd].T.copy()  # (nnode, 3)
    r = (K @ u_dofs)[nd].T.copy()

    gen = common.generator(__file__, "scikit-fem", skfem.__version__,
                           {"scipy": scipy.__version__,
                            "element": "ElementVector(ElementHex1()), intorder=3",
                            "linear_solver": "scipy.sparse.linalg.spsolve (SuperLU)"})
    doc = common.patch_json(d, gen, u, r)
    print("patch test (scikit-fem): max |u - u_exact| =", doc["checks"]["max_abs_displacement_error"],
          "m; relative", doc["checks"]["max_rel_displacement_error"])
    if doc["checks"]["max_rel_displacement_error"] > 1e-10:
        raise SystemExit("patch test failed in scikit-fem: the reference is wrong")
    common.write_json(out, doc)


if __name__ == "__main__":
    main()
