"""Import circles between the modules of a crate: `python3 scripts/import_cycles.py [SRC]`.

Every `.rs` file under SRC (default `src`) is a module (`foo/mod.rs` is `foo`); a module
depends on another when its code names it by path (`crate::a::b`, `super::c`, `self::d`,
in `use` lines and inline; test modules included, as the compiler sees them). The script
prints each strongly connected group of modules (a set that reaches itself through its
imports) with one circle through it, and exits 1 if there is any, 0 otherwise.
"""
import os
import re
import sys

SRC = sys.argv[1] if len(sys.argv) > 1 else "src"


def module_of(path):
    rel = os.path.relpath(path, SRC)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib", "main"):
        rel = rel[:-1]
    return tuple(rel)


modules = {}
for root, _, files in os.walk(SRC):
    for f in files:
        if f.endswith(".rs"):
            path = os.path.join(root, f)
            modules[module_of(path)] = path

PATH = re.compile(r"\b(crate|super|self)((?:::\w+)+)")
USE_GROUP = re.compile(r"\buse\s+(crate|super|self)((?:::\w+)*)::\{([^;]*)\};", re.S)
COMMENT = re.compile(r"//[^\n]*")


def resolve(base, head, parts):
    """The longest known module named by `head::parts` seen from module `base`."""
    if head == "crate":
        start = ()
    elif head == "self":
        start = base
    else:
        start = base[:-1]
        while parts and parts[0] == "super":
            start, parts = start[:-1], parts[1:]
    best = None
    for n in range(len(parts) + 1):
        candidate = start + tuple(parts[:n])
        if candidate in modules:
            best = candidate
    return best


graph = {m: set() for m in modules}
for m, path in modules.items():
    text = COMMENT.sub("", open(path, encoding="utf-8").read())
    # A file that is a directory's mod.rs is its own `self`; `super` is one level up.
    base = m
    found = []
    for head, rest, group in USE_GROUP.findall(text):
        prefix = [p for p in rest.split("::") if p]
        for item in re.split(r"[,\s]+", group):
            item = item.strip("{} ")
            if item and item not in ("self", "*"):
                found.append((head, prefix + item.split("::")))
            elif item == "self":
                found.append((head, prefix))
    for head, rest in PATH.findall(text):
        found.append((head, [p for p in rest.split("::") if p]))
    for head, parts in found:
        target = resolve(base, head, parts)
        if target is not None and target != m and target != ():
            # A module's parent (its `mod` declarations) is not an import of it.
            if m[: len(target)] != target:
                graph[m].add(target)

# Tarjan's strongly connected components.
index, low, on, stack, groups, counter = {}, {}, set(), [], [], [0]


def visit(v):
    index[v] = low[v] = counter[0]
    counter[0] += 1
    stack.append(v)
    on.add(v)
    for w in graph[v]:
        if w not in index:
            visit(w)
            low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        group = []
        while True:
            w = stack.pop()
            on.discard(w)
            group.append(w)
            if w == v:
                break
        if len(group) > 1:
            groups.append(group)


sys.setrecursionlimit(10000)
for v in sorted(graph):
    if v not in index:
        visit(v)


def name(m):
    return "::".join(("crate",) + m)


def circle(group):
    """One circle through the group, by breadth-first search back to its first member."""
    members = set(group)
    first = sorted(group)[0]
    paths = {first: [first]}
    queue = [first]
    while queue:
        v = queue.pop(0)
        for w in sorted(graph[v]):
            if w == first:
                return paths[v] + [first]
            if w in members and w not in paths:
                paths[w] = paths[v] + [w]
                queue.append(w)
    return [first]


for group in sorted(groups, key=lambda g: sorted(g)):
    print(f"circle among {len(group)} modules: " + ", ".join(name(m) for m in sorted(group)))
    print("  for example: " + " -> ".join(name(m) for m in circle(group)))
print(f"{len(modules)} modules, {sum(len(e) for e in graph.values())} imports between them, "
      f"{len(groups)} circle(s)")
sys.exit(1 if groups else 0)
