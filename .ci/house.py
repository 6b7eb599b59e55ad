#!/usr/bin/env python3
"""The house rules that the compiler does not check (docs/architecture.md):

- no function longer than LIMIT lines (signature to closing brace) in the explicit core and the
  application crates: solver/, phantom/, scene/, campaign/ and the CLI's campaign front;
- no two files of one crate that import each other, directly or around a loop: a file's
  imports are the `crate::` and `super::` paths it names, resolved to the file that defines
  each name (a `pub use` re-export is followed to the defining file; `mod` lines are not
  imports).

    python3 .ci/house.py            # both checks; exit status 1 if either fails
    python3 .ci/house.py --report   # also list the ten longest functions

Rust source is read with a small lexer (strings, raw strings, chars, comments), not parsed.
"""
import os
import re
import sys

LIMIT = 120
LENGTH_ROOTS = ["solver/src", "phantom/src", "scene/src", "campaign/src", "src/cli/campaign.rs"]
CRATES = ["material", "contact", "solver", "phantom", "scene", "campaign", "surrogate",
          "verification", "lsdyna", "picture", "benches", "."]


def code_only(text):
    """The text with string and char literals and comments blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            i = j
            continue
        if text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append("\n" * text.count("\n", i, j))
            i = j
            continue
        m = re.match(r'b?r(#*)"', text[i:i + 12])
        if m and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            close = '"' + m.group(1)
            j = text.find(close, i + m.end())
            j = n if j < 0 else j + len(close)
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
            continue
        if c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j + 1
            continue
        if c == "'":
            m = re.match(r"'(\\.|\\u\{[0-9a-fA-F]+\}|[^\\'])'", text[i:i + 12])
            if m:
                out.append("''")
                i += m.end()
                continue
        out.append(c)
        i += 1
    return "".join(out)


def rust_files(root):
    if root.endswith(".rs"):
        return [root] if os.path.exists(root) else []
    found = []
    for d, dirs, fs in os.walk(root):
        dirs[:] = [x for x in dirs if x not in ("target", ".git")]
        found += [os.path.join(d, f) for f in fs if f.endswith(".rs")]
    return sorted(found)


FN = re.compile(r"^\s*(pub(\([^)]*\))?\s+)?((const|async|unsafe|extern\s+\"C\")\s+)*fn\s+(\w+)")


def functions(path):
    """(name, first line, length) of every function with a body."""
    lines = code_only(open(path, encoding="utf-8").read()).split("\n")
    res = []
    for i, line in enumerate(lines):
        m = FN.match(line)
        if not m:
            continue
        depth, opened = 0, False
        for j in range(i, len(lines)):
            for ch in lines[j]:
                if ch == "{":
                    depth, opened = depth + 1, True
                elif ch == "}":
                    depth -= 1
                elif ch == ";" and not opened and depth == 0:
                    break
            else:
                if opened and depth <= 0:
                    res.append((m.group(5), i + 1, j - i + 1))
                    break
                continue
            break
    return res


def module_files(crate):
    """Module path (tuple) -> file, for one crate's src/."""
    src = os.path.join(crate, "src")
    mods = {}
    for f in rust_files(src):
        rel = os.path.relpath(f, src)[:-3].split(os.sep)
        if rel[-1] in ("lib", "main", "mod"):
            rel = rel[:-1]
        if rel and rel[0] == "bin":
            continue
        mods[tuple(rel)] = f
    return mods


DEF = re.compile(r"^\s*pub(\([^)]*\))?\s+(?:unsafe\s+)?(?:struct|enum|fn|const|static|type|trait|union|mod)\s+(\w+)", re.M)
MACRO_DEF = re.compile(r"^\s*macro_rules!\s*(\w+)", re.M)
REEXPORT = re.compile(r"^\s*pub(?:\([^)]*\))?\s+use\s+([^;]+);", re.M)
USE = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?use\s+([^;]+);", re.M)
PATH = re.compile(r"\b(crate|super)((?:::\w+)+)")


def expand(tree):
    """`a::{b, c::{d}}` -> ['a::b', 'a::c::d'] (globs and renames kept as written)."""
    tree = re.sub(r"\s*(::|,|\{|\})\s*", r"\1", re.sub(r"\s+", " ", tree.strip()))
    m = re.match(r"^(.*?)\{(.*)\}$", tree)
    if not m:
        return [tree]
    prefix, inner = m.group(1), m.group(2)
    parts, depth, cur = [], 0, ""
    for ch in inner:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += ch == "{"
        depth -= ch == "}"
        cur += ch
    parts.append(cur)
    return [p for part in parts if part for p in expand(prefix + part)]


def cycles(crate):
    mods = module_files(crate)
    if not mods:
        return []
    texts = {f: code_only(open(f, encoding="utf-8").read()) for f in mods.values()}
    mod_of = {f: m for m, f in mods.items()}
    defined = {
        m: {d[1] for d in DEF.findall(texts[f])} | set(MACRO_DEF.findall(texts[f]))
        for m, f in mods.items()
    }
    reexports = {}
    for m, f in mods.items():
        for tree in REEXPORT.findall(texts[f]):
            for p in expand(tree):
                path, _, alias = p.partition(" as ")
                name = alias or path.split("::")[-1]
                reexports.setdefault(m, {})[name] = path

    def absolute(mod, path):
        segs = path.split("::")
        if segs[0] == "crate":
            return list(segs[1:])
        base = list(mod)
        while segs and segs[0] == "super":
            base, segs = base[:-1], segs[1:]
        if segs and segs[0] == "self":
            segs = segs[1:]
        return base + segs

    def resolve(mod, path, seen=0):
        """The file that defines what `path` (seen from module `mod`) names."""
        segs = absolute(mod, path)
        for k in range(len(segs), -1, -1):
            m = tuple(segs[:k])
            if m in mods:
                rest = segs[k:]
                if not rest or rest[0] in ("*", "self"):
                    return mods[m]
                name = rest[0]
                if name in reexports.get(m, {}) and name not in defined.get(m, ()) and seen < 8:
                    target = reexports[m][name]
                    if target.startswith(("crate", "super", "self")):
                        return resolve(m, target, seen + 1)
                    return resolve(m, "self::" + target, seen + 1)
                return mods[m]
        return None

    edges = {f: set() for f in mods.values()}
    for f, text in texts.items():
        mod = mod_of[f]
        body = REEXPORT.sub("", text)
        refs = [p.partition(" as ")[0] for tree in USE.findall(body) for p in expand(tree)]
        refs += [a + b for a, b in PATH.findall(USE.sub("", body))]
        for r in refs:
            if not r.startswith(("crate::", "super::")):
                continue
            g = resolve(mod, r)
            if g and g != f:
                edges[f].add(g)
    # strongly connected components (Tarjan)
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def main():
    os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    report = "--report" in sys.argv
    bad = 0
    fns = [(n, f, line, name) for root in LENGTH_ROOTS for f in rust_files(root)
           for name, line, n in functions(f)]
    fns.sort(reverse=True)
    long = [x for x in fns if x[0] > LIMIT]
    for n, f, line, name in long:
        print(f"too long: {f}:{line} `{name}`: {n} lines (limit {LIMIT})")
    bad += len(long)
    if report:
        print(f"longest functions in {', '.join(LENGTH_ROOTS)}:")
        for n, f, line, name in fns[:10]:
            print(f"  {n:4d}  {f}:{line} {name}")
    n_cycles = 0
    for crate in CRATES:
        for comp in cycles(crate):
            print(f"file cycle in {crate}: {' <-> '.join(comp)}")
            n_cycles += 1
    bad += n_cycles
    print(f"{len(fns)} functions checked, {len(long)} over {LIMIT} lines; "
          f"{len(CRATES)} crates checked, {n_cycles} file cycles")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
