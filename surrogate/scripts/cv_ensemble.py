"""Training-only cross-validation of palpa's own GP, its MLP and their blend.

Each training location between raster neighbours (the sets of `model_probes.py cv`) is left
out in turn: a copy of the dataset marks it (and the test locations) held out, `palpa train`
fits the GP and the paper-size MLP (Adam) on the rest, and `palpa predict --stdin` predicts
the left-out samples. The script prints each fold's Fit (paper eq. 5) and the pooled Fit of
the blend w MLP + (1 - w) GP for w = 0, 0.25, 0.5, 0.75, 1, over the interior locations and
over those between two neighbours. It asks whether averaging the two model classes, chosen
without the test locations, would beat the GP alone.

The GP learns the principal stress by default (`--gp-target principal`, the GP this study was
run with, see docs/surrogate.md); `--gp-target tensor` blends the stress-tensor GP instead.

    python surrogate/scripts/cv_ensemble.py CAMPAIGN_DIR [--palpa target/release/palpa] [--work DIR] [--gp-target T]
    (needs numpy; about 12 s of MLP training per fold on 2 cores)
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

from idw_baseline import fit  # paper eq. 5, beside this script
from model_probes import Data, cv_sets


def predict(palpa, model, x):
    lines = "".join(json.dumps({"x": r[0], "y": r[1], "force": r[2]}) + "\n" for r in x)
    out = subprocess.run([palpa, "predict", model, "--stdin"], input=lines, capture_output=True,
                         text=True, check=True).stdout
    return np.array([json.loads(line)["stress"] for line in out.splitlines()])


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign")
    ap.add_argument("--palpa", default="target/release/palpa")
    ap.add_argument("--work", default=None, help="where the fold datasets and models go (default: a temporary directory)")
    ap.add_argument("--gp-target", default="principal", choices=("principal", "tensor"),
                    help="what the GP learns (palpa train --target), principal by default")
    a = ap.parse_args(argv)
    try:
        d = Data(a.campaign)
        z = dict(np.load(f"{a.campaign}/dataset.npz"))
    except (OSError, KeyError, ValueError) as e:
        print(f"error: {a.campaign}: {e}", file=sys.stderr)
        sys.exit(2)
    if not os.path.isfile(a.palpa):
        print(f"error: no palpa binary at {a.palpa} (build it with `cargo build --release`, or pass --palpa)",
              file=sys.stderr)
        sys.exit(2)
    _, sets = cv_sets(d)
    folds = sorted({l for s in sets.values() for l in s})
    work = a.work or tempfile.mkdtemp(prefix="palpa-cv-")
    pred = {}
    for l in folds:
        fold = os.path.join(work, d.labels[l])
        os.makedirs(fold, exist_ok=True)
        split = z["split"].copy()
        split[d.loc == l] = 1
        np.savez(os.path.join(fold, "dataset.npz"), **{**z, "split": split})
        shutil.copy(f"{a.campaign}/manifest.json", fold)
        rows = d.loc == l
        for model, extra in (("gp", ["--target", a.gp_target]), ("mlp", ["--optimizer", "adam"])):
            r = subprocess.run([a.palpa, "train", fold, "--model", model, "--out", os.path.join(fold, model)] + extra,
                               capture_output=True, text=True)
            if r.returncode:
                sys.exit(f"error: palpa train --model {model} on fold {d.labels[l]}: {r.stderr.strip()}")
            pred[l, model] = predict(a.palpa, os.path.join(fold, model), d.x[rows])
        t = d.y[rows]
        print(f"{d.labels[l]}: GP {fit(t, pred[l, 'gp']):.3f}  MLP {fit(t, pred[l, 'mlp']):.3f}  "
              f"mean of both {fit(t, 0.5 * (pred[l, 'gp'] + pred[l, 'mlp'])):.3f}", flush=True)
    for what, inner in sets.items():
        truth = np.vstack([d.y[d.loc == l] for l in inner])
        blends = []
        for w in (0.0, 0.25, 0.5, 0.75, 1.0):
            p = np.vstack([w * pred[l, "mlp"] + (1 - w) * pred[l, "gp"] for l in inner])
            blends.append(f"w {w:.2f}: {fit(truth, p):.3f}")
        print(f"cv, {what}, w MLP + (1 - w) GP: " + ", ".join(blends))
    if a.work is None:
        shutil.rmtree(work)


if __name__ == "__main__":
    main(sys.argv[1:])
