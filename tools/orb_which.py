#!/usr/bin/env python3
"""The crate's one "which model when" guide, from the orb sweep's curves.

    python3 tools/orb_which.py [CSV] [ERROR ...]   print the per-map tables (stdout)
    python3 tools/orb_which.py --write [CSV]       render the guide into its copies
    python3 tools/orb_which.py --check [CSV]       exit 1 when a copy differs from what the CSV gives

CSV defaults to docs/data/orb_curves.csv (written by `cargo run --release --example orb --
--curves`). The guide has two parts, both computed from the CSV:

- the summary table (rows: texels per pixel; columns: target errors): per footprint and target, the
  method first to reach the target on each map, grouped by method, with the glint models' speedups
  over naive; and the mixture's own error at its defaults. It is rendered between the markers
  `<!-- which-model:begin -->` and `<!-- which-model:end -->` in docs/glint.md, src/lib.rs (the
  crate docs) and src/glint/mod.rs (the `brdf::glint` module doc), as Markdown or as `//!` lines;
- the per-map tables (docs/glint.md only, between `<!-- which-model-maps:begin -->` and
  `<!-- which-model-maps:end -->`).

Winner rule. For each map, footprint and target error (default 0.2, 0.1, 0.05): the method that
first reaches a denoised relative RMSE against (a) at or below the target. Naive sampling's time at
the target is interpolated on its measured curve (log time against log error, between the spp that
bracket the target; its 1-spp time if that already meets it); a glint model (σ_ε-matched: the
mixture at its defaults and without level of detail, the smoothed bin map, position-normal at σ_r =
σ_ε) counts with the fastest of its 1, 4 and 16 evaluations per pixel that meets the target (the
count in brackets when not 1). Per-map cells: the winner, its time and, for a glint model, its
speedup over naive (∞: naive does not get there); "+build:" the winner when build times count, if
it differs; "none": nothing gets there."""
import csv
import difflib
import math
import os
import sys
import textwrap

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_CSV = "docs/data/orb_curves.csv"
ERRORS = [0.2, 0.1, 0.05]
# Prose lines wrap at this width (tables stay one line per row).
WIDTH = 100

CANDIDATES = {
    "mixture": "mixture",
    "mixture (no LOD)": "mixture (no LOD)",
    "bin map": "bin map",
    "position-normal": "pos.-normal",
}

# Where the summary goes: (file, form). The per-map tables go to docs/glint.md only.
COPIES = [
    ("docs/glint.md", "md"),
    ("src/lib.rs", "rust"),
    ("src/glint/mod.rs", "rust"),
]
SUMMARY = ("<!-- which-model:begin -->", "<!-- which-model:end -->")
MAPS = ("<!-- which-model-maps:begin -->", "<!-- which-model-maps:end -->")


def sec(t):
    return f"{t:.2g} s" if t < 100 else f"{t:.0f} s"


def naive_time(points, target):
    """Time naive sampling needs for `target`, on its (time, error) curve in spp order."""
    if not points:
        return None
    if points[0][1] <= target:
        return points[0][0]
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e1 <= target < e0:
            if e0 <= 0 or e1 <= 0 or t0 <= 0 or t1 <= 0:
                return t1
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None


def speedup(naive, t):
    """Naive's time over the model's, or None when naive does not get there (∞)."""
    return None if naive is None else naive / t


def fmt_speed(x):
    if x is None:
        return "∞×"
    return f"{x:.2g}×" if x < 100 else f"{x:.0f}×"


def fmt_speeds(finite, infinite):
    """A range of speedups: "1.2-2.4×", "4.5-∞×", "∞×"."""
    if not finite:
        return "∞×"
    lo = fmt_speed(min(finite))[:-1]
    hi = "∞" if infinite else fmt_speed(max(finite))[:-1]
    return f"{lo}×" if lo == hi else f"{lo}-{hi}×"


def load(path):
    rows = list(csv.DictReader(open(path, encoding="utf-8")))
    maps = list(dict.fromkeys(r["map"] for r in rows))
    scales = list(dict.fromkeys(r["scale"] for r in rows))
    texels = {}
    for r in rows:
        texels.setdefault(r["scale"], int(r["texels_per_pixel"]))
    return rows, maps, scales, texels


def winner(rows, m, sc, target):
    """The winner at (map, scale, target): dict with label, method (no eval count), time, glint
    (bool), speed (None = ∞) and, build counted, build_label / build_time; None if nothing gets
    there."""
    at = [r for r in rows if r["map"] == m and r["scale"] == sc]
    naive = [(float(r["render_s"]), float(r["rel_rmse_denoised"])) for r in at if r["method"] == "naive"]
    tn = naive_time(naive, target)
    best, best_b = None, None
    if tn is not None:
        best = ("naive", "naive", tn, False)
        best_b = ("naive", tn)
    for r in at:
        name = CANDIDATES.get(r["method"])
        if name is None or float(r["rel_rmse_denoised"]) > target:
            continue
        ev = r["evals_per_pixel"]
        label = name if ev == "1" else f"{name} ({ev})"
        t, b = float(r["render_s"]), float(r["build_s"])
        if best is None or t < best[2]:
            best = (label, name, t, True)
        if best_b is None or t + b < best_b[1]:
            best_b = (label, t + b)
    if best is None:
        return None
    return {
        "label": best[0],
        "method": best[1],
        "time": best[2],
        "glint": best[3],
        "speed": speedup(tn, best[2]) if best[3] else None,
        "build_label": best_b[0],
        "build_time": best_b[1],
    }


def per_map_tables(rows, maps, scales, texels, errors):
    """The per-map tables (Markdown lines), one per target error."""
    out = []
    for target in errors:
        out.append(f"**Error {target:g}**")
        out.append("")
        head = " | ".join(f"{texels[sc]:,} texels/px" for sc in scales)
        out.append(f"| map | {head} |")
        out.append("| --- " * (1 + len(scales)) + "|")
        for m in maps:
            cells = []
            for sc in scales:
                w = winner(rows, m, sc, target)
                if w is None:
                    cells.append("none")
                    continue
                cell = f"{w['label']} {sec(w['time'])}"
                if w["glint"]:
                    cell += f", {fmt_speed(w['speed'])}"
                if w["build_label"] != w["label"]:
                    cell += f" · +build: {w['build_label']} {sec(w['build_time'])}"
                cells.append(cell)
            out.append(f"| {m} | " + " | ".join(cells) + " |")
        out.append("")
    return out


def summary_cell(rows, maps, sc, target):
    """One summary cell: the winners grouped by method (glint models with their speedup range),
    methods in order of the maps they win, then the maps nothing reaches."""
    groups = {}
    for m in maps:
        w = winner(rows, m, sc, target)
        key = "none" if w is None else w["method"]
        groups.setdefault(key, []).append((m, w))
    order = sorted((k for k in groups if k != "none"), key=lambda k: -len(groups[k]))
    parts = []
    for k in order:
        text = f"{k}: " + ", ".join(m for m, _ in groups[k])
        w = [x for _, x in groups[k]]
        if w[0]["glint"]:
            finite = [x["speed"] for x in w if x["speed"] is not None]
            text += f" ({fmt_speeds(finite, len(finite) < len(w))})"
        parts.append(text)
    if "none" in groups:
        parts.append("nothing: " + ", ".join(m for m, _ in groups["none"]))
    return "; ".join(parts)


def mixture_errors(rows, sc):
    """Range over maps of the default mixture's denoised error at 1 evaluation per pixel."""
    e = [float(r["rel_rmse_denoised"]) for r in rows
         if r["scale"] == sc and r["method"] == "mixture" and r["evals_per_pixel"] == "1"]
    return f"{min(e):.2f}-{max(e):.2f}" if e else "—"


def summary(rows, maps, scales, texels, errors, form):
    """The summary guide as Markdown lines; `form` "rust" links the types for rustdoc."""
    if form == "rust":
        # A label that is not a path: the same line resolves in the crate root and in `glint`.
        mix = "[the mixture](crate::glint::BeckmannMixture)"
        per_map = "docs/glint.md, \"Which model where\", has the per-map tables with builds"
    else:
        mix = "the mixture (`BeckmannMixture`)"
        per_map = "the per-map tables below count them"
    intro = (
        "Measured on the orb (docs/results.md, \"Error against time\"): a metallic sphere under a point "
        f"light, 128² pixels, {len(maps)} maps of 512² ({', '.join(maps)}) at {len(scales)} "
        "pixel footprints, every glint model at the material's σ_ε = 0.01 and its default "
        "options (the mixture also with its level of detail off, \"no LOD\"), against naive "
        "normal mapping at 1-4,096 samples per pixel. Per footprint and target error (denoised "
        "relative RMSE against the exact P-BRDF): the method that first reaches it on each map, "
        "with a glint model's equal-error speedup over naive (∞: naive does not get there by "
        f"4,096 spp); build times not counted ({per_map}). Times are wall-clock, ±30 % between "
        "runs. Last column: "
        f"the error of {mix} at its defaults, one evaluation per pixel. Generated "
        "from docs/data/orb_curves.csv by `python3 tools/orb_which.py --write`."
    )
    width = WIDTH - (4 if form == "rust" else 0)
    lines = textwrap.wrap(intro, width, break_on_hyphens=False, break_long_words=False) + [""]
    head = " | ".join(f"first to {e:g}" for e in errors)
    lines.append(f"| texels per pixel | {head} | mixture's error |")
    lines.append("|---" * (len(errors) + 2) + "|")
    for sc in scales:
        cells = [summary_cell(rows, maps, sc, e) for e in errors]
        lines.append(f"| {texels[sc]:,} | " + " | ".join(cells) + f" | {mixture_errors(rows, sc)} |")
    return lines


def wrap_rust(lines):
    """Markdown lines as `//!` doc lines (tables stay one line each)."""
    return ["//!" if not x else f"//! {x}" for x in lines]


def splice(text, markers, body, form, path):
    """`text` with the lines between the marker lines replaced by `body`."""
    begin, end = markers
    lines = text.split("\n")
    idx_b = [i for i, x in enumerate(lines) if x.strip().endswith(begin)]
    idx_e = [i for i, x in enumerate(lines) if x.strip().endswith(end)]
    if len(idx_b) != 1 or len(idx_e) != 1 or idx_e[0] < idx_b[0]:
        sys.exit(f"{path}: expected one '{begin}' line followed by one '{end}' line")
    body = wrap_rust(body) if form == "rust" else body
    return "\n".join(lines[: idx_b[0] + 1] + body + lines[idx_e[0]:])


def rendered(csv_path):
    """{file: expected text} for every copy."""
    rows, maps, scales, texels = load(csv_path)
    out = {}
    for path, form in COPIES:
        full = os.path.join(ROOT, path)
        text = open(full, encoding="utf-8").read()
        new = splice(text, SUMMARY, summary(rows, maps, scales, texels, ERRORS, form), form, path)
        if path == "docs/glint.md":
            tables = per_map_tables(rows, maps, scales, texels, ERRORS)
            while tables and not tables[-1]:
                tables.pop()
            new = splice(new, MAPS, tables, form, path)
        out[path] = (text, new)
    return out


def main(argv):
    mode = None
    if argv and argv[0] in ("--write", "--check"):
        mode, argv = argv[0], argv[1:]
    if argv and argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0
    csv_path = argv[0] if argv else os.path.join(ROOT, DEFAULT_CSV)
    if mode is None:
        rows, maps, scales, texels = load(csv_path)
        errors = [float(e) for e in argv[1:]] or ERRORS
        print("\n".join(per_map_tables(rows, maps, scales, texels, errors)))
        return 0
    stale = []
    for path, (old, new) in rendered(csv_path).items():
        if old == new:
            continue
        if mode == "--write":
            open(os.path.join(ROOT, path), "w", encoding="utf-8").write(new)
            print(f"wrote {path}")
        else:
            stale.append(path)
            sys.stdout.writelines(difflib.unified_diff(
                old.splitlines(True), new.splitlines(True), f"{path} (committed)",
                f"{path} (from {os.path.relpath(csv_path, ROOT)})", n=1))
    if stale:
        print(f"\nthe which-model guide differs from the CSV in: {', '.join(stale)}; "
              "run `python3 tools/orb_which.py --write`", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
