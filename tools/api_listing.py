#!/usr/bin/env python3
"""The crate's public API as text, from the rustdoc HTML, so that API changes show in review.

Reads target/doc/brdf/all.html (written by `cargo doc --no-deps`, default features) and, for every
item it lists, the item's declaration and the signatures of its inherent methods (trait impls,
auto traits and blanket impls are left out; glam's re-exported Vec2, Vec3 and Mat2 are listed by
name only). Writes the listing to docs/api.txt, or with --check compares it with docs/api.txt and
fails (exit 1, with a diff) when they differ.

Usage: cargo doc --no-deps && python3 tools/api_listing.py [--check] [--doc-dir DIR]
"""

import argparse
import difflib
import html
import os
import re
import sys

# Pages whose members are another crate's API (re-exports).
FOREIGN = {"Vec2", "Vec3", "Mat2"}
# Sections after which a type page documents trait impls, not its own API.
END_SECTIONS = (
    'id="trait-implementations"',
    'id="synthetic-implementations"',
    'id="blanket-implementations"',
    'id="implementors"',
    'id="foreign-impls"',
    'id="dyn-compatibility"',
)


def text(fragment: str) -> str:
    """Rustdoc HTML to one line of plain text."""
    fragment = re.sub(r"<[^>]+>", "", fragment)
    fragment = " ".join(html.unescape(fragment).split())
    # Rustdoc's fold toggles ("Show 14 variants") are page furniture, not API.
    return re.sub(r"\s*Show \d+ (variants|fields|methods)\s*", " ", fragment)


def item_listing(page: str, name: str) -> list[str]:
    """The declaration and inherent method signatures of one item page."""
    if name.split("::")[-1] in FOREIGN:
        return []
    cut = min([page.find(s) for s in END_SECTIONS if s in page] + [len(page)])
    own = page[:cut]
    out = []
    decl = re.search(r'<pre class="rust item-decl">(.*?)</pre>', own, re.S)
    if decl:
        out.append("    " + text(decl.group(1)))
    # Inherent impl headers and their items (methods, associated constants and types).
    impls = own.find('id="implementations"')
    if impls >= 0:
        for m in re.finditer(r'<h([34]) class="code-header">(.*?)</h\1>', own[impls:], re.S):
            indent = "    " if m.group(1) == "3" else "        "
            out.append(indent + text(m.group(2)))
    return out


def listing(doc_dir: str) -> str:
    with open(os.path.join(doc_dir, "all.html"), encoding="utf-8") as f:
        all_html = f.read()
    items = re.findall(r'<a href="([^"#]+\.html)">([^<]+)</a>', all_html)
    lines = [
        "# The public API of brdf (default features), from rustdoc: item declarations and inherent",
        "# methods. Regenerate with `cargo doc --no-deps && python3 tools/api_listing.py`.",
    ]
    for href, name in sorted(set(items), key=lambda x: (x[1], x[0])):
        kind = os.path.basename(href).split(".")[0]
        if kind == "index":
            continue
        lines.append(f"{kind} brdf::{text(name)}")
        with open(os.path.join(doc_dir, href), encoding="utf-8") as f:
            lines.extend(item_listing(f.read(), text(name)))
    return "\n".join(lines) + "\n"


def main() -> int:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(root, "target"))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="fail if docs/api.txt is stale")
    ap.add_argument("--doc-dir", default=os.path.join(target, "doc", "brdf"))
    args = ap.parse_args()
    new = listing(args.doc_dir)
    path = os.path.join(root, "docs", "api.txt")
    if not args.check:
        with open(path, "w", encoding="utf-8") as f:
            f.write(new)
        print(f"wrote {path} ({new.count(chr(10))} lines)")
        return 0
    old = open(path, encoding="utf-8").read() if os.path.exists(path) else ""
    if old == new:
        print("docs/api.txt is up to date")
        return 0
    sys.stdout.writelines(
        difflib.unified_diff(
            old.splitlines(True), new.splitlines(True), "docs/api.txt", "rustdoc"
        )
    )
    print(
        "\ndocs/api.txt is stale: the public API changed. Regenerate it with "
        "`cargo doc --no-deps && python3 tools/api_listing.py` and commit it.",
        file=sys.stderr,
    )
    return 1


if __name__ == "__main__":
    sys.exit(main())
