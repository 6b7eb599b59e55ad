#!/bin/sh
# Install CalculiX (Debian's calculix-ccx, 2.20 on bookworm) when `ccx` is not on the PATH.
# Needs root and apt; used by compare.py, or run it by hand: sh benches/calculix/install_ccx.sh
set -e
if command -v ccx >/dev/null 2>&1; then
    exit 0
fi
apt-get update
DEBIAN_FRONTEND=noninteractive apt-get install -y calculix-ccx
dpkg-query -W calculix-ccx
