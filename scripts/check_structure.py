#!/usr/bin/env python3
"""The source tree's structure against issue 56's limits: files of src/ over 700 lines,
functions of 100 lines or more, and include cycles between units (a .hpp with its .cpp of the
same name), which show an include running back up. Prints each, then a line of counts.

    python3 scripts/check_structure.py [src]

The function finder reads braces, not C++: a count to act on, not a proof."""
import collections
import os
import re
import sys

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', 'src')
sources = []
for folder, _, files in os.walk(root):
    sources += [os.path.join(folder, f) for f in files if f.endswith(('.cpp', '.hpp'))]
sources.sort()


def code_of(line):
    return re.sub(r'//.*|"(\\.|[^"\\])*"|\'(\\.|[^\'\\])*\'', '', line)


def long_files(limit=700):
    for path in sources:
        n = open(path).read().count('\n')
        if n > limit:
            yield n, os.path.relpath(path, root)


def long_functions(limit=100):
    for path in sources:
        lines = open(path).read().split('\n')
        depth, starts = 0, {}
        for i, line in enumerate(lines):
            code = code_of(line)
            for ch in code:
                if ch == '{':
                    head = code.split('{')[0]
                    prev = code_of(lines[i - 1]) if i else ''
                    control = re.search(r'\b(if|for|while|switch|catch)\s*\(', head)
                    lambda_ = '[' in head.split('(')[0]
                    closes = re.search(r'\)\s*(const)?\s*(noexcept)?\s*(override)?\s*(->[^{]*)?\s*$',
                                       head) or (not head.strip() and re.search(r'\)\s*(const)?\s*$', prev))
                    if (closes or re.search(r'\)\s*:\s*\w', head)) and not control and not lambda_:
                        starts[depth] = i
                    depth += 1
                elif ch == '}':
                    depth -= 1
                    if depth in starts:
                        n = i - starts[depth] + 1
                        if n >= limit:
                            yield n, f'{os.path.relpath(path, root)}:{starts[depth] + 1}', \
                                lines[starts[depth]].strip()[:70]
                        del starts[depth]


def include_cycles():
    edges = collections.defaultdict(set)
    for path in sources:
        unit = os.path.splitext(os.path.relpath(path, root))[0]
        for m in re.finditer(r'#include "fiberfluid/([^"]+)"', open(path).read()):
            other = os.path.splitext(m.group(1))[0]
            if other != unit:
                edges[unit].add(other)
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return cycles


files = list(long_files())
functions = sorted(long_functions(), reverse=True)
cycles = include_cycles()
for n, path in files:
    print(f'file over 700 lines: {path} ({n})')
for n, where, text in functions:
    print(f'function of {n} lines: {where} {text}')
for c in cycles:
    print(f'include cycle of {len(c)} units: ' + ', '.join(c))
print(f'{len(files)} files over 700 lines, {len(functions)} functions of 100 lines or more, '
      f'{len(cycles)} include cycles')
