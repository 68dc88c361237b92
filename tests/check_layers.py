#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The layering of the tree, checked (docs/architecture.md is the map).

    check_layers.py ROOT [LIBDEM]

The folders are layered one way: engine/ -> experiments/ -> calib/ (tests/ may
use any of them), and inside experiments/ and calib/ each subfolder holds one
kind of code and may include only the subfolders FOLDERS below names. Prints
the folder-level include graph ("folder -> folders it includes", with the
number of #include lines), then fails (exit 1, naming each offending file and
line) on
  * a file in engine/ including an experiments or calib header (exp_*.h,
    cal_*.h, or any header that lives in experiments/ or calib/);
  * a file in experiments/ including a calib header (cal_*.h, or any header
    that lives in calib/);
  * a file of experiments/ or calib/ including a header of a subfolder its
    own subfolder's rule in FOLDERS does not name (ARROWS lets one folder of
    experiments use one named header of another, with the reason); a .c or .h
    directly in experiments/ or calib/, or in a subfolder FOLDERS does not
    know; a file whose name lacks its top folder's prefix (dem_, exp_, cal_);
    two headers of one name (an #include names the header alone: the build
    puts every subfolder on the include path, CMakeLists.txt);
  * an include cycle inside engine/ between modules. A module is one stem:
    engine/dem_foo.c and dem_foo_internal.h are module dem_foo, so dem_foo.c
    including dem_bar_internal.h while dem_bar_internal.h includes
    dem_foo_internal.h is a cycle, although no header includes itself. A
    public header (dem_foo.h) is a node of its own;
  * a file outside engine/ (any folder of ROOT but engine/, hidden folders
    and build trees) including an engine-private header: by convention, any
    engine/*_internal.h. The engine's own unit tests may, where ENGINE_TESTS
    below lists them with the reason;
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

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')

# The folders above the engine, lowest first, with the prefix of their files:
# a folder may include from the ones before it, never from the ones after.
LAYERS = (("engine", "dem_"), ("experiments", "exp_"), ("calib", "cal_"))

# The subfolders above the engine: what each holds, and the other subfolders
# its files may include (a folder may always include itself and engine/'s
# public headers). experiments/: what the experiments share at the bottom; the
# tools (images, figures) on it; the experiments on both, never on each other
# but where ARROWS says. calib/ is a ladder, methods -> inputs -> runs ->
# search -> outputs -> cli, each rung on the rungs below it and on any folder
# of experiments/ (methods on nothing: it knows no drum, config or store).
EXP_COMMON = {"experiments/common"}
EXP_TOOLS = {"experiments/image", "experiments/plot"}
EXP_ALL = EXP_COMMON | EXP_TOOLS | {"experiments/" + e for e in ("scene", "cylinder", "drum", "compress", "silo", "incline")}
CAL_LADDER = ("calib/methods", "calib/inputs", "calib/runs", "calib/search", "calib/outputs", "calib/cli")
FOLDERS = {
    "experiments/common": ("what the experiments share: pouring, contact rules, cost, size tables, YAML, "
                           "result files, version and errors", set()),
    "experiments/image": ("drum-face rasters, images and photographs", EXP_COMMON),
    "experiments/plot": ("every figure, through PLplot", EXP_COMMON),
    "experiments/scene": ("explicit scenes", EXP_COMMON | EXP_TOOLS),
    "experiments/cylinder": ("the poured cylinder", EXP_COMMON | EXP_TOOLS),
    "experiments/drum": ("the rotating drum", EXP_COMMON | EXP_TOOLS),
    "experiments/compress": ("confined compression", EXP_COMMON | EXP_TOOLS),
    "experiments/silo": ("silo discharge", EXP_COMMON | EXP_TOOLS),
    "experiments/incline": ("a sphere on an inclined plane", EXP_COMMON | EXP_TOOLS),
    "calib/methods": ("numerical methods of the search: the two-fidelity map", set()),
    "calib/inputs": ("the config and the lab data", set(CAL_LADDER[:1]) | EXP_ALL),
    "calib/runs": ("the calibration's simulations through the store, workers, MPI, plan, progress, files",
                   set(CAL_LADDER[:2]) | EXP_ALL),
    "calib/search": ("the stages and the posterior", set(CAL_LADDER[:3]) | EXP_ALL),
    "calib/outputs": ("report, status, export, figures", set(CAL_LADDER[:4]) | EXP_ALL),
    "calib/cli": ("the granucal command: main, options, one file a command", set(CAL_LADDER[:5]) | EXP_ALL),
}

# One folder of experiments/ using another's header, by name, with the reason.
ARROWS = {
    ("experiments/drum", "experiments/cylinder"): (
        {"exp_cylinder.h"}, "stage 1 on the drum's own bed (exp_drum_bed) counts its contacts as the poured "
                            "cylinder's bed is counted: exp_count_bed_contacts, exp_cylinder_result"),
}

# Includes known to break a rule and being removed: (file, header) -> why it is
# still there. Reported, not failed on; a line that is gone is reported too.
KNOWN_INCLUDES = {}


def module_of(name):
    """dem_foo.c and dem_foo_internal.h are module dem_foo; a public header is
    its own node (it declares an API; what implements it is the call check's)."""
    stem, ext = os.path.splitext(name)
    if ext == ".h" and not stem.endswith("_internal"):
        return name
    return stem[: -len("_internal")] if stem.endswith("_internal") else stem


def include_lines(path):
    """(line number, included name as written) of each #include in a file."""
    with open(path, encoding="utf-8", errors="replace") as f:
        return [(k, m.group(1)) for k, line in enumerate(f, 1) for m in [INCLUDE.match(line)] if m]


def includes(path):
    return [name for _, name in include_lines(path)]


def skipped(path):
    """A hidden folder, a build tree (one with a CMakeCache.txt) or a build* folder (.gitignore's
    build*/: what a script exports there, such as vs_peers.sh's copy of the sources, is not this tree's
    source): not source."""
    name = os.path.basename(path)
    return name.startswith((".", "build")) or os.path.exists(os.path.join(path, "CMakeCache.txt"))


def sources(root, top):
    """The .c and .h files under ROOT/top, sorted, skipped folders left out."""
    out = []
    for dirpath, dirs, names in os.walk(os.path.join(root, top)):
        dirs[:] = sorted(d for d in dirs if not skipped(os.path.join(dirpath, d)))
        out += [os.path.join(dirpath, n) for n in sorted(names) if n.endswith((".c", ".h"))]
    return out


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
    outside = sorted(d for d in os.listdir(root) if d != "engine" and os.path.isdir(os.path.join(root, d))
                     and not skipped(os.path.join(root, d)))
    for top in outside:
        for path in sources(root, top):
            rel = os.path.relpath(path, root)
            allowed = ENGINE_TESTS.get(rel, set())
            for line, inc in include_lines(path):
                name = os.path.basename(inc)
                if name in private and name not in allowed:
                    problems.append('%s:%d: includes the engine-private header "%s" (outside engine/ use the '
                                    "public API in engine/dem_*.h, or list an engine unit test in ENGINE_TESTS "
                                    "with a reason)" % (rel, line, inc))
    return problems, graph


def folder_problems(root):
    """Includes against the one-way order of LAYERS: a file in a folder naming a
    header of a folder above it (by its prefix, or because it lives there)."""
    headers = {top: {os.path.basename(p) for p in sources(root, top) if p.endswith(".h")} for top, _ in LAYERS}
    problems = []
    for k, (low, _) in enumerate(LAYERS):
        above = LAYERS[k + 1:]
        for path in sources(root, low):
            rel = os.path.relpath(path, root)
            for line, inc in include_lines(path):
                name = os.path.basename(inc)
                if name in headers[low]:
                    continue
                for high, prefix in above:
                    if name.startswith(prefix) or name in headers[high]:
                        problems.append('%s:%d: includes "%s", a header of %s/, which is above %s/ (the layers go '
                                        "one way: %s; move what both need down, or the code up)"
                                        % (rel, line, inc, high, low, " -> ".join(t + "/" for t, _ in LAYERS)))
                        break
    return problems


def folder_of(rel):
    """The folder a file belongs to in the graph: engine, or the first
    subfolder of experiments/ or calib/ (a file directly in either: that top)."""
    parts = rel.split("/")
    if parts[0] in ("experiments", "calib") and len(parts) > 2:
        return parts[0] + "/" + parts[1]
    return parts[0]


def allowed_text(allowed):
    """What a folder may include, in words: "calib/methods/, any folder of experiments/"."""
    words = [x + "/" for x in sorted(allowed - EXP_ALL if EXP_ALL <= allowed else allowed)]
    if EXP_ALL <= allowed:
        words.append("any folder of experiments/")
    return ", ".join(words) or "no other folder"


def subfolder_problems(root):
    """The subfolders' rules (FOLDERS, ARROWS, KNOWN_INCLUDES), names and
    prefixes. Returns (problems, known, graph): graph[a][b] counts the #include
    lines from files of folder a naming a header of folder b."""
    files = [os.path.relpath(p, root) for top, _ in LAYERS for p in sources(root, top)]
    prefix = dict(LAYERS)
    problems, known, where = [], [], {}
    for rel in files:
        top, name = rel.split("/")[0], os.path.basename(rel)
        if not name.startswith(prefix[top]):
            problems.append("%s: a file of %s/ must be named %s* (docs/architecture.md, Names)"
                            % (rel, top, prefix[top]))
        if top != "engine" and folder_of(rel) not in FOLDERS:
            problems.append("%s: in no folder check_layers.py knows (%s): put it in the subfolder of its kind, or "
                            "add the new folder's rule to FOLDERS and its line to docs/architecture.md"
                            % (rel, ", ".join(sorted(f for f in FOLDERS if f.startswith(top + "/")))))
        if name.endswith(".h"):
            where.setdefault(name, []).append(rel)
    for name, paths in sorted(where.items()):
        if len(paths) > 1:
            problems.append("%s: one header name in %d places (an #include names the header alone): %s"
                            % (name, len(paths), ", ".join(paths)))
    graph, seen = {}, set()
    for rel in files:
        a = folder_of(rel)
        graph.setdefault(a, {})
        for line, inc in include_lines(os.path.join(root, rel)):
            name = os.path.basename(inc)
            if name not in where:
                continue
            b = folder_of(where[name][0])
            if b == a:
                continue
            graph[a][b] = graph[a].get(b, 0) + 1
            if a == "engine" or a not in FOLDERS or b == "engine":
                continue  # engine/'s own rules are folder_problems' and include_problems'
            allowed = FOLDERS[a][1]
            arrow = ARROWS.get((a, b))
            if b in allowed or (arrow and name in arrow[0]):
                continue
            if (rel, name) in KNOWN_INCLUDES:
                seen.add((rel, name))
                known.append('%s:%d: includes "%s" of %s/ (%s)' % (rel, line, inc, b, KNOWN_INCLUDES[(rel, name)]))
                continue
            if b.split("/")[0] != a.split("/")[0] and b.startswith("calib"):
                continue  # experiments/ -> calib/: folder_problems says it
            problems.append('%s:%d: includes "%s", a header of %s/ (%s), which %s/ (%s) may not include: it may '
                            "include %s (tests/check_layers.py, FOLDERS; docs/architecture.md)"
                            % (rel, line, inc, b, FOLDERS.get(b, ("",))[0], a, FOLDERS[a][0], allowed_text(allowed)))
    for rel, name in sorted(set(KNOWN_INCLUDES) - seen):
        known.append('%s no longer includes "%s": remove its entry from KNOWN_INCLUDES' % (rel, name))
    return problems, known, graph


def print_graph(graph):
    """The folder-level include graph, engine first, then experiments/, calib/."""
    order = ["engine"] + sorted(f for f in FOLDERS if f.startswith("experiments/")) + list(CAL_LADDER)
    order += sorted(set(graph) - set(order))
    rank = {f: k for k, f in enumerate(order)}
    width = max(len(f) for f in order)
    print("include graph (folder -> folders it includes: #include lines):")
    for a in order:
        if a not in graph:
            continue
        out = sorted(graph[a].items(), key=lambda e: rank.get(e[0], len(order)))
        print("  %-*s -> %s" % (width, a, ", ".join("%s %d" % (b, n) for b, n in out) or "(none)"))


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
    problems += folder_problems(root)
    sub_problems, sub_known, folders = subfolder_problems(root)
    problems += sub_problems
    print_graph(folders)
    for k in sub_known:
        print("known, being removed: " + k)
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
        print("layering: %d problem(s)" % len(failing))
        print("\n".join(line for b in failing for line in b))
        return 1
    print("layering: engine/ %d modules, %s include cycle%s; no private header used outside engine/; "
          "includes one way, %s; %d subfolders of experiments/ and calib/, each including only what its rule "
          "names"
          % (len(graph), "no other" if known else "no", ", no call cycle" if len(sys.argv) == 3 else "",
             " -> ".join(t + "/" for t, _ in LAYERS), len([f for f in folders if f in FOLDERS])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
