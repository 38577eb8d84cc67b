#!/usr/bin/env python3
"""The full-run table of docs/results.md ("Error against time") from the orb sweep's CSVs.

    python3 tools/orb_table.py docs/data/orb_curves.csv docs/data/orb_speedup.csv [EVALS]

One row per map and scale, one column per method at EVALS evaluations per pixel (default 1). Each
cell: denoised relative RMSE against (a) / against (b) · equal-error speedup against (a) / the same
with the build; `>x`: naive sampling did not reach the error by its largest spp, `<x`: naive at 1
spp already does. "(b) gap": the denoised error of reference (b) against (a)."""
import csv
import sys

METHODS = [
    "mixture",
    "mixture (no LOD)",
    "bin map",
    "bin map σ = 0 (paper default)",
    "position-normal",
    "position-normal σ_r = 0.005 (paper default)",
]


def num(x):
    x = float(x)
    if x >= 100:
        return f"{x:.0f}"
    if x >= 10:
        return f"{x:.1f}"
    return f"{x:.2g}"


def main(curves_path, speedup_path, evals="1"):
    curves = list(csv.DictReader(open(curves_path)))
    speed = {}
    for r in csv.DictReader(open(speedup_path)):
        if r["truth"] == "a":
            speed[(r["map"], r["scale"], r["method"], r["evals_per_pixel"])] = r
    rows = []
    for r in curves:
        key = (r["map"], r["scale"])
        if key not in rows:
            rows.append(key)
    methods = [m for m in METHODS if any(r["method"] == m for r in curves)]
    print("| map | texels/px | (b) gap | " + " | ".join(methods) + " |")
    print("| --- " * (3 + len(methods)) + "|")
    for m, sc in rows:
        at = [r for r in curves if r["map"] == m and r["scale"] == sc]
        gap = next(r for r in at if r["method"].startswith("(b)"))
        cells = []
        for meth in methods:
            r = next((r for r in at if r["method"] == meth and r["evals_per_pixel"] == evals), None)
            if r is None:
                cells.append("—")
                continue
            s = speed[(m, sc, meth, evals)]
            b = "" if s["naive_bound"] == "=" else s["naive_bound"]
            cells.append(
                f"{float(r['rel_rmse_denoised']):.3f} / {float(r['rel_rmse_denoised_vs_b']):.3f} · "
                f"{b}{num(s['speedup'])}× / {b}{num(s['speedup_with_build'])}×"
            )
        tpp = f"{int(gap['texels_per_pixel']):,}"
        print(f"| {m} | {tpp} | {float(gap['rel_rmse_denoised']):.3f} | " + " | ".join(cells) + " |")


main(*sys.argv[1:])
