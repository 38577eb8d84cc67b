#!/usr/bin/env python3
"""Share of a render's shading time per pass of a glint shading point.

Reads a `perf record --call-graph dwarf` profile of the render example's frame-time harness timing
one material, e.g.

    perf record --call-graph dwarf,16384 -F 250 -o bin.data \
        target/release/examples/render --timing --quick --texels 500 --materials "=bin map"
    python3 tools/perf_passes.py bin.data

Every sample under `Scene::radiance` is put under the public call it is in (`Material::bsdf`: the
patch; `Bxdf::eval_pdf`; `Bxdf::sample`; none: the integrator and ray tracing) and, within it,
under the first pass below that call whose name matches (outermost first). Prints the shares.
Release builds keep debug info (Cargo.toml), so inlined passes are named too."""
import sys, subprocess, collections

API = [("patch", ["Material::bsdf"]), ("sample", ["Bxdf>::sample"]),
       ("eval_pdf", ["Bxdf>::eval_pdf", "Bxdf>::eval", "Bxdf>::pdf"])]
SUB = [
    ("LOD search", ["lod_error_of", "one_step_bound", "level_range"]),
    ("gather (weights, moments, blocks)", ["gather::gather", "slot_weights", "block_weights"]),
    ("filtered mixture lookup", ["filtered_mixture", "gmm::", "bilinear_nodes"]),
    ("sub-texel lobe", ["sub_texel::"]),
    ("exact masking set-up (clipped texels)", ["ExactMasking::new"]),
    ("element slots", ["PositionNormalPatch::slots", "Geometry::new"]),
    ("V (visible area)", ["visible_area", "masking_factor_with"]),
    ("pdf (visible normals)", ["pdf_visible"]),
    ("pick and sample", ["sample_visible", "VisiblePick", "sample_normal"]),
    ("D", ["Ndf>::d", "d_with_stats", "d_f64", "untruncated_d"]),
    ("Fresnel", ["fresnel"]),
]

def main(path):
    out = subprocess.run(["perf", "script", "-i", path, "-F", "comm,ip,sym"],
                         capture_output=True, text=True).stdout
    counts = collections.Counter()
    total = 0
    for block in out.split("\n\n"):
        frames = [l.strip() for l in block.strip().split("\n")[1:]]
        if not any("Scene::radiance" in f for f in frames):
            continue
        total += 1
        outer = frames[::-1]  # outermost first
        api, at = "integrator, tracing", None
        for i, f in enumerate(outer):
            hit = next((n for n, ks in API if any(k in f for k in ks)), None)
            if hit:
                api, at = hit, i
                break
        sub = "other"
        if at is not None:
            for f in outer[at + 1:]:
                hit = next((n for n, ks in SUB if any(k in f for k in ks)), None)
                if hit:
                    sub = hit
                    break
        counts[(api, sub if at is not None else "")] += 1
    print(f"samples under Scene::radiance: {total}")
    for (api, sub), c in sorted(counts.items(), key=lambda kv: -kv[1]):
        print(f"{100.0 * c / total:6.1f} %  {api}{': ' + sub if sub else ''}")

main(sys.argv[1])
