"""DOLFINx helpers: mesh import from VTK-ordered hexahedra and dof <-> input node maps.

mpi4py is imported before dolfinx on purpose: the dolfinx-solver-real wheel binds to the
libmpi that mpi4py loaded, and ``import dolfinx`` fails on libmpi otherwise."""

from mpi4py import MPI  # noqa: F401  (must come first)

try:  # orders MPI ahead of the bindings and rejects a foreign petsc4py (dolfinx-solver wheels)
    import dolfinx_solver  # noqa: F401
except ImportError:  # a DOLFINx from elsewhere
    dolfinx_solver = None

import basix  # noqa: E402
import basix.ufl  # noqa: E402
import dolfinx  # noqa: E402
import dolfinx.fem.petsc  # noqa: E402,F401
import numpy as np  # noqa: E402
import ufl  # noqa: E402
from dolfinx import fem, mesh  # noqa: E402,F401
from petsc4py import PETSc  # noqa: E402

import common  # noqa: E402

if MPI.COMM_WORLD.size != 1:
    raise SystemExit("the reference scripts run in serial")
if np.dtype(PETSc.ScalarType).kind != "f":
    raise SystemExit("these scripts need a real-scalar PETSc (dolfinx-solver-real)")


def versions(extra=None):
    import ffcx

    v = {
        "basix": basix.__version__,
        "ffcx": ffcx.__version__,
        "ufl": ufl.__version__,
        "petsc4py": __import__("petsc4py").__version__,
        "petsc": "%d.%d.%d" % PETSc.Sys.getVersion(),
    }
    if dolfinx_solver is not None:
        v["wheel"] = "dolfinx-solver-real " + getattr(dolfinx_solver, "__version__", "?")
    if extra:
        v.update(extra)
    return v


def mesh_from_vtk_hex(nodes, cells_vtk):
    """DOLFINx hexahedral (Q1 geometry) mesh from VTK-ordered connectivity."""
    coord_el = ufl.Mesh(basix.ufl.element("Lagrange", "hexahedron", 1, shape=(3,)))
    return mesh.create_mesh(MPI.COMM_WORLD, common.cells_to_dolfinx(cells_vtk), coord_el,
                            np.asarray(nodes, dtype=np.float64))


def input_node_of_dof(msh, V, nodes):
    """For a degree-1 Lagrange space on a Q1 mesh: input node id of every dof block.

    Goes through the cells: local dof i of cell c and local geometry node i of cell c are the
    same vertex; the geometry node's input index comes from ``input_global_indices``. Checked
    against the coordinates."""
    geo = msh.geometry
    inp = np.asarray(geo.input_global_indices, dtype=np.int64)
    gdm = geo.dofmap
    ncell = msh.topology.index_map(msh.topology.dim).size_local
    ndof = V.dofmap.index_map.size_local
    out = -np.ones(ndof, dtype=np.int64)
    for c in range(ncell):
        dofs = V.dofmap.cell_dofs(c)
        out[dofs] = inp[gdm[c]]
    if (out < 0).any():
        raise SystemExit("dof map incomplete")
    xd = V.tabulate_dof_coordinates()[:ndof]
    if np.abs(xd - np.asarray(nodes)[out]).max() > 1e-14:
        raise SystemExit("dof -> input node map disagrees with the coordinates")
    return out
