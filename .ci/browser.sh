#!/usr/bin/env bash
# The live training view in a real browser (`palpa serve`, tests/browser.rs): Debian's chromium,
# headless, driven over the DevTools protocol. Installs chromium with apt-get when it is missing
# (a fresh machine), then runs the test: the picture at A, B and C checked pixel by pixel against
# the model's own prediction, the warning outside the body, and the input-to-paint latency and
# frame rate under a 100 Hz plate stream (figures printed, and written to target/browser/).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

if ! command -v chromium >/dev/null 2>&1; then
    echo "   chromium is not installed: installing Debian's package"
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium >/dev/null
fi
echo "   $(chromium --version 2>/dev/null | tail -n 1)"

# the test profile, already built by `cargo test --workspace` (`--workspace` here too: `-p palpa`
# resolves features without the benches member and rebuilds half the tree); one test at a time
PALPA_CHROMIUM="$(command -v chromium)" cargo test --quiet --workspace --test browser -- --nocapture --test-threads=1
