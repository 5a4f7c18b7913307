#!/usr/bin/env python3
"""Checks the include rule of docs/architecture.md ("Layers") on the sources under src/.

Each `#include "folder/..."` line of a non-test source (not *_test.*, not *test_support*) is an edge
from the folder the file is in to the folder it names. A folder may include folders of its own layer
or of a layer above it in the table, never one below; and the folders may form no cycle of includes
(within a layer as well). Also the size rule: no non-test source under src/ (C++ or Python) over
MAX_LINES lines, the vendored FMI headers (src/fmi/api/) aside. Prints every edge and file that
breaks a rule, each edge with the lines behind it, and exits 1 if there is one; with --graph, also
prints every folder edge and how many lines make it.

Usage: scripts/check_layers.py [--graph] [REPOSITORY]   (default: the repository this script is in)
"""
import collections
import os
import re
import sys

# The layers of docs/architecture.md, top first; keep the two in step.
LAYERS = [
    ("numerics", ["util", "model", "sensors", "trajectory", "control", "controllers"]),
    ("co-simulation", ["sim"]),
    ("drivers", ["drivers"]),
    ("edges", ["dds", "fmi", "isolation", "sitl", "io", "foxglove", "security", "analysis", "sweep"]),
    ("hosts", ["hosts"]),
    ("front ends", ["app", "python"]),
]
MAX_LINES = 500
RANK = {folder: i for i, (_, folders) in enumerate(LAYERS) for folder in folders}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"/]+)/[^"]+"')


def edges_of(src):
    edges = collections.defaultdict(list)
    for top, _, files in os.walk(src):
        for name in sorted(files):
            if not name.endswith((".cpp", ".hpp", ".h")) or "_test" in name or "test_support" in name:
                continue
            path = os.path.join(top, name)
            rel = os.path.relpath(path, src)
            folder = rel.split(os.sep)[0]
            with open(path, encoding="utf-8", errors="replace") as f:
                for number, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if m and m.group(1) != folder and os.path.isdir(os.path.join(src, m.group(1))):
                        edges[(folder, m.group(1))].append(f"{rel}:{number}: {line.strip()}")
    return edges


def cycles_of(edges):
    graph = collections.defaultdict(set)
    for a, b in edges:
        graph[a].add(b)
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
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
            visit(v)
    return found


def oversized(src):
    """(path, lines) of the non-test sources over MAX_LINES lines."""
    out = []
    for top, _, files in os.walk(src):
        for name in sorted(files):
            path = os.path.join(top, name)
            rel = os.path.relpath(path, src)
            if not name.endswith((".cpp", ".hpp", ".h", ".py")) or rel.startswith(os.path.join("fmi", "api")) \
                    or "_test" in name or name.startswith("test_") or "test_support" in name:
                continue
            with open(path, encoding="utf-8", errors="replace") as f:
                n = sum(1 for _ in f)
            if n > MAX_LINES:
                out.append((rel, n))
    return sorted(out)


def main(argv):
    graph = "--graph" in argv
    args = [a for a in argv if a != "--graph"]
    repo = args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    src = os.path.join(repo, "src")
    edges = edges_of(src)
    problems = 0
    for folder in sorted({a for a, _ in edges} | {b for _, b in edges}):
        if folder not in RANK:
            print(f"src/{folder}/: in no layer of scripts/check_layers.py (docs/architecture.md, 'Layers')")
            problems += 1
    if graph:
        for (a, b), lines in sorted(edges.items()):
            print(f"{a} -> {b} ({len(lines)})")
    for (a, b), lines in sorted(edges.items()):
        if a in RANK and b in RANK and RANK[b] > RANK[a]:
            problems += 1
            print(f"{a} ({LAYERS[RANK[a]][0]}) includes {b} ({LAYERS[RANK[b]][0]}), a layer below it:")
            for line in lines:
                print(f"  {line}")
    for component in cycles_of(edges):
        problems += 1
        print("folders that include each other in a cycle: " + ", ".join(component))
        for (a, b), lines in sorted(edges.items()):
            if a in component and b in component:
                print(f"  {a} -> {b}: {lines[0]}" + (f" (and {len(lines) - 1} more)" if len(lines) > 1 else ""))
    for rel, n in oversized(src):
        problems += 1
        print(f"src/{rel}: {n} lines, over {MAX_LINES} (split it by job)")
    if problems == 0:
        print(f"layers: {len(edges)} folder edges, none upward, no cycle; no source over {MAX_LINES} lines")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
