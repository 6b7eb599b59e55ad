#!/usr/bin/env python3
"""Write the example LS-DYNA decks of scenes/decks/ (standard library only).

    python3 scenes/decks/make_decks.py

The decks are written the way an LS-DYNA user writes them (kg-mm-ms, fixed columns, `$`
comment lines with the field names), each with a palpa TOML twin beside it:

- block-mesh.k: the 10 mm cube, 4 x 4 x 4 hexahedra, with its node sets (xmin, ymin, zmin,
  zmax); included by the four compression decks;
- compression-elastic.k   *MAT_ELASTIC (001), no *CONTROL_UNITS: run with --units kg-mm-ms;
- compression-ogden.k     *MAT_OGDEN_RUBBER (077_O) with three Prony terms (the paper's liver),
                          *CONTROL_UNITS;
- compression-rubber.k    *MAT_SIMPLIFIED_RUBBER/FOAM (181) with its load curve, free format;
- compression-plastic.k   *MAT_PIECEWISE_LINEAR_PLASTICITY (024) (the paper's ribs);
- hertz-sphere.k          a rigid sphere meshed with shells pressed 0.5 mm into a graded quarter
                          block (*CONTROL_UNITS).

Each compression block is rolled on xmin, ymin and zmin and its top (zmax) pressed down along a
ramp (1 mm in 20 ms, then held to 30 ms).
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def f10(*vals):
    """Fixed format: 10 columns per field."""
    out = ""
    for v in vals:
        s = "" if v is None else (repr(v) if isinstance(v, float) else str(v))
        out += s.rjust(10)
    return out.rstrip()


def node_line(nid, x, y, z, wide=False):
    if wide:
        return f"{nid:>20d}{x:>20.12g}{y:>20.12g}{z:>20.12g}"
    return f"{nid:>8d}{x:>16.10g}{y:>16.10g}{z:>16.10g}"


def block_mesh(n=4, size=10.0):
    h = size / n
    nid = lambda i, j, k: 1 + i + (n + 1) * (j + (n + 1) * k)
    lines = ["$ The 10 mm cube, 4 x 4 x 4 hexahedra (coordinates in mm), part 1.",
             "*NODE", "$    NID               X               Y               Z"]
    for k in range(n + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                lines.append(node_line(nid(i, j, k), i * h, j * h, k * h))
    lines += ["*ELEMENT_SOLID", "$    EID     PID      N1      N2      N3      N4      N5      N6      N7      N8"]
    e = 1
    for k in range(n):
        for j in range(n):
            for i in range(n):
                c = [nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
                     nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1), nid(i, j + 1, k + 1)]
                lines.append(f"{e:>8d}{1:>8d}" + "".join(f"{x:>8d}" for x in c))
                e += 1
    sets = {
        "xmin": [nid(0, j, k) for k in range(n + 1) for j in range(n + 1)],
        "ymin": [nid(i, 0, k) for k in range(n + 1) for i in range(n + 1)],
        "zmin": [nid(i, j, 0) for j in range(n + 1) for i in range(n + 1)],
        "zmax": [nid(i, j, n) for j in range(n + 1) for i in range(n + 1)],
    }
    for sid, (name, nodes) in enumerate(sets.items(), 1):
        lines += ["*SET_NODE_LIST_TITLE", name, f10(sid)]
        for a in range(0, len(nodes), 8):
            lines.append(f10(*sorted(nodes)[a:a + 8]))
    return "\n".join(lines) + "\n"


COMMON = """$ Rollers on xmin, ymin, zmin; the top face pressed 1 mm down in 20 ms, then held.
*BOUNDARY_SPC_SET
$     NSID       CID      DOFX      DOFY      DOFZ     DOFRX     DOFRY     DOFRZ
         1         0         1         0         0
         2         0         0         1         0
         3         0         0         0         1
*BOUNDARY_PRESCRIBED_MOTION_SET
$     NSID       DOF       VAD      LCID        SF
         4         3         2         1      -1.0
*DEFINE_CURVE_TITLE
top displacement (mm) against time (ms)
$     LCID
         1
                 0.0                 0.0
                20.0                 1.0
                30.0                 1.0
*CONTROL_TERMINATION
$   ENDTIM
      30.0
*CONTROL_TIMESTEP
$   DTINIT    TSSFAC
       0.0       0.9
*DATABASE_BINARY_D3PLOT
$       DT
       5.0
*DATABASE_GLSTAT
       0.1
*DATABASE_SPCFORC
       0.1
*DATABASE_BNDOUT
       0.1
*INCLUDE
block-mesh.k
*END
"""

PART = """*PART
block
$      PID     SECID       MID     EOSID      HGID
         1         1         1         0         1
*SECTION_SOLID
$    SECID    ELFORM
         1         1
*HOURGLASS
$     HGID       IHQ        QM
         1         2       0.1
"""


TWIN_COMMON = """
[[boundary]]
nodes = "xmin"
symmetry = "x"
[[boundary]]
nodes = "ymin"
symmetry = "y"
[[boundary]]
nodes = "zmin"
symmetry = "z"
[[boundary]]
nodes = "zmax"
displacement = { z = { kind = "table", time = ["0 ms", "20 ms", "30 ms"], value = ["0 mm", "-1 mm", "-1 mm"] } }

[output]
interval = "5 ms"
history_interval = "0.1 ms"
fields = ["displacement", "velocity", "part", "stress", "von_mises", "max_principal"]
reactions = ["xmin", "ymin", "zmin", "zmax"]
"""


def twin(name, title, card):
    """The palpa scene the deck stands for (the box generator's cube)."""
    text = f"""# The TOML twin of {name.replace('.toml', '.k')} (written by make_decks.py): the same
# block, law, element, boundary conditions and output in palpa's scene format.
[run]
title = "{title}"
end_time = "30 ms"
dt_factor = 0.9

[mesh]
generator = "box"
size = ["10 mm", "10 mm", "10 mm"]
divisions = [4, 4, 4]
part = "block"

[materials.m]
{card}
[[part]]
name = "block"
material = "m"
formulation = "one_point"
hourglass = "viscous"
hourglass_coefficient = 0.1
""" + TWIN_COMMON
    with open(os.path.join(HERE, name), "w") as f:
        f.write(text)


def compression(name, title, material, units=False):
    head = f"*KEYWORD\n*TITLE\n{title}\n"
    if units:
        head += "*CONTROL_UNITS\n$ LENGTH     TIME      MASS\nmm        ms        kg\n"
    head += "$ Units kg-mm-ms: stresses in GPa, densities in kg/mm^3.\n"
    with open(os.path.join(HERE, name), "w") as f:
        f.write(head + PART + material + COMMON)


ELASTIC = """*MAT_ELASTIC
$      MID        RO         E        PR
         1    1.0e-6    1.0e-3       0.3
"""
OGDEN = """*MAT_OGDEN_RUBBER
$ The paper's liver: three Ogden terms (original form) and three Prony terms.
$      MID        RO        PR         N        NV         G      SIGF       REF
         1   1.05e-6      0.49         0
$      MU1       MU2       MU3
  8.914e-8  9.965e-9 -9.275e-8
$   ALPHA1    ALPHA2    ALPHA3
       1.0   19.0656  -10.9604
$       GI     BETAI
 6.9701e-6       0.1
 5.8327e-5      0.01
 3.5291e-5     0.001
"""
RUBBER = """*MAT_SIMPLIFIED_RUBBER/FOAM
$ Free format. The curve is force (kN) against the change of a 10 mm gauge length of a
$ 2 x 5 mm specimen: nominal stress -140, 0, 42.2 kPa at stretches 0.5, 1, 1.5.
$ MID,RO,KM,MU,G
1,1.06e-6,2.0e-3,0.4,4.0e-5
$ SGL,SW,ST,LC
10.0,2.0,5.0,2
*DEFINE_CURVE_TITLE
force against change in gauge length
$ LCID
2
-5.0,-1.4e-3
0.0,0.0
5.0,4.22e-4
"""
PLASTIC = """*MAT_PIECEWISE_LINEAR_PLASTICITY
$ The paper's ribs: bilinear, yield 1.8 MPa, tangent modulus 1 MPa.
$      MID        RO         E        PR      SIGY      ETAN
         1    1.0e-6      0.04      0.45    0.0018     0.001
$        C         P      LCSS
       0.0       0.0         0
$ EPS1-8 and ES1-8 left blank (the bilinear curve of SIGY and ETAN)


"""


HERTZ_TWIN = f"""# The TOML twin of hertz-sphere.k (written by make_decks.py): the same graded quarter block,
# law, damping and contact penalty, pressed by an exact (analytic) sphere instead of a meshed one.
[run]
title = "Hertz sphere (twin)"
end_time = "70 ms"

[mesh]
generator = "box"
origin = ["0 mm", "0 mm", "-60 mm"]
size = ["60 mm", "60 mm", "60 mm"]
divisions = [12, 12, 12]
grading = [66.0, 66.0, 0.01515]
part = "gel"

[materials.gel]
law = "ogden"
density = "1e-6 kg/mm^3"
mu = ["{f"{30e-6 / (2 * 1.49):.5e}".replace("e-05", "e-5")} GPa"]
alpha = [2.0]
poisson_ratio = 0.49

[[part]]
name = "gel"
material = "gel"

[[boundary]]
nodes = "xmin"
symmetry = "x"
[[boundary]]
nodes = "ymin"
symmetry = "y"
[[boundary]]
nodes = "zmin"
symmetry = "z"

[damping]
mass_proportional = "0.02 1/ms"

[[indenter]]
name = "sphere"
direction = [0, 0, -1]
motion = {{ kind = "displacement", curve = {{ kind = "smooth_step", value = "0.5 mm", end = "60 ms" }} }}
part = [{{ shape = "sphere", center = ["0 mm", "0 mm", "5 mm"], radius = "5 mm" }}]

[contact]
surface = "zmax"
penalty = "max"
soft_scale = 0.4

[output]
interval = "10 ms"
history_interval = "0.5 ms"
"""


def hertz(n=12, segments=24):
    """Quarter block 60 mm, graded towards the contact (ratios 66, 66, 1/66 as the TOML twin),
    and a rigid sphere of radius 5 mm centred 5 mm above the surface, meshed with quads: a
    cube-sphere of `segments` quads per cube edge (4 x 24 = 96 around a great circle: facets of
    0.33 mm, whose chord lies 2.7 um inside the sphere, 3 % of the smallest depth compared)."""
    def graded(x0, length, m, ratio):
        q = ratio ** (1.0 / (m - 1))
        h0 = length * (q - 1.0) / (q ** m - 1.0)
        xs, x = [x0], x0
        for k in range(m):
            x += h0 * q ** k
            xs.append(x)
        xs[m] = x0 + length
        return xs
    xs = graded(0.0, 60.0, n, 66.0)
    zs = graded(-60.0, 60.0, n, 0.01515)
    nid = lambda i, j, k: 1 + i + (n + 1) * (j + (n + 1) * k)
    mu = f"{30e-6 / (2 * 1.49):.5e}".replace("e-05", "e-5")
    L = ["*KEYWORD", "*TITLE", "Hertz sphere (deck)",
         "$ A rigid sphere (R = 5 mm, shells) pressed 0.5 mm into a quarter block of gel",
         "$ (one-term Ogden, alpha = 2: neo-Hookean, E = 30 kPa, nu = 0.49).",
         "*CONTROL_UNITS", "$ LENGTH     TIME      MASS", "mm        ms        kg",
         "*CONTROL_TERMINATION", "$   ENDTIM", f10(70.0),
         "*DAMPING_GLOBAL", "$     LCID    VALDMP", f10(None, 0.02),
         "*PART", "gel", "$      PID     SECID       MID", f10(1, 1, 1),
         "*SECTION_SOLID", f10(1, 1),
         "*MAT_OGDEN_RUBBER", "$      MID        RO        PR", f10(1, "1.0e-6", 0.49),
         "$      MU1", mu.rjust(10), "$   ALPHA1", f10(2.0),
         "*PART", "sphere", f10(2, 2, 2),
         "*SECTION_SHELL", f10(2, 2), "$       T1        T2        T3        T4",
         f10("1.0e-3", "1.0e-3", "1.0e-3", "1.0e-3"),
         "*MAT_RIGID", "$      MID        RO         E        PR", f10(2, "1.0e-6", "1.0e-3", 0.3),
         "$      CMO      CON1      CON2", f10(1.0, 4, 7),
         "*BOUNDARY_PRESCRIBED_MOTION_RIGID", "$      PID       DOF       VAD      LCID        SF",
         f10(2, 3, 2, 1, -1.0),
         "*DEFINE_CURVE_TITLE", "sphere travel (mm): quintic smooth step over 60 ms, held to 70 ms",
         f10(1)]
    for k in range(61):
        t = k * 1.0
        r = t / 60.0
        L.append(f"{t:>20.12g}{0.5 * r ** 3 * (10 - 15 * r + 6 * r * r):>20.12g}")
    L.append(f"{70.0:>20.12g}{0.5:>20.12g}")
    L += ["*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE",
          "$ slave: the top face (segment set 1); master: the sphere (part 2); SOFT = 1",
          "$     SSID      MSID     SSTYP     MSTYP", f10(1, 2, 0, 3), "", "",
          "$     SOFT    SOFSCL", f10(1, 0.4),
          "*SET_NODE_LIST_TITLE", "xmin", f10(1)]
    def put_set(ids):
        for a in range(0, len(ids), 8):
            L.append(f10(*ids[a:a + 8]))
    put_set([nid(0, j, k) for k in range(n + 1) for j in range(n + 1)])
    L += ["*SET_NODE_LIST_TITLE", "ymin", f10(2)]
    put_set([nid(i, 0, k) for k in range(n + 1) for i in range(n + 1)])
    L += ["*SET_NODE_LIST_TITLE", "zmin", f10(3)]
    put_set([nid(i, j, 0) for j in range(n + 1) for i in range(n + 1)])
    L += ["*BOUNDARY_SPC_SET", "$     NSID       CID      DOFX      DOFY      DOFZ",
          f10(1, 0, 1), f10(2, 0, 0, 1), f10(3, 0, 0, 0, 1),
          "*SET_SEGMENT_TITLE", "top face", f10(1)]
    for j in range(n):
        for i in range(n):
            L.append(f10(nid(i, j, n), nid(i + 1, j, n), nid(i + 1, j + 1, n), nid(i, j + 1, n)))
    L += ["*DATABASE_BINARY_D3PLOT", f10(10.0), "*DATABASE_GLSTAT", f10(0.5),
          "*DATABASE_RCFORC", f10(0.5), "*NODE"]
    for k in range(n + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                L.append(node_line(nid(i, j, k), xs[i], xs[j], zs[k]))
    # The sphere: a cube-sphere of quads (segments per cube edge), nodes after the block's.
    base = (n + 1) ** 3
    keys, index, quads = [], {}, []
    m = segments
    def vid(key):
        if key not in index:
            index[key] = len(keys)
            keys.append(key)
        return index[key]
    for axis in range(3):
        for side in (0, m):
            for i in range(m):
                for j in range(m):
                    def pt(a, b):
                        k = [0, 0, 0]
                        k[axis], k[(axis + 1) % 3], k[(axis + 2) % 3] = side, a, b
                        return tuple(k)
                    q = [vid(pt(i, j)), vid(pt(i + 1, j)), vid(pt(i + 1, j + 1)), vid(pt(i, j + 1))]
                    quads.append(q if side == m else q[::-1])
    for idx, key in enumerate(keys):
        x, y, z = (2.0 * c / m - 1.0 for c in key)
        sx = x * math.sqrt(1 - y * y / 2 - z * z / 2 + y * y * z * z / 3)
        sy = y * math.sqrt(1 - z * z / 2 - x * x / 2 + z * z * x * x / 3)
        sz = z * math.sqrt(1 - x * x / 2 - y * y / 2 + x * x * y * y / 3)
        L.append(node_line(base + idx + 1, 5.0 * sx, 5.0 * sy, 5.0 + 5.0 * sz))
    L += ["*ELEMENT_SOLID"]
    e = 1
    for k in range(n):
        for j in range(n):
            for i in range(n):
                c = [nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
                     nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1), nid(i, j + 1, k + 1)]
                L.append(f"{e:>8d}{1:>8d}" + "".join(f"{x:>8d}" for x in c))
                e += 1
    L += ["*ELEMENT_SHELL"]
    for q in quads:
        L.append(f"{e:>8d}{2:>8d}" + "".join(f"{base + x + 1:>8d}" for x in q))
        e += 1
    L.append("*END")
    with open(os.path.join(HERE, "hertz-sphere.k"), "w") as f:
        f.write("\n".join(L) + "\n")


if __name__ == "__main__":
    with open(os.path.join(HERE, "block-mesh.k"), "w") as f:
        f.write("*KEYWORD\n" + block_mesh() + "*END\n")
    compression("compression-elastic.k", "compression block, *MAT_ELASTIC", ELASTIC)
    compression("compression-ogden.k", "compression block, *MAT_OGDEN_RUBBER", OGDEN, units=True)
    compression("compression-rubber.k", "compression block, *MAT_SIMPLIFIED_RUBBER/FOAM", RUBBER, units=True)
    compression("compression-plastic.k", "compression block, *MAT_PIECEWISE_LINEAR_PLASTICITY", PLASTIC, units=True)
    twin("compression-elastic.toml", "compression block, linear_elastic",
         'law = "linear_elastic"\ndensity = "1.0e-6 kg/mm^3"\nyoungs_modulus = "1.0e-3 GPa"\npoisson_ratio = 0.3\n')
    twin("compression-ogden.toml", "compression block, ogden", 'library = "paper:liver"\n')
    twin("compression-rubber.toml", "compression block, simplified_rubber",
         'law = "simplified_rubber"\ndensity = "1.06e-6 kg/mm^3"\nbulk_modulus = "2.0e-3 GPa"\n'
         'shear_modulus = "4.0e-5 GPa"\ndamping = 0.4\n'
         'curve = [[0.5, "-1.4e-4 GPa"], [1.0, 0], [1.5, "4.22e-5 GPa"]]\n')
    twin("compression-plastic.toml", "compression block, piecewise_linear_plasticity", 'library = "paper:ribs"\n')
    hertz()
    with open(os.path.join(HERE, "hertz-sphere.toml"), "w") as f:
        f.write(HERTZ_TWIN)
