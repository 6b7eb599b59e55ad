"""Compare palpate runs with a reference run (the table in docs/palpate.md).

    python3 verification/python/compare_palpations.py REF_DIR RUN_DIR [RUN_DIR ...]

Each DIR is a `palpa palpate --out DIR` output. For every run it prints
- the hand force (`hand_reaction` of history.csv), averaged over 1 ms around 10, 15, 20 and
  24.5 ms, as a signed error against the reference's, and
- the Fit (paper eq. 5) of the ROI maximum principal stress of roi_stress.csv against the
  reference's, pooled over every sample after t = 0 and per sample:
  Fit = 1 - sqrt(sum (y - yhat)^2 / sum (y - ybar)^2).
The runs must share the mesh (the same voxel size), so that the ROI rows correspond.
Standard library only.
"""
import csv
import math
import sys


def history(d):
    rows = list(csv.DictReader(open(d + "/history.csv")))
    return [float(r["time"]) for r in rows], [float(r["hand_reaction"]) for r in rows]


def average(t, f, centre, width=1e-3):
    s = [fi for ti, fi in zip(t, f) if abs(ti - centre) <= width / 2]
    return sum(s) / len(s) if s else float("nan")


def roi(d):
    rows = list(csv.DictReader(open(d + "/roi_stress.csv")))
    cols = [c for c in rows[0] if c.startswith("s_")]
    return cols, [[float(r[c]) for c in cols] for r in rows]


def fit(y, yhat):
    ybar = sum(y) / len(y)
    sse = sum((a - b) ** 2 for a, b in zip(y, yhat))
    sst = sum((a - ybar) ** 2 for a in y)
    return 1.0 - math.sqrt(sse / sst)


def main(ref, runs):
    t0, f0 = history(ref)
    c0, s0 = roi(ref)
    for d in runs:
        t1, f1 = history(d)
        c1, s1 = roi(d)
        if len(s1) != len(s0) or len(c1) != len(c0):
            sys.exit(f"{d}: its ROI or its number of samples differs from {ref}'s (same voxel size?)")
        force = []
        for tc in (0.010, 0.015, 0.020, 0.0245):
            a, b = average(t0, f0, tc), average(t1, f1, tc)
            force.append(f"{tc * 1e3:.1f} ms {100 * (b - a) / a:+.1f} %")
        per = [fit([r[k] for r in s0], [r[k] for r in s1]) for k in range(1, len(c0))]
        pooled = fit(
            [r[k] for r in s0 for k in range(1, len(c0))],
            [r[k] for r in s1 for k in range(1, len(c0))],
        )
        print(f"{d}: hand force {', '.join(force)}; ROI Fit {pooled:.4f} (per sample "
              + " ".join(f"{x:.4f}" for x in per) + ")")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2:])
