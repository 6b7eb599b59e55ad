"""Probes of surrogate model classes on a campaign's dataset, scored by held-out Fit (paper eq. 5).

These are the numpy / scikit-learn prototypes behind docs/surrogate.md and docs/campaigns.md. None of
them is a palpa model; each asks whether a different model class would lift the held-out Fit
above what `palpa train` gives on the same data.

- gp: a GP with one kernel shared by all outputs, as `palpa train --model gp` (inputs z-scored,
  outputs centred per element and scaled by one pooled deviation; hyperparameters by marginal
  likelihood over the rows with distinct targets, then conditioned on all rows), with the
  squared-exponential kernel and Matern 5/2, 3/2 and 1/2 kernels (ARD, plus white noise).
- gp-lolo: the same kernels with hyperparameters chosen by leave-one-location-out error on the
  training locations (Rasmussen & Williams 2006, sec. 5.4.2) instead of marginal likelihood.
- pointwise: one MLP (scikit-learn, 3 hidden layers) over every (sample, ROI element) pair, with
  inputs finger x, y, force, the element's centroid and its plan offset from the fingers, so
  that it can learn a stress pattern that moves with the hand.
- cv: model choice without the test locations. Each training location between raster
  neighbours (on all 4 sides, and, as a second set, on both sides along x or y) is left out in
  turn and predicted from the rest. Models: the GP as `palpa train` with the SE, Matern 5/2 and
  a two-scale SE + SE kernel (a narrow one for the hot spot under the fingers, a wide one for
  the background), each also over the stress per newton of contact force, Y / F (a kernel
  F F' k(x, x'), so that the stress vanishes with the force, as it does in the solver). Only
  training locations are used, so it can pick a model before anyone looks at A, B and C, and
  it runs on a campaign that is still going.
- pca: the targets projected on their k leading principal components (k = 3, 6, 10, 20), one
  GP per component with its own SE-ARD kernel (a model with a kernel per output direction
  instead of one shared kernel), scored like `cv` on the interior training locations and on
  the test locations.
- tensor: the GP as `palpa train --model gp --target tensor`: the same GP over the six Cauchy
  components of every ROI element (`S`, 6R outputs sharing one kernel), the prediction's largest
  eigenvalue per element scored against Y; scored like `cv` on the training locations (each
  interior one, and each between two raster neighbours, left out in turn) next to the GP on Y,
  then on the test locations.
- shift: inverse-distance weighting of the 4 nearest training fields, each first shifted in plan
  by a fraction alpha of the offset between its hand and the test hand (alpha 0 = plain IDW),
  the shifted field read off with a 4 mm Gaussian kernel over the ROI centroids.

    python surrogate/scripts/model_probes.py CAMPAIGN_DIR [gp] [gp-lolo] [pointwise] [shift] [cv] [pca] [tensor]
    (needs numpy, scipy and scikit-learn; the pointwise probe takes a few minutes)
"""
import json
import sys
import warnings

import numpy as np

from idw_baseline import fit  # paper eq. 5, beside this script

warnings.filterwarnings("ignore")


class Data:
    def __init__(self, d):
        z = np.load(f"{d}/dataset.npz")
        with open(f"{d}/manifest.json") as f:
            self.labels = json.load(f)["location_labels"]
        self.x, self.y = z["X"][:, :3], z["Y"]
        self.loc, self.split, self.c = z["location"], z["split"], z["roi_centroids"]
        # the stress tensors flattened element-major, n x 6R ([xx, yy, zz, xy, yz, zx] each)
        self.s6 = z["S"].reshape(len(self.y), -1) if "S" in z.files else None
        self.tr, self.te = self.split == 0, self.split != 0
        self.mu, self.sd = self.x[self.tr].mean(0), self.x[self.tr].std(0)
        self.u = (self.x - self.mu) / self.sd
        self.ym = self.y[self.tr].mean(0)
        self.s = np.sqrt(self.y[self.tr].var(0).mean())
        self.v = (self.y - self.ym) / self.s

    def report(self, name, pred):
        t = self.y[self.te]
        lt = self.loc[self.te]
        per = " / ".join(f"{self.labels[l]} {fit(t[lt == l], pred[lt == l]):.3f}" for l in np.unique(lt))
        print(f"{name}: held-out Fit {fit(t, pred):.3f} (per location {per})", flush=True)


def kernels():
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, Matern, WhiteKernel

    noise = WhiteKernel(1e-2, (1e-8, 10.0))
    return {
        "SE": ConstantKernel(1.0) * RBF([1.0] * 3, (1e-2, 1e2)) + noise,
        "Matern 5/2": ConstantKernel(1.0) * Matern([1.0] * 3, (1e-2, 1e2), nu=2.5) + noise,
        "Matern 3/2": ConstantKernel(1.0) * Matern([1.0] * 3, (1e-2, 1e2), nu=1.5) + noise,
        "Matern 1/2": ConstantKernel(1.0) * Matern([1.0] * 3, (1e-2, 1e2), nu=0.5) + noise,
        "SE + SE": ConstantKernel(1.0) * RBF([0.5] * 3, (1e-2, 1e2))
        + ConstantKernel(1.0) * RBF([2.0] * 3, (1e-2, 1e2)) + noise,
    }


def probe_gp(d):
    for name, k in kernels().items():
        pred, g = gp_fit_predict(k, d.u[d.tr], d.y[d.tr], d.u[d.te])
        lml = g.log_marginal_likelihood_value_
        d.report(f"GP {name}, marginal likelihood (log {lml:.1f}; {g.kernel_})", pred)


def probe_gp_lolo(d):
    from scipy.optimize import minimize

    u, v, loc = d.u[d.tr], d.v[d.tr], d.loc[d.tr]

    def kern(a, b, ls, nu):
        r2 = (((a[:, None, :] - b[None, :, :]) / ls) ** 2).sum(-1)
        if nu is None:
            return np.exp(-0.5 * r2)
        r = np.sqrt(r2)
        if nu == 1.5:
            return (1 + np.sqrt(3) * r) * np.exp(-np.sqrt(3) * r)
        return (1 + np.sqrt(5) * r + 5 / 3 * r2) * np.exp(-np.sqrt(5) * r)

    def predict(ua, va, ub, th, nu):
        ls, sn = np.exp(th[:3]), np.exp(th[3])
        k = kern(ua, ua, ls, nu) + sn * np.eye(len(ua))
        return kern(ub, ua, ls, nu) @ np.linalg.solve(k, va)

    def lolo(th, nu):
        sse = 0.0
        for l in np.unique(loc):
            m = loc == l
            sse += ((predict(u[~m], v[~m], u[m], th, nu) - v[m]) ** 2).sum()
        return sse

    for name, nu in (("SE", None), ("Matern 5/2", 2.5), ("Matern 3/2", 1.5)):
        best = None
        for l0 in (0.5, 1.0, 2.0):
            th0 = np.array([np.log(l0)] * 3 + [np.log(0.03)])
            r = minimize(lambda t: lolo(t, nu), th0, method="Nelder-Mead",
                         options={"maxiter": 300, "xatol": 1e-3, "fatol": 1e-6})
            if best is None or r.fun < best.fun:
                best = r
        th = best.x
        ls = ", ".join(f"{x:.2f}" for x in np.exp(th[:3]))
        d.report(f"GP {name}, leave-one-location-out hyperparameters (lengths {ls}, noise {np.exp(th[3]):.4f})",
                 predict(u, v, d.u[d.te], th, nu) * d.s + d.ym)


def gp_fit_predict(k, u, y, ut, f=None, ft=None):
    """The GP as `palpa train` (outputs centred per element, one pooled scale, hyperparameters by
    marginal likelihood over the rows with distinct targets, then conditioned on every row),
    predicting at `ut`; returns the prediction and the fitted regressor (for its likelihood).
    Given the forces `f` (training) and `ft` (prediction) it models Y / F over the rows with
    F > 0 and predicts F* times that."""
    from sklearn.gaussian_process import GaussianProcessRegressor as Gpr

    if f is not None:
        m = f > 0
        u, y = u[m], y[m] / f[m, None]
    ym, s = y.mean(0), np.sqrt(y.var(0).mean())
    v = (y - ym) / s
    _, first = np.unique(np.round(v, 12), axis=0, return_index=True)
    first = np.sort(first)
    g = Gpr(k, n_restarts_optimizer=2, random_state=0).fit(u[first], v[first])
    pred = Gpr(g.kernel_, optimizer=None).fit(u, v).predict(ut) * s + ym
    return (pred if f is None else pred * ft[:, None]), g


def max_principal(s6):
    """Largest eigenvalue per element of stress tensors flattened element-major (..., 6R)."""
    s = s6.reshape(s6.shape[:-1] + (-1, 6))
    m = np.empty(s.shape[:-1] + (3, 3))
    for c, (i, j) in enumerate(((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))):
        m[..., i, j] = m[..., j, i] = s[..., c]
    return np.linalg.eigvalsh(m)[..., -1]


def tensor_gp_fit_predict(d, tr, te):
    """The GP over the stress tensors of the rows `tr`, predicting the rows `te`; returns the
    largest eigenvalue of the predicted tensor of every ROI element and the fitted regressor."""
    pred, g = gp_fit_predict(kernels()["SE"], d.u[tr], d.s6[tr], d.u[te])
    return max_principal(pred), g


def cv_sets(d):
    """The training locations the cv probes leave out: those with raster neighbours on all 4
    sides, and those between two neighbours along x or y."""
    locs = list(np.unique(d.loc[d.tr]))
    xy = {l: d.x[d.loc == l][0, :2] for l in locs}
    step = np.array([np.diff(np.unique(np.round(d.x[d.tr, i], 6))).min() for i in (0, 1)])

    def has(l, o):
        return any(np.allclose(xy[g], xy[l] + np.array(o) * step, atol=1e-6) for g in locs)

    def between(l, axes):
        return [has(l, o) and has(l, (-o[0], -o[1])) for o in axes]

    return locs, {
        "interior (neighbours on 4 sides)": [l for l in locs if all(between(l, ((1, 0), (0, 1))))],
        "between two neighbours (along x or y)": [l for l in locs if any(between(l, ((1, 0), (0, 1))))],
    }


def probe_cv(d):
    locs, sets = cv_sets(d)
    ks = kernels()
    variants = [(name, per_newton) for name in ("SE", "Matern 5/2", "SE + SE") for per_newton in (False, True)]

    def predict(name, per_newton, tr, te):
        forces = (d.x[tr, 2], d.x[te, 2]) if per_newton else (None, None)
        return gp_fit_predict(ks[name], d.u[tr], d.y[tr], d.u[te], *forces)[0]

    for what, inner in sets.items():
        print(f"cv, {len(locs)} training locations, {what}, each left out in turn: "
              f"{' '.join(d.labels[l] for l in inner)}")
        if not inner:
            continue
        truth = [d.y[d.loc == l] for l in inner]
        for name, per_newton in variants:
            pred = [predict(name, per_newton, d.tr & (d.loc != l), d.loc == l) for l in inner]
            per = [fit(t, p) for t, p in zip(truth, pred)]
            print(f"  GP {name} on {'Y / F' if per_newton else 'Y'}: Fit {fit(np.vstack(truth), np.vstack(pred)):.3f} "
                  f"(mean {np.mean(per):.3f}, worst {min(per):.3f})", flush=True)
    if not d.te.any():
        return
    for name, per_newton in variants:
        d.report(f"GP {name} on {'Y / F' if per_newton else 'Y'}, test locations", predict(name, per_newton, d.tr, d.te))


def pca_gp_predict(u, y, ut, k):
    """Y projected on its k leading principal components (over the training rows), one GP per
    component with its own SE-ARD kernel by marginal likelihood, the rest left at the mean."""
    from sklearn.gaussian_process import GaussianProcessRegressor as Gpr

    ym = y.mean(0)
    _, _, vt = np.linalg.svd(y - ym, full_matrices=False)
    z = (y - ym) @ vt[:k].T
    pred = np.tile(ym, (len(ut), 1))
    for j in range(k):
        s = z[:, j].std()
        g = Gpr(kernels()["SE"], n_restarts_optimizer=1, random_state=0).fit(u, z[:, j] / s)
        pred += np.outer(g.predict(ut) * s, vt[j])
    return pred


def probe_pca(d):
    _, sets = cv_sets(d)
    inner = next(iter(sets.values()))
    truth = [d.y[d.loc == l] for l in inner]
    for k in (3, 6, 10, 20):
        pred = [pca_gp_predict(d.u[d.tr & (d.loc != l)], d.y[d.tr & (d.loc != l)], d.u[d.loc == l], k)
                for l in inner]
        print(f"cv, interior, GP per principal component, k = {k}: Fit {fit(np.vstack(truth), np.vstack(pred)):.3f}",
              flush=True)
        if d.te.any():
            d.report(f"GP per principal component, k = {k}", pca_gp_predict(d.u[d.tr], d.y[d.tr], d.u[d.te], k))


def probe_tensor(d):
    if d.s6 is None:
        print("tensor: the dataset holds no stress tensors (S)")
        return
    k = kernels()["SE"]
    _, sets = cv_sets(d)
    for what, inner in sets.items():
        if not inner:
            continue
        truth = np.vstack([d.y[d.loc == l] for l in inner])
        on_y = np.vstack([gp_fit_predict(k, d.u[d.tr & (d.loc != l)], d.y[d.tr & (d.loc != l)], d.u[d.loc == l])[0]
                          for l in inner])
        on_s = np.vstack([tensor_gp_fit_predict(d, d.tr & (d.loc != l), d.loc == l)[0] for l in inner])
        print(f"cv, {what} ({len(inner)} locations), each left out in turn: GP on Y {fit(truth, on_y):.3f}, "
              f"GP on S {fit(truth, on_s):.3f}", flush=True)
    if d.te.any():
        pred, g = tensor_gp_fit_predict(d, d.tr, d.te)
        d.report(f"GP on S ({g.kernel_})", pred)


def probe_pointwise(d):
    from sklearn.neural_network import MLPRegressor

    def rows(mask):
        h = d.x[mask]
        n, r = len(h), len(d.c)
        hh = np.repeat(h, r, 0)
        e = np.tile(d.c, (n, 1))
        f = np.column_stack([hh, e, e[:, 0] - hh[:, 0], e[:, 1] - hh[:, 1]])
        return f, d.y[mask].reshape(-1)

    ftr, ytr = rows(d.tr)
    fte, _ = rows(d.te)
    mu, sd, ys = ftr.mean(0), ftr.std(0), ytr.std()
    for hidden in ((128, 128, 128), (256, 256, 256)):
        m = MLPRegressor(hidden_layer_sizes=hidden, max_iter=200, batch_size=256,
                         learning_rate_init=1e-3, random_state=0, alpha=1e-5)
        m.fit((ftr - mu) / sd, ytr / ys)
        pred = (m.predict((fte - mu) / sd) * ys).reshape(d.te.sum(), -1)
        d.report(f"pointwise MLP {hidden}", pred)


def probe_shift(d):
    from scipy.spatial import cKDTree

    tree = cKDTree(d.c)
    locs = np.unique(d.loc)
    hand = {l: d.x[d.loc == l][0, :2] for l in locs}
    field = {l: d.y[d.loc == l] for l in locs}
    train = [l for l in locs if d.split[d.loc == l][0] == 0]
    test = [l for l in locs if d.split[d.loc == l][0] != 0]

    def shifted(f, delta, alpha, h=0.004):
        q = d.c.copy()
        q[:, :2] -= alpha * delta
        out = f.copy()
        for e, ix in enumerate(tree.query_ball_point(q, r=2.5 * h)):
            if ix:
                w = np.exp(-((d.c[ix] - q[e]) ** 2).sum(1) / h**2)
                out[:, e] = f[:, ix] @ w / w.sum()
        return out

    for alpha in (0.0, 0.5, 1.0):
        pred = []
        for l in test:
            dist = np.array([np.linalg.norm(hand[g] - hand[l]) for g in train])
            near = np.argsort(dist)[:4]
            w = 1.0 / np.maximum(dist[near], 1e-9) ** 2
            w /= w.sum()
            pred.append(sum(wi * shifted(field[train[n]], hand[l] - hand[train[n]], alpha)
                            for wi, n in zip(w, near)))
        d.report(f"IDW of 4 fields shifted by {alpha:.1f} x the hand offset", np.vstack(pred))


def main(argv):
    d = Data(argv[0])
    probes = argv[1:] or ["gp", "gp-lolo", "shift"]
    table = {"gp": probe_gp, "gp-lolo": probe_gp_lolo, "pointwise": probe_pointwise, "shift": probe_shift,
             "cv": probe_cv, "pca": probe_pca, "tensor": probe_tensor}
    for p in probes:
        table[p](d)


if __name__ == "__main__":
    main(sys.argv[1:])
