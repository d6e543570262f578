#!/usr/bin/env python3
"""Checks that each crate's modules form a DAG: no import circle among modules.

Usage: python3 tests/scripts/module_dag.py [CRATE_ROOT ...]   (run from the repository root;
by default every crate of the workspace). Exit status 1 and the circles when there are any.

The graph: a file's module depends on another module when it names it by a path starting with
`crate::`, `super::` or `self::` (in a `use` or in code; `use` groups are expanded). A path is
resolved to the deepest module (file) it reaches, then the edge is lifted to the two modules'
ancestors that are siblings (children of their lowest common ancestor): `controller::session`
using `setpoints` is an edge `controller -> setpoints`. A parent and its own descendants are
not an import (a `mod.rs` re-exporting its children, a child using its parent's items): that
is containment. Among the siblings of every module the edges must form a DAG. Unit-test
modules (`#[cfg(test)] mod ...` to the end of a file) are left out: tests may look anywhere.

Written by hand (about 150 lines of Python): the tools that draw module graphs
(cargo-modules) need a full build of the crate and a nightly-like toolchain set-up; this
reads the sources and takes a second.
"""

import re
import sys
from pathlib import Path

# The workspace's crate roots: (the root file, the directory its modules live in).
CRATES = [
    "src/lib.rs",
    "src/main.rs",
    "firmware-protocol/src/lib.rs",
    "form-description/src/lib.rs",
    "sim/form-sim/src/lib.rs",
    "sim/capture-sim/src/lib.rs",
]

# Circles known and left to the engineers who own those modules (issue 17): reported on every
# run, not failed. Any other circle fails. Remove an entry once its circle is gone.
KNOWN = set()

USE = re.compile(r"\buse\s+((?:crate|super|self)\b[^;]*);", re.S)
PATH = re.compile(r"\b((?:crate|super|self)(?:\s*::\s*\w+)+)")
TEST_MODULE = re.compile(r"^\s*#\[cfg\(test\)\]\s*\n\s*(pub\s+)?mod\s+\w+\s*\{", re.M)
MOD_DECL = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;", re.M)
COMMENT = re.compile(r"//[^\n]*")


def expand(tree):
    """`a::{b, c::{d, e}}` -> ['a::b', 'a::c::d', 'a::c::e'] (whitespace removed)."""
    tree = re.sub(r"\s+", "", tree)
    brace = tree.find("{")
    if brace < 0:
        return [tree]
    prefix, inner = tree[:brace], tree[brace + 1 : tree.rfind("}")]
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(inner):
        depth += ch == "{"
        depth -= ch == "}"
        if ch == "," and depth == 0:
            parts.append(inner[start:i])
            start = i + 1
    parts.append(inner[start:])
    return [p for part in parts if part for p in expand(prefix + part)]


def modules_of(root_file):
    """Module path (tuple) -> file, following `mod x;` declarations from the root file."""
    modules = {}

    def visit(path, file):
        modules[path] = file
        text = COMMENT.sub("", file.read_text())
        is_dir_module = file.name in ("mod.rs", "lib.rs", "main.rs")
        base = file.parent if is_dir_module else file.parent / file.stem
        for name in MOD_DECL.findall(text):
            for candidate in (base / f"{name}.rs", base / name / "mod.rs"):
                if candidate.exists():
                    visit(path + (name,), candidate)
                    break

    visit((), Path(root_file))
    return modules


def resolve(here, path, modules):
    """The module a `crate::`/`super::`/`self::` path names (its deepest existing prefix)."""
    segments = path.split("::")
    current = list(here)
    head = 0
    if segments[0] == "crate":
        current, head = [], 1
    while head < len(segments) and segments[head] in ("super", "self"):
        if segments[head] == "super" and current:
            current.pop()
        head += 1
    for segment in segments[head:]:
        if tuple(current + [segment]) in modules:
            current.append(segment)
        else:
            break
    return tuple(current)


def edges_of(modules):
    edges = set()
    for here, file in modules.items():
        text = COMMENT.sub("", file.read_text())
        test = TEST_MODULE.search(text)
        if test:
            text = text[: test.start()]
        paths = [p for tree in USE.findall(text) for p in expand(tree)]
        paths += [re.sub(r"\s+", "", p) for p in PATH.findall(text)]
        for path in paths:
            there = resolve(here, path, modules)
            common = 0
            while common < min(len(here), len(there)) and here[common] == there[common]:
                common += 1
            if common in (len(here), len(there)):
                continue  # containment: a module and its own ancestor or descendant
            edges.add((here[: common + 1], there[: common + 1]))
    return edges


def circles(edges):
    """The strongly connected components of more than one module (Tarjan)."""
    graph = {}
    for a, b in edges:
        graph.setdefault(a, set()).add(b)
        graph.setdefault(b, set())
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def strong(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return found


def main():
    roots = sys.argv[1:] or CRATES
    failed = False
    for root in roots:
        modules = modules_of(root)
        edges = edges_of(modules)
        found = circles(edges)
        name = root.rsplit("/src/", 1)[0] if "/src/" in root else root
        new = 0
        for component in found:
            names = tuple("::".join(m) for m in component)
            inside = [f"{'::'.join(a)} -> {'::'.join(b)}" for a, b in sorted(edges)
                      if a in component and b in component]
            known = (root, names) in KNOWN
            new += not known
            label = "known import circle (owned elsewhere)" if known else "import circle"
            print(f"{name}: {label} among {', '.join(names)}: {'; '.join(inside)}")
        failed |= new > 0
        if not new:
            print(f"{name}: {len(modules)} modules, {len(edges)} edges between siblings, no new circle")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
