#!/usr/bin/env bash
# Fuzzing, short: replay the committed corpus through the harnesses (a plain cargo test), then
# build the afl.rs targets and fuzz each for FUZZ_SECONDS (default 20) starting from the
# committed corpus. Fails if the replay fails or afl saves any crash or hang.
# Docs: docs/fuzzing.md. Usage: bash .ci/fuzz.sh [TARGET...] (default: every target).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../fuzz"
export CARGO_TERM_COLOR=never
AFL_VERSION=0.18.2
secs=${FUZZ_SECONDS:-20}
t_all=$SECONDS

if ! cargo afl --version 2>/dev/null | grep -q "$AFL_VERSION"; then
    echo "== installing cargo-afl $AFL_VERSION"
    cargo install --locked "cargo-afl@$AFL_VERSION"
fi
# builds AFL++ once per toolchain; a no-op (an error we ignore) when already built
cargo afl config --build >/dev/null 2>&1 || true

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(scene units material campaign nifti vtu vtk model predict_line serve_message deck gmsh abaqus stl
        raw_volume)
fi

if [ -z "${FUZZ_NO_REPLAY:-}" ]; then
    echo "== the corpus replayed without afl (cargo test)"
    t0=$SECONDS
    CARGO_TARGET_DIR=target/plain cargo test --release --quiet --test corpus
    echo "   replay took $((SECONDS - t0)) s"
else
    # afl's own dry run below feeds every corpus file to each target first and stops on a crash
    echo "== corpus replay left to afl's dry run (FUZZ_NO_REPLAY)"
fi

echo "== afl targets built"
t0=$SECONDS
# fuzz/target; the plain build above has its own directory, so both keep their cache
cargo afl build --release --quiet --bins
echo "   build took $((SECONDS - t0)) s"

export AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_UI=1 AFL_NO_AFFINITY=1
export RAYON_NUM_THREADS=1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failed=()
for t in "${targets[@]}"; do
    # the scene harness builds its phantom on its first phantom scene: 1.4 s of CPU at afl's
    # opt-level 3, 2.1 s at CI's opt-level 1 (docs/fuzzing.md)
    timeout_ms=1000
    [ "$t" = scene ] && timeout_ms=10000
    cargo afl fuzz -i "corpus/$t" -o "$out/$t" -V "$secs" -t "$timeout_ms" -m 4096 \
        "${CARGO_TARGET_DIR:-target}/release/$t" >"$out/$t.log" 2>&1 || {
        echo "   $t: afl-fuzz failed to run:"
        tail -n 20 "$out/$t.log"
        failed+=("$t")
        continue
    }
    stats="$out/$t/default/fuzzer_stats"
    get() { awk -F' *: *' -v k="$1" '$1 == k { print $2 }' "$stats"; }
    n_crash=$(find "$out/$t/default/crashes" -type f -name 'id:*' | wc -l)
    n_hang=$(find "$out/$t/default/hangs" -type f -name 'id:*' | wc -l)
    echo "   $t: $(get execs_done) execs in $(get run_time) s ($(get execs_per_sec)/s), corpus $(get corpus_count), crashes $n_crash, hangs $n_hang"
    if [ "$n_crash" -gt 0 ] || [ "$n_hang" -gt 0 ]; then
        failed+=("$t")
        mkdir -p "out/$t"
        cp -r "$out/$t/default/crashes" "$out/$t/default/hangs" "out/$t/"
        echo "   kept in fuzz/out/$t/; reproduce with a plain build: (cd fuzz && CARGO_TARGET_DIR=target/plain cargo run --release --bin $t -- out/$t/crashes/id*)"
    fi
done
echo "   fuzzing took $((SECONDS - t_all)) s in all"
if [ ${#failed[@]} -gt 0 ]; then
    echo "FAILED: ${failed[*]}"
    exit 1
fi
