"""Two yardsticks for a surrogate's held-out Fit (paper eq. 5), from the campaign's data alone.

- IDW: each test location's ROI stress predicted by inverse-distance weighting of its 4 nearest
  training locations at the same time stamps. It uses no force input: a baseline a model
  should beat.
- Oracle: the best least-squares blend of those 4 neighbours' fields, with weights fitted per
  time stamp to the test location's own answer. No model that blends neighbouring fields can
  do better. It shows how much of the test field the raster resolves at all. The same oracle
  over the 9 nearest and over all training locations is printed too (a GP with one shared
  kernel predicts a blend of training fields, so the all-locations oracle bounds it from above
  at each time stamp).
- Neighbour means (when the training locations form a full raster): the mean of the two
  raster neighbours predicting the point between them, along x and along y. It measures how
  much the field changes over one raster spacing.

    python surrogate/scripts/idw_baseline.py CAMPAIGN_DIR   (needs numpy)
"""
import json
import sys

import numpy as np


def fit(y, yhat):
    return 1.0 - np.sqrt(((y - yhat) ** 2).sum() / ((y - y.mean()) ** 2).sum())


def nearest(train, xy, t, k):
    """The k training locations nearest to location t in the plane."""
    return sorted(train, key=lambda g: np.linalg.norm(xy[g] - xy[t]))[:k]


def best_blend(ys, near, t):
    """Least-squares blend of the fields of `near` fitted to location t's field, per time stamp."""
    out = []
    for k in range(len(ys[t])):
        a = np.stack([ys[g][k] for g in near], 1)
        c, *_ = np.linalg.lstsq(a, ys[t][k], rcond=None)
        out.append(a @ c)
    return np.array(out)


def main(d):
    data = np.load(f"{d}/dataset.npz")
    labels = json.load(open(f"{d}/dataset.json"))["location_labels"]
    x, y, loc, split = data["X"], data["Y"], data["location"], data["split"]
    xy = {labels[i]: x[loc == i][0, :2] for i in range(len(labels))}
    ys = {labels[i]: y[loc == i] for i in range(len(labels))}
    train = sorted({labels[i] for i in loc[split == 0]})
    test = sorted({labels[i] for i in loc[split == 1]})
    all_y, all_p, all_o = [], [], []
    for t in test:
        near = nearest(train, xy, t, 4)
        w = np.array([1.0 / max(np.linalg.norm(xy[g] - xy[t]), 1e-9) for g in near])
        w /= w.sum()
        pred = sum(wi * ys[g] for wi, g in zip(w, near))
        oracle = best_blend(ys, near, t)
        print(f"{t}: neighbours {near}, IDW Fit {fit(ys[t], pred):.3f}, oracle {fit(ys[t], oracle):.3f}")
        all_y.append(ys[t])
        all_p.append(pred)
        all_o.append(oracle)
    y = np.vstack(all_y)
    print(f"all test samples: IDW Fit {fit(y, np.vstack(all_p)):.3f}, oracle {fit(y, np.vstack(all_o)):.3f}")
    for k in sorted({min(9, len(train)), len(train)} - {4}):
        oy = [best_blend(ys, nearest(train, xy, t, k), t) for t in test]
        print(f"all test samples: oracle over the {k} nearest training locations {fit(y, np.vstack(oy)):.3f}")
    neighbour_means(train, xy, ys)


def neighbour_means(train, xy, ys):
    """Mean of the two raster neighbours against the point between them, along x and y."""
    xs = sorted({round(float(xy[g][0]), 6) for g in train})
    ys_ = sorted({round(float(xy[g][1]), 6) for g in train})
    at = {(round(float(xy[g][0]), 6), round(float(xy[g][1]), 6)): g for g in train}
    if len(at) != len(xs) * len(ys_) or len(xs) < 3 or len(ys_) < 3:
        return
    for axis, name in ((0, "x"), (1, "y")):
        t, p = [], []  # per location: samples x elements
        for i, xv in enumerate(xs):
            for j, yv in enumerate(ys_):
                if (axis == 0 and 0 < i < len(xs) - 1) or (axis == 1 and 0 < j < len(ys_) - 1):
                    lo = (xs[i - 1], yv) if axis == 0 else (xv, ys_[j - 1])
                    hi = (xs[i + 1], yv) if axis == 0 else (xv, ys_[j + 1])
                    t.append(ys[at[(xv, yv)]])
                    p.append(0.5 * (ys[at[lo]] + ys[at[hi]]))
        step = (xs[1] - xs[0]) if axis == 0 else (ys_[1] - ys_[0])
        per_sample = ", ".join(
            f"{fit(np.array([a[k] for a in t]), np.array([b[k] for b in p])):.2f}"
            for k in range(1, len(t[0]))
        )
        print(
            f"raster neighbour mean along {name} (+-{step * 1e3:.1f} mm): Fit "
            f"{fit(np.vstack(t), np.vstack(p)):.3f}; each time stamp after the first alone: {per_sample}"
        )


if __name__ == "__main__":
    main(sys.argv[1])
