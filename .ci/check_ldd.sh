#!/usr/bin/env bash
# The release binary must run on a bare node: it may link only the C library's family
# (libc, libm, libgcc_s, the loader, the vDSO), never fontconfig, freetype, lzma or expat.
set -euo pipefail
bin=${1:-target/release/palpa}
libs=$(ldd "$bin" | awk '{print $1}')
echo "$libs" | sed 's/^/   /'
bad=$(echo "$libs" | grep -Ev '^(linux-vdso\.so\.1|linux-gate\.so\.1|/lib.*/ld-linux.*\.so\.[0-9]+|lib(c|m|gcc_s|pthread|dl|rt|util)\.so\.[0-9]+)$' || true)
if [ -n "$bad" ]; then
  echo "error: $bin links libraries a bare node lacks:" >&2
  echo "$bad" >&2
  exit 1
fi
echo "   $bin links only the C library's family"
