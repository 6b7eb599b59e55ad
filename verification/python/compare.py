"""Numerical comparison of regenerated reference files with the committed ones (stdlib only).

usage: python3 compare.py COMMITTED_DIR REGENERATED_DIR [--rtol 1e-9]

Rules, per leaf (a numeric array counts as one leaf):
  * "generator"                   : informational (printed, never compared);
  * "newton_iterations_per_step"  : informational;
  * "checks"                      : round-off metrics; the regenerated value must be <= 1e-9;
  * "convergence"                 : derived from differences of converged values: rtol 1e-6;
  * strings, integers             : exact;
  * floats                        : max |new - old| <= rtol * max |old| over the leaf.
Exit status 1 on any failure, 2 on usage errors.
"""

import argparse
import json
import math
import os
import sys

INFO_KEYS = {"generator", "newton_iterations_per_step"}
CHECK_LIMIT = 1e-9
CONVERGENCE_RTOL = 1e-6


def flatten_numeric(v):
    """List of numbers if v is a (nested) numeric list, else None."""
    if isinstance(v, bool):
        return None
    if isinstance(v, (int, float)):
        return [v]
    if isinstance(v, list):
        out = []
        for x in v:
            f = flatten_numeric(x)
            if f is None:
                return None
            out.extend(f)
        return out
    return None


def shape(v):
    if isinstance(v, list):
        return [len(v)] + (shape(v[0]) if v and isinstance(v[0], list) else [])
    return []


def walk(old, new, path, rows, rtol, mode):
    key = path.split(".")[-1].split("[")[0] if path else ""
    if key in INFO_KEYS:
        return
    if key == "checks":
        mode = "checks"
    elif key == "convergence":
        mode = "convergence"

    fo = flatten_numeric(old)
    if fo is not None:
        fn = flatten_numeric(new)
        if fn is None or shape(old) != shape(new):
            rows.append((path, len(fo), None, "-", "FAIL (shape)"))
            return
        if mode == "checks":
            worst = max(abs(x) for x in fn) if fn else 0.0
            ok = worst <= CHECK_LIMIT
            rows.append((path, len(fn), worst, "<= %.0e" % CHECK_LIMIT, "ok" if ok else "FAIL"))
            return
        if all(isinstance(x, int) for x in fo) and all(isinstance(x, int) for x in fn):
            ok = fo == fn
            rows.append((path, len(fo), 0.0 if ok else None, "exact", "ok" if ok else "FAIL"))
            return
        tol = CONVERGENCE_RTOL if mode == "convergence" else rtol
        if any(not math.isfinite(float(x)) for x in fn):
            rows.append((path, len(fn), None, "%.0e" % tol, "FAIL (non-finite)"))
            return
        scale = max((abs(float(x)) for x in fo), default=0.0)
        diff = max((abs(float(a) - float(b)) for a, b in zip(fo, fn)), default=0.0)
        rel = diff / scale if scale > 0 else diff
        ok = diff <= tol * scale if scale > 0 else diff == 0.0
        rows.append((path, len(fo), rel, "%.0e" % tol, "ok" if ok else "FAIL"))
        return

    if isinstance(old, dict):
        if not isinstance(new, dict):
            rows.append((path, 0, None, "-", "FAIL (type)"))
            return
        for k in old:
            p = f"{path}.{k}" if path else k
            if k not in new:
                if k not in INFO_KEYS:
                    rows.append((p, 0, None, "-", "FAIL (missing)"))
                continue
            walk(old[k], new[k], p, rows, rtol, mode)
        for k in new:
            if k not in old and k not in INFO_KEYS:
                rows.append((f"{path}.{k}" if path else k, 0, None, "-", "FAIL (unexpected)"))
        return
    if isinstance(old, list):
        if not isinstance(new, list) or len(old) != len(new):
            rows.append((path, len(old), None, "-", "FAIL (length)"))
            return
        for i, (a, b) in enumerate(zip(old, new)):
            walk(a, b, f"{path}[{i}]", rows, rtol, mode)
        return
    ok = old == new
    rows.append((path, 1, 0.0 if ok else None, "exact", "ok" if ok else "FAIL"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("committed")
    ap.add_argument("regenerated")
    ap.add_argument("--rtol", type=float, default=1e-9)
    a = ap.parse_args()

    names = sorted(f for f in os.listdir(a.committed) if f.endswith(".json"))
    fresh = sorted(f for f in os.listdir(a.regenerated) if f.endswith(".json"))
    if not names:
        print(f"no reference files in {a.committed}")
        return 2
    failed = 0
    for f in sorted(set(fresh) - set(names)):
        print(f"FAIL: {f} was regenerated but is not committed")
        failed += 1
    for name in names:
        print(f"\n== {name}")
        p_new = os.path.join(a.regenerated, name)
        if not os.path.exists(p_new):
            print(f"FAIL: {name} was not regenerated")
            failed += 1
            continue
        with open(os.path.join(a.committed, name)) as fh:
            old = json.load(fh)
        with open(p_new) as fh:
            new = json.load(fh)
        gen_o, gen_n = old.get("generator", {}), new.get("generator", {})
        print("   regenerated by %s %s (%s); committed by %s %s" % (
            gen_n.get("solver"), gen_n.get("solver_version"), gen_n.get("script"),
            gen_o.get("solver"), gen_o.get("solver_version")))
        rows = []
        walk(old, new, "", rows, a.rtol, None)
        # Table: every numeric (tolerance) row and every failure; exact matches of strings and
        # integer arrays (connectivity, node ids, names) are only counted.
        shown = [r for r in rows if r[4] != "ok" or r[3] != "exact"]
        n_exact = sum(1 for r in rows if r[4] == "ok" and r[3] == "exact")
        w = max([len(r[0]) for r in shown] + [8])
        print(f"   {'quantity':<{w}}  {'n':>6}  {'max rel diff':>12}  {'tol':>8}  result")
        for path, n, rel, tol, res in shown:
            rel_s = "-" if rel is None else "%.2e" % rel
            print(f"   {path:<{w}}  {n:>6}  {rel_s:>12}  {tol:>8}  {res}")
        print(f"   (+ {n_exact} strings / integer arrays identical)")
        bad = [r for r in rows if r[4] != "ok"]
        with open(os.path.join(a.committed, name), "rb") as f1, open(p_new, "rb") as f2:
            identical = f1.read() == f2.read()
        print(f"   {len(rows) - len(bad)}/{len(rows)} ok; files byte-identical: {identical}")
        failed += len(bad)
    print()
    if failed:
        print(f"references: {failed} difference(s) beyond tolerance")
        return 1
    print("references: all regenerated values match the committed ones")
    return 0


if __name__ == "__main__":
    sys.exit(main())
