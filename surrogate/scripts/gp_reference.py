"""The scikit-learn reference for palpa's GP surrogate on a campaign's dataset.

It fits scikit-learn's GaussianProcessRegressor the way `palpa train --model gp` fits its GP:
- inputs z-scored over the training rows;
- outputs centred per output and scaled by one pooled deviation;
- one squared-exponential ARD kernel shared by all outputs, plus white noise;
- hyperparameters by marginal likelihood over the training rows with distinct targets, then
  conditioned on every training row.

It does so for both targets (`palpa train --target`): `principal`, the ROI's maximum principal
stress Y itself, and `tensor`, the six stress components of every ROI element (S), whose
predicted tensor's largest eigenvalue is the prediction. The tensor reference keeps every
output direction, so it also checks palpa's truncated output basis (`gp::train`). It scores each
GP on the held-out locations with the Fit of paper eq. 5 against Y, pooled and per location, and
writes those figures as JSON. The test `surrogate/tests/default_campaign.rs`
asserts that palpa's own GP gives the same Fit on the committed default campaign. CI reruns
this script and compares its output with the committed file.

    python surrogate/scripts/gp_reference.py CAMPAIGN_DIR --out FILE.json    # write
    python surrogate/scripts/gp_reference.py CAMPAIGN_DIR --check FILE.json  # compare, exit 1 on a difference

Needs numpy, scipy and scikit-learn (the `.venv-skfem` environment of CI has them).
"""
import argparse
import json
import os
import sys

import numpy as np
import scipy
import sklearn

from idw_baseline import fit  # paper eq. 5, beside this script
from model_probes import Data, gp_fit_predict, kernels, tensor_gp_fit_predict

# A rerun with the pinned versions gives the same numbers to rounding; this tolerance allows
# for a different BLAS summing in a different order.
CHECK_TOLERANCE = 1e-4


def scored(d, pred, g):
    t, lt = d.y[d.te], d.loc[d.te]
    return {
        "kernel": str(g.kernel_),
        "log_marginal_likelihood": float(g.log_marginal_likelihood_value_),
        "fit": float(fit(t, pred)),
        "fit_by_location": {d.labels[l]: float(fit(t[lt == l], pred[lt == l]))
                            for l in np.unique(lt)},
    }


def reference(campaign):
    d = Data(campaign)
    r = {
        "what": "scikit-learn GaussianProcessRegressor, SE-ARD + white noise, fitted as "
        "`palpa train --model gp --target principal|tensor` (surrogate/scripts/gp_reference.py)",
        "versions": {"scikit-learn": sklearn.__version__, "scipy": scipy.__version__,
                     "numpy": np.__version__},
        "n_train": int(d.tr.sum()),
        "n_test": int(d.te.sum()),
        "principal": scored(d, *gp_fit_predict(kernels()["SE"], d.u[d.tr], d.y[d.tr], d.u[d.te])),
    }
    if d.s6 is not None:
        r["tensor"] = scored(d, *tensor_gp_fit_predict(d, d.tr, d.te))
    return r


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("campaign", help="campaign directory holding dataset.npz and manifest.json")
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--out", help="write the reference to this JSON file")
    mode.add_argument("--check", help="compare with this committed JSON file")
    a = ap.parse_args(argv)
    try:
        return run(a)
    except (OSError, ValueError) as e:  # a missing or unreadable dataset or reference file
        print(f"gp_reference.py: error: {e}", file=sys.stderr)
        return 2
    except KeyError as e:
        print(f"gp_reference.py: error: {a.check or a.campaign} has no entry {e}", file=sys.stderr)
        return 2


def run(a):
    r = reference(a.campaign)
    targets = [t for t in ("principal", "tensor") if t in r]
    for t in targets:
        per = " / ".join(f"{k} {v:.4f}" for k, v in r[t]["fit_by_location"].items())
        print(f"scikit-learn GP, {t} target: held-out Fit {r[t]['fit']:.4f} ({per}); {r[t]['kernel']}")
    if a.out:
        tmp = f"{a.out}.tmp"
        with open(tmp, "w") as f:
            json.dump(r, f, indent=2)
            f.write("\n")
        os.replace(tmp, a.out)  # never a half-written reference
        return 0
    with open(a.check) as f:
        want = json.load(f)
    pairs = []
    for t in sorted(set(targets) | {k for k in ("principal", "tensor") if k in want}):
        w, g = want.get(t, {}), r.get(t, {})
        pairs.append((f"{t}.fit", w.get("fit", float("nan")), g.get("fit", float("nan"))))
        pairs += [(f"{t}.fit_by_location.{k}", v, g.get("fit_by_location", {}).get(k, float("nan")))
                  for k, v in w.get("fit_by_location", {}).items()]
    bad = [(n, w, g) for n, w, g in pairs if not abs(w - g) <= CHECK_TOLERANCE]
    for n, w, g in bad:
        print(f"{a.check}: {n} is {w:.6f} committed, {g:.6f} regenerated "
              f"(tolerance {CHECK_TOLERANCE})", file=sys.stderr)
    if bad:
        return 1
    print(f"   matches {a.check} within {CHECK_TOLERANCE}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
