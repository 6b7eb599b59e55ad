#!/usr/bin/env python3
"""Pass CI output through, folding any line longer than LIMIT characters to its head and
tail. A failed link prints the whole linker command line (tens of kilobytes), and the
reason that follows it is what matters; CI logs keep only a bounded tail."""
import sys

LIMIT = 600
KEEP = 250

for line in sys.stdin:
    body = line.rstrip("\n")
    if len(body) > LIMIT:
        body = f"{body[:KEEP]} [... {len(body) - 2 * KEEP} characters folded ...] {body[-KEEP:]}"
    sys.stdout.write(body + "\n")
    sys.stdout.flush()
