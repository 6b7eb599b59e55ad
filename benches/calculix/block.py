"""The benchmark block, written once for CalculiX (an .inp deck) and once for palpa (a scene).

A cube of side SIDE split into n x n x n eight-node hexahedra (n = 32: 32,768 elements,
35,937 nodes). The bottom face (z = 0) is clamped. The top face (z = SIDE) is held in x and y
and pressed down by PRESS, following a smooth step (10 t^3 - 15 t^4 + 6 t^5) sampled at
AMP_POINTS points over the time of the longest run, the same piecewise-linear table in both
codes. The step is fixed at DT in both, so a run of N increments ends at N * DT.

Material: neo-Hookean, mu = 40 kPa, nu = 0.45 (K = 386.7 kPa), rho = 1000 kg/m^3.
CalculiX's NEO HOOKE potential is U = C10 (I1bar - 3) + (J - 1)^2 / D1, so C10 = mu / 2 and
D1 = 2 / K. palpa's neo_hookean is mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2 with
lambda = K - 2 mu / 3: the same initial shear and bulk moduli (the two potentials differ at
second order in the strain).

Elements: CalculiX C3D8R (one point, its own Flanagan-Belytschko hourglass control, stiffness
form); palpa one_point with viscous hourglass control (the stiffness form changes the compared
figures by under 0.2 %). palpa's bulk viscosity is switched off, since CalculiX has none.
Time integration: central differences in both (CalculiX with ALPHA=0; its default -0.05 damps).
DT is below both codes' stable step; CalculiX would otherwise scale masses to reach it.
Units: SI (m, kg, s, N, Pa) in both.
"""

SIDE = 0.032  # m
MU = 40e3  # Pa
NU = 0.45
K = 2.0 * MU * (1.0 + NU) / (3.0 * (1.0 - 2.0 * NU))  # Pa
RHO = 1000.0  # kg/m^3
PRESS = 0.0016  # m: 5 % of the side at the end of the longest run
DT = 15e-6  # s: below both codes' stable step for 1 mm elements (CalculiX: 18.7 us)
AMP_POINTS = 41
OUTPUTS = 4  # output blocks per run (reactions, the probe's displacement)


def probe_node(n):
    """The centre node of the face x = SIDE: its x displacement is the bulge."""
    return node_id(n, n, n // 2, n // 2)


def amplitude(t_end):
    """(time, fraction) pairs of the smooth step from 0 at t = 0 to 1 at t_end."""
    pts = []
    for i in range(AMP_POINTS):
        s = i / (AMP_POINTS - 1)
        pts.append((s * t_end, s**3 * (10.0 - 15.0 * s + 6.0 * s * s)))
    return pts


def node_id(n, i, j, k):
    """1-based id of the grid node (i, j, k), x fastest."""
    return 1 + i + (n + 1) * (j + (n + 1) * k)


def write_inp(path, n, steps, t_ramp):
    """CalculiX deck: `steps` explicit increments of DT, the press ramped over t_ramp."""
    h = SIDE / n
    out = ["*HEADING", f"palpa benchmark block {n}^3 C3D8R neo-Hooke, {steps} increments"]
    out.append("*NODE, NSET=NALL")
    for k in range(n + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                out.append(f"{node_id(n, i, j, k)}, {i * h:.9e}, {j * h:.9e}, {k * h:.9e}")
    out.append("*ELEMENT, TYPE=C3D8R, ELSET=EALL")
    e = 0
    for k in range(n):
        for j in range(n):
            for i in range(n):
                e += 1
                c = [node_id(n, i + a, j + b, k + z) for z, b, a in
                     ((0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0),
                      (1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 1, 0))]
                out.append(f"{e}, " + ", ".join(map(str, c)))
    out += ["*NSET, NSET=NPROBE", str(probe_node(n))]
    for name, k in (("NBOT", 0), ("NTOP", n)):
        out.append(f"*NSET, NSET={name}")
        ids = [node_id(n, i, j, k) for j in range(n + 1) for i in range(n + 1)]
        out.extend(", ".join(map(str, ids[p:p + 16])) for p in range(0, len(ids), 16))
    out += ["*MATERIAL, NAME=TISSUE", "*HYPERELASTIC, NEO HOOKE",
            f"{MU / 2.0:.9e}, {2.0 / K:.9e}", "*DENSITY", f"{RHO:.9e}",
            "*SOLID SECTION, ELSET=EALL, MATERIAL=TISSUE"]
    out.append("*AMPLITUDE, NAME=PRESS")
    pts = amplitude(t_ramp)
    for p in range(0, len(pts), 4):
        out.append(", ".join(f"{t:.9e}, {a:.9e}" for t, a in pts[p:p + 4]))
    out += ["*BOUNDARY", "NBOT, 1, 3", "NTOP, 1, 2",
            f"*STEP, NLGEOM, INC={10 * steps + 100}",
            # ALPHA=0: plain central differences (the default -0.05 damps, as gamma = 0.55).
            # No DIRECT: with it ccx 2.20 leaves the explicit increment at zero. Without it the
            # increment is the Courant one, bounded by the minimum and maximum given here (both DT).
            "*DYNAMIC, EXPLICIT, ALPHA=0", f"{DT:.9e}, {steps * DT:.9e}, {DT:.9e}, {DT:.9e}",
            "*BOUNDARY, AMPLITUDE=PRESS", f"NTOP, 3, 3, {-PRESS:.9e}",
            # Output every steps/OUTPUTS increments (FREQUENCY applies to every print request):
            # the time of each block proves the increment count; totals only, a single node.
            f"*NODE PRINT, NSET=NBOT, TOTALS=ONLY, FREQUENCY={steps // OUTPUTS}", "RF",
            "*NODE PRINT, NSET=NTOP, TOTALS=ONLY", "RF",
            "*NODE PRINT, NSET=NPROBE", "U",
            "*END STEP"]
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def write_toml(path, n, steps, t_ramp, precision="f64"):
    """palpa scene: `steps` steps of DT (dt_max below the stable step), same press, element
    kernels in `precision` (f64 or f32)."""
    pts = amplitude(t_ramp)
    times = ", ".join(f"{t:.9e}" for t, _ in pts)
    values = ", ".join(f"{-PRESS * a:.9e}" for _, a in pts)
    end = steps * DT
    text = f"""# benchmark block {n}^3, one-point neo-Hookean, {steps} steps (benches/calculix)
[run]
title = "calculix comparison block"
end_time = {end!r}
dt_max = {DT!r}
precision = "{precision}"

[mesh]
generator = "box"
size = [{SIDE!r}, {SIDE!r}, {SIDE!r}]
divisions = [{n}, {n}, {n}]
part = "block"

[materials.tissue]
law = "neo_hookean"
density = {RHO!r}
shear_modulus = {MU!r}
bulk_modulus = {K!r}

[[part]]
name = "block"
material = "tissue"
formulation = "one_point"
hourglass = "viscous"

[bulk_viscosity]
enabled = false

[[boundary]]
nodes = "zmin"
fix = ["all"]
[[boundary]]
nodes = "zmax"
fix = ["x", "y"]
[[boundary]]
nodes = "zmax"
displacement = {{ z = {{ kind = "table", time = [{times}], value = [{values}] }} }}

[output]
# Frames at t = 0 and at the end (the probe's displacement). History rows a hair before each
# quarter, so that round-off in the summed step times cannot push a row one step late.
interval = {end!r}
fields = ["displacement"]
history_interval = {end / OUTPUTS * (1 - 1e-6)!r}
reactions = ["zmin", "zmax"]
"""
    with open(path, "w") as f:
        f.write(text)
