//! The facet lattice of a procedural glint surface: its levels, the stateless hash that places
//! each cell's lobe, and the gather of one level's lobes under the tent of a footprint.
//!
//! Level l tiles the uv period with `cells` × `cells` cells (about 2^l times fewer per side than
//! level 0, whose cells hold one facet each on average); every cell holds one lobe at a position
//! jittered uniformly in the cell, with a standard-normal pair z for its mean (and, for a surface
//! of the GGX limit, a third uniform for its variance scale, src/glint/procedural/ggx.rs), all
//! from one hash of (seed, level, cell). The lobes' widths and the spread of their means are set
//! per patch from the footprint (src/glint/procedural/patch.rs, docs/procedural.md "Lobe
//! widths"), so that every lobe has the limit NDF as its mean.
//!
//! A footprint reads the lobes of the cells around its centre through a separable tent one cell
//! wide on each side (stretched along u or v by the footprint's anisotropy): about four lobes per
//! level, the lobe of the cell under the centre always among them, weights continuous in the
//! centre (bilinear filtering over jittered positions, as a GPU filters a texture level).

use super::params::ProceduralParams;

/// Largest ratio of the footprint kernel's major to minor standard deviation the gather reads: a
/// thinner footprint's kernel is widened along its minor axis to this ratio (as a GPU's
/// anisotropic filtering caps its taps), which bounds the lobes a patch holds.
pub(super) const MAX_ANISOTROPY: f64 = 2.0;

/// The cells of the finer level a footprint reads are between `CELL_SIGMAS`/2 and `CELL_SIGMAS`
/// of its kernel's geometric standard deviation (λ1 λ2)^¼ wide (the coarser level's twice that):
/// the tent over one cell on each side then has a standard deviation of 0.6-1.2 of the
/// kernel's.
pub(super) const CELL_SIGMAS: f64 = 3.0;

/// The share of each octave of footprint sizes over which a patch blends its two levels: below
/// it the finer level alone, across it the weight of the coarser one rises linearly from 0 to 1
/// (a "brilinear" filter: continuous in the footprint's size like a trilinear one, with one
/// level's lobes instead of two over most sizes).
pub(super) const BLEND_BAND: f64 = 0.25;

/// One level of the lattice.
#[derive(Clone, Copy, Debug)]
pub(super) struct Level {
    /// Cells per uv period along u and v.
    pub cells: [u32; 2],
    /// Cell sides in texels along u and v: resolution / cells (equal up to the rounding of the
    /// cell counts).
    pub spacing: [f64; 2],
}

/// The levels of a surface, from level 0 (about one facet per cell) up to the level of one cell per
/// uv period.
pub(super) fn levels(p: &ProceduralParams) -> Vec<Level> {
    let res = p.resolution.map(|r| r as f64);
    let n0 = res.map(|r| (r * (p.density as f64).sqrt()).round().max(1.0));
    let mut out: Vec<Level> = Vec::new();
    let mut l = 0i32;
    loop {
        let cells = n0.map(|n| (n * 2f64.powi(-l)).round().max(1.0) as u32);
        if out.last().is_some_and(|last| last.cells == cells) {
            break;
        }
        let spacing = [0, 1].map(|a| res[a] / cells[a] as f64);
        out.push(Level { cells, spacing });
        if cells == [1, 1] {
            break;
        }
        l += 1;
    }
    out
}

/// The lobes' shared width: per axis 1/β² = 1/σ² + r (1/σ_f² − 1/σ²) with r = min(1, K/n), for a
/// patch whose kernel weights have the effective count K = 1/Σ w_i² and whose footprint holds n
/// facets (docs/procedural.md, "Lobe widths"): (β², τ² = σ² − β²) per axis.
pub(super) fn lobe_widths(sigma: [f64; 2], sigma_f: f64, r: f64) -> ([f64; 2], [f64; 2]) {
    let r = r.clamp(0.0, 1.0);
    let beta2 =
        sigma.map(|s| 1.0 / (1.0 / (s * s) + r * (1.0 / (sigma_f * sigma_f) - 1.0 / (s * s))));
    let tau2 = [0, 1].map(|a| (sigma[a] * sigma[a] - beta2[a]).max(0.0));
    (beta2, tau2)
}

/// The SplitMix64 finaliser (Steele et al. 2014): a bijective mix of 64 bits.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

/// Two 24-bit uniforms in (0, 1) from one hash (bits 40-63 and 16-39).
#[inline]
fn uniforms(h: u64) -> [f32; 2] {
    const SCALE: f32 = 1.0 / (1u32 << 24) as f32;
    [
        ((h >> 40) as f32 + 0.5) * SCALE,
        (((h >> 16) & 0xff_ffff) as f32 + 0.5) * SCALE,
    ]
}

/// The key of a surface's seed, which every cell's hash mixes in (computed once per gather).
#[inline]
fn seed_key(seed: u64) -> u64 {
    mix(seed.wrapping_add(GOLDEN))
}

/// The hash of cell (i, j) of level `level` (indices already wrapped into [0, cells)): one
/// finaliser of the cell's key, spread by the golden ratio, and the seed's key.
#[inline]
fn cell_hash(seed_key: u64, level: usize, i: u32, j: u32) -> u64 {
    let key = ((level as u64) << 50) ^ ((i as u64) << 25) ^ (j as u64);
    mix(key.wrapping_mul(GOLDEN) ^ seed_key)
}

/// The jitter of a cell's lobe in the cell, in (0, 1)², from the cell's hash.
#[inline]
fn jitter(h: u64) -> [f32; 2] {
    uniforms(h)
}

/// The standard-normal coordinates of a cell's lobe mean, from the cell's hash (one more
/// finaliser, so that they are independent of the jitter), through the normal quantile
/// (`gauss::inv_std_cdf_f32`, within 4·10⁻⁷ of Φ⁻¹).
#[inline]
fn mean_z(h: u64) -> [f32; 2] {
    uniforms(mix(h ^ GOLDEN)).map(crate::ndf::gauss::inv_std_cdf_f32)
}

/// A third uniform in (0, 1) from the cell's hash, independent of its jitter and mean: the variance
/// scale of a GGX surface's lobe (src/glint/procedural/ggx.rs).
#[inline]
fn scale_uniform(h: u64) -> f32 {
    uniforms(mix(h ^ GOLDEN.wrapping_mul(3)))[0]
}

/// A footprint kernel: centre and covariance (texels), its principal axes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Kernel {
    pub center: [f64; 2],
    /// Unit major axis.
    pub e1: [f64; 2],
    /// Variances along the major and minor axes.
    pub lambda: [f64; 2],
}

impl Kernel {
    /// The kernel of a footprint Gaussian (centre, covariance xx, xy, yy), its major variance
    /// lowered to at most `ceiling` (a footprint wider than the pattern's period averages the
    /// period), its minor variance raised to at least λ1 / [`MAX_ANISOTROPY`]², both to at least
    /// `floor`.
    pub fn new(center: [f64; 2], cov: [f64; 3], floor: f64, ceiling: f64) -> Kernel {
        let [sxx, sxy, syy] = cov;
        let half_tr = 0.5 * (sxx + syy);
        let d = (0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy).sqrt();
        let l1 = (half_tr + d).min(ceiling).max(floor);
        let l2 = (half_tr - d)
            .max(l1 / (MAX_ANISOTROPY * MAX_ANISOTROPY))
            .max(floor);
        let e1 = if sxy.abs() > 1e-300 {
            let (x, y) = (l1 - syy, sxy);
            let n = (x * x + y * y).sqrt();
            if n > 0.0 { [x / n, y / n] } else { [1.0, 0.0] }
        } else if sxx >= syy {
            [1.0, 0.0]
        } else {
            [0.0, 1.0]
        };
        Kernel {
            center,
            e1,
            lambda: [l1, l2],
        }
    }

    /// Σ as (xx, xy, yy).
    pub fn covariance(&self) -> [f64; 3] {
        let [c, s] = self.e1;
        let [a, b] = self.lambda;
        [
            a * c * c + b * s * s,
            (a - b) * c * s,
            a * s * s + b * c * c,
        ]
    }

    /// The geometric mean of the kernel's two standard deviations, (λ1 λ2)^¼ (texels): the side
    /// of the isotropic kernel of the same area, which sets the levels the footprint reads.
    pub fn geometric_sd(&self) -> f64 {
        (self.lambda[0] * self.lambda[1]).sqrt().sqrt()
    }

    /// The tent's stretch along u and v: the kernel's marginal standard deviations over its
    /// geometric one, at least 1 (at most √[`MAX_ANISOTROPY`]).
    pub fn stretch(&self) -> [f64; 2] {
        let [sxx, _, syy] = self.covariance();
        let g = self.geometric_sd().max(1e-300);
        [sxx, syy].map(|v| (v.sqrt() / g).max(1.0))
    }
}

/// The lobes a patch gathers before their width is known: kernel weight, standard-normal mean
/// coordinates and (for a GGX surface) the uniform of the variance scale, at most
/// [`Candidates::CAPACITY`] (on the stack: a patch allocates nothing).
pub(super) struct Candidates {
    pub len: usize,
    pub w: [f32; Candidates::CAPACITY],
    pub z: [[f32; 2]; Candidates::CAPACITY],
    /// The cell's third uniform (0.5 where the gather was asked for none).
    pub u: [f32; Candidates::CAPACITY],
}

impl Candidates {
    /// What a patch can gather: two levels of at most 4 × 4 cells (a tent at most √2 cells wide
    /// on each side spans at most four cells per axis).
    pub const CAPACITY: usize = 32;

    pub fn new() -> Candidates {
        Candidates {
            len: 0,
            w: [0.0; Candidates::CAPACITY],
            z: [[0.0; 2]; Candidates::CAPACITY],
            u: [0.5; Candidates::CAPACITY],
        }
    }
}

/// ⌊x⌋ as an integer, for |x| < 2⁶³ (cell indices): the truncation, one less where it rounded up
/// (without SSE4.1, `f64::floor` is a library call).
#[inline]
fn floor_i64(x: f64) -> i64 {
    let i = x as i64;
    if (i as f64) > x { i - 1 } else { i }
}

/// Adds the lobes of `level` under the tent of `kernel` to `out`: the lobes of the cells around
/// the kernel's centre weighted by the separable tent k(p) = (1 − |dx|/H_u)⁺ (1 − |dy|/H_v)⁺,
/// normalised over the level and scaled by `scale`. The half-widths are the level's cell sides
/// times the kernel's [`Kernel::stretch`], so at least one cell on both axes: the lobe of the cell
/// under the centre always weighs, and the level's sum never vanishes. With `scales`, each lobe's
/// third uniform (the variance scale of a GGX surface) is read too.
pub(super) fn gather_level(
    levels: &[Level],
    index: usize,
    seed: u64,
    kernel: &Kernel,
    scale: f32,
    scales: bool,
    out: &mut Candidates,
) {
    let (seed_key, stretch) = (seed_key(seed), kernel.stretch());
    let level = &levels[index];
    let [s, t] = level.spacing;
    let (hu, hv) = (s * stretch[0], t * stretch[1]);
    let [cx, cy] = kernel.center;
    let (i0, i1) = (floor_i64((cx - hu) / s), floor_i64((cx + hu) / s));
    let (j0, j1) = (floor_i64((cy - hv) / t), floor_i64((cy + hv) / t));
    let [cells_u, cells_v] = level.cells;
    let (iu, iv) = (1.0 / hu, 1.0 / hv);
    let start = out.len;
    let mut sum = 0.0f64;
    let mut wj = j0.rem_euclid(cells_v as i64) as u32;
    for j in j0..=j1 {
        let y0 = j as f64 * t - cy;
        let mut wi = i0.rem_euclid(cells_u as i64) as u32;
        for i in i0..=i1 {
            if out.len < Candidates::CAPACITY {
                let h = cell_hash(seed_key, index, wi, wj);
                let [ju, jv] = jitter(h);
                let dx = i as f64 * s - cx + ju as f64 * s;
                let dy = y0 + jv as f64 * t;
                let w = ((1.0 - dx.abs() * iu).max(0.0) * (1.0 - dy.abs() * iv).max(0.0)) as f32;
                if w > 0.0 {
                    out.w[out.len] = w;
                    out.z[out.len] = mean_z(h);
                    if scales {
                        out.u[out.len] = scale_uniform(h);
                    }
                    out.len += 1;
                    sum += w as f64;
                }
            }
            wi += 1;
            if wi == cells_u {
                wi = 0;
            }
        }
        wj += 1;
        if wj == cells_v {
            wj = 0;
        }
    }
    if sum > 0.0 {
        let f = (scale as f64 / sum) as f32;
        for w in &mut out.w[start..out.len] {
            *w *= f;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A uniform in [0, 1) from a counter (the lattice's own finaliser: the tests need no RNG).
    fn uniform(k: u64) -> f64 {
        (mix(k.wrapping_mul(GOLDEN)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A kernel at `center` of standard deviations `sd` along an axis at angle `angle`, through
    /// `Kernel::new` (anisotropy capped at 2).
    fn kernel(center: [f64; 2], sd: [f64; 2], angle: f64) -> Kernel {
        let (c, s) = (angle.cos(), angle.sin());
        let [a, b] = sd.map(|v| v * v);
        let cov = [
            a * c * c + b * s * s,
            (a - b) * c * s,
            a * s * s + b * c * c,
        ];
        Kernel::new(center, cov, 1e-6, 1e12)
    }

    /// Every level of a surface, at random centres and kernels (isotropic to the anisotropy cap,
    /// every angle): the tent keeps at least one lobe (the cell under the centre), at most 16 (the
    /// 4 × 4 cells its half-widths of at most √2 cells span), and its weights sum to the level's
    /// scale. A stretch below one cell (a level's sum may vanish) fails here.
    #[test]
    fn every_level_keeps_one_to_sixteen_lobes() {
        let p = ProceduralParams {
            resolution: [256, 192],
            ..ProceduralParams::default()
        };
        let levels = levels(&p);
        for k in 0..4000u64 {
            let index = (k as usize) % levels.len();
            let [su, sv] = levels[index].spacing;
            let center = [uniform(3 * k) * 256.0, uniform(3 * k + 1) * 192.0];
            let minor = 0.05 + 3.0 * uniform(3 * k + 2) * su.min(sv);
            let ratio = 1.0 + 9.0 * uniform(7 * k + 5);
            let angle = std::f64::consts::PI * uniform(11 * k + 3);
            let kern = kernel(center, [minor * ratio, minor], angle);
            let mut out = Candidates::new();
            gather_level(&levels, index, 9, &kern, 0.75, false, &mut out);
            assert!(
                (1..=16).contains(&out.len),
                "level {index}, centre {center:?}: {} lobes",
                out.len
            );
            let sum: f64 = out.w[..out.len].iter().map(|&w| w as f64).sum();
            assert!((sum - 0.75).abs() < 1e-5, "sum {sum}");
        }
    }

    /// The weights are continuous in the centre: walking it across 20 cells in steps of 10⁻³
    /// cell, no lobe's normalised weight moves by more than 0.01 in one step (measured 0.0025:
    /// lobes enter and leave the tent at weight 0; the same walk with a hard-edged kernel, the
    /// tent's support at weight 1, measures 0.5).
    #[test]
    fn weights_are_continuous_in_the_centre() {
        let p = ProceduralParams::default();
        let levels = levels(&p);
        let index = 2;
        let s = levels[index].spacing[0];
        let gather = |x: f64| {
            let mut c = Candidates::new();
            let kern = kernel([x, 37.3 * s], [0.4 * s, 0.3 * s], 0.3);
            gather_level(&levels, index, 5, &kern, 1.0, false, &mut c);
            c
        };
        // A lobe is known by its mean coordinates; one absent weighs 0.
        let weight = |c: &Candidates, z: [f32; 2]| -> f32 {
            (0..c.len).find(|&i| c.z[i] == z).map_or(0.0, |i| c.w[i])
        };
        let mut worst = 0.0f32;
        let mut last = gather(0.0);
        for k in 1..20_000 {
            let next = gather(k as f64 * 1e-3 * s);
            for c in [&last, &next] {
                for i in 0..c.len {
                    let step = (weight(&last, c.z[i]) - weight(&next, c.z[i])).abs();
                    worst = worst.max(step);
                }
            }
            last = next;
        }
        println!("largest step of a weight per 10⁻³ cell: {worst}");
        assert!(worst < 0.01, "largest step of a weight: {worst}");
    }
}
