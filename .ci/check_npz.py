#!/usr/bin/env python3
"""Check that numpy reads a palpa campaign dataset in one line (issue 7).

    python .ci/check_npz.py DIR [--runs N] [--samples S]

DIR is a `palpa campaign` output directory: DIR/dataset.npz is loaded with a bare
`numpy.load(...)` (no allow_pickle, no custom reader), and its arrays are checked against each
other and against DIR/manifest.json: X (n x c, c >= 3, columns named by x_columns), Y (n x R),
optional S (n x R x 6), roi_ids (R), roi_centroids (R x 3), location (n, indices into
location_labels), split (n, 0 train / 1 test); every value finite. With --runs/--samples, n
must equal runs x samples. Exits non-zero with a message on the first failure.
"""
import argparse
import json
import os
import sys

import numpy as np


def fail(msg):
    print(f"check_npz: FAILED: {msg}")
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--runs", type=int)
    ap.add_argument("--samples", type=int)
    a = ap.parse_args()

    d = np.load(os.path.join(a.dir, "dataset.npz"))  # the one line a user writes
    with open(os.path.join(a.dir, "manifest.json")) as f:
        m = json.load(f)

    need = ["X", "Y", "roi_ids", "roi_centroids", "location", "split"]
    missing = [k for k in need if k not in d.files]
    if missing:
        fail(f"missing arrays {missing}; has {d.files}")
    X, Y = d["X"], d["Y"]
    if X.ndim != 2 or X.shape[1] < 3:
        fail(f"X has shape {X.shape}, expected (n, >=3)")
    n, r = X.shape[0], Y.shape[1] if Y.ndim == 2 else -1
    if Y.shape != (n, r) or r < 1:
        fail(f"Y has shape {Y.shape}, expected ({n}, R)")
    if "S" in d.files and d["S"].shape != (n, r, 6):
        fail(f"S has shape {d['S'].shape}, expected ({n}, {r}, 6)")
    if d["roi_ids"].shape != (r,) or d["roi_centroids"].shape != (r, 3):
        fail(f"roi_ids {d['roi_ids'].shape} / roi_centroids {d['roi_centroids'].shape}, R = {r}")
    if d["location"].shape != (n,) or d["split"].shape != (n,):
        fail(f"location {d['location'].shape} / split {d['split'].shape}, n = {n}")
    if X.dtype != np.float64 or Y.dtype != np.float64:
        fail(f"X, Y dtypes {X.dtype}, {Y.dtype}: expected float64")
    if not set(np.unique(d["split"])) <= {0, 1}:
        fail(f"split values {np.unique(d['split'])}")
    labels = m.get("location_labels", [])
    if d["location"].min() < 0 or d["location"].max() >= len(labels):
        fail(f"location indices outside the {len(labels)} labels of the manifest")
    if len(m.get("x_columns", [])) != X.shape[1] or m["x_columns"][:3] != ["x", "y", "force"]:
        fail(f"manifest x_columns {m.get('x_columns')} for X with {X.shape[1]} columns")
    for k in d.files:
        if d[k].dtype.kind == "f" and not np.all(np.isfinite(d[k])):
            fail(f"{k} holds non-finite values")
    if a.runs is not None and a.samples is not None and n != a.runs * a.samples:
        fail(f"{n} samples, expected {a.runs} runs x {a.samples} samples")
    train = int((d["split"] == 0).sum())
    print(
        f"check_npz: ok: {a.dir}/dataset.npz: {sorted(d.files)}; {n} samples ({train} train, "
        f"{n - train} test) x {r} ROI elements; X columns {m['x_columns']}; "
        f"locations {labels}; Y {Y.min():.4g} .. {Y.max():.4g} Pa"
    )


if __name__ == "__main__":
    main()
