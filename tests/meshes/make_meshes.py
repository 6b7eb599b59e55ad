#!/usr/bin/env python3
"""Write the mesh files of tests/meshes/ with the tools users have: VTK, meshio and Gmsh.

    python -m venv /tmp/meshvenv
    /tmp/meshvenv/bin/pip install numpy==2.4.6 meshio==5.3.5 vtk==9.7.2 gmsh==4.15.2
    /tmp/meshvenv/bin/python tests/meshes/make_meshes.py

Every file holds the same block: 30 x 20 x 20 mm (coordinates in m), 3 x 2 x 2 hexahedra,
the 6 cells with x < 15 mm in part 1 ("left"), the 6 others in part 2 ("right"):

| file | written by | format |
|---|---|---|
| vtk-appended-zlib.vtu | VTK 9.7 vtkXMLUnstructuredGridWriter, its defaults | appended raw data, zlib compressed, UInt32 headers |
| vtk-binary-base64.vtu | VTK, SetDataModeToBinary | inline base64, zlib |
| vtk-ascii.vtu | VTK, SetDataModeToAscii | ASCII |
| vtk-appended-lz4.vtu | VTK, SetCompressorTypeToLZ4 | appended raw, LZ4 |
| vtk-appended-plain.vtu | VTK, SetCompressorTypeToNone, EncodeAppendedData | appended base64, no compression |
| vtk-legacy-ascii.vtk | VTK vtkUnstructuredGridWriter | legacy ASCII |
| vtk-legacy-binary.vtk | VTK vtkUnstructuredGridWriter, SetFileTypeToBinary | legacy binary (big-endian) |
| meshio-default.vtu | meshio 5.3 | inline base64, zlib |
| meshio-ascii.vtu | meshio, binary=False | ASCII |
| meshio-legacy.vtk | meshio | legacy binary |
| gmsh.msh | Gmsh 4.15 (transfinite, recombined) | MSH 4.1 ASCII, physical volumes "left", "right", physical surface "xmin" |
| gmsh-binary.msh | Gmsh | MSH 4.1 binary |
| abaqus.inp | this script, as Abaqus/CAE writes it (in mm) | *Part with *Node, *Element type=C3D8R, *Elset FAT/MUSCLE and their *Solid Section, *Instance, *Nset XMIN, *Elset generate |

and the files palpa must refuse: tetra.vtu (tetrahedra), mixed.vtu (hexahedra and a wedge),
inverted.vtu (a hexahedron with its faces swapped).

The VTK and meshio files carry the part as the cell array `part_id` (1, 2); the VTK ones also
name the parts in the field data `part_names`, as palpa's own frames do.
"""
import os

import meshio
import numpy as np
import vtk
from vtk.util import numpy_support as ns

HERE = os.path.dirname(os.path.abspath(__file__))
NX, NY, NZ = 3, 2, 2
SIZE = (0.030, 0.020, 0.020)


def block():
    xs = [np.linspace(0.0, SIZE[k], n + 1) for k, n in enumerate((NX, NY, NZ))]
    nid = lambda i, j, k: i + (NX + 1) * (j + (NY + 1) * k)
    pts = np.array([[xs[0][i], xs[1][j], xs[2][k]]
                    for k in range(NZ + 1) for j in range(NY + 1) for i in range(NX + 1)])
    cells, part = [], []
    for k in range(NZ):
        for j in range(NY):
            for i in range(NX):
                cells.append([nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
                              nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1),
                              nid(i, j + 1, k + 1)])
                part.append(1 if i == 0 or (i == 1 and j == 0) else 2)
    return pts, np.array(cells), np.array(part, dtype=np.int32)


def vtk_grid(pts, cells, part, cell_type=vtk.VTK_HEXAHEDRON):
    g = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    p.SetData(ns.numpy_to_vtk(pts.astype(np.float64), deep=True))
    g.SetPoints(p)
    for c, t in zip(cells, cell_type if isinstance(cell_type, list) else [cell_type] * len(cells)):
        ids = vtk.vtkIdList()
        for v in c:
            ids.InsertNextId(int(v))
        g.InsertNextCell(t, ids)
    a = ns.numpy_to_vtk(part, deep=True)
    a.SetName("part_id")
    g.GetCellData().AddArray(a)
    names = vtk.vtkStringArray()
    names.SetName("part_names")
    for n in ("", "left", "right"):
        names.InsertNextValue(n)
    g.GetFieldData().AddArray(names)
    return g


def write_xml(g, name, setup):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(os.path.join(HERE, name))
    w.SetInputData(g)
    setup(w)
    assert w.Write() == 1, name


def main():
    pts, cells, part = block()
    g = vtk_grid(pts, cells, part)
    write_xml(g, "vtk-appended-zlib.vtu", lambda w: None)
    write_xml(g, "vtk-binary-base64.vtu", lambda w: w.SetDataModeToBinary())
    write_xml(g, "vtk-ascii.vtu", lambda w: w.SetDataModeToAscii())
    write_xml(g, "vtk-appended-lz4.vtu", lambda w: w.SetCompressorTypeToLZ4())

    def plain(w):
        w.SetCompressorTypeToNone()
        w.SetEncodeAppendedData(1)
    write_xml(g, "vtk-appended-plain.vtu", plain)
    for name, binary in (("vtk-legacy-ascii.vtk", False), ("vtk-legacy-binary.vtk", True)):
        w = vtk.vtkUnstructuredGridWriter()
        w.SetFileName(os.path.join(HERE, name))
        w.SetInputData(g)
        if binary:
            w.SetFileTypeToBinary()
        assert w.Write() == 1, name
    m = meshio.Mesh(pts, [("hexahedron", cells)], cell_data={"part_id": [part]})
    m.write(os.path.join(HERE, "meshio-default.vtu"))
    m.write(os.path.join(HERE, "meshio-ascii.vtu"), binary=False)
    m.write(os.path.join(HERE, "meshio-legacy.vtk"))
    gmsh_files()
    abaqus(pts, cells, part)
    # Files palpa must refuse.
    tets = np.array([[c[0], c[1], c[3], c[4]] for c in cells])
    meshio.Mesh(pts, [("tetra", tets)]).write(os.path.join(HERE, "tetra.vtu"))
    wedge = np.array([[cells[0][0], cells[0][1], cells[0][3], cells[0][4], cells[0][5], cells[0][7]]])
    meshio.Mesh(pts, [("hexahedron", cells[1:]), ("wedge", wedge)]).write(os.path.join(HERE, "mixed.vtu"))
    bad = cells.copy()
    bad[0] = np.concatenate([bad[0][4:], bad[0][:4]])
    meshio.Mesh(pts, [("hexahedron", bad)]).write(os.path.join(HERE, "inverted.vtu"))


def gmsh_files():
    import gmsh
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("block")
    a = gmsh.model.occ.addBox(0, 0, 0, 0.010, 0.020, 0.020)
    b = gmsh.model.occ.addBox(0.010, 0, 0, 0.020, 0.020, 0.020)
    gmsh.model.occ.fragment([(3, a)], [(3, b)])
    gmsh.model.occ.synchronize()
    vols = [v for _, v in gmsh.model.getEntities(3)]
    for _, c in gmsh.model.getEntities(1):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(1, c)
        n = 3 if max(x1 - x0, y1 - y0, z1 - z0) > 0.015 else 2
        gmsh.model.mesh.setTransfiniteCurve(c, n)
    for _, s in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(s)
        gmsh.model.mesh.setRecombine(2, s)
    for v in vols:
        gmsh.model.mesh.setTransfiniteVolume(v)
        gmsh.model.mesh.setRecombine(3, v)
    left = [v for v in vols if gmsh.model.getBoundingBox(3, v)[3] < 0.011]
    right = [v for v in vols if v not in left]
    gmsh.model.addPhysicalGroup(3, left, 1, "left")
    gmsh.model.addPhysicalGroup(3, right, 2, "right")
    xmin = [s for _, s in gmsh.model.getEntities(2) if gmsh.model.getBoundingBox(2, s)[3] < 1e-6]
    gmsh.model.addPhysicalGroup(2, xmin, 3, "xmin")
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.write(os.path.join(HERE, "gmsh.msh"))
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.write(os.path.join(HERE, "gmsh-binary.msh"))
    gmsh.finalize()


def abaqus(pts, cells, part):
    """The block as Abaqus/CAE writes an input file: one part in mm, its element sets and solid
    sections, one instance in the assembly, a node set there."""
    lines = ["*Heading", "** Job name: block Model name: Model-1",
             "*Preprint, echo=NO, model=NO, history=NO, contact=NO",
             "**", "** PARTS", "**", "*Part, name=BLOCK", "*Node"]
    for i, p in enumerate(pts * 1000.0, 1):
        lines.append(f"{i:7d}, {p[0]:12.6g}, {p[1]:12.6g}, {p[2]:12.6g}")
    lines.append("*Element, type=C3D8R")
    for e, c in enumerate(cells, 1):
        lines.append(f"{e}, " + ", ".join(str(v + 1) for v in c))
    for pid, name in ((1, "FAT"), (2, "MUSCLE")):
        ids = [e for e, q in enumerate(part, 1) if q == pid]
        lines.append(f"*Elset, elset={name}")
        for k in range(0, len(ids), 16):
            lines.append(", ".join(map(str, ids[k:k + 16])))
    for name, mat in (("FAT", "Fat"), ("MUSCLE", "Muscle")):
        lines += [f"** Section: Section-{name}", f"*Solid Section, elset={name}, material={mat}", ","]
    lines += ["*End Part", "**", "** ASSEMBLY", "**", "*Assembly, name=Assembly", "**",
              "*Instance, name=BLOCK-1, part=BLOCK", "*End Instance", "**",
              "*Nset, nset=XMIN, instance=BLOCK-1"]
    xmin = [i + 1 for i, p in enumerate(pts) if p[0] == 0.0]
    for k in range(0, len(xmin), 16):
        lines.append(", ".join(map(str, xmin[k:k + 16])) + ",")
    lines += ["*Elset, elset=ALL, instance=BLOCK-1, generate", f"1, {len(cells)}, 1",
              "*End Assembly", "**", "** MATERIALS", "**", "*Material, name=Fat", "*Density",
              "9.5e-10,", "*Elastic", "0.01, 0.45", "*Material, name=Muscle", "*Density",
              "1.06e-09,", "*Elastic", "0.05, 0.45"]
    with open(os.path.join(HERE, "abaqus.inp"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
