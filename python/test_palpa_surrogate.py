#!/usr/bin/env python3
"""The numpy loader reproduces `palpa predict`.

    python python/test_palpa_surrogate.py CAMPAIGN_DIR MODEL_DIR... [--palpa target/release/palpa]

For each model (an MLP, a GP on the principal stress, a GP on the stress tensor, ...), the
inputs are the campaign's own samples (CAMPAIGN_DIR/dataset.npz, columns x, y, force, and
phase for a respiratory campaign) and as
many points drawn inside their range; `palpa predict MODEL --stdin` answers them all (its JSON
numbers are shortest round-trip decimals, i.e. the exact binary values), and
`palpa_surrogate.Surrogate.predict` must agree with every ROI value to 1e-6 of the largest
magnitude of that prediction. The safetensors header must carry the model's kind, target,
version, input columns and units. Exits non-zero with a message on the first failure.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from palpa_surrogate import Surrogate  # noqa: E402

TOL = 1e-6


def fail(msg):
    print(f"test_palpa_surrogate: FAILED: {msg}")
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("campaign")
    ap.add_argument("models", nargs="+")
    ap.add_argument("--palpa", default=os.path.join("target", "release", "palpa"))
    a = ap.parse_args()
    # a respiratory campaign's models take the phase as a fourth input
    with open(os.path.join(a.campaign, "manifest.json")) as f:
        columns = json.load(f)["x_columns"]
    names = ["x", "y", "force"] + (["phase"] if "phase" in columns else [])
    x = np.load(os.path.join(a.campaign, "dataset.npz"))["X"][:, [columns.index(n) for n in names]]
    rng = np.random.default_rng(7)
    lo, hi = x.min(axis=0), x.max(axis=0)
    inputs = np.vstack([x, lo + (hi - lo) * rng.random(x.shape)])
    lines = "".join(
        json.dumps({**{n: float(v) for n, v in zip(names, p)}, "id": i}) + "\n"
        for i, p in enumerate(inputs)
    )
    for model in a.models:
        s = Surrogate(model)
        meta = s.metadata
        for key, want in (
            ("kind", s.kind),
            ("target", s.target),
            ("version", str(s.meta["version"])),
            ("input_columns", json.dumps(names, separators=(",", ":"))),
            ("input_units", json.dumps(["m", "m", "N", "1"][: len(names)], separators=(",", ":"))),
            ("output_unit", "Pa"),
        ):
            if meta.get(key) != want:
                fail(f"{model}: safetensors __metadata__ {key} = {meta.get(key)!r}, expected {want!r}")
        out = subprocess.run(
            [a.palpa, "predict", model, "--stdin"],
            input=lines,
            capture_output=True,
            text=True,
        )
        if out.returncode != 0:
            fail(f"palpa predict {model} --stdin: {out.stderr.strip()}")
        answers = [json.loads(l) for l in out.stdout.splitlines() if l.strip()]
        if len(answers) != len(inputs):
            fail(f"{model}: {len(answers)} answers for {len(inputs)} inputs")
        worst = 0.0
        exact = 0
        for p, ans in zip(inputs, answers):
            if "error" in ans:
                fail(f"{model}: palpa predict: {ans['error']}")
            want = np.asarray(ans["stress"], dtype=np.float64)
            got = s.predict(*p)
            if got.shape != want.shape:
                fail(f"{model}: {got.shape[0]} values against palpa's {want.shape[0]}")
            scale = max(np.abs(want).max(), 1e-300)
            d = np.abs(got - want).max() / scale
            worst = max(worst, d)
            exact += int(np.array_equal(got, want))
            if d > TOL:
                fail(
                    f"{model}: at {dict(zip(names, p))} the loader differs from "
                    f"palpa predict by {d:.3e} of the largest stress (tolerance {TOL})"
                )
        print(
            f"  {s.kind} ({s.target}, {len(s.roi_ids)} ROI elements) {model}: {len(inputs)} "
            f"predictions, largest difference {worst:.2e} of the largest stress, "
            f"{exact} bit for bit"
        )
    print("test_palpa_surrogate: ok")


if __name__ == "__main__":
    main()
