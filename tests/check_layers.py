#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The engine's layering, checked (issue 23).

    check_layers.py ROOT [LIBDEM]

Fails (exit 1, with the offending files named) on
  * an include cycle inside engine/ between modules. A module is one stem:
    engine/dem_foo.c and dem_foo_internal.h are module dem_foo, so dem_foo.c
    including dem_bar_internal.h while dem_bar_internal.h includes
    dem_foo_internal.h is a cycle, although no header includes itself. A
    public header (dem_foo.h) is a node of its own;
  * a file outside engine/ (calib/, experiments/, tests/) including an
    engine-private header: by convention, any engine/*_internal.h. The engine's
    own unit tests may, where ENGINE_TESTS below lists them with the reason;
  * with LIBDEM (the built libdem.a): a call cycle between the engine's object
    files, read from their defined and undefined symbols (nm). Functions inline
    in a header are not calls: their header's include edges are checked above.
"""
import os
import re
import subprocess
import sys

# Tests of the engine's own internals, and the private headers they may read.
ENGINE_TESTS = {
    # The multi-thread test must run a bed above DEM_OMP_MIN_GRANULES.
    "tests/stability/test_hard_cases.c": {"dem_threads_internal.h"},
}

# Problems known and being removed (issue 23): reported, not failed on. Each
# entry is the start of a problem's first line; empty once the engine is layered.
KNOWN = []

INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)
OUTSIDE = ("calib", "experiments", "tests")


def module_of(name):
    """dem_foo.c and dem_foo_internal.h are module dem_foo; a public header is
    its own node (it declares an API; what implements it is the call check's)."""
    stem, ext = os.path.splitext(name)
    if ext == ".h" and not stem.endswith("_internal"):
        return name
    return stem[: -len("_internal")] if stem.endswith("_internal") else stem


def includes(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return INCLUDE.findall(f.read())


def cycles(graph):
    """Strongly connected components of more than one node (Tarjan), each sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
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
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def explain(comp, edges):
    """The edges inside one cycle, as 'a -> b (why)' lines."""
    return ["    %s -> %s  (%s)" % (a, b, ", ".join(sorted(edges[(a, b)])[:3]))
            for (a, b) in sorted(edges) if a in comp and b in comp]


def include_problems(root):
    engine = os.path.join(root, "engine")
    files = sorted(f for f in os.listdir(engine) if f.endswith((".c", ".h")))
    graph, edges, problems = {}, {}, []
    for f in files:
        a = module_of(f)
        graph.setdefault(a, set())
        for inc in includes(os.path.join(engine, f)):
            if inc not in files:
                continue
            b = module_of(inc)
            if a != b:
                graph[a].add(b)
                edges.setdefault((a, b), set()).add('%s includes "%s"' % (f, inc))
    for comp in cycles(graph):
        problems.append("include cycle in engine/ between modules %s:" % ", ".join(comp))
        problems += explain(comp, edges)
    private = {f for f in files if f.endswith("_internal.h")}
    for top in OUTSIDE:
        for dirpath, _, names in os.walk(os.path.join(root, top)):
            for n in sorted(names):
                if not n.endswith((".c", ".h")):
                    continue
                path = os.path.join(dirpath, n)
                rel = os.path.relpath(path, root)
                allowed = ENGINE_TESTS.get(rel, set())
                for inc in includes(path):
                    if inc in private and inc not in allowed:
                        problems.append('%s includes the engine-private header "%s" (use the public API in '
                                        "engine/dem_*.h, or list an engine unit test in ENGINE_TESTS with a reason)"
                                        % (rel, inc))
    return problems, graph


def call_problems(lib):
    """Call cycles between libdem's object files (module = object file's stem)."""
    out = subprocess.run(["nm", "-A", "--defined-only", "-g", lib], capture_output=True, text=True, check=True).stdout
    defined = {}
    for line in out.splitlines():
        head, _, sym = line.rpartition(" ")
        obj = head.split(":")[1] if ":" in head else head
        defined[sym] = obj
    out = subprocess.run(["nm", "-A", "-u", lib], capture_output=True, text=True, check=True).stdout
    graph, edges = {}, {}
    for obj in set(defined.values()):
        graph.setdefault(module_of(obj.split(".")[0]), set())
    for line in out.splitlines():
        head, _, sym = line.rpartition(" ")
        obj = head.split(":")[1] if ":" in head else head
        if sym not in defined:
            continue
        a, b = module_of(obj.split(".")[0]), module_of(defined[sym].split(".")[0])
        if a != b:
            graph.setdefault(a, set()).add(b)
            edges.setdefault((a, b), set()).add(sym)
    problems = []
    for comp in cycles(graph):
        problems.append("call cycle in engine/ between %s:" % ", ".join(comp))
        problems += explain(comp, edges)
    return problems


def main():
    if len(sys.argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    root = sys.argv[1]
    problems, graph = include_problems(root)
    if len(sys.argv) == 3:
        problems += call_problems(sys.argv[2])
    blocks = []  # each problem's first line and its explanation lines
    for p in problems:
        if p.startswith("    "):
            blocks[-1].append(p)
        else:
            blocks.append([p])
    known = [b for b in blocks if b[0].startswith(tuple(KNOWN))]
    failing = [b for b in blocks if b not in known]
    for b in known:
        print("\n".join(["known, being removed (issue 23): " + b[0]] + b[1:]))
    if failing:
        print("engine layering: %d problem(s)" % len(failing))
        print("\n".join(line for b in failing for line in b))
        return 1
    print("engine layering: %d modules; %s include cycle, no private header used outside engine/%s"
          % (len(graph), "no other" if known else "no", ", no call cycle" if len(sys.argv) == 3 else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
