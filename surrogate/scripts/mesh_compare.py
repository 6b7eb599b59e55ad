"""Two campaigns of the same locations on two meshes: is the ROI stress converged, and does the
finer mesh give a field that the raster resolves better?

For every location the two campaigns share (by label) it prints the force at each sample and
each run's peak ROI stress. Then, on common ground (the coarse campaign's ROI elements with a
fine ROI centroid within `--radius`, the fine field read there by inverse-distance weighting of
its 4 nearest elements), it prints:
- the Fit (paper eq. 5) with which the fine field predicts the coarse one, location by
  location: 1 when the ROI stress is converged in the mesh;
- the mean of each location's two raster neighbours along x (same row, the nearest on each
  side) predicting it, on each mesh: how much the field changes over one raster spacing,
  i.e. what bounds a surrogate trained on the raster (`idw_baseline.py` prints the same on the
  whole ROI of one campaign).

With `--smooth H` both fields are first averaged over their own ROI with a Gaussian of width H
(m) and compared at the common-ground centroids: whether the field converges at a scale coarser
than one element.

    python surrogate/scripts/mesh_compare.py COARSE_DIR FINE_DIR [--radius 0.002] [--smooth 0.005]
    (needs numpy, scipy)

Example (3 mm default against the 2.5 mm row of `scenes/campaign-convergence-2.5mm.toml`):
    python surrogate/scripts/mesh_compare.py data/default-campaign-3mm results/convergence-2.5mm
"""
import argparse
import sys

import numpy as np
from scipy.spatial import cKDTree

from idw_baseline import fit  # paper eq. 5, beside this script
from model_probes import Data  # the dataset reader of the probes, beside this script


class Campaign:
    """One campaign's ROI centroids, and its fields, forces and hand positions by label."""

    def __init__(self, d):
        try:
            z = Data(d)
        except (OSError, KeyError, ValueError) as e:
            print(f"error: {d}: {e}", file=sys.stderr)
            sys.exit(2)
        self.c = z.c
        locs = [(z.labels[l], z.loc == l) for l in np.unique(z.loc)]
        self.field = {name: z.y[rows] for name, rows in locs}
        self.force = {name: z.x[rows, 2] for name, rows in locs}
        self.xy = {name: z.x[rows][0, :2] for name, rows in locs}


def neighbours_x(c, label):
    """The nearest location on each side of `label` along x in its row, or None."""
    p = c.xy[label]
    row = [g for g in c.xy if g != label and abs(c.xy[g][1] - p[1]) < 1e-6]
    left = [g for g in row if c.xy[g][0] < p[0]]
    right = [g for g in row if c.xy[g][0] > p[0]]
    if not left or not right:
        return None
    return max(left, key=lambda g: c.xy[g][0]), min(right, key=lambda g: c.xy[g][0])


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("coarse")
    ap.add_argument("fine")
    ap.add_argument("--radius", type=float, default=0.002, help="common ground: fine centroid within this distance (m)")
    ap.add_argument("--smooth", type=float, default=0.0,
                    help="compare Gaussian averages of each field over its own ROI, exp(-d^2 / h^2) with this h (m), "
                         "instead of the element values: is a smoothed field converged?")
    a = ap.parse_args(argv)
    cs, fn = Campaign(a.coarse), Campaign(a.fine)
    shared = [l for l in fn.field if l in cs.field]
    if not shared:
        print("error: the two campaigns share no location label", file=sys.stderr)
        sys.exit(2)
    dist, idx = cKDTree(fn.c).query(cs.c, 4)
    ground = dist[:, 0] < a.radius
    w = 1.0 / np.maximum(dist, 1e-12)
    w /= w.sum(1, keepdims=True)

    def gauss(c, l):
        q = cs.c[ground]
        k = np.exp(-((q[:, None, :] - c.c[None]) ** 2).sum(2) / a.smooth**2)
        return c.field[l] @ (k / k.sum(1, keepdims=True)).T

    def on_ground(c, l):
        if a.smooth > 0:
            return gauss(c, l)
        return c.field[l][:, ground] if c is cs else (fn.field[l][:, idx] * w[None]).sum(2)[:, ground]

    print(f"ROI: coarse {len(cs.c)} elements, fine {len(fn.c)}; common ground {ground.sum()} coarse elements"
          + (f"; fields smoothed over h = {a.smooth * 1e3:g} mm" if a.smooth > 0 else ""))
    for l in shared:
        print(f"{l}: force coarse {np.round(cs.force[l], 1)} N, fine {np.round(fn.force[l], 1)} N; "
              f"peak ROI stress {cs.field[l].max() / 1e3:.2f} / {fn.field[l].max() / 1e3:.2f} kPa; "
              f"fine predicts coarse on common ground: Fit {fit(on_ground(cs, l), on_ground(fn, l)):.3f}")
    for l in shared:
        nb = neighbours_x(fn, l)
        if nb is None or any(g not in cs.field for g in nb):
            continue
        own = [fit(c.field[l], 0.5 * (c.field[nb[0]] + c.field[nb[1]])) for c in (cs, fn)]
        common = [fit(on_ground(c, l), 0.5 * (on_ground(c, nb[0]) + on_ground(c, nb[1]))) for c in (cs, fn)]
        print(f"{l} from {nb[0]} and {nb[1]}: neighbour mean Fit coarse / fine {own[0]:.3f} / {own[1]:.3f} "
              f"(own ROI), {common[0]:.3f} / {common[1]:.3f} (common ground)")


if __name__ == "__main__":
    main(sys.argv[1:])
