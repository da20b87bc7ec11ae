#!/usr/bin/env python3
"""Import graph between the files of each crate: edges from `use crate::x` / `use super::x` /
`crate::x::` paths (all occurrences, not only use lines); reports strongly connected components."""
import os, re, sys
root = sys.argv[1]
crates = sys.argv[2:]
def modpath(src, f):
    rel = os.path.relpath(f, src)[:-3].split(os.sep)
    if rel[-1] in ('lib', 'main'): rel = rel[:-1]
    elif rel[-1] == 'mod': rel = rel[:-1]
    return tuple(rel)
for c in crates:
    src = os.path.join(root, 'crates', c, 'src')
    files = {}
    for d, _, fs in os.walk(src):
        for fn in fs:
            if fn.endswith('.rs'):
                p = os.path.join(d, fn); files[modpath(src, p)] = p
    mods = set(files)
    def resolve(path):
        # longest prefix that's a module file
        for i in range(len(path), 0, -1):
            if tuple(path[:i]) in mods: return tuple(path[:i])
        return ()
    edges = {m: set() for m in mods}
    for m, p in files.items():
        text = open(p).read()
        # strip #[cfg(test)] mod tests { ... } at end roughly: cut at '#[cfg(test)]\nmod tests'
        m_ = re.search(r'#\[cfg\(test\)\]\n(pub(\(crate\))? )?mod tests', text); i = m_.start() if m_ else -1
        if i >= 0: text = text[:i]
        text = re.sub(r'^\s*//.*$', '', text, flags=re.M)
        is_modrs = p.endswith('mod.rs') or p.endswith('lib.rs')
        for mm in re.finditer(r'\b(crate|super)((?:::\{?[A-Za-z_][A-Za-z0-9_]*)+)', text):
            kind, rest = mm.group(1), mm.group(2)
            parts = [x.strip('{') for x in rest.split('::') if x]
            if kind == 'crate': base = []
            else: base = list(m[:-1])
            # handle super::super
            while parts and parts[0] == 'super':
                base = base[:-1]; parts = parts[1:]
            target = resolve(base + parts) if base + parts else ()
            if target != m and target != ():
                edges[m].add(target)
        # also grouped use crate::{a::X, b::Y}
        for mm in re.finditer(r'use (crate|super)::\{([^;]*)\};', text, re.S):
            base = [] if mm.group(1) == 'crate' else list(m[:-1])
            for item in re.split(r',\s*', mm.group(2)):
                item = item.strip()
                if not item or not re.match(r'[a-z_]', item): continue
                parts = [x.strip('{} ') for x in item.split('::')]
                t = resolve(base + parts)
                if t != m and t != (): edges[m].add(t)
        for mm in re.finditer(r'^\s*(?:pub(?:\([a-z]+\))? )?mod ([a-z_0-9]+);', text, re.M):
            child = m + (mm.group(1),)
            if child in mods and re.search(r'(?<![:\w])' + mm.group(1) + r'::', text):
                edges[m].add(child)
    # Tarjan
    index = {}; low = {}; st = []; on = set(); out = []; n = [0]
    sys.setrecursionlimit(10000)
    def sc(v):
        index[v] = low[v] = n[0]; n[0] += 1; st.append(v); on.add(v)
        for w in edges.get(v, ()):
            if w not in index: sc(w); low[v] = min(low[v], low[w])
            elif w in on: low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = st.pop(); on.discard(w); comp.append(w)
                if w == v: break
            if len(comp) > 1: out.append(comp)
    for v in list(edges):
        if v not in index: sc(v)
    for comp in out:
        print(c, 'CYCLE:', sorted('/'.join(x) or 'lib' for x in comp))
        for a in comp:
            for b in edges[a]:
                if b in comp: print('   ', '/'.join(a) or 'lib', '->', '/'.join(b) or 'lib')
