//! The facet lattice of a procedural glint surface: its levels (cell size, the facets a lobe
//! stands for, the lobes' shared width and the spread of their means), the stateless hash that
//! places each cell's lobe, and the gather of one level's lobes under a footprint kernel.
//!
//! Level l tiles the uv square with `cells` × `cells` square cells (about 2^l times fewer per side
//! than level 0, whose cells hold one facet each); every cell holds one lobe, a slope Gaussian
//! N(μ, β_l² I_axes) at a jittered position in the cell, with μ ~ N(0, diag(τ_l²)) and
//! β_l² + τ_l² = σ² per axis (σ = α/√2, the limit Beckmann lobe's slope deviation), so that every
//! lobe of every level has the limit NDF as its mean. A lobe of level l stands for the
//! n_l = density · spacing_l² facets of its cell: β_l is chosen so that the expected squared L2
//! distance of the lobe to the limit equals that of n_l facets of roughness σ_f with means drawn
//! from N(0, σ² − σ_f²) (docs/procedural.md, "Levels"):
//! 1/β_l² = 1/σ² + (1/σ_f² − 1/σ²) / n_l. A surface of the GGX limit reads a third uniform per
//! cell, its lobe's variance scale (src/glint/procedural/ggx.rs).

use super::params::ProceduralParams;

/// Kernel truncation radius, in Mahalanobis units: lobes with q = dᵀ Σ⁻¹ d ≥ R² weigh 0.
pub(super) const RADIUS: f64 = 2.5;

/// Largest ratio of the footprint kernel's major to minor standard deviation the gather reads: a
/// thinner footprint's kernel is widened along its minor axis to this ratio (as a GPU's
/// anisotropic filtering caps its taps), which bounds the lobes a patch holds.
pub(super) const MAX_ANISOTROPY: f64 = 2.0;

/// The cells of the finer level a footprint reads are between `CELL_SIGMAS`/2 and `CELL_SIGMAS`
/// of its kernel's minor standard deviations wide (the coarser level's twice that): the kernel
/// sees a few lobes per level.
pub(super) const CELL_SIGMAS: f64 = 3.0;

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

/// Two 24-bit uniforms in (0, 1) from one hash.
#[inline]
fn uniforms(h: u64) -> [f32; 2] {
    const SCALE: f32 = 1.0 / (1u32 << 24) as f32;
    [
        ((h >> 40) as f32 + 0.5) * SCALE,
        (((h >> 16) & 0xff_ffff) as f32 + 0.5) * SCALE,
    ]
}

/// The standard normal quantile Φ⁻¹(u) of u ∈ (0, 1) (`f64` rational approximations, no logarithm
/// for u ∈ [0.075, 0.925]: `gauss::inv_std_cdf`).
#[inline]
fn normal_quantile(u: f32) -> f32 {
    crate::ndf::gauss::inv_std_cdf(u as f64) as f32
}

/// The hash of cell (i, j) of level `level` (indices already wrapped into [0, cells)).
#[inline]
fn cell_hash(seed: u64, level: usize, i: u32, j: u32) -> u64 {
    let key = ((level as u64) << 50) ^ ((i as u64) << 25) ^ (j as u64);
    mix(seed ^ mix(key.wrapping_add(GOLDEN)))
}

/// The jitter of a cell's lobe in the cell, in (0, 1)², from the cell's hash.
#[inline]
fn jitter(h: u64) -> [f32; 2] {
    uniforms(mix(h.wrapping_add(GOLDEN)))
}

/// The standard-normal coordinates of a cell's lobe mean, from the cell's hash.
#[inline]
fn mean_z(h: u64) -> [f32; 2] {
    let [a, b] = uniforms(mix(h.wrapping_add(GOLDEN.wrapping_mul(2))));
    [normal_quantile(a), normal_quantile(b)]
}

/// A third uniform in (0, 1) from the cell's hash, independent of its jitter and mean: the variance
/// scale of a GGX surface's lobe (src/glint/procedural/ggx.rs).
#[inline]
fn scale_uniform(h: u64) -> f32 {
    uniforms(mix(h.wrapping_add(GOLDEN.wrapping_mul(3))))[0]
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

    /// The same kernel with both variances raised to at least `floor`.
    pub fn floored(&self, floor: f64) -> Kernel {
        let l1 = self.lambda[0].max(floor);
        Kernel {
            lambda: [l1, self.lambda[1].max(floor).min(l1)],
            ..*self
        }
    }

    /// Σ⁻¹ as (xx, xy, yy).
    fn inverse(&self) -> [f64; 3] {
        let [c, s] = self.e1;
        let (a, b) = (1.0 / self.lambda[0], 1.0 / self.lambda[1]);
        [
            a * c * c + b * s * s,
            (a - b) * c * s,
            a * s * s + b * c * c,
        ]
    }

    /// Σ as (xx, xy, yy).
    fn covariance(&self) -> [f64; 3] {
        let [c, s] = self.e1;
        let [a, b] = self.lambda;
        [
            a * c * c + b * s * s,
            (a - b) * c * s,
            a * s * s + b * c * c,
        ]
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
    /// More than a patch can gather (two levels of at most ~20 lobes each within the kernel's
    /// ellipse; `procedural_glints::every_patch_holds_few_lobes`).
    pub const CAPACITY: usize = 128;

    pub fn new() -> Candidates {
        Candidates {
            len: 0,
            w: [0.0; Candidates::CAPACITY],
            z: [[0.0; 2]; Candidates::CAPACITY],
            u: [0.5; Candidates::CAPACITY],
        }
    }
}

/// Adds the lobes of `level` under `kernel` to `out`, their weights
/// k(p) = exp(−q/2) − exp(−R²/2) (q < R², continuous at the truncation) normalised over the level
/// and scaled by `scale`. The kernel is floored at the level's cell: both its standard deviations at
/// least half a cell, so that a cell's lobe always lies within R of the centre. With `scales`, each
/// lobe's third uniform (the variance scale of a GGX surface) is read too.
pub(super) fn gather_level(
    levels: &[Level],
    index: usize,
    seed: u64,
    kernel: &Kernel,
    scale: f32,
    scales: bool,
    out: &mut Candidates,
) {
    let level = &levels[index];
    let [s, t] = level.spacing;
    let kernel = kernel.floored(0.25 * s.max(t) * s.max(t));
    let [ixx, ixy, iyy] = kernel.inverse();
    let [sxx, _, syy] = kernel.covariance();
    let [cx, cy] = kernel.center;
    let (hx, hy) = (RADIUS * sxx.sqrt(), RADIUS * syy.sqrt());
    let (i0, i1) = (
        ((cx - hx) / s).floor() as i64,
        ((cx + hx) / s).floor() as i64,
    );
    let (j0, j1) = (
        ((cy - hy) / t).floor() as i64,
        ((cy + hy) / t).floor() as i64,
    );
    let [cells_u, cells_v] = level.cells.map(i64::from);
    let r2 = RADIUS * RADIUS;
    let edge = (-0.5 * r2 as f32).exp();
    // A cell whose rectangle is farther than R major standard deviations from the centre holds no
    // lobe of the ellipse (its Mahalanobis distance is at least its distance over σ_major).
    let far2 = r2 * kernel.lambda[0];
    let start = out.len;
    let mut sum = 0.0f64;
    for j in j0..=j1 {
        let (y0, y1) = (j as f64 * t - cy, (j + 1) as f64 * t - cy);
        let ny = if y0 > 0.0 {
            y0
        } else if y1 < 0.0 {
            y1
        } else {
            0.0
        };
        for i in i0..=i1 {
            let (x0, x1) = (i as f64 * s - cx, (i + 1) as f64 * s - cx);
            let nx = if x0 > 0.0 {
                x0
            } else if x1 < 0.0 {
                x1
            } else {
                0.0
            };
            if nx * nx + ny * ny >= far2 || out.len == Candidates::CAPACITY {
                continue;
            }
            let (wi, wj) = (i.rem_euclid(cells_u) as u32, j.rem_euclid(cells_v) as u32);
            let h = cell_hash(seed, index, wi, wj);
            let jit = jitter(h);
            let dx = x0 + jit[0] as f64 * s;
            let dy = y0 + jit[1] as f64 * t;
            let q = ixx * dx * dx + 2.0 * ixy * dx * dy + iyy * dy * dy;
            if q >= r2 {
                continue;
            }
            let w = ((-0.5 * q) as f32).exp() - edge;
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
    }
    if sum > 0.0 {
        let f = (scale as f64 / sum) as f32;
        for w in &mut out.w[start..out.len] {
            *w *= f;
        }
    }
}
