#!/usr/bin/env python3
"""The tables of docs/results.md "Bias floor decomposition" from the orb's CSVs.

Usage: python3 tools/orb_bias_table.py docs/data/orb_bias.csv [docs/data/orb_bias_spacing.csv]

The first table: per map and scale, the noise of reference (a) under the point and the disc light,
then the denoised relative RMSE against (a) of every configuration (columns in the CSV's order).
The second (if the spacing CSV is given): per map and scale, each seed kernel and spacing as
"error / energy error / render s / build s".
"""

import csv
import sys
from collections import OrderedDict

TEXELS = {"0.35": "1", "1": "9", "2": "34", "16": "2,186", "128": "139,898"}


def scale_label(s):
    return TEXELS.get(s, s)


def bias_table(path):
    rows = list(csv.DictReader(open(path)))
    methods = []
    for r in rows:
        if r["method"] not in methods:
            methods.append(r["method"])
    cells = OrderedDict()
    for r in rows:
        cells.setdefault((r["map"], r["scale"]), {})[r["method"]] = r
    disc = next((m for m in methods if "disc" in m and not m.startswith(("bin", "pos"))), None)
    head = ["map", "texels/px", "noise of (a) point / disc"] + methods
    print("| " + " | ".join(head) + " |")
    print("| " + " | ".join("---" for _ in head) + " |")
    for (m, s), d in cells.items():
        noise = float(d["mixture"]["reference_noise"])
        noise_disc = float(d[disc]["reference_noise"]) if disc in d else float("nan")
        vals = [f"{float(d[k]['rel_rmse_denoised']):.3f}" if k in d else "—" for k in methods]
        print(f"| {m} | {scale_label(s)} | {noise:.3f} / {noise_disc:.3f} | " + " | ".join(vals) + " |")


def spacing_table(path):
    rows = list(csv.DictReader(open(path)))
    cols = []
    for r in rows:
        key = (r["seed"], r["spacing"])
        if key not in cols:
            cols.append(key)
    cells = OrderedDict()
    for r in rows:
        cells.setdefault((r["map"], r["scale"]), {})[(r["seed"], r["spacing"])] = r
    head = ["map", "texels/px"] + [f"{k} {h}" for k, h in cols]
    print("| " + " | ".join(head) + " |")
    print("| " + " | ".join("---" for _ in head) + " |")
    for (m, s), d in cells.items():
        vals = []
        for c in cols:
            r = d.get(c)
            if r is None:
                vals.append("—")
                continue
            vals.append(
                f"{float(r['rel_rmse_denoised']):.3f} / {float(r['energy_error']):+.3f} / "
                f"{float(r['render_s']):.3f} / {float(r['build_s']):.2f}"
            )
        print(f"| {m} | {scale_label(s)} | " + " | ".join(vals) + " |")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    bias_table(sys.argv[1])
    if len(sys.argv) > 2:
        print()
        spacing_table(sys.argv[2])


if __name__ == "__main__":
    main()
