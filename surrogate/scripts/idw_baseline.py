"""Two yardsticks for a surrogate's held-out Fit (paper eq. 5), from the campaign's data alone.

- IDW: each test location's ROI stress predicted by inverse-distance weighting of its 4 nearest
  training locations at the same time stamps. It uses no force input: a baseline a model
  should beat.
- Oracle: the best least-squares blend of those 4 neighbours' fields, with weights fitted per
  time stamp to the test location's own answer. No model that blends neighbouring fields can
  do better. It shows how much of the test field the raster resolves at all.

    python surrogate/scripts/idw_baseline.py CAMPAIGN_DIR   (needs numpy)
"""
import json
import sys

import numpy as np


def fit(y, yhat):
    return 1.0 - np.sqrt(((y - yhat) ** 2).sum() / ((y - y.mean()) ** 2).sum())


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
        near = sorted(train, key=lambda g: np.linalg.norm(xy[g] - xy[t]))[:4]
        w = np.array([1.0 / max(np.linalg.norm(xy[g] - xy[t]), 1e-9) for g in near])
        w /= w.sum()
        pred = sum(wi * ys[g] for wi, g in zip(w, near))
        oracle = []
        for k in range(len(ys[t])):
            a = np.stack([ys[g][k] for g in near], 1)
            c, *_ = np.linalg.lstsq(a, ys[t][k], rcond=None)
            oracle.append(a @ c)
        oracle = np.array(oracle)
        print(f"{t}: neighbours {near}, IDW Fit {fit(ys[t], pred):.3f}, oracle {fit(ys[t], oracle):.3f}")
        all_y.append(ys[t])
        all_p.append(pred)
        all_o.append(oracle)
    y = np.vstack(all_y)
    print(f"all test samples: IDW Fit {fit(y, np.vstack(all_p)):.3f}, oracle {fit(y, np.vstack(all_o)):.3f}")


if __name__ == "__main__":
    main(sys.argv[1])
