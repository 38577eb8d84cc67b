//! The mixture's levels of detail measured in slope space (issue 15 item 2): the patch of merged
//! lobes against the full mixture, both as explicit Gaussian mixtures splatted on a fine slope grid,
//! optionally convolved with an isotropic Gaussian of std r (the resolution of the level-of-detail
//! error, `PatchOptions::lod_resolution`).
//!
//! The ignored `lod_diagnose` prints the table behind docs/results.md "Levels of detail chosen by
//! error (issue 15)", "Why merged levels lose":
//! `cargo test --release --test it -- --ignored mixture_lod::lod_diagnose --nocapture`

use crate::support;

use brdf::glint::GlintNdf;
use brdf::glint::mixture::{MixtureParams, PatchOptions};
use brdf::glint::{
    BeckmannMixture, Footprint, HemisphereBins, Kernel, MixturePatch, binned_pndf, tv_distance,
};
use brdf::ndf::{Ndf, SlopeGaussian};
use brdf::{Vec2, Vec3};

/// One Gaussian of a slope mixture: weight, mean, covariance [xx, xy, yy] (f64).
#[derive(Clone, Copy, Debug)]
struct Comp {
    w: f64,
    mu: [f64; 2],
    cov: [f64; 3],
}

fn comp(w: f64, g: &SlopeGaussian) -> Comp {
    let (m, c) = (g.mean(), g.covariance());
    Comp {
        w,
        mu: [m.x as f64, m.y as f64],
        cov: [c.x_axis.x as f64, c.x_axis.y as f64, c.y_axis.y as f64],
    }
}

/// The patch's weighted lobes as a mixture (the filtered lobe alone for a filtered-lobe patch).
fn patch_mixture(p: &MixturePatch) -> Vec<Comp> {
    if p.is_filtered_lobe() {
        return vec![comp(1.0, p.filtered_lobe())];
    }
    p.weighted_lobes()
        .map(|(w, g)| comp(w as f64, &g))
        .collect()
}

/// Mean and covariance [xx, xy, yy] of a mixture.
fn moments(mix: &[Comp]) -> ([f64; 2], [f64; 3]) {
    let wsum: f64 = mix.iter().map(|c| c.w).sum();
    let mut m = [0.0; 2];
    let mut s = [0.0; 3];
    for c in mix {
        let w = c.w / wsum;
        m[0] += w * c.mu[0];
        m[1] += w * c.mu[1];
        s[0] += w * (c.cov[0] + c.mu[0] * c.mu[0]);
        s[1] += w * (c.cov[1] + c.mu[0] * c.mu[1]);
        s[2] += w * (c.cov[2] + c.mu[1] * c.mu[1]);
    }
    (
        m,
        [s[0] - m[0] * m[0], s[1] - m[0] * m[1], s[2] - m[1] * m[1]],
    )
}

/// A square slope grid: cell centres lo + (i + ½) step, i < n per axis.
#[derive(Clone, Copy, Debug)]
struct Grid {
    lo: [f64; 2],
    step: f64,
    n: usize,
}

impl Grid {
    /// Covers every component of the mixtures to ±6 σ (σ widened by r).
    fn covering(mixes: &[&[Comp]], step: f64, r: f64) -> Grid {
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for c in mixes.iter().flat_map(|m| m.iter()) {
            for k in 0..2 {
                let s = (c.cov[2 * k] + r * r).sqrt();
                lo[k] = lo[k].min(c.mu[k] - 6.0 * s);
                hi[k] = hi[k].max(c.mu[k] + 6.0 * s);
            }
        }
        let side = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        Grid {
            lo,
            step,
            n: (side / step).ceil() as usize + 1,
        }
    }

    /// The mixture's density on the cell centres (each component convolved with N(0, r² I)),
    /// each component evaluated within ±6 σ of its mean per axis.
    fn splat(&self, mix: &[Comp], r: f64) -> Vec<f64> {
        let n = self.n;
        let mut out = vec![0.0f64; n * n];
        for c in mix {
            let (a, b, d) = (c.cov[0] + r * r, c.cov[1], c.cov[2] + r * r);
            let det = a * d - b * b;
            if det.is_nan() || det <= 0.0 || c.w == 0.0 {
                continue;
            }
            let norm = c.w / (std::f64::consts::TAU * det.sqrt());
            let (ia, ib, id) = (d / det, -b / det, a / det);
            let cell = |x: f64, k: usize| ((x - self.lo[k]) / self.step - 0.5).floor();
            let (sx, sy) = (a.sqrt(), d.sqrt());
            let i0 = cell(c.mu[0] - 6.0 * sx, 0).max(0.0) as usize;
            let i1 = (cell(c.mu[0] + 6.0 * sx, 0) + 1.0).clamp(0.0, n as f64) as usize;
            let j0 = cell(c.mu[1] - 6.0 * sy, 1).max(0.0) as usize;
            let j1 = (cell(c.mu[1] + 6.0 * sy, 1) + 1.0).clamp(0.0, n as f64) as usize;
            for j in j0..j1 {
                let dy = self.lo[1] + (j as f64 + 0.5) * self.step - c.mu[1];
                let row = &mut out[j * n..(j + 1) * n];
                for (i, v) in row.iter_mut().enumerate().take(i1).skip(i0) {
                    let dx = self.lo[0] + (i as f64 + 0.5) * self.step - c.mu[0];
                    let q = ia * dx * dx + 2.0 * ib * dx * dy + id * dy * dy;
                    *v += norm * (-0.5 * q).exp();
                }
            }
        }
        out
    }

    /// ½ ∫ |p − q| by the midpoint rule.
    fn tv(&self, p: &[f64], q: &[f64]) -> f64 {
        0.5 * p.iter().zip(q).map(|(a, b)| (a - b).abs()).sum::<f64>() * self.step * self.step
    }

    /// The P22 on the grid as an [`Ndf`] (bilinear between cell centres), for `tv_distance`.
    fn ndf<'a>(&'a self, p22: &'a [f64]) -> GridNdf<'a> {
        GridNdf { grid: self, p22 }
    }
}

/// A tabulated slope density as an NDF: D(m) = P22(slope(m)) / cos⁴θ. Only `d` is meaningful (the
/// TV to a binned truth needs nothing else).
struct GridNdf<'a> {
    grid: &'a Grid,
    p22: &'a [f64],
}

impl Ndf for GridNdf<'_> {
    fn d(&self, m: Vec3) -> f32 {
        if m.z.is_nan() || m.z <= 0.0 {
            return 0.0;
        }
        let s = [-(m.x / m.z) as f64, -(m.y / m.z) as f64];
        let g = self.grid;
        let u = (s[0] - g.lo[0]) / g.step - 0.5;
        let v = (s[1] - g.lo[1]) / g.step - 0.5;
        if !(u >= 0.0 && v >= 0.0 && u < (g.n - 1) as f64 && v < (g.n - 1) as f64) {
            return 0.0;
        }
        let (i, j) = (u.floor() as usize, v.floor() as usize);
        let (fu, fv) = (u - i as f64, v - j as f64);
        let at = |i: usize, j: usize| self.p22[j * g.n + i];
        let p = (1.0 - fv) * ((1.0 - fu) * at(i, j) + fu * at(i + 1, j))
            + fv * ((1.0 - fu) * at(i, j + 1) + fu * at(i + 1, j + 1));
        let c = 1.0 + s[0] * s[0] + s[1] * s[1];
        (p * c * c) as f32
    }
    fn lambda(&self, _: Vec3) -> f32 {
        0.0
    }
    fn sample_normal(&self, _: Vec2) -> Vec3 {
        Vec3::Z
    }
    fn sample_visible(&self, _: Vec3, _: Vec2) -> Vec3 {
        Vec3::Z
    }
}

/// The level-0 mixture of a footprint written out here (independently of the patch code): lobe
/// (i, j) at texel position (i + ½, j + ½) (spacing 1), weight ∝ the Gaussian k_P ∗ k_i at its
/// centre (Σ_P + σ_k² I, σ_k = 1/(2√(2 ln 2))), over ±`t` σ per axis; with the lobe indices
/// (unwrapped).
fn own_full(mix: &BeckmannMixture, fp: &Footprint, t: f64) -> Vec<(i64, i64, Comp)> {
    let (nx, ny) = mix.grid();
    let (c, s) = fp.gaussian_texels(nx, ny);
    let k2 = (1.0 / (2.0 * (2.0 * std::f64::consts::LN_2).sqrt())).powi(2);
    let (a, b, d) = (
        s.x_axis.x as f64 + k2,
        s.x_axis.y as f64,
        s.y_axis.y as f64 + k2,
    );
    let det = a * d - b * b;
    let (ia, ib, id) = (d / det, -b / det, a / det);
    let (c0, c1) = (c.x as f64, c.y as f64);
    let (hx, hy) = (t * a.sqrt(), t * d.sqrt());
    let mut out = Vec::new();
    for j in ((c1 - 0.5 - hy).ceil() as i64)..=((c1 - 0.5 + hy).floor() as i64) {
        for i in ((c0 - 0.5 - hx).ceil() as i64)..=((c0 - 0.5 + hx).floor() as i64) {
            let (dx, dy) = (i as f64 + 0.5 - c0, j as f64 + 0.5 - c1);
            let w = (-0.5 * (ia * dx * dx + 2.0 * ib * dx * dy + id * dy * dy)).exp();
            out.push((i, j, comp(w, &mix.lobe(i, j))));
        }
    }
    let total: f64 = out.iter().map(|p| p.2.w).sum();
    for p in &mut out {
        p.2.w /= total;
    }
    out
}

/// Groups a level-0 mixture into nodes of 2^l × 2^l lobes: node weight W_n = Σ W_i (exact), node
/// Gaussian the moment match of its lobes (`equal`: equal weights, as the stored levels; otherwise
/// weighted by W_i). Also returns the children grouped per node (the mixture Σ W_n M_n).
fn own_level(full: &[(i64, i64, Comp)], l: u32, equal: bool) -> Vec<Comp> {
    use std::collections::BTreeMap;
    let mut nodes: BTreeMap<(i64, i64), Vec<Comp>> = BTreeMap::new();
    for &(i, j, c) in full {
        nodes.entry((i >> l, j >> l)).or_default().push(c);
    }
    nodes
        .values()
        .map(|cs| {
            let w: f64 = cs.iter().map(|c| c.w).sum();
            let eq: Vec<Comp> = cs.iter().map(|c| Comp { w: 1.0, ..*c }).collect();
            let (mu, cov) = moments(if equal { &eq } else { cs });
            Comp { w, mu, cov }
        })
        .collect()
}

/// Excess kurtosis E[(x − m)⁴]/E[(x − m)²]² − 3 of the mixture's marginals along x and y.
fn excess_kurtosis(mix: &[Comp]) -> [f64; 2] {
    let (m, _) = moments(mix);
    let wsum: f64 = mix.iter().map(|c| c.w).sum();
    [0, 1].map(|k| {
        let (mut e2, mut e4) = (0.0, 0.0);
        for c in mix {
            let (d, v) = (c.mu[k] - m[k], c.cov[2 * k]);
            e2 += c.w / wsum * (d * d + v);
            e4 += c.w / wsum * (d.powi(4) + 6.0 * d * d * v + 3.0 * v * v);
        }
        e4 / (e2 * e2) - 3.0
    })
}

fn fmt_m((m, c): ([f64; 2], [f64; 3])) -> String {
    format!(
        "μ ({:+.4}, {:+.4}) Σ ({:.5}, {:+.5}, {:.5})",
        m[0], m[1], c[0], c[1], c[2]
    )
}

/// Diagnosis of "merged levels lose to the single filtered lobe" at 4096 and 65 536 texels on
/// bumpy and brushed (512²): for levels l = 1, 2, 3 (forced by the cost cap), the continuous TV
/// between the patch and the full mixture, the same for the patch written out here (exact node
/// weights, equal- and weight-weighted merges), the moments of each, and the binned TV to the
/// ground truth of each (the tabulated mixtures through `tv_distance`).
#[test]
#[ignore]
fn lod_diagnose() {
    let n = 512;
    let bins = HemisphereBins::new(64).unwrap();
    let maps = support::procedural_maps(n);
    // LOD_DIAG_MAPS=brushed (comma-separated) restricts the maps (default: bumpy and brushed).
    let only = std::env::var("LOD_DIAG_MAPS").unwrap_or_else(|_| "bumpy,brushed".into());
    for (name, map) in maps
        .iter()
        .filter(|(n, _)| only.split(',').any(|o| o == *n))
    {
        let mix = BeckmannMixture::build(map, MixtureParams::default()).unwrap();
        for texels in [4096.0f32, 65536.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), texels, n, n);
            let truth = binned_pndf(map, &fp, Kernel::Gaussian, &bins, 4_000_000, 17);
            let opts = |lobes: f32| PatchOptions {
                lod_lobes: lobes,
                lod_tolerance: 0.0,
                filtered_area: f32::INFINITY,
                cut_nodes: 0,
                ..PatchOptions::default()
            };
            let full_p = mix.patch_with(&fp, &opts(f32::INFINITY), None);
            let full = patch_mixture(&full_p);
            let own = own_full(&mix, &fp, 3.0);
            let own_c: Vec<Comp> = own.iter().map(|p| p.2).collect();
            let filt = patch_mixture(&mix.patch_with(&fp, &opts(0.0), None));
            let grid = Grid::covering(&[&full], 0.005, 0.0);
            let g_full = grid.splat(&full, 0.0);
            let grid2 = Grid {
                step: 2.0 * grid.step,
                n: grid.n / 2,
                ..grid
            };
            let tv_truth = |g: &Grid, v: &[f64]| tv_distance(&g.ndf(v), &truth, 4);
            println!(
                "\n{name} {texels}: full {} lobes, {}; own full TV to it {:.5}; truth TV {:.4} (grid {}²)",
                full.len(),
                fmt_m(moments(&full)),
                grid.tv(&g_full, &grid.splat(&own_c, 0.0)),
                tv_truth(&grid, &g_full),
                grid.n
            );
            let g_filt = grid.splat(&filt, 0.0);
            println!(
                "  filtered lobe: TV to full {:.4}, truth {:.4}, {}",
                grid.tv(&g_full, &g_filt),
                tv_truth(&grid, &g_filt),
                fmt_m(moments(&filt))
            );
            // The blurred TVs at 4096 texels only (at 65 536 the splats of 2·10⁵ blurred lobes
            // dominate the run).
            let rs: &[f64] = if texels > 5000.0 {
                &[]
            } else {
                &[0.01, 0.02, 0.05]
            };
            let r_grids: Vec<(Grid, Vec<f64>, f64)> = rs
                .iter()
                .map(|&r| {
                    let g = Grid::covering(&[&full], (r / 3.0f64).max(0.005), r);
                    let gf = g.splat(&full, r);
                    let tf = g.tv(&gf, &g.splat(&filt, r));
                    (g, gf, tf)
                })
                .collect();
            let levels = if texels > 5000.0 { 2 } else { 3 };
            println!(
                "  excess kurtosis: full {:.3?}, filtered lobe 0",
                excess_kurtosis(&full)
            );
            for l in 1..=levels {
                let p = mix.patch_with(&fp, &opts(1.01 * texels / 4f32.powi(l as i32)), None);
                assert_eq!(p.level(), l as usize);
                let lv = patch_mixture(&p);
                let g_lv = grid.splat(&lv, 0.0);
                let coarse = grid2.tv(&grid2.splat(&full, 0.0), &grid2.splat(&lv, 0.0));
                let own_eq = own_level(&own, l, true);
                let g_eq = grid.splat(&own_eq, 0.0);
                println!(
                    "  level {l}: {} nodes, bound {:.3}; TV to full {:.4} (step×2: {coarse:.4}), \
                     own equal-merge {:.4}, patch vs own-equal {:.4}; \
                     truth: patch {:.4} own-eq {:.4}; {}; excess kurtosis {:.3?}",
                    lv.len(),
                    p.lod_error(),
                    grid.tv(&g_full, &g_lv),
                    grid.tv(&g_full, &g_eq),
                    grid.tv(&g_lv, &g_eq),
                    tv_truth(&grid, &g_lv),
                    tv_truth(&grid, &g_eq),
                    fmt_m(moments(&lv)),
                    excess_kurtosis(&lv)
                );
                for (&r, (g, gf, tf)) in rs.iter().zip(&r_grids) {
                    println!(
                        "    r {r}: TV(level, full) {:.4}, TV(filtered, full) {tf:.4}",
                        g.tv(gf, &g.splat(&lv, r)),
                    );
                }
            }
        }
    }
}

/// The node weights W'_n of a level-l patch, written out here as docs/mixture.md states them (not
/// through the patch code): the Gaussian of covariance (Σ_P + (σ_k² + (4^l − 1)/12) I) / 4^l (σ_k²
/// the seed kernel's weight variance) at the node centres (X + ½, Y + ½) in node units (lobe units
/// counted from the seed's origin), over ±3 σ per axis of it (`weight_sigmas`), normalised; keyed
/// by unwrapped node index.
fn own_node_weights(mix: &BeckmannMixture, fp: &Footprint, l: u32) -> Vec<((i64, i64), f64)> {
    let (nx, ny) = mix.grid();
    // Lobe units are texels here (spacing 1); lobe i sits at i + ½ + the seed's origin.
    assert_eq!(mix.spacing(), (1.0, 1.0));
    let (c, s) = fp.gaussian_texels(nx, ny);
    let seed = mix.params().seed;
    let c = c - Vec2::splat(seed.origin() as f32);
    let n2 = 4f64.powi(l as i32);
    let k2 = seed.weight_variance() + (n2 - 1.0) / 12.0;
    let (a, b, d) = (
        (s.x_axis.x as f64 + k2) / n2,
        s.x_axis.y as f64 / n2,
        (s.y_axis.y as f64 + k2) / n2,
    );
    let det = a * d - b * b;
    let (ia, ib, id) = (d / det, -b / det, a / det);
    let scale = 1.0 / 2f64.powi(l as i32);
    let (c0, c1) = (c.x as f64 * scale, c.y as f64 * scale);
    let (hx, hy) = (3.0 * a.sqrt(), 3.0 * d.sqrt());
    let (i0, i1) = (
        (c0 - 0.5 - hx).ceil() as i64,
        (c0 - 0.5 + hx).floor() as i64,
    );
    let (j0, j1) = (
        (c1 - 0.5 - hy).ceil() as i64,
        (c1 - 0.5 + hy).floor() as i64,
    );
    // No folding: the rectangle must be narrower than the node grid (as in the cases below).
    assert!(((i1 - i0 + 1) as usize) < nx >> l && ((j1 - j0 + 1) as usize) < ny >> l);
    let mut out = Vec::new();
    for j in j0..=j1 {
        for i in i0..=i1 {
            let (dx, dy) = (i as f64 + 0.5 - c0, j as f64 + 0.5 - c1);
            let w = (-0.5 * (ia * dx * dx + 2.0 * ib * dx * dy + id * dy * dy)).exp();
            out.push(((i, j), w));
        }
    }
    let total: f64 = out.iter().map(|p| p.1).sum();
    out.iter().map(|&(k, w)| (k, w / total)).collect()
}

/// Σ_n W'_n M_n: each node's weight spread evenly over its 4^l level-0 lobes (the mixture the
/// merge bound compares the merged lobes with).
fn spread_children(mix: &BeckmannMixture, nodes: &[((i64, i64), f64)], l: u32) -> Vec<Comp> {
    let side = 1i64 << l;
    let share = 1.0 / (side * side) as f64;
    let mut out = Vec::new();
    for &((x, y), w) in nodes {
        for j in y * side..(y + 1) * side {
            for i in x * side..(x + 1) * side {
                out.push(comp(w * share, &mix.lobe(i, j)));
            }
        }
    }
    out
}

/// The level of detail respects its tolerance at its resolution: on the four procedural maps
/// (64²) at 256- and 1024-texel footprints, for resolutions r = 0.01 (the default) and 0.04 and
/// tolerances 0.02 and 0.3, the patch's bound Σ W'_n e_r(n) is at most the tolerance, and the TV
/// between the patch's merged lobes and the level-0 lobes they replace with the same node weights
/// (Σ W'_n G_n against Σ W'_n M_n, [`spread_children`]), both convolved with N(0, r² I) in slope
/// space, is at most that bound plus three times the quadrature's error estimate (the midpoint sum
/// at step h against 2h) plus 1e-4 (the f32 rounding of the stored moments and weights, ~1e-6 of
/// each lobe's mass). That is exactly what the bound claims (levels.rs). The rest of the TV to the
/// full mixture, TV(Σ W'_n M_n, full) — the node weights spread evenly over their lobes — is not
/// bounded; it is printed (docs/mixture.md gives the measured values). At least four cases must
/// pick a level ≥ 1 (otherwise the test would check nothing).
///
/// The default suite takes the 256-texel footprints;
/// [`level_of_detail_respects_its_tolerance_at_1024_texels`] adds 1024.
#[test]
fn level_of_detail_respects_its_tolerance_at_its_resolution() {
    level_of_detail_respects_its_tolerance_at(&[256.0]);
}

/// `cargo test --release --test it -- --ignored
/// mixture_lod::level_of_detail_respects_its_tolerance_at_1024_texels`
#[test]
#[ignore]
fn level_of_detail_respects_its_tolerance_at_1024_texels() {
    level_of_detail_respects_its_tolerance_at(&[256.0, 1024.0]);
}

fn level_of_detail_respects_its_tolerance_at(areas: &[f32]) {
    let n = 64;
    let mut merged = 0;
    for (name, map) in support::procedural_maps(n) {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for &area in areas {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let full_p = mix.patch_with(
                &fp,
                &PatchOptions {
                    lod_lobes: f32::INFINITY,
                    lod_tolerance: 0.0,
                    filtered_area: f32::INFINITY,
                    cut_nodes: 0,
                    ..PatchOptions::default()
                },
                None,
            );
            assert_eq!(full_p.level(), 0);
            let full = patch_mixture(&full_p);
            for r in [0.01f32, 0.04] {
                let rr = r as f64;
                // Step: a quarter of the narrowest convolved σ (≥ r), so the midpoint rule resolves
                // every lobe.
                let grid = Grid::covering(&[&full], rr / 4.0, rr);
                let coarse = Grid {
                    step: 2.0 * grid.step,
                    n: grid.n.div_ceil(2),
                    ..grid
                };
                let g_full = grid.splat(&full, rr);
                for tol in [0.02f32, 0.3] {
                    let p = mix.patch_with(
                        &fp,
                        &PatchOptions {
                            lod_lobes: f32::INFINITY,
                            lod_tolerance: tol,
                            lod_resolution: r,
                            filtered_area: f32::INFINITY,
                            cut_nodes: 0,
                            ..PatchOptions::default()
                        },
                        None,
                    );
                    let bound = p.lod_error() as f64;
                    assert!(
                        bound <= tol as f64,
                        "{name}: bound {bound} > tolerance {tol}"
                    );
                    if p.level() == 0 {
                        assert_eq!(bound, 0.0);
                        continue;
                    }
                    merged += 1;
                    let l = p.level() as u32;
                    let lv = patch_mixture(&p);
                    let spread = spread_children(&mix, &own_node_weights(&mix, &fp, l), l);
                    let g_lv = grid.splat(&lv, rr);
                    let g_spread = grid.splat(&spread, rr);
                    let tv = grid.tv(&g_spread, &g_lv);
                    let tv2 = coarse.tv(&coarse.splat(&spread, rr), &coarse.splat(&lv, rr));
                    let q = (tv - tv2).abs();
                    println!(
                        "{name} {area} r {r} tol {tol}: level {l} bound {bound:.4}, TV(merged, \
                         spread children) {tv:.4} (±{q:.1e}); unbounded weight term \
                         TV(spread children, full) {:.4}; TV(patch, full) {:.4}",
                        grid.tv(&g_spread, &g_full),
                        grid.tv(&g_lv, &g_full)
                    );
                    assert!(
                        tv <= bound + 3.0 * q + 1e-4,
                        "{name} {area} r {r} tol {tol}: TV {tv} > bound {bound} + 3 × {q}"
                    );
                }
            }
        }
    }
    assert!(merged >= 4, "only {merged} cases used a level ≥ 1");
}

/// The resolution is a per-query option, not validated: a patch is total for any value (a NaN or
/// negative resolution reads the continuous bound, r = 0: never a smaller bound).
#[test]
fn lod_resolution_is_total() {
    let map = &support::procedural_maps(32)[2].1;
    let mix = BeckmannMixture::build(map, MixtureParams::default()).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 256.0, 32, 32);
    let at = |r: f32| {
        mix.patch_with(
            &fp,
            &PatchOptions {
                lod_lobes: f32::INFINITY,
                lod_tolerance: 0.3,
                lod_resolution: r,
                filtered_area: f32::INFINITY,
                cut_nodes: 0,
                ..PatchOptions::default()
            },
            None,
        )
    };
    let zero = at(0.0);
    for r in [f32::NAN, -1.0, f32::NEG_INFINITY] {
        let p = at(r);
        assert_eq!((p.level(), p.lod_error()), (zero.level(), zero.lod_error()));
        assert!(p.d(Vec3::Z).is_finite());
    }
    // The stored bounds are non-increasing in r, node by node.
    for l in 1..mix.level_count() {
        for k in 1..brdf::glint::mixture::LOD_RESOLUTIONS.len() {
            let (a, b) = (mix.level_errors_at(l, k - 1), mix.level_errors_at(l, k));
            assert_eq!(a.len(), b.len());
            assert!(a.iter().zip(b).all(|(x, y)| y <= x), "level {l} res {k}");
        }
    }
}
