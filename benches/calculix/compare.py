#!/usr/bin/env python3
"""CalculiX 2.20 against palpa on the same 32k-element neo-Hookean block.

Writes the block of block.py for both codes, runs each for 200 and 400 increments on
--threads threads (OMP_NUM_THREADS for ccx, RAYON_NUM_THREADS for palpa), times the wall clock
of every run, and prints per code the marginal rate

    elements * 200 / (t400 - t200)   element-cycles per second

(set-up, mesh reading and output cancel in the difference), the same per processor second
(user + system time of all threads: what other work on a shared machine disturbs least), the
ratio palpa / CalculiX, and the two codes' reactions and bulge at the same times of the
400-increment run (agreement.py). Each run is
checked: CalculiX's output blocks must fall at the expected times (one every steps/4
increments of the fixed increment), palpa's summary.json must report the steps asked for.
Anything else stops the script with an error.

    python3 benches/calculix/compare.py [--palpa target/release/palpa] [--repeat 3] [--precision f32]

Needs Python 3.11 (standard library only); installs Debian's calculix-ccx when `ccx` is missing
(install_ccx.sh). Scratch files go to --work (default: a temporary directory).
"""
import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import agreement  # noqa: E402
import block  # noqa: E402
import results  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SHORT, LONG = 200, 400


def fail(msg):
    sys.exit(f"compare.py: {msg}")


def timed(cmd, cwd, env):
    """Run cmd, return ((wall s, processor s), stdout); stop on a non-zero exit. The processor
    time (user + system, all threads) is the figure that other work on the machine disturbs
    least; the wall clock is the one that counts."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    if p.returncode != 0:
        fail(f"{' '.join(cmd)} exited {p.returncode}:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    return (wall, cpu), p.stdout


def run_ccx(work, n, steps, threads, tell=False):
    """One CalculiX run: ((wall s, processor s), {(set, time): vector})."""
    d = os.path.join(work, f"ccx{steps}")
    os.makedirs(d, exist_ok=True)
    block.write_inp(os.path.join(d, "block.inp"), n, steps, LONG * block.DT)
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    wall, out = timed(["ccx", "-i", "block"], d, env)
    version = results.ccx_version(out)
    if version != "2.20":
        print(f"  note: CalculiX {version}, not 2.20")
    if results.ccx_threads(out) != threads:
        fail(f"ccx did not report {threads} threads for its stress calculation")
    courant = results.ccx_courant(out)
    if courant <= block.DT:
        fail(f"ccx's stable increment {courant:g} s is below {block.DT:g} s "
             "(it would scale masses)")
    dt = results.ccx_increment(out)
    if tell:
        print(f"  ccx {version}: stable (Courant) increment {courant * 1e6:.2f} us, "
              f"selected {dt * 1e6:.2f} us")
    if abs(dt - block.DT) > 1e-9 * block.DT:
        fail(f"ccx chose the increment {dt:g} s, not {block.DT:g} s")
    dat = results.ccx_dat(os.path.join(d, "block.dat"))
    want = [(k + 1) * steps // block.OUTPUTS * block.DT for k in range(block.OUTPUTS)]
    got = sorted({t for (_, t) in dat})
    if len(got) != len(want) or any(abs(a - b) > 1e-6 * b for a, b in zip(got, want)):
        fail(f"ccx {steps}: output at times {got}, expected {want} "
             f"(one block every {steps // block.OUTPUTS} increments of {block.DT:g} s)")
    return wall, dat


def run_palpa(work, exe, n, steps, threads, precision):
    """One palpa run: ((wall s, processor s), summary, history rows, output directory)."""
    d = os.path.join(work, f"palpa{steps}")
    os.makedirs(d, exist_ok=True)
    scene = os.path.join(d, "block.toml")
    block.write_toml(scene, n, steps, LONG * block.DT, precision)
    out = os.path.join(d, "out")
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    wall, _ = timed([exe, "run", scene, "--out", out, "--quiet"], d, env)
    s = results.palpa_summary(os.path.join(out, "summary.json"))
    if s.get("steps") != steps:
        fail(f"palpa ran {s.get('steps')} steps, expected {steps} (summary.json)")
    if s.get("threads") != threads:
        fail(f"palpa ran on {s.get('threads')} threads, expected {threads}")
    if s.get("precision") != precision:
        fail(f"palpa ran its element kernels in {s.get('precision')}, expected {precision}")
    if not str(s.get("status", "")).startswith("completed"):
        fail(f"palpa status: {s.get('status')}")
    return wall, s, results.palpa_history(os.path.join(out, "history.csv")), out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--palpa", default=os.path.join(ROOT, "target", "release", "palpa"),
                    help="palpa binary (default: the repository's target/release/palpa)")
    ap.add_argument("--repeat", type=int, default=3, help="pairs of runs per code (median)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--divisions", type=int, default=32, help="elements per edge")
    ap.add_argument("--precision", choices=["f64", "f32"], default="f64",
                    help="palpa's element kernels (CalculiX runs in double precision)")
    ap.add_argument("--work", help="scratch directory, kept (default: a temporary one, removed)")
    a = ap.parse_args()
    if a.repeat < 1:
        fail("--repeat must be at least 1")
    exe = os.path.abspath(a.palpa)
    if not os.access(exe, os.X_OK):
        fail(f"no palpa binary at {exe} (cargo build --release, or --palpa PATH)")
    if shutil.which("ccx") is None:
        subprocess.run(["sh", os.path.join(HERE, "install_ccx.sh")], check=True)
    n = a.divisions
    ne = n**3
    work = a.work or tempfile.mkdtemp(prefix="ccx-compare-")
    os.makedirs(work, exist_ok=True)
    print(f"block: {n}^3 = {ne} hexahedra, dt {block.DT * 1e6:g} us, {a.threads} threads, "
          f"palpa kernels in {a.precision}, work in {work}")

    rates = {"ccx": [], "palpa": []}  # (wall rate, processor-time rate) per pair
    last = {}
    for r in range(a.repeat):
        t = {}
        for steps in (SHORT, LONG):
            t["ccx", steps], last["ccx", steps] = run_ccx(work, n, steps, a.threads, tell=r == 0 and steps == SHORT)
        for steps in (SHORT, LONG):
            clock, s, hist, out = run_palpa(work, exe, n, steps, a.threads, a.precision)
            t["palpa", steps], last["palpa", steps] = clock, (s, hist, out)
        for code in rates:
            (w2, c2), (w4, c4) = t[code, SHORT], t[code, LONG]
            if w4 <= w2 or c4 <= c2:
                fail(f"{code}: the 400-increment run was not slower than the 200 one")
            cycles = ne * (LONG - SHORT)
            rates[code].append((cycles / (w4 - w2), cycles / (c4 - c2)))
            print(f"  pair {r + 1} {code:5}: {SHORT} in {w2:6.2f} s, {LONG} in {w4:6.2f} s -> "
                  f"{rates[code][-1][0] / 1e6:6.3f} M el-cyc/s [{rates[code][-1][1] / 1e6:.3f}]"
                  f" (load {os.getloadavg()[0]:.1f})")

    print(f"\nmarginal element-cycles/s, wall clock (median of {a.repeat}, {a.threads} threads; "
          "per processor second in brackets):")
    med = {}
    for c in ("palpa", "ccx"):
        wall = [w for w, _ in rates[c]]
        cpu = [p for _, p in rates[c]]
        med[c] = (statistics.median(wall), statistics.median(cpu))
        print(f"  {c:5}: {med[c][0] / 1e6:8.3f} M  (range {min(wall) / 1e6:.3f}-"
              f"{max(wall) / 1e6:.3f})  [{med[c][1] / 1e6:.3f} M]")
    ratio = med["palpa"][0] / med["ccx"][0]
    print(f"  palpa / CalculiX: {ratio:.1f}x  (goal 40x: {'met' if ratio >= 40 else 'NOT met'}); "
          f"per processor second {med['palpa'][1] / med['ccx'][1]:.1f}x")

    _, hist, out = last["palpa", LONG]
    worst = agreement.report(last["ccx", LONG], hist, out, LONG)
    if not a.work:
        shutil.rmtree(work)
    if worst > agreement.TOLERANCE:
        fail("the two codes disagree: the speed comparison does not hold")


if __name__ == "__main__":
    main()
