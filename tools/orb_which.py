#!/usr/bin/env python3
"""The "Which model where" tables of docs/glint.md from the orb sweep's curves.

    python3 tools/orb_which.py docs/data/orb_curves.csv [ERROR ...]

For each map, footprint and target error (default 0.2, 0.1, 0.05): the method that first reaches a
denoised relative RMSE against (a) at or below the target. Naive sampling's time at the target is
interpolated on its measured curve (log time against log error, between the spp that bracket the
target; its 1-spp time if that already meets it); a glint model (σ_ε-matched: the mixture at its
defaults and without level of detail, the smoothed bin map, position-normal at σ_r = σ_ε) counts
with the fastest of its 1, 4 and 16 evaluations per pixel that meets the target (the count in
brackets when not 1). Each cell: the winner, its time and, for a glint model, its speedup over
naive (∞: naive does not get there); "+build:" the winner when build times count, if it differs;
"none": nothing gets there."""
import csv
import math
import sys

CANDIDATES = {
    "mixture": "mixture",
    "mixture (no LOD)": "mixture (no LOD)",
    "bin map": "bin map",
    "position-normal": "pos.-normal",
}


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


def speed(naive, t):
    if naive is None:
        return "∞×"
    x = naive / t
    return f"{x:.2g}×" if x < 100 else f"{x:.0f}×"


def main(path, *errors):
    errors = [float(e) for e in errors] or [0.2, 0.1, 0.05]
    rows = list(csv.DictReader(open(path)))
    maps = list(dict.fromkeys(r["map"] for r in rows))
    scales = list(dict.fromkeys(r["scale"] for r in rows))
    for target in errors:
        print(f"**Error {target:g}**\n")
        head = " | ".join(f"{int(r['texels_per_pixel']):,} texels/px" for r in rows
                          if r["map"] == maps[0] and r["method"] == "naive" and r["evals_per_pixel"] == "1")
        print(f"| map | {head} |")
        print("| --- " * (1 + len(scales)) + "|")
        for m in maps:
            cells = []
            for sc in scales:
                at = [r for r in rows if r["map"] == m and r["scale"] == sc]
                naive = [(float(r["render_s"]), float(r["rel_rmse_denoised"]))
                         for r in at if r["method"] == "naive"]
                tn = naive_time(naive, target)
                best, best_b = None, None
                if tn is not None:
                    best, best_b = ("naive", tn, None), ("naive", tn, None)
                for r in at:
                    name = CANDIDATES.get(r["method"])
                    if name is None or float(r["rel_rmse_denoised"]) > target:
                        continue
                    ev = r["evals_per_pixel"]
                    label = name if ev == "1" else f"{name} ({ev})"
                    t, b = float(r["render_s"]), float(r["build_s"])
                    if best is None or t < best[1]:
                        best = (label, t, r)
                    if best_b is None or t + b < best_b[1]:
                        best_b = (label, t + b, r)
                if best is None:
                    cells.append("none")
                    continue
                cell = f"{best[0]} {sec(best[1])}"
                if best[2] is not None:
                    cell += f", {speed(tn, best[1])}"
                if best_b[0] != best[0]:
                    cell += f" · +build: {best_b[0]} {sec(best_b[1])}"
                cells.append(cell)
            print(f"| {m} | " + " | ".join(cells) + " |")
        print()


main(*sys.argv[1:])
