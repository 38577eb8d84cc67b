#!/usr/bin/env python3
"""Import cycles between the files of a Rust crate's source tree (CI check).

Usage: python3 tools/import_cycles.py [SRC_DIR] [--graph] [-v]
       python3 tools/import_cycles.py --self-test

Nodes are the .rs files of the module tree rooted at SRC_DIR/lib.rs (and SRC_DIR/main.rs, as a
second crate root, if present). The tree is read from `mod x;` declarations (any visibility, any
`#[cfg(...)]` except `cfg(test)`; `x.rs` or `x/mod.rs`, or a `#[path = "..."]` attribute) and
inline `mod x { ... }` blocks.

Edges: every `use` declaration (nested groups, `self`, `super`, `crate`, `as` renames, globs) and
every path written in code that starts with `crate::`, `$crate::`, `super::`, `self::` or the name
of a child module of the current module, outside comments and string literals. Each imported name
is resolved to the file that DEFINES it:
  - an item (struct/enum/union/fn/trait/type/const/static/macro_rules) defined in the target
    module -> that module's file (`#[macro_export]` macros: the file of their definition);
  - a name the module imports (`pub use` / `pub(crate) use` re-exports, groups and renames,
    and also private `use`s, which descendants can name through `super::`) -> followed to the
    defining file; glob imports (`pub use child::*`) are searched too;
  - a submodule -> the submodule's file; anything else -> the target module's file.
  Names imported from other crates (std, glam, ...) make no edge.

Kept too: edges from a child to an ancestor module file (a child using an item its parent defines):
a parent that calls into its child while the child uses the parent's items is a cycle like any other,
which is why a model folder keeps its types in files of their own and its mod.rs to declarations and
re-exports. Ignored: edges from a file to itself, edges from a module file to its own descendants
made by `pub use` re-exports (`mod` declarations make none), and test code: every item carrying `#[cfg(test)]` (the
`mod tests { ... }` blocks, test-only helpers) and files whose module is `#[cfg(test)]`.

Reports the strongly connected components with more than one file (Tarjan) with the edges
(file:line of the use) inside each, and one shortest loop through it. Exit status 0: no cycle,
1: cycle(s), 2: usage or input error. `--graph` also prints the kept edge list.
Python 3.11 standard library only.
"""

import argparse
import bisect
import os
import re
import sys
import tempfile
from collections import defaultdict, deque
from dataclasses import dataclass, field

# ----------------------------------------------------------------------------------------------
# Lexing: comments and literals blanked (offsets and line numbers kept), then tokens.

_RAW_STR = re.compile(r'(?:b|c)?r(#*)"')
_TOKEN = re.compile(r'\$crate|r#[A-Za-z_]\w*|[A-Za-z_]\w*|\d\w*|::|"|\S')
_IDENT = re.compile(r'(?:\$crate|[A-Za-z_]\w*)\Z')


def _ident_char(c):
    return c.isalnum() or c == "_"


def blank_source(text):
    """Comments and the contents of string / char literals replaced by spaces (newlines kept).
    A string literal leaves a single `"` at its first character; `strings` maps that offset to
    the literal's contents (for `#[path = "..."]`)."""
    out = list(text)
    strings = {}
    n = len(text)

    def blank(a, b, keep_quote=False):
        for k in range(a, min(b, n)):
            if out[k] != "\n":
                out[k] = " "
        if keep_quote and a < n:
            out[a] = '"'

    i = 0
    while i < n:
        c = text[i]
        prev_ident = i > 0 and _ident_char(text[i - 1])
        if c == "/" and text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
            continue
        if c == "/" and text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            blank(i, j)
            i = j
            continue
        if c in "bcr" and not prev_ident:
            m = _RAW_STR.match(text, i)
            if m:
                close = '"' + m.group(1)
                j = text.find(close, m.end())
                j = n if j < 0 else j + len(close)
                strings[i] = text[m.end() : j - len(close)]
                blank(i, j, keep_quote=True)
                i = j
                continue
        if c == '"' or (c in "bc" and not prev_ident and text.startswith('"', i + 1)):
            j = i + (1 if c == '"' else 2)
            body = j
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            strings[i] = text[body:j]
            blank(i, j + 1, keep_quote=True)
            i = j + 1
            continue
        if c == "'" or (c == "b" and not prev_ident and text.startswith("'", i + 1)):
            q = i if c == "'" else i + 1
            if q + 1 < n and text[q + 1] == "\\":  # '\n', '\'', '\u{..}'
                j = text.find("'", q + 3)
                j = n - 1 if j < 0 else j
                blank(i, j + 1)
                i = j + 1
                continue
            if q + 2 < n and text[q + 2] == "'" and text[q + 1] != "\n":  # 'a'
                blank(i, q + 3)
                i = q + 3
                continue
            i = q + 1  # a lifetime or a label
            continue
        i += 1
    return "".join(out), strings


@dataclass
class Tok:
    text: str
    off: int
    line: int


def tokenize(code):
    starts = [0] + [m.end() for m in re.finditer("\n", code)]
    toks = []
    for m in _TOKEN.finditer(code):
        t = m.group(0)
        if t.startswith("r#"):
            t = t[2:]
        toks.append(Tok(t, m.start(), bisect.bisect_right(starts, m.start())))
    return toks


def is_ident(t):
    return bool(_IDENT.match(t))


# ----------------------------------------------------------------------------------------------
# The module tree and what each module defines and imports.


@dataclass
class Import:
    ctx: tuple  # module key the path is written in
    segs: list  # path segments
    want_module: bool  # `path::{self}`


@dataclass
class Module:
    key: tuple  # (crate root file, name, name, ...)
    file: str  # path of the file holding it, relative to the source dir
    child_dir: str  # where `mod x;` inside it looks for x.rs / x/mod.rs
    path_base: str  # what `#[path]` inside it is relative to
    parent: tuple | None
    children: dict = field(default_factory=dict)
    defs: set = field(default_factory=set)
    extern_defs: dict = field(default_factory=dict)  # #[macro_export] macros: name -> file
    extern_crates: set = field(default_factory=set)
    imports: dict = field(default_factory=lambda: defaultdict(list))
    globs: list = field(default_factory=list)


@dataclass
class Use:
    """One place that names another module's item: a `use` leaf or a path in code."""

    file: str
    line: int
    ctx: tuple
    segs: list
    want_module: bool
    reexport: bool  # a leaf of a `pub use` / `pub(...) use`
    text: str


ITEM_KEYWORDS = {
    "mod", "fn", "const", "static", "struct", "enum", "union", "trait", "impl", "type", "use",
    "macro_rules", "extern",
}
DEF_KEYWORDS = {"fn", "const", "static", "struct", "enum", "union", "trait", "type"}
PATH_STARTS = {"crate", "$crate", "super", "self"}


class ParseError(Exception):
    pass


class Crate:
    def __init__(self, root, verbose=False):
        self.root = root
        self.verbose = verbose
        self.modules = {}
        self.file_module = {}  # file -> its (file-level) module key
        self.uses = []
        self.child_refs = []  # candidate `child::...` paths, kept if `child` is a child module
        self.warnings = []
        self.unresolved = []
        for name in ("lib.rs", "main.rs"):
            if os.path.isfile(os.path.join(root, name)):
                key = (name,)
                self.modules[key] = Module(key, name, "", "", None)
                self._load_file(key)
        if not self.modules:
            raise SystemExit(f"import_cycles: no lib.rs or main.rs in {root}")
        reached = set(self.file_module)
        for dirpath, _, names in os.walk(root):
            for name in names:
                rel = os.path.relpath(os.path.join(dirpath, name), root).replace(os.sep, "/")
                if name.endswith(".rs") and rel not in reached:
                    self.warnings.append(f"{self.show(rel)}: not in the module tree (not checked)")

    def show(self, rel):
        return os.path.join(self.root, rel).replace(os.sep, "/")

    # -- reading one file ---------------------------------------------------------------------

    def _load_file(self, key):
        mod = self.modules[key]
        self.file_module[mod.file] = key
        with open(os.path.join(self.root, mod.file), encoding="utf-8") as f:
            text = f.read()
        code, strings = blank_source(text)
        toks = tokenize(code)
        pending_files = []
        self._scan(mod.file, key, toks, strings, pending_files)
        for child in pending_files:
            self._load_file(child)

    def _scan(self, file, file_key, toks, strings, pending_files):
        n = len(toks)

        def tok(k):
            return toks[k].text if k < n else ""

        def close_of(k):  # index of the delimiter closing toks[k]
            pairs = {"{": "}", "(": ")", "[": "]"}
            depth = 0
            for j in range(k, n):
                t = toks[j].text
                if t in pairs:
                    depth += 1
                elif t in ("}", ")", "]"):
                    depth -= 1
                    if depth == 0:
                        return j
            return n - 1

        def item_head(k):
            """(is_pub, keyword index) if an item starts at k, else None."""
            is_pub = False
            if tok(k) == "pub":
                is_pub = True
                k += 1
                if tok(k) == "(":
                    k = close_of(k) + 1
            while True:
                t = tok(k)
                if t in ("async", "unsafe", "default", "auto"):
                    k += 1
                elif t == "extern" and tok(k + 1) == '"':
                    k += 2
                elif t == "const" and tok(k + 1) in ("fn", "unsafe", "async", "extern"):
                    k += 1
                else:
                    break
            t = tok(k)
            if t not in ITEM_KEYWORDS:
                return None
            if t == "union" and not is_ident(tok(k + 1)):
                return None
            return is_pub, k

        def item_end(k):
            """Index just past the item whose keyword is at k."""
            kw = tok(k)
            semicolon_only = kw in ("const", "static", "use", "type") or (
                kw == "extern" and tok(k + 1) == "crate"
            )
            if kw == "const" and tok(k + 1) == "fn":
                semicolon_only = False
            depth = 0
            j = k
            while j < n:
                t = toks[j].text
                if t in ("(", "["):
                    depth += 1
                elif t == "{":
                    if depth == 0 and not semicolon_only:
                        return close_of(j) + 1
                    depth += 1
                elif t in (")", "]", "}"):
                    depth -= 1
                    if depth < 0:
                        return j
                elif t == ";" and depth == 0:
                    return j + 1
                j += 1
            return n

        def is_cfg_test(attr):
            texts = [t.text for t in attr]
            return texts[:4] == ["cfg", "(", "test", ")"]

        # A `#![cfg(test)]` file is test code.
        if tok(0) == "#" and tok(1) == "!" and tok(2) == "[":
            if is_cfg_test(toks[3 : close_of(2)]):
                return

        stack = [("mod", file_key)]  # ("mod", key) | ("block", None)
        attrs = []
        i = 0
        while i < n:
            t = toks[i].text
            ctx = next(s[1] for s in reversed(stack) if s[0] == "mod")
            module_level = all(s[0] == "mod" for s in stack)
            mod = self.modules[ctx]

            if t == "#" and tok(i + 1) in ("[", "!"):
                j = i + 1 + (tok(i + 1) == "!")
                if tok(j) == "[":
                    end = close_of(j)
                    if tok(i + 1) == "[":
                        attrs.append(toks[j + 1 : end])
                    i = end + 1
                    continue

            # Items start a statement: after `;`, `{`, `}` or an attribute's `]`.
            head = item_head(i) if i == 0 or tok(i - 1) in (";", "{", "}", "]") else None
            if head is not None and any(is_cfg_test(a) for a in attrs):
                i = item_end(head[1])  # test code may use anything
                attrs = []
                continue
            item_attrs, attrs = attrs, []
            if head is not None:
                is_pub, k = head
                kw = tok(k)
                if kw == "use" and tok(k + 1) != "<":
                    end = item_end(k)
                    self._use(file, ctx, toks[k + 1 : end - 1], is_pub, module_level)
                    i = end
                    continue
                if kw == "mod" and is_ident(tok(k + 1)):
                    name = tok(k + 1)
                    path_attr = next(
                        (strings.get(a[2].off) for a in item_attrs
                         if len(a) >= 3 and a[0].text == "path" and a[1].text == "=" and a[2].text == '"'),
                        None,
                    )
                    if tok(k + 2) == ";":
                        if module_level:
                            child = self._declare(mod, name, path_attr, toks[k].line)
                            if child is not None:
                                pending_files.append(child)
                        i = k + 3
                        continue
                    if tok(k + 2) == "{":
                        ckey = ctx + (name,)
                        child_dir = path_join(mod.child_dir, path_attr or name)
                        self.modules[ckey] = Module(ckey, file, child_dir, child_dir, ctx)
                        mod.children[name] = ckey
                        stack.append(("mod", ckey))
                        i = k + 3
                        continue
                if module_level:
                    if kw in DEF_KEYWORDS and is_ident(tok(k + 1)):
                        name = tok(k + 2) if tok(k + 1) == "mut" else tok(k + 1)
                        if name != "_" and is_ident(name):
                            mod.defs.add(name)
                    elif kw == "macro_rules" and tok(k + 1) == "!" and is_ident(tok(k + 2)):
                        name = tok(k + 2)
                        if any(a and a[0].text == "macro_export" for a in item_attrs):
                            self.modules[(ctx[0],)].extern_defs[name] = file
                        else:
                            mod.defs.add(name)
                    elif kw == "extern" and tok(k + 1) == "crate":
                        end = item_end(k)
                        words = [x.text for x in toks[k + 2 : end - 1]]
                        mod.extern_crates.add(words[-1] if words else "")
                        i = end
                        continue
                i = k + 1
                continue

            if t == "{":
                stack.append(("block", None))
            elif t in ("(", "["):
                stack.append(("paren", None))
            elif t in ("}", ")", "]"):
                if len(stack) > 1:
                    stack.pop()
            elif is_ident(t) and tok(i + 1) == "::" and (i == 0 or tok(i - 1) not in ("::", ".")):
                k = i
                segs = [t]
                while tok(k + 1) == "::" and is_ident(tok(k + 2)):
                    segs.append(tok(k + 2))
                    k += 2
                use = Use(file, toks[i].line, ctx, segs, False, False, "::".join(segs))
                if t in PATH_STARTS:
                    self.uses.append(use)
                elif len(segs) > 1:
                    self.child_refs.append(use)
                i = k + 1
                continue
            i += 1

    def _declare(self, mod, name, path_attr, line):
        if path_attr is not None:
            cands = [path_join(mod.path_base, path_attr)]
        else:
            cands = [path_join(mod.child_dir, name + ".rs"), path_join(mod.child_dir, name, "mod.rs")]
        for rel in cands:
            rel = os.path.normpath(rel).replace(os.sep, "/")
            if os.path.isfile(os.path.join(self.root, rel)):
                key = mod.key + (name,)
                if path_attr is not None or rel.endswith("/mod.rs") or rel == "mod.rs":
                    child_dir = os.path.dirname(rel)
                else:
                    child_dir = rel[: -len(".rs")]
                base = os.path.dirname(rel)
                self.modules[key] = Module(key, rel, child_dir, base, mod.key)
                mod.children[name] = key
                return key
        self.warnings.append(f"{self.show(mod.file)}:{line}: `mod {name};` has no file ({', '.join(cands)})")
        return None

    def _use(self, file, ctx, toks, is_pub, module_level):
        try:
            leaves = []
            k = parse_use_tree(toks, 0, [], leaves)
            if k != len(toks):
                raise ParseError("trailing tokens")
        except ParseError as e:
            line = toks[0].line if toks else "?"
            self.warnings.append(f"{self.show(file)}:{line}: unparsed use ({e}) skipped")
            return
        mod = self.modules[ctx]
        for segs, alias, glob, line in leaves:
            want_module = False
            if len(segs) > 1 and segs[-1] == "self":
                segs, want_module = segs[:-1], True
            if not segs or segs == ["self"]:
                continue
            text = "::".join(segs) + ("::*" if glob else "") + (f" as {alias}" if alias else "")
            self.uses.append(Use(file, line, ctx, segs, want_module, is_pub, text))
            if module_level:
                imp = Import(ctx, segs, want_module)
                if glob:
                    mod.globs.append(imp)
                else:
                    bound = alias or segs[-1]
                    if bound != "_" and bound not in PATH_STARTS:
                        mod.imports[bound].append(imp)

    # -- resolution -----------------------------------------------------------------------------

    def resolve(self, ctx, segs, want_module=False, seen=frozenset()):
        """("mod", key) | ("file", file) | None (another crate's name, or unresolvable)."""
        first, rest = segs[0], list(segs)
        if first in ("crate", "$crate"):
            cur, rest = (ctx[0],), rest[1:]
        elif first == "self":
            cur, rest = ctx, rest[1:]
        elif first == "super":
            cur = ctx
            while rest and rest[0] == "super":
                cur = self.modules[cur].parent if cur else None
                rest = rest[1:]
            if cur is None:
                return None
        else:
            cur = ctx
            found = self.lookup(cur, first, len(rest) > 1 or want_module, seen)
            if found is None or found == "extern":
                return None
        if not rest:
            return ("mod", cur)
        for idx, name in enumerate(rest):
            last = idx == len(rest) - 1
            found = self.lookup(cur, name, not last or want_module, seen)
            if found == "extern":
                return None
            if found is None:
                self.unresolved.append((cur, name))
                return ("file", self.modules[cur].file)
            if found[0] == "file":
                return found  # an item: further segments are its variants / associated items
            cur = found[1]
        return ("mod", cur)

    def lookup(self, key, name, prefer_module, seen):
        """Where `name` in module `key` is defined: ("mod", key) | ("file", file) | "extern" | None."""
        m = self.modules[key]
        if prefer_module and name in m.children:
            return ("mod", m.children[name])
        if name in m.defs:
            return ("file", m.file)
        if name in m.extern_defs:
            return ("file", m.extern_defs[name])
        if name in m.extern_crates:
            return "extern"
        if name in m.imports and (key, name) not in seen:
            for imp in m.imports[name]:
                r = self.resolve(imp.ctx, imp.segs, imp.want_module or prefer_module, seen | {(key, name)})
                if r is not None:
                    return r
            return "extern"
        if name in m.children:
            return ("mod", m.children[name])
        for g in m.globs:
            if (key, "*", tuple(g.segs)) in seen:
                continue
            s = seen | {(key, "*", tuple(g.segs))}
            target = self.resolve(g.ctx, g.segs, True, s)
            if target is not None and target[0] == "mod":
                r = self.lookup(target[1], name, prefer_module, s)
                if r is not None and r != "extern":
                    return r
        return None

    # -- the graph --------------------------------------------------------------------------------

    def edges(self):
        """Kept edges {(src, dst): [(line, text), ...]} and the count of ignored ones."""
        kept = defaultdict(list)
        ignored = defaultdict(int)
        uses = list(self.uses)
        for use in self.child_refs:  # `name::...` where name is a child module or an imported module
            found = self.lookup(use.ctx, use.segs[0], True, frozenset())
            if isinstance(found, tuple) and found[0] == "mod":
                uses.append(use)
        for use in uses:
            r = self.resolve(use.ctx, use.segs, use.want_module)
            if r is None:
                continue
            dst = self.modules[r[1]].file if r[0] == "mod" else r[1]
            src = use.file
            skey, dkey = self.file_module[src], self.file_module[dst]
            if src == dst:
                ignored["same file"] += 1
            elif use.reexport and skey == dkey[: len(skey)]:
                ignored["re-export of a descendant"] += 1
            else:
                kept[(src, dst)].append((use.line, use.text))
        return kept, ignored


def path_join(*parts):
    return "/".join(p for p in parts if p)


def parse_use_tree(toks, k, prefix, leaves):
    """Parses one use tree at toks[k]; appends (segs, alias, glob, line) to leaves."""
    n = len(toks)

    def tok(j):
        return toks[j].text if j < n else ""

    segs = list(prefix)
    if tok(k) == "::":
        k += 1
    while True:
        t = tok(k)
        if t == "{":
            k += 1
            while tok(k) != "}":
                if k >= n:
                    raise ParseError("unclosed {")
                k = parse_use_tree(toks, k, segs, leaves)
                if tok(k) == ",":
                    k += 1
                elif tok(k) != "}":
                    raise ParseError(f"unexpected {tok(k)!r}")
            return k + 1
        if t == "*":
            leaves.append((segs, None, True, toks[k].line))
            return k + 1
        if is_ident(t):
            segs.append(t)
            line = toks[k].line
            k += 1
            if tok(k) == "::":
                k += 1
                continue
            alias = None
            if tok(k) == "as":
                alias = tok(k + 1)
                if not is_ident(alias):
                    raise ParseError("bad `as`")
                k += 2
            leaves.append((segs, alias, False, line))
            return k
        raise ParseError(f"unexpected {t!r}")


# ----------------------------------------------------------------------------------------------
# Strongly connected components (Tarjan) and one shortest loop through each.


def tarjan(nodes, succ):
    sys.setrecursionlimit(max(10000, 4 * len(nodes)))
    index, low, on, stack, out = {}, {}, set(), [], []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in succ[v]:
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
            out.append(sorted(comp))

    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def shortest_loop(comp, succ):
    members = set(comp)
    best = None
    for start in comp:
        prev = {start: None}
        q = deque([start])
        found = None
        while q and found is None:
            v = q.popleft()
            for w in sorted(succ[v]):
                if w not in members:
                    continue
                if w == start:
                    found = v
                    break
                if w not in prev:
                    prev[w] = v
                    q.append(w)
        if found is not None:
            path = [found]
            while prev[path[-1]] is not None:
                path.append(prev[path[-1]])
            path.reverse()
            path.append(start)
            if best is None or len(path) < len(best):
                best = path
    return best


def analyse(root, verbose=False):
    crate = Crate(root, verbose)
    kept, ignored = crate.edges()
    nodes = set(crate.file_module)
    succ = defaultdict(set)
    for src, dst in kept:
        succ[src].add(dst)
    cycles = [c for c in tarjan(nodes, succ) if len(c) > 1]
    return crate, kept, ignored, cycles, succ


def run(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("src", nargs="?", default="src", help="the crate's source dir (default: src)")
    ap.add_argument("--graph", action="store_true", help="print the kept edges")
    ap.add_argument("-v", "--verbose", action="store_true", help="print warnings and unresolved names")
    ap.add_argument("--self-test", action="store_true", help="check this script on a temporary tree")
    args = ap.parse_args(argv)
    if args.self_test:
        return self_test()
    if not os.path.isdir(args.src):
        print(f"import_cycles: {args.src} is not a directory", file=sys.stderr)
        return 2
    crate, kept, ignored, cycles, succ = analyse(args.src, args.verbose)
    show = crate.show
    for w in crate.warnings:
        print(f"warning: {w}", file=sys.stderr)
    if args.verbose:
        for key, name in sorted(set(crate.unresolved)):
            print(f"note: `{name}` not found in {'::'.join(key[1:]) or 'crate'} "
                  f"({show(crate.modules[key].file)}), taken as defined there", file=sys.stderr)
    if args.graph:
        for src, line, dst, text in sorted(
            (src, line, dst, text) for (src, dst), sites in kept.items() for line, text in sites
        ):
            print(f"{show(src)}:{line} -> {show(dst)}  ({text})")
    n_edges = sum(len(s) for s in kept.values())
    ign = ", ".join(f"{v} {k}" for k, v in sorted(ignored.items())) or "none"
    print(f"import_cycles: {len(crate.file_module)} files, {len(kept)} file->file edges "
          f"from {n_edges} uses (ignored: {ign})")
    if not cycles:
        print("import_cycles: no cycle")
        return 0
    for idx, comp in enumerate(cycles, 1):
        print(f"\ncycle {idx}: {len(comp)} files: {', '.join(show(f) for f in comp)}")
        loop = shortest_loop(comp, succ)
        print("  shortest loop: " + " -> ".join(show(f) for f in loop))
        print("  edges inside:")
        members = set(comp)
        for src, line, dst, text in sorted(
            (src, line, dst, text) for (src, dst), sites in kept.items() for line, text in sites
            if src in members and dst in members
        ):
            print(f"    {show(src)}:{line} -> {show(dst)}  ({text})")
    print(f"\nimport_cycles: {len(cycles)} cycle(s)")
    return 1


# ----------------------------------------------------------------------------------------------


SELF_TEST_TREE = {
    "lib.rs": """
        //! Not a use: crate::d::D in a doc comment.
        mod a;
        mod b;
        mod d;
        pub mod p;
        mod q;
        pub use p::{C, P as Renamed};
    """,
    # a.rs <-> b.rs: a `use` one way, an inline path in code the other way.
    "a.rs": """
        use crate::b::B;
        pub struct A(pub B);
        #[cfg(test)]
        mod tests {
            use crate::d::D; // test code may use anything
        }
    """,
    "b.rs": """
        pub struct B;
        pub fn make() -> crate::a::A {
            let _s = "crate::d::D in a string";
            crate::a::A(B)
        }
    """,
    # d.rs: a nested multi-line group, a rename, `self`, and a name re-exported by p (-> p/c.rs).
    "d.rs": """
        use crate::{
            p::{self, C as Cee},
            Renamed,
        };
        pub struct D(pub Cee, pub p::P, pub Renamed);
    """,
    # p/mod.rs declares and re-exports its child, and the child uses its parent: an edge, no cycle.
    "p/mod.rs": """
        mod c;
        pub use c::C;
        pub struct P;
    """,
    "p/c.rs": """
        use super::P;
        pub struct C(pub P);
    """,
    # q/mod.rs calls into its child, which uses the parent's type: a child -> parent cycle.
    "q/mod.rs": """
        mod e;
        pub struct Q;
        pub fn make() -> Q {
            e::build()
        }
    """,
    "q/e.rs": """
        use super::Q;
        pub fn build() -> Q {
            Q
        }
    """,
}


def self_test():
    with tempfile.TemporaryDirectory() as tmp:
        for rel, body in SELF_TEST_TREE.items():
            path = os.path.join(tmp, rel)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8") as f:
                f.write("\n".join(line[8:] for line in body.strip("\n").split("\n")) + "\n")
        crate, kept, ignored, cycles, _ = analyse(tmp)
        edges = {(s, d): sorted(line for line, _ in sites) for (s, d), sites in kept.items()}
        expected = {
            ("a.rs", "b.rs"): [1],  # use crate::b::B
            ("b.rs", "a.rs"): [2, 4],  # crate::a::A in the signature and the body
            ("d.rs", "p/c.rs"): [2],  # C through p's `pub use c::C`
            ("d.rs", "p/mod.rs"): [2, 3, 5],  # p::{self}, Renamed (= p::P through lib.rs), p::P
            ("p/c.rs", "p/mod.rs"): [1],  # use super::P: a child using its parent's item
            ("q/mod.rs", "q/e.rs"): [4],  # e::build() in code
            ("q/e.rs", "q/mod.rs"): [1],  # use super::Q
        }
        ok = True
        if edges != expected:
            print(f"self-test: edges {edges}\n      expected {expected}", file=sys.stderr)
            ok = False
        want_cycles = [["a.rs", "b.rs"], ["q/e.rs", "q/mod.rs"]]
        if sorted(cycles) != want_cycles:
            print(f"self-test: cycles {cycles}, expected {want_cycles}", file=sys.stderr)
            ok = False
        if crate.warnings:
            print(f"self-test: warnings {crate.warnings}", file=sys.stderr)
            ok = False
        # The command line: exit status 1 and the cycle printed with its file:line edges.
        import contextlib
        import io

        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            status = run([tmp])
        out = buf.getvalue().replace(tmp + "/", "")
        for want in (
            "a.rs:1 -> b.rs",
            "b.rs:2 -> a.rs",
            "b.rs:4 -> a.rs",
            "q/e.rs:1 -> q/mod.rs",
            "2 cycle(s)",
        ):
            if want not in out:
                print(f"self-test: {want!r} not in the report:\n{out}", file=sys.stderr)
                ok = False
        if status != 1:
            print(f"self-test: exit status {status}, expected 1", file=sys.stderr)
            ok = False
        # Without b's use of a and q's call into e, no cycle and exit status 0.
        with open(os.path.join(tmp, "b.rs"), "w", encoding="utf-8") as f:
            f.write("pub struct B;\n")
        with open(os.path.join(tmp, "q/mod.rs"), "w", encoding="utf-8") as f:
            f.write("mod e;\npub struct Q;\n")
        with contextlib.redirect_stdout(io.StringIO()):
            status = run([tmp])
        if status != 0:
            print(f"self-test: exit status {status} without the cycle, expected 0", file=sys.stderr)
            ok = False
    print("import_cycles self-test: " + ("ok" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(run(sys.argv[1:]))
