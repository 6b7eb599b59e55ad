#!/usr/bin/env python3
"""Pass CI output through, folding any line longer than LIMIT characters to its head and
tail. A failed link prints the whole linker command line (tens of kilobytes), and the
reason that follows it is what matters; CI logs keep only a bounded tail."""
import sys

LIMIT = 600
KEEP = 250

for raw in sys.stdin.buffer:
    # a stray invalid byte must not end the CI log in a traceback
    body = raw.decode("utf-8", errors="replace").rstrip("\n")
    if len(body) > LIMIT:
        body = f"{body[:KEEP]} [... {len(body) - 2 * KEEP} characters folded ...] {body[-KEEP:]}"
    sys.stdout.write(body + "\n")
    sys.stdout.flush()
