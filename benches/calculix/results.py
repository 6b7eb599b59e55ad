"""Read what the two codes wrote: CalculiX's .dat blocks, palpa's summary, history and frame.

Each reader returns plain dicts or lists and raises ValueError when a file is not as expected,
so that the comparison stops loudly instead of printing figures from a run that did other work.
"""
import base64
import csv
import json
import re
import struct
import zlib

BLOCK = re.compile(r"^\s*(total force \(fx,fy,fz\)|displacements \(vx,vy,vz\)) for set (\S+) "
                   r"and time\s+(\S+)\s*$")


def ccx_dat(path):
    """CalculiX .dat blocks as {(set, time): (x, y, z)}, in file order of their times."""
    lines = open(path).read().splitlines()
    blocks = {}
    i = 0
    while i < len(lines):
        m = BLOCK.match(lines[i])
        i += 1
        if not m:
            continue
        while i < len(lines) and not lines[i].strip():
            i += 1
        nums = [float(v) for v in lines[i].split()]
        # A totals line is three numbers; a nodal line starts with the node id.
        blocks[(m.group(2), float(m.group(3)))] = tuple(nums[-3:])
        i += 1
    return blocks


def ccx_version(stdout):
    """The version CalculiX prints in its banner ("2.20"), or "unknown"."""
    m = re.search(r"CalculiX Version (\S+),", stdout)
    return m.group(1) if m else "unknown"


def ccx_threads(stdout):
    """The thread count CalculiX reports for its stress calculation (None if absent)."""
    m = re.search(r"Using up to (\d+) cpu\(s\) for the stress calculation", stdout)
    return int(m.group(1)) if m else None


def ccx_increment(stdout):
    """The explicit increment CalculiX selected (s)."""
    m = re.search(r"SELECTED time increment[^:]*:\s*(\S+)", stdout)
    if not m:
        raise ValueError("CalculiX printed no 'SELECTED time increment'")
    return float(m.group(1))


def ccx_courant(stdout):
    """CalculiX's initial stable (Courant) increment (s): below it, it would scale masses."""
    m = re.search(r"COURANT initial stable time increment:\s*(\S+)", stdout)
    if not m:
        raise ValueError("CalculiX printed no COURANT stable increment")
    return float(m.group(1))


def palpa_summary(path):
    """palpa's summary.json."""
    with open(path) as f:
        return json.load(f)


def palpa_history(path):
    """palpa's history.csv as a list of {column: float}."""
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def _vtu_array(xml, name):
    """The raw bytes of one zlib-compressed inline base64 DataArray (UInt64 header)."""
    m = re.search(r'<DataArray[^>]*Name="%s"[^>]*>\s*([A-Za-z0-9+/=\s]+?)\s*</DataArray>' % name,
                  xml)
    if not m:
        raise ValueError(f"no DataArray named {name}")
    text = re.sub(r"\s", "", m.group(1))
    head = base64.b64decode(text[:32])  # 24 bytes: blocks, block size, last block size
    nblocks = struct.unpack("<Q", head[:8])[0]
    hlen = 8 * (3 + nblocks)
    hchars = 4 * ((hlen + 2) // 3)
    header = struct.unpack(f"<{3 + nblocks}Q", base64.b64decode(text[:hchars])[:hlen])
    data = base64.b64decode(text[hchars:])
    out, pos = [], 0
    for size in header[3:]:
        out.append(zlib.decompress(data[pos:pos + size]))
        pos += size
    return b"".join(out)


def palpa_point_at(vtu_path, xyz, name="displacement"):
    """A point field's 3-vector at the node of a palpa frame nearest to xyz (reference, m)."""
    xml = open(vtu_path).read()
    pts = _vtu_array(xml, "Points")
    count = len(pts) // 24
    best = min(range(count), key=lambda i: sum(
        (c - x) ** 2 for c, x in zip(struct.unpack_from("<3d", pts, 24 * i), xyz)))
    return struct.unpack_from("<3d", _vtu_array(xml, name), 24 * best)
