"""Do the two codes compute the same motion? Their reactions and bulge side by side.

At each output time of the 400-increment runs: the z reaction of the clamped bottom face and
of the pressed top face (CalculiX: the RF totals of NBOT and NTOP; palpa: history.csv's
zmin/zmax reactions; both the force the constraint exerts on the body, palpa's with the
constrained nodes' inertia m a, CalculiX's static only), and at the end the displacement of the
centre node of the face x = SIDE (the bulge; palpa: its last frame).
"""
import glob
import os

import block
import results

TOLERANCE = 0.05  # relative difference above which the comparison is flagged


def _row(label, a, b, scale):
    """One printed line, the difference relative to `scale`."""
    rel = (b - a) / scale if scale else float("nan")
    flag = "" if abs(rel) <= TOLERANCE else "  <-- differs"
    print(f"  {label:<28} {a:13.5e} {b:13.5e} {100 * rel:+8.2f} %{flag}")
    return abs(rel)


def report(dat, hist, out, steps):
    """Print the comparison of one CalculiX run (its .dat blocks) and one palpa run (its
    history rows and output directory); return the largest relative difference."""
    times = sorted({t for (_, t) in dat})
    print(f"\nagreement after {steps} increments (CalculiX, palpa, palpa - CalculiX relative to "
          "CalculiX's largest value of that quantity):")
    worst = 0.0
    for key, col in (("NBOT", "zmin_reaction_z"), ("NTOP", "zmax_reaction_z")):
        scale = max(abs(dat[key, t][2]) for t in times)
        for t in times:
            row = min(hist, key=lambda r: abs(r["time"] - t))
            if abs(row["time"] - t) > 0.5 * block.DT:
                raise ValueError(f"palpa has no history row at {t} s (nearest {row['time']})")
            worst = max(worst, _row(f"{key} reaction z, {t * 1e3:.1f} ms", dat[key, t][2],
                                    row[col], scale))
    frames = sorted(glob.glob(os.path.join(out, "frame_*.vtu")))
    if not frames:
        raise ValueError(f"palpa wrote no frame in {out}")
    probe = (block.SIDE, block.SIDE / 2, block.SIDE / 2)
    u = results.palpa_point_at(frames[-1], probe)
    uc = dat["NPROBE", times[-1]]
    scale = max(abs(c) for c in uc)
    for i, axis in enumerate("xz"):
        j = "xyz".index(axis)
        worst = max(worst, _row(f"bulge node u{axis}, {times[-1] * 1e3:.1f} ms", uc[j], u[j],
                                scale))
    verdict = "agree" if worst <= TOLERANCE else "DISAGREE"
    print(f"  largest difference {100 * worst:.2f} %: the codes {verdict} "
          f"(tolerance {100 * TOLERANCE:.0f} %)")
    return worst
