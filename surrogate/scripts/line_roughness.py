"""How rough the ROI field is in the hand's position, below any design's spacing.

A line campaign presses at points a fixed step apart along x (labels X0, X1, ...) and along y
(Y0, Y1, ...; the centre X4 is shared). For each interior point and each half-width k steps,
the mean of the two fields k steps either side predicts the point between them: at the same
time stamps, and at the same hand force (each neighbour's field interpolated linearly in its
filtered force to the point's forces, as a surrogate on force sees it). Its Fit (paper eq. 5,
pooled over the samples) is printed against the distance between the two neighbours. Then the best polynomial in the position
through all the line's fields, fitted to them, bounds every model smooth along the line.

If the field were smooth, the neighbour mean's error would shrink as the square of the
spacing. A floor that does not shrink is the field's roughness at the scale of the step: part
of the field that no surrogate built from runs farther apart can learn. With independent
roughness of relative size e (of the field's spread) at every point, the neighbour mean's
error is sqrt(1.5) e, so a surrogate that learned the smooth part perfectly would score about
1 - (1 - Fit_neighbour) / sqrt(1.5).

    python surrogate/scripts/line_roughness.py CAMPAIGN_DIR [--recover H_M]   (needs numpy)

`--recover H` (m) first averages each element's stress over the ROI with the Gaussian weights
exp(-d^2 / H^2) of `palpa train --recover` (the centroids from the dataset).
"""
import json
import sys

import numpy as np


def fit(y, yhat):
    return 1.0 - np.sqrt(((y - yhat) ** 2).sum() / ((y - y.mean()) ** 2).sum())


def recovery_matrix(d, h):
    c = np.load(f"{d}/dataset.npz")["roi_centroids"]
    d2 = ((c[:, None, :] - c[None, :, :]) ** 2).sum(-1)
    w = np.exp(-d2 / h**2)
    return w / w.sum(1, keepdims=True)


def at_force(y, f, targets):
    """A run's field at the forces `targets`, linear in its (filtered, rising) hand force."""
    order = np.argsort(f)
    return np.stack([np.interp(targets, f[order], y[order, j]) for j in range(y.shape[1])], 1)


def neighbour_mean(ys, force, a, b, c, by_force):
    """The mean of the fields of a and c predicting b's: at the same time stamps, or at b's
    forces (the samples of b inside both neighbours' force ranges)."""
    if not by_force:
        return ys[b], 0.5 * (ys[a] + ys[c])
    fb = force[b]
    keep = (fb >= max(force[a].min(), force[c].min())) & (fb <= min(force[a].max(), force[c].max()))
    pa = at_force(ys[a], force[a], fb[keep])
    pc = at_force(ys[c], force[c], fb[keep])
    return ys[b][keep], 0.5 * (pa + pc)


def smooth_fits(ys, line, step):
    """The best smooth field along the line, fitted to the answer: a polynomial of degree 1 to
    3 in the position through all the line's fields, per element and time stamp. Its Fit over
    the line (pooled mean, as the held-out Fit) bounds any model smooth over the line's length
    from above; what it leaves is the field's roughness."""
    s = np.arange(len(line)) * step
    y = np.stack([ys[l] for l in line])
    flat = y.reshape(len(line), -1)
    for deg in range(1, min(3, len(line) - 2) + 1):
        c = np.polynomial.polynomial.polyfit(s, flat, deg)
        p = np.polynomial.polynomial.polyval(s, c).T.reshape(y.shape)
        print(f"  a degree-{deg} polynomial in position over {s[-1] * 1e3:.0f} mm, fitted to "
              f"the answer: Fit {fit(y, p):.4f}")


def where_the_error_is(ys, line):
    """For the neighbour mean over two steps (3 mm for the committed line): the Fit with each
    field first averaged over 3 samples in time (a 3 ms box at 1 ms samples), the share of its
    squared error in the worst 5 % of the ROI's elements, and the share in the last 6 samples
    (20 ms on for the committed line)."""
    def box(y):
        z = y.copy()
        z[1:-1] = (y[:-2] + y[1:-1] + y[2:]) / 3.0
        return z
    mid = range(1, len(line) - 1)
    t = np.concatenate([box(ys[line[i]]) for i in mid])
    p = np.concatenate([0.5 * (box(ys[line[i - 1]]) + box(ys[line[i + 1]])) for i in mid])
    print(f"  the neighbour mean over 2 steps, each field averaged over 3 samples in time: Fit {fit(t, p):.4f}")
    worst, late = [], []
    for i in mid:
        e2 = (ys[line[i]] - 0.5 * (ys[line[i - 1]] + ys[line[i + 1]])) ** 2
        by_element = np.sort(e2.sum(0))[::-1]
        worst.append(by_element[: max(1, len(by_element) // 20)].sum() / by_element.sum())
        late.append(e2[-6:].sum() / e2.sum())
    print(f"  its squared error: {min(worst):.0%}-{max(worst):.0%} in the worst 5 % of the elements, "
          f"{min(late):.0%}-{max(late):.0%} in the last 6 samples (per point)")


def lines(labels):
    """The x line and the y line, each as a list of labels in order (the centre X4 in both)."""
    xs = sorted((l for l in labels if l.startswith("X")), key=lambda l: int(l[1:]))
    ys = sorted((l for l in labels if l.startswith("Y")), key=lambda l: int(l[1:]))
    centre = xs[len(xs) // 2]
    ys = ys[: len(ys) // 2] + [centre] + ys[len(ys) // 2 :] if ys else []
    return {"x": xs, "y": ys}


def main(d, h):
    data = np.load(f"{d}/dataset.npz")
    labels = json.load(open(f"{d}/dataset.json"))["location_labels"]
    x, field, loc = data["X"], data["Y"], data["location"]
    if h is not None:
        field = field @ recovery_matrix(d, h).T
    ys = {labels[i]: field[loc == i] for i in range(len(labels))}
    xy = {labels[i]: x[loc == i][0, :2] for i in range(len(labels))}
    force = {labels[i]: x[loc == i][:, 2] for i in range(len(labels))}
    print(f"{d}: {len(labels)} locations, {field.shape[0] // len(labels)} samples each"
          + (f", recovered over H = {h * 1e3:g} mm" if h else ", element stress"))
    for axis, line in lines(labels).items():
        if len(line) < 3:
            continue
        step = np.linalg.norm(xy[line[1]] - xy[line[0]])
        print(f"\nalong {axis}: {len(line)} points {step * 1e3:.2f} mm apart")
        n = len(line)
        for by_force in (False, True):
            print("  at the same " + ("force" if by_force else "time stamps")
                  + ": neighbours apart (mm) | Fit of the neighbour mean, pooled | per point")
            for k in range(1, n // 2 + 1):
                fits, ally, allp = [], [], []
                for i in range(k, n - k):
                    y, p = neighbour_mean(ys, force, line[i - k], line[i], line[i + k], by_force)
                    fits.append(fit(y, p))
                    ally.append(y)
                    allp.append(p)
                pooled = fit(np.concatenate(ally), np.concatenate(allp))
                per = " ".join(f"{f:.3f}" for f in fits)
                kept = sum(len(a) for a in ally)
                total = sum(len(ys[line[i]]) for i in range(k, n - k))
                print(f"    {2 * k * step * 1e3:7.1f} | {pooled:.4f} | {per}"
                      + (f"  ({kept} of {total} samples inside both neighbours' forces)" if by_force else ""))
        smooth_fits(ys, line, step)
        where_the_error_is(ys, line)
        ends = " ".join(f"{force[l][-1]:.1f}" for l in line)
        print(f"  hand force at the end (1 ms centred average): {ends} N")


if __name__ == "__main__":
    args = sys.argv[1:]
    h = None
    if "--recover" in args:
        i = args.index("--recover")
        h = float(args[i + 1])
        del args[i : i + 2]
    main(args[0], h)
