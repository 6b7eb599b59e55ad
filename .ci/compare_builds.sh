#!/usr/bin/env bash
# Bitwise check of two revisions: build each in release mode in its own git worktree (each with
# its own target directory, one after the other), run the same commands on both, and compare
# their outputs file by file (sha256). Exits non-zero if any file differs or exists on one
# side only.
#
#   .ci/compare_builds.sh BASE_REV [HEAD_REV]     (HEAD_REV defaults to HEAD)
#
# Commands, each run from the revision's own checkout:
#   palpa run scenes/compression-block.toml --out OUT/compression-block
#   palpa run scenes/finger-press.toml --out OUT/finger-press
#   palpa verify --out OUT/verify
#   palpa campaign scenes/campaign-quick.toml --out OUT/campaign-quick --quiet
#   palpa palpate --out OUT/palpate          (the main job, about a minute on 2 cores)
#
# Files that hold wall times or dates are compared without them (everything else in them
# must match to the bit):
#   - JSON files (summary.json, done.json, ...): the keys wall_seconds,
#     element_cycles_per_second, stage_times (seconds and shares of the wall time) and
#     finished_unix are removed before the comparison;
#   - the verification report (report.md): its "(wall time 12.3 s)" and the clamped block's
#     "N relaxation steps, 1.2 s" have the seconds masked.
#
# The worktrees, builds, outputs and logs live in a temporary directory, removed at the end
# unless KEEP=1. Set CARGO_BUILD_JOBS to limit the build's parallelism.
set -euo pipefail

if [[ $# -lt 1 || $# -gt 2 || $1 == -h || $1 == --help ]]; then
    sed -n '2,26p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
repo=$(git rev-parse --show-toplevel)
base_rev=$(git -C "$repo" rev-parse --verify "$1^{commit}")
head_rev=$(git -C "$repo" rev-parse --verify "${2:-HEAD}^{commit}")
work=$(mktemp -d -t palpa-compare.XXXXXX)
export CARGO_TERM_COLOR=never

cleanup() {
    for side in base head; do
        if [[ -d $work/$side/src ]]; then
            git -C "$repo" worktree remove --force "$work/$side/src" >/dev/null 2>&1 || true
        fi
    done
    git -C "$repo" worktree prune >/dev/null 2>&1 || true
    if [[ ${KEEP:-0} == 1 ]]; then
        echo "kept: $work"
    else
        rm -rf "$work"
    fi
}
trap cleanup EXIT

echo "base: $base_rev"
echo "head: $head_rev"
echo "work: $work"

# build and run one side: $1 = side name, $2 = revision
run_side() {
    local side=$1 rev=$2
    local src=$work/$side/src out=$work/$side/out
    mkdir -p "$work/$side" "$out"
    git -C "$repo" worktree add --detach --quiet "$src" "$rev"
    echo "== $side: cargo build --release ($rev)"
    local t0=$SECONDS
    (cd "$src" && CARGO_TARGET_DIR="$work/$side/target" cargo build --release --quiet --bin palpa)
    echo "   built in $((SECONDS - t0)) s"
    local palpa=$work/$side/target/release/palpa
    # relative paths, the same on both sides, so that no output names the side's directory;
    # each command's exit status is an output too (NAME.exit), its log is not (wall times)
    cd "$src"
    mkdir -p "$work/$side/logs"
    run_one() {
        local name=$1 status=0
        shift
        echo "== $side: palpa $*"
        local t1=$SECONDS
        "$palpa" "$@" >"$work/$side/logs/$name.log" 2>&1 || status=$?
        echo "$status" >"../out/$name.exit"
        echo "   exit status $status, $((SECONDS - t1)) s"
    }
    run_one compression-block run scenes/compression-block.toml --out ../out/compression-block --quiet
    run_one finger-press run scenes/finger-press.toml --out ../out/finger-press --quiet
    run_one verify verify --out ../out/verify
    run_one campaign-quick campaign scenes/campaign-quick.toml --out ../out/campaign-quick --quiet
    run_one palpate palpate --out ../out/palpate
    cd "$repo"
}

run_side base "$base_rev"
run_side head "$head_rev"

echo "== comparing $work/base/out with $work/head/out"
python3 - "$work/base/out" "$work/head/out" <<'EOF'
import hashlib, json, os, re, sys

base, head = sys.argv[1], sys.argv[2]
# keys that hold wall times or dates
TIMING_KEYS = {"wall_seconds", "element_cycles_per_second", "stage_times", "finished_unix"}
# wall times in the verification report
MASKS = [
    (re.compile(rb"\(wall time [0-9.]+ s\)"), b"(wall time - s)"),
    (re.compile(rb"relaxation steps, [0-9.]+ s"), b"relaxation steps, - s"),
]


def files(root):
    out = set()
    for d, _, fs in os.walk(root):
        for f in fs:
            out.add(os.path.relpath(os.path.join(d, f), root))
    return out


def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in TIMING_KEYS}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v


def digest(path):
    """sha256 of the file, or of its content without wall times; and what was left out."""
    data = open(path, "rb").read()
    note = ""
    if path.endswith(".json"):
        try:
            v = json.loads(data)
        except ValueError:
            v = None
        if v is not None:
            s = strip(v)
            if s != v:
                # the rest of the document, keys in file order, floats as they round-trip
                note = " (timing keys removed)"
                data = json.dumps(s, indent=1, ensure_ascii=False).encode()
    elif path.endswith(".md"):
        for rx, rep in MASKS:
            data, n = rx.subn(rep, data)
            if n:
                note = " (wall times masked)"
    return hashlib.sha256(data).hexdigest(), note


bad = 0
names = sorted(files(base) | files(head))
for name in names:
    a, b = os.path.join(base, name), os.path.join(head, name)
    if not os.path.exists(a) or not os.path.exists(b):
        print(f"different  {name}  (only in {'head' if os.path.exists(b) else 'base'})")
        bad += 1
        continue
    (da, note), (db, _) = digest(a), digest(b)
    if da == db:
        print(f"identical  {name}{note}")
    else:
        print(f"different  {name}{note}")
        bad += 1
print(f"{len(names) - bad} identical, {bad} different, of {len(names)} files")
sys.exit(1 if bad else 0)
EOF
