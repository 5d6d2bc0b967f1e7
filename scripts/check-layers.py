#!/usr/bin/env python3
"""Fails on an import cycle between the modules of a crate, or on an import against the layers.

Every `crate::…` and `super::…` path in a crate's code (comments and strings left out) is an
edge from the file's module to the module the path names (the longest module prefix of it).
Edges from a module into its own descendants are structure (a parent declares and composes its
children) and are not counted; everything else is: a child using its parent's helpers while the
parent uses the child is a cycle. The layers of the server (who may depend on whom) are listed
in LAYERS below and in docs/ARCHITECTURE.md.

Usage: scripts/check-layers.py [workspace root]   (exit 1 with the cycles and violations)
"""

import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))

CRATES = {
    "motion": "backend/motion/src",
    "drives": "backend/drives/src",
    "ethercat": "backend/ethercat/src",
    "server": "backend/server/src",
}

# (crate, module prefix, module prefixes it must not import). The server's layers, top down:
# api → blocks (the block families: bodies, checks, catalogue entries) → service → store, with
# app (registry, pump, cycle link) below service; shared types (errors, ids, validation errors,
# the command resource) in leaf modules that import none of these.
LAYERS = [
    ("server", "service", ["api", "blocks"]),
    ("server", "app", ["api", "service", "blocks"]),
    ("server", "store", ["api", "service", "app", "blocks"]),
    ("server", "blocks", ["api"]),
    ("server", "error", ["api", "service", "app", "store", "blocks", "model"]),
    ("server", "auth", ["api", "service", "blocks"]),
    ("server", "metrics", ["api", "service", "app", "blocks"]),
    ("server", "model", ["api", "service", "app", "blocks"]),
]


def strip(code):
    """The code without comments and string/char literals (their text is not an import)."""
    out = []
    i, n = 0, len(code)
    while i < n:
        c = code[i]
        if code.startswith("//", i):
            j = code.find("\n", i)
            i = n if j < 0 else j
        elif code.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if code.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif code.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
        elif c == "r" and re.match(r'r#*"', code[i:i + 12]) and (i == 0 or not (code[i - 1].isalnum() or code[i - 1] == "_")):
            m = re.match(r'r(#*)"', code[i:])
            end = code.find('"' + m.group(1), i + len(m.group(0)))
            i = n if end < 0 else end + 1 + len(m.group(1))
            out.append('""')
        elif c == '"':
            i += 1
            while i < n and code[i] != '"':
                i += 2 if code[i] == "\\" else 1
            i += 1
            out.append('""')
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", code[i:i + 4]) or code.startswith("'\\u{", i):
            j = code.find("'", i + 1)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def modules(src):
    """{module path tuple: file} of a crate (lib.rs/main.rs is the root ())."""
    mods = {}
    for dirpath, _, files in os.walk(src):
        for f in files:
            if not f.endswith(".rs"):
                continue
            rel = os.path.relpath(os.path.join(dirpath, f), src)
            parts = rel[:-3].split(os.sep)
            if parts[-1] == "mod" or (len(parts) == 1 and parts[0] in ("lib", "main")):
                parts = parts[:-1]
            mods[tuple(parts)] = os.path.join(dirpath, f)
    return mods


def inline_modules(code, here):
    """Inline `mod name {` blocks are part of their file's module (tests and the like)."""
    return {here + (m,) for m in re.findall(r"\bmod\s+([a-z_][a-z0-9_]*)\s*\{", code)}


PATH = re.compile(r"\b(crate|super)((?:\s*::\s*(?:super|[A-Za-z_][A-Za-z0-9_]*))+)")
GROUP = re.compile(r"\b(crate|super)((?:\s*::\s*(?:super|[A-Za-z_][A-Za-z0-9_]*))*)\s*::\s*\{")


def resolve(kind, segs, here, mods):
    """The module a `crate::a::b…` / `super::…` path names, from module `here`."""
    if kind == "crate":
        base = ()
    else:
        base = here[:-1]
    segs = list(segs)
    while segs and segs[0] == "super":
        base = base[:-1]
        segs.pop(0)
    best = base
    cur = base
    for s in segs:
        cur = cur + (s,)
        if cur in mods:
            best = cur
        else:
            break
    return best


def edges_of(crate, src):
    mods = modules(src)
    edges = {}
    for here, path in mods.items():
        code = strip(open(path, encoding="utf-8").read())
        targets = set()
        for m in PATH.finditer(code):
            segs = [s.strip() for s in m.group(2).split("::") if s.strip()]
            targets.add(resolve(m.group(1), segs, here, mods))
        # `use crate::{a, b::c}` / `use super::{x::Y, z}`: each member of the group.
        for m in GROUP.finditer(code):
            prefix = [s.strip() for s in m.group(2).split("::") if s.strip()]
            depth, j = 1, m.end()
            while j < len(code) and depth:
                depth += {"{": 1, "}": -1}.get(code[j], 0)
                j += 1
            body = code[m.end():j - 1]
            for item in re.split(r"[,{}]", body):
                item = item.strip()
                if item:
                    segs = prefix + [s.strip() for s in item.split(" as ")[0].split("::") if s.strip()]
                    targets.add(resolve(m.group(1), segs, here, mods))
        for t in targets:
            # Into itself or into its own descendants: structure, not an import.
            if t[: len(here)] == here:
                continue
            edges.setdefault(here, set()).add(t)
    return mods, edges


def cycles(nodes, edges):
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
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
    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def name(m):
    return "::".join(m) or "crate"


def main():
    failures = []
    for crate, rel in CRATES.items():
        src = os.path.join(ROOT, rel)
        if not os.path.isdir(src):
            continue
        mods, edges = edges_of(crate, src)
        for comp in cycles(mods.keys(), edges):
            members = set(comp)
            arrows = sorted(
                f"{name(a)} → {name(b)}" for a in comp for b in edges.get(a, ()) if b in members
            )
            failures.append(f"{crate}: import cycle between {', '.join(name(m) for m in comp)}:\n    " + "\n    ".join(arrows))
        # The server's root (lib.rs) is the command line and the start-up: nothing below it
        # may reach back into it.
        if crate == "server":
            for a, targets in sorted(edges.items()):
                if a and () in targets:
                    failures.append(f"{crate}: {name(a)} imports the crate root (lib.rs, the start-up)")
        for c, frm, banned in LAYERS:
            if c != crate:
                continue
            for a, targets in edges.items():
                if not a or a[0] != frm:
                    continue
                for b in targets:
                    if b and b[0] in banned:
                        failures.append(f"{crate}: {name(a)} imports {name(b)} ({frm} is below {b[0]})")
    if failures:
        print("\n".join(failures))
        print(f"\n{len(failures)} layering failure(s): see docs/ARCHITECTURE.md (who may depend on whom)")
        return 1
    print("layers: no import cycle, no upward import in " + ", ".join(CRATES))
    return 0


if __name__ == "__main__":
    sys.exit(main())
