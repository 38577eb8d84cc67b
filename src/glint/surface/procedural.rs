//! Procedural normal maps: stand-ins for the measured maps of \[Chermain2019\] Fig. 7 (scratched,
//! brushed, bumpy, metallic flakes).
//!
//! Every generator is seeded (`u64`) and deterministic whatever the number of rayon threads: random
//! numbers are drawn from one PCG stream per row (or per feature, drawn sequentially) derived from the
//! seed, every output texel is a fixed-order function of them, and sums over the map are reduced row by
//! row, then sequentially. All maps tile: noise is periodic, convolutions wrap, features near an edge
//! reappear on the other side.
//!
//! Height-field generators (bumpy, brushed, scratched) build heights in texel units and take slopes by
//! central differences with wrapping, as [`NormalMap::from_heights`] does: ñ = (∂h/∂u, ∂h/∂v).
//!
//! Costs: O(W·H·(ℓx + ℓy)) for the Gaussian-filtered noise (separable convolution, 4σ truncation);
//! scratches cost their total length times their width; flakes 25 distance tests per texel.
//!
//! ## Bounds
//! Every generator checks its parameters against what it can compute in bounded time and memory,
//! and returns [`Error::InvalidParameter`] naming the parameter (or [`Error::InvalidSize`] for the
//! map size) instead of panicking, aborting on allocation or running for ever:
//! - maps of at most [`MAX_GENERATED_TEXELS`] texels (peak memory about 20 bytes per texel);
//! - correlation lengths at most the map size along their axis (O(W·H·ℓ) work);
//! - RMS slopes, tilts and groove slopes at most `MAX_SLOPE / 100`;
//! - flakes of at least [`MIN_CELL_TEXELS`] texels (at most 4 Voronoi sites per texel);
//! - scratches no wider than the map's shorter side, at most 10⁵ per 256² texels and 10⁵ texels
//!   long, and together at most [`MAX_CARVE_WORK_PER_TEXEL`] texel visits of the rasteriser per
//!   texel of the map (the defaults use about 4).

use super::normal_map::{MAX_SLOPE, NormalMap};
use crate::error::{Error, Result, non_negative, positive};
use glam::Vec2;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// Rows per parallel band in the scratch rasteriser.
const BAND_ROWS: usize = 32;

/// The largest map a generator builds: 2²⁶ texels (8192²). Its buffers (noise, blur, heights,
/// slopes) take about 20 bytes per texel, 1.3 GiB at this size; larger requests are refused with
/// [`Error::InvalidSize`] rather than aborting on allocation.
pub const MAX_GENERATED_TEXELS: usize = 1 << 26;

/// The smallest flake ([`FlakesParams::cell_texels`]): half a texel, i.e. at most 4 Voronoi sites
/// per texel (a flake smaller than a texel is seen by no texel centre anyway).
pub const MIN_CELL_TEXELS: f32 = 0.5;

/// The scratch rasteriser's budget: at most this many texel visits per texel of the map, counted
/// before carving as scratches × segments per scratch × texels of a segment's bounding box (the
/// defaults use about 4). Beyond it [`scratched`] refuses `density`, `length_texels` and
/// `width_texels` together.
pub const MAX_CARVE_WORK_PER_TEXEL: f64 = 1024.0;

/// The carve budget's floor, so that small maps still take a few long scratches: 2²⁰ texel visits
/// (a millisecond).
const MIN_CARVE_WORK: f64 = (1u64 << 20) as f64;

/// Checks a generator's map size: both sides ≥ 1 and at most [`MAX_GENERATED_TEXELS`] texels.
fn generated_size(width: usize, height: usize) -> Result<usize> {
    let n = super::normal_map::texel_count(width, height, width.saturating_mul(height))?;
    if n > MAX_GENERATED_TEXELS {
        return Err(Error::InvalidSize {
            width,
            height,
            reason: "a generated map holds at most MAX_GENERATED_TEXELS = 2^26 texels",
        });
    }
    Ok(n)
}

/// SplitMix64 finaliser: a well-mixed 64-bit hash of `x`.
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// An independent stream for (seed, purpose, index).
fn stream(seed: u64, purpose: u64, index: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(mix(mix(seed ^ mix(purpose)) ^ index))
}

/// Two independent standard normal variates (Box–Muller, f64).
fn gaussian_pair(rng: &mut Pcg64Mcg) -> (f64, f64) {
    let u1 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2 = rng.random::<f64>();
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (2.0 * std::f64::consts::PI * u2).sin_cos();
    (r * c, r * s)
}

/// Periodic white Gaussian noise, one stream per row.
fn white_noise(width: usize, height: usize, seed: u64, purpose: u64) -> Vec<f32> {
    let mut out = vec![0.0f32; width * height];
    out.par_chunks_mut(width).enumerate().for_each(|(j, row)| {
        let mut rng = stream(seed, purpose, j as u64);
        for pair in row.chunks_mut(2) {
            let (a, b) = gaussian_pair(&mut rng);
            pair[0] = a as f32;
            if let Some(v) = pair.get_mut(1) {
                *v = b as f32;
            }
        }
    });
    out
}

/// Normalised Gaussian kernel of standard deviation `sigma` truncated at 4σ (at least one tap).
fn kernel(sigma: f64) -> Vec<f32> {
    let r = (4.0 * sigma).ceil().max(0.0) as i64;
    let w: Vec<f64> = (-r..=r)
        .map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp())
        .collect();
    let s: f64 = w.iter().sum();
    w.iter().map(|v| (v / s) as f32).collect()
}

/// Wrapping Gaussian blur along rows (x) and columns (y). A σ below 0.05 texel is the identity.
fn blur(field: &[f32], width: usize, height: usize, sigma_x: f64, sigma_y: f64) -> Vec<f32> {
    let mut tmp = field.to_vec();
    if sigma_x >= 0.05 {
        let k = kernel(sigma_x);
        let r = (k.len() / 2) as i64;
        tmp.par_chunks_mut(width)
            .zip(field.par_chunks(width))
            .for_each(|(dst, src)| {
                let padded: Vec<f32> = (-r..width as i64 + r)
                    .map(|i| src[i.rem_euclid(width as i64) as usize])
                    .collect();
                // Tap-major order: the inner loop is a vectorisable axpy, and every output is summed
                // in the same (tap) order whatever the thread count.
                dst.fill(0.0);
                for (t, &wk) in k.iter().enumerate() {
                    for (d, s) in dst.iter_mut().zip(&padded[t..t + width]) {
                        *d += wk * s;
                    }
                }
            });
    }
    if sigma_y < 0.05 {
        return tmp;
    }
    let k = kernel(sigma_y);
    let r = (k.len() / 2) as i64;
    let mut out = vec![0.0f32; width * height];
    out.par_chunks_mut(width).enumerate().for_each(|(j, dst)| {
        for (t, &wk) in k.iter().enumerate() {
            let src_row = (j as i64 + t as i64 - r).rem_euclid(height as i64) as usize;
            let src = &tmp[src_row * width..(src_row + 1) * width];
            for (d, s) in dst.iter_mut().zip(src) {
                *d += wk * s;
            }
        }
    });
    out
}

/// Central-difference slopes of a tiled height field (texel units).
fn height_slopes(h: &[f32], width: usize, height: usize) -> Vec<Vec2> {
    let mut out = vec![Vec2::ZERO; width * height];
    out.par_chunks_mut(width).enumerate().for_each(|(j, row)| {
        let up = ((j + 1) % height) * width;
        let down = ((j + height - 1) % height) * width;
        let here = j * width;
        for (i, s) in row.iter_mut().enumerate() {
            let (l, r) = ((i + width - 1) % width, (i + 1) % width);
            *s = Vec2::new(
                0.5 * (h[here + r] - h[here + l]),
                0.5 * (h[up + i] - h[down + i]),
            );
        }
    });
    out
}

/// (E\[x̃²\], E\[ỹ²\]) of a slope field: per-row f64 sums, then a sequential sum (thread-independent).
fn mean_square(slopes: &[Vec2], width: usize) -> (f64, f64) {
    let rows: Vec<(f64, f64)> = slopes
        .par_chunks(width)
        .map(|row| {
            row.iter().fold((0.0, 0.0), |(a, b), s| {
                (a + (s.x as f64).powi(2), b + (s.y as f64).powi(2))
            })
        })
        .collect();
    let (a, b) = rows.iter().fold((0.0, 0.0), |(a, b), r| (a + r.0, b + r.1));
    let n = slopes.len() as f64;
    (a / n, b / n)
}

/// A Gaussian random height field (white noise filtered by a Gaussian of standard deviations
/// (ℓx/2, ℓy/2)), not yet scaled.
fn gaussian_field(
    width: usize,
    height: usize,
    corr_x: f64,
    corr_y: f64,
    seed: u64,
    purpose: u64,
) -> Vec<f32> {
    let noise = white_noise(width, height, seed, purpose);
    blur(&noise, width, height, 0.5 * corr_x, 0.5 * corr_y)
}

/// Checks a correlation length: finite, > 0 and not longer than the map along its axis.
fn correlation(name: &'static str, value: f32, extent: usize) -> Result<f64> {
    positive(name, value)?;
    if value as f64 > extent as f64 {
        return Err(Error::InvalidParameter {
            name,
            value: value as f64,
            reason: "must not exceed the map size along its axis (the field would be nearly constant)",
        });
    }
    Ok(value as f64)
}

/// Checks an RMS slope: finite, > 0, and well below `MAX_SLOPE` (random fields reach ~6 σ).
fn rms(name: &'static str, value: f32) -> Result<f64> {
    positive(name, value)?;
    if value > MAX_SLOPE / 100.0 {
        return Err(Error::InvalidParameter {
            name,
            value: value as f64,
            reason: "must be at most MAX_SLOPE / 100",
        });
    }
    Ok(value as f64)
}

/// Scales heights so that √((E\[x̃²\] + E\[ỹ²\]) / 2) of their slopes is `target` (or √E\[ỹ²\] when
/// `across_only`); returns the slopes. A field without slope fails.
fn scaled_slopes(
    heights: &[f32],
    width: usize,
    height: usize,
    target: f64,
    across_only: bool,
) -> Result<Vec<Vec2>> {
    let slopes = height_slopes(heights, width, height);
    let (mx, my) = mean_square(&slopes, width);
    let current = if across_only {
        my.sqrt()
    } else {
        (0.5 * (mx + my)).sqrt()
    };
    if !(current > 0.0 && current.is_finite()) {
        return Err(Error::InvalidSize {
            width,
            height,
            reason: "too small for a random height field (its slopes vanish)",
        });
    }
    let k = (target / current) as f32;
    Ok(slopes.into_iter().map(|s| s * k).collect())
}

// ---------------------------------------------------------------------------------------------
// Bumpy
// ---------------------------------------------------------------------------------------------

/// An isotropic Gaussian random height field with a requested RMS slope (bumpy plastic / hammered
/// metal).
///
/// Heights: periodic white Gaussian noise convolved (with wrapping) with a Gaussian of standard
/// deviation ℓ/2, ℓ = `correlation_texels`, so the height autocorrelation is ∝ exp(−r²/ℓ²) (ℓ is the
/// usual correlation length of a Gaussian surface). Slopes: central differences, then one scale factor
/// on the heights makes the RMS slope over both axes, √((E\[x̃²\] + E\[ỹ²\]) / 2) over the texels, equal
/// to `rms_slope` exactly (up to f32 rounding). Each axis then matches it within the statistical
/// fluctuation of the field (a few % when the map spans many correlation lengths); a single factor
/// keeps the slopes a true gradient field. The slope distribution is close to a centred Gaussian of
/// standard deviation `rms_slope` per axis (a Beckmann surface of α = √2 · rms_slope).
///
/// # Errors
/// [`Error::InvalidParameter`] for `rms_slope` not in (0, MAX_SLOPE/100] or `correlation_texels` not
/// in (0, min(width, height)]; [`Error::InvalidSize`] for a zero size, more than
/// [`MAX_GENERATED_TEXELS`] texels, or a map too small to have any slope (1 × 1).
pub fn bumpy(
    width: usize,
    height: usize,
    rms_slope: f32,
    correlation_texels: f32,
    seed: u64,
) -> Result<NormalMap> {
    generated_size(width, height)?;
    let target = rms("rms_slope", rms_slope)?;
    let corr = correlation("correlation_texels", correlation_texels, width.min(height))?;
    let h = gaussian_field(width, height, corr, corr, seed, 1);
    let slopes = scaled_slopes(&h, width, height, target, false)?;
    NormalMap::from_slopes(width, height, slopes)
}

// ---------------------------------------------------------------------------------------------
// Brushed
// ---------------------------------------------------------------------------------------------

/// Parameters of [`brushed`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushedParams {
    /// RMS slope across the brushing direction, √E\[ỹ²\] (exact after rescaling). Default 0.15.
    pub rms_slope: f32,
    /// Correlation length along the brushing direction (+u), in texels. Default 32.
    pub length_texels: f32,
    /// Correlation length across it (+v), in texels. Default 1.5.
    pub width_texels: f32,
}

impl Default for BrushedParams {
    fn default() -> Self {
        BrushedParams {
            rms_slope: 0.15,
            length_texels: 32.0,
            width_texels: 1.5,
        }
    }
}

/// Brushed metal: strongly anisotropic fine noise, grooves running along +u.
///
/// The same Gaussian random height field as [`bumpy`] with correlation lengths `length_texels` along u
/// and `width_texels` along v; one factor scales the heights so that the RMS slope across the grooves,
/// √E\[ỹ²\], equals `rms_slope`. The RMS slope along them is smaller by about width/length (a stretched
/// field), limited by the central differences at widths near one texel: with the defaults the ratio
/// √E\[ỹ²\] / √E\[x̃²\] is about 13 (tests require > 8). The P-NDF is a thin streak along ỹ.
///
/// # Errors
/// As [`bumpy`], for each parameter (lengths bounded by the map size along their axis).
pub fn brushed(width: usize, height: usize, params: BrushedParams, seed: u64) -> Result<NormalMap> {
    generated_size(width, height)?;
    let target = rms("rms_slope", params.rms_slope)?;
    let lx = correlation("length_texels", params.length_texels, width)?;
    let ly = correlation("width_texels", params.width_texels, height)?;
    let h = gaussian_field(width, height, lx, ly, seed, 2);
    let slopes = scaled_slopes(&h, width, height, target, true)?;
    NormalMap::from_slopes(width, height, slopes)
}

// ---------------------------------------------------------------------------------------------
// Scratched
// ---------------------------------------------------------------------------------------------

/// Parameters of [`scratched`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScratchedParams {
    /// Number of scratches per 256 × 256 texels (scaled with the map area). Default 40.
    pub density: f32,
    /// Mean full width of a groove, in texels (each scratch draws ×U[0.75, 1.25]). Default 3.
    pub width_texels: f32,
    /// Largest slope of the groove profile (each scratch draws ×U[0.5, 1]). Default 0.6.
    pub max_slope: f32,
    /// Length range in texels (each scratch draws uniformly in it). Default (25, 150).
    pub length_texels: (f32, f32),
    /// Probability that a scratch is curved (a circular arc) rather than straight. Default 0.5.
    pub curved_fraction: f32,
    /// Largest total turning angle of a curved scratch, in radians (each draws U[−max, max]).
    /// Default 1.5.
    pub max_turn: f32,
    /// RMS slope of the base surface ([`bumpy`]-like); 0 for a flat base. Default 0.02.
    pub base_rms_slope: f32,
    /// Correlation length of the base surface, in texels. Default 8.
    pub base_correlation_texels: f32,
}

impl Default for ScratchedParams {
    fn default() -> Self {
        ScratchedParams {
            density: 40.0,
            width_texels: 3.0,
            max_slope: 0.6,
            length_texels: (25.0, 150.0),
            curved_fraction: 0.5,
            max_turn: 1.5,
            base_rms_slope: 0.02,
            base_correlation_texels: 8.0,
        }
    }
}

/// One straight piece of a scratch (unwrapped texel coordinates).
#[derive(Clone, Copy, Debug)]
struct Segment {
    p0: Vec2,
    p1: Vec2,
    half_width: f32,
    depth: f32,
}

/// The groove profile: −depth (1 − t²)² for t = r / half_width < 1 (C¹, flat bottom, smooth rims),
/// whose largest slope is depth · 8 / (3√3) / half_width at t = 1/√3.
const PROFILE_SLOPE: f32 = 1.539_600_7; // 8 / (3√3)

impl Segment {
    fn groove(&self, c: Vec2) -> f32 {
        let d = self.p1 - self.p0;
        let len2 = d.length_squared();
        let t = if len2 > 0.0 {
            ((c - self.p0).dot(d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let r = (c - (self.p0 + d * t)).length() / self.half_width;
        if r < 1.0 {
            let q = 1.0 - r * r;
            -self.depth * q * q
        } else {
            0.0
        }
    }

    /// Inclusive texel ranges (unwrapped) whose centres may be within reach.
    fn texel_bounds(&self) -> (i64, i64, i64, i64) {
        let lo = self.p0.min(self.p1) - Vec2::splat(self.half_width);
        let hi = self.p0.max(self.p1) + Vec2::splat(self.half_width);
        (
            (lo.x - 0.5).ceil() as i64,
            (hi.x - 0.5).floor() as i64,
            (lo.y - 0.5).ceil() as i64,
            (hi.y - 0.5).floor() as i64,
        )
    }
}

/// The number of scratches of [`scratch_segments`].
fn scratch_count(width: usize, height: usize, p: &ScratchedParams) -> usize {
    (p.density as f64 * (width * height) as f64 / 65536.0).round() as usize
}

/// An upper bound of the rasteriser's texel visits (see [`MAX_CARVE_WORK_PER_TEXEL`]): scratches ×
/// segments per scratch (length / 8, rounded up) × the bounding box of a segment (8 texels long at
/// most, half-width 0.625 `width_texels` at most, plus a texel of rounding each way).
fn carve_work(width: usize, height: usize, p: &ScratchedParams) -> f64 {
    let segments = (p.length_texels.1 as f64 / 8.0).ceil().max(1.0);
    let side = 8.0 + 1.25 * p.width_texels as f64 + 2.0;
    scratch_count(width, height, p) as f64 * segments * side * side
}

/// The scratches as polylines of segments at most 8 texels long (sequential draws from the seed).
fn scratch_segments(width: usize, height: usize, p: &ScratchedParams, seed: u64) -> Vec<Segment> {
    let mut rng = stream(seed, 3, 0);
    let count = scratch_count(width, height, p);
    let mut segs = Vec::new();
    for _ in 0..count {
        let start = Vec2::new(
            rng.random::<f32>() * width as f32,
            rng.random::<f32>() * height as f32,
        );
        let (l0, l1) = p.length_texels;
        let length = l0 + (l1 - l0) * rng.random::<f32>();
        let heading = std::f32::consts::PI * rng.random::<f32>();
        let turn = if rng.random::<f32>() < p.curved_fraction {
            p.max_turn * (2.0 * rng.random::<f32>() - 1.0)
        } else {
            0.0
        };
        let half_width = 0.5 * p.width_texels * (0.75 + 0.5 * rng.random::<f32>());
        let depth = p.max_slope * half_width / PROFILE_SLOPE * (0.5 + 0.5 * rng.random::<f32>());
        let n = (length / 8.0).ceil().max(1.0) as usize;
        let step = length / n as f32;
        let mut a = start;
        for k in 0..n {
            let theta = heading + turn * (k as f32 + 0.5) / n as f32;
            let b = a + Vec2::new(theta.cos(), theta.sin()) * step;
            segs.push(Segment {
                p0: a,
                p1: b,
                half_width,
                depth,
            });
            a = b;
        }
    }
    segs
}

/// Rasterises the grooves: per texel, the deepest groove (a minimum: order-independent, so the
/// parallel bands give the same result whatever the thread count).
fn carve(width: usize, height: usize, segs: &[Segment]) -> Vec<f32> {
    let bands = height.div_ceil(BAND_ROWS);
    let mut lists: Vec<Vec<usize>> = vec![Vec::new(); bands];
    for (s, seg) in segs.iter().enumerate() {
        let (_, _, y0, y1) = seg.texel_bounds();
        for y in y0..=y1 {
            let b = y.rem_euclid(height as i64) as usize / BAND_ROWS;
            if lists[b].last() != Some(&s) {
                lists[b].push(s);
            }
        }
    }
    let mut out = vec![0.0f32; width * height];
    out.par_chunks_mut(BAND_ROWS * width)
        .zip(lists.par_iter())
        .enumerate()
        .for_each(|(b, (band, list))| {
            let first = b * BAND_ROWS;
            let rows = band.len() / width;
            for &s in list {
                let seg = &segs[s];
                let (x0, x1, y0, y1) = seg.texel_bounds();
                for y in y0..=y1 {
                    let r = y.rem_euclid(height as i64) as usize;
                    if r < first || r >= first + rows {
                        continue;
                    }
                    let row = &mut band[(r - first) * width..(r - first + 1) * width];
                    for x in x0..=x1 {
                        let g = seg.groove(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
                        let cell = &mut row[x.rem_euclid(width as i64) as usize];
                        *cell = cell.min(g);
                    }
                }
            }
        });
    out
}

/// Scratched metal: random straight and curved grooves over a flat or slightly rough base.
///
/// Scratches: `density` per 256² texels, each a polyline (straight, or a circular arc turning by up to
/// `max_turn`) starting uniformly on the map with a uniform heading, of length uniform in
/// `length_texels`, cut with the groove profile h(r) = −d (1 − (r/w)²)² of half-width w
/// (r = distance to the scratch's centre line); d is set so the profile's largest slope is
/// `max_slope` × U[0.5, 1]. Where grooves cross, the deeper cut wins (a minimum). The base is a
/// [`bumpy`] field of RMS slope `base_rms_slope` (skipped when 0). Slopes are central differences of
/// base + grooves. The P-NDF shows a base peak plus arcs from the grooves' walls: the glint streaks
/// of scratched metal.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the field for a non-finite or out-of-range parameter:
/// `density` in [0, 10⁵]; `width_texels` in (0, min(width, height)]; `max_slope` and
/// `base_rms_slope` in [0, MAX_SLOPE / 100]; `max_turn` ≥ 0; `curved_fraction` in [0, 1];
/// `length_texels` ordered in [0, 10⁵]; `base_correlation_texels` in (0, min(width, height)] when
/// `base_rms_slope` > 0; and `density`, `length_texels` and `width_texels` together within the
/// rasteriser's budget ([`MAX_CARVE_WORK_PER_TEXEL`], module docs). [`Error::InvalidSize`] for a zero
/// size or more than [`MAX_GENERATED_TEXELS`] texels.
pub fn scratched(
    width: usize,
    height: usize,
    params: ScratchedParams,
    seed: u64,
) -> Result<NormalMap> {
    generated_size(width, height)?;
    let p = params;
    non_negative("density", p.density)?;
    if p.density > 1e5 {
        return Err(Error::InvalidParameter {
            name: "density",
            value: p.density as f64,
            reason: "must be at most 1e5 scratches per 256² texels",
        });
    }
    positive("width_texels", p.width_texels)?;
    if p.width_texels as f64 > width.min(height) as f64 {
        return Err(Error::InvalidParameter {
            name: "width_texels",
            value: p.width_texels as f64,
            reason: "must not exceed the map's shorter side",
        });
    }
    non_negative("max_slope", p.max_slope)?;
    if p.max_slope > MAX_SLOPE / 100.0 {
        return Err(Error::InvalidParameter {
            name: "max_slope",
            value: p.max_slope as f64,
            reason: "must be at most MAX_SLOPE / 100",
        });
    }
    non_negative("max_turn", p.max_turn)?;
    non_negative("base_rms_slope", p.base_rms_slope)?;
    if p.base_rms_slope > 0.0 {
        rms("base_rms_slope", p.base_rms_slope)?;
    }
    let unit = |name, v: f32| {
        if (0.0..=1.0).contains(&v) {
            Ok(())
        } else {
            Err(Error::InvalidParameter {
                name,
                value: v as f64,
                reason: "must be in [0, 1]",
            })
        }
    };
    unit("curved_fraction", p.curved_fraction)?;
    non_negative("length_texels.0", p.length_texels.0)?;
    non_negative("length_texels.1", p.length_texels.1)?;
    if p.length_texels.0 > p.length_texels.1 || p.length_texels.1 > 1e5 {
        return Err(Error::InvalidParameter {
            name: "length_texels",
            value: p.length_texels.1 as f64,
            reason: "needs 0 <= lower <= upper <= 1e5",
        });
    }
    let work = carve_work(width, height, &p);
    if work > (MAX_CARVE_WORK_PER_TEXEL * (width * height) as f64).max(MIN_CARVE_WORK) {
        return Err(Error::InvalidParameter {
            name: "density * length_texels.1 * width_texels",
            value: work / (width * height) as f64,
            reason: "the scratches would take more than MAX_CARVE_WORK_PER_TEXEL = 1024 texel \
                     visits per texel (value: the visits per texel): fewer, shorter or narrower",
        });
    }
    let base = if p.base_rms_slope > 0.0 {
        let corr = correlation(
            "base_correlation_texels",
            p.base_correlation_texels,
            width.min(height),
        )?;
        let h = gaussian_field(width, height, corr, corr, seed, 4);
        let slopes = height_slopes(&h, width, height);
        let (mx, my) = mean_square(&slopes, width);
        let current = (0.5 * (mx + my)).sqrt();
        let k = if current > 0.0 {
            (p.base_rms_slope as f64 / current) as f32
        } else {
            0.0
        };
        h.into_iter().map(|v| v * k).collect()
    } else {
        vec![0.0f32; width * height]
    };
    let grooves = carve(width, height, &scratch_segments(width, height, &p, seed));
    let total: Vec<f32> = base.iter().zip(&grooves).map(|(a, b)| a + b).collect();
    NormalMap::from_slopes(width, height, height_slopes(&total, width, height))
}

// ---------------------------------------------------------------------------------------------
// Flakes
// ---------------------------------------------------------------------------------------------

/// Parameters of [`flakes`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlakesParams {
    /// Mean flake diameter (Voronoi cell spacing), in texels. Default 12.
    pub cell_texels: f32,
    /// Standard deviation of each component of a flake's slope (Gaussian tilt). Default 0.2.
    pub tilt_sigma: f32,
}

impl Default for FlakesParams {
    fn default() -> Self {
        FlakesParams {
            cell_texels: 12.0,
            tilt_sigma: 0.2,
        }
    }
}

/// Metallic flakes: Voronoi cells, each a flat facet with a random tilt.
///
/// Sites: one per cell of a gx × gy grid, gx = max(1, round(W / `cell_texels`)) (likewise gy), at a
/// uniform random position in its cell; the grid spans the map exactly, so the cells tile. A texel
/// belongs to the site nearest to its centre (toroidal distance; the 5 × 5 neighbouring grid cells are
/// searched, which is exact for a jittered grid whose cell aspect is within [1/√3, √3], i.e. unless a
/// map side is much shorter than `cell_texels`). Each site's slope is drawn from a centred Gaussian
/// of standard deviation `tilt_sigma` per axis, so the texel slopes of a large map follow that
/// Gaussian (a Beckmann NDF of α = √2 σ) while every footprint smaller than a flake sees a few mirror
/// directions only: the sparkle of metallic paint.
///
/// # Errors
/// [`Error::InvalidParameter`] for `cell_texels` not in [[`MIN_CELL_TEXELS`], max(W, H)] (at most
/// 4 sites per texel) or `tilt_sigma` not in [0, MAX_SLOPE / 100]; [`Error::InvalidSize`] for a zero
/// size or more than [`MAX_GENERATED_TEXELS`] texels.
pub fn flakes(width: usize, height: usize, params: FlakesParams, seed: u64) -> Result<NormalMap> {
    generated_size(width, height)?;
    positive("cell_texels", params.cell_texels)?;
    if params.cell_texels < MIN_CELL_TEXELS {
        return Err(Error::InvalidParameter {
            name: "cell_texels",
            value: params.cell_texels as f64,
            reason: "must be at least MIN_CELL_TEXELS = 0.5 (at most 4 flakes per texel)",
        });
    }
    if params.cell_texels as f64 > width.max(height) as f64 {
        return Err(Error::InvalidParameter {
            name: "cell_texels",
            value: params.cell_texels as f64,
            reason: "must not exceed the map size",
        });
    }
    non_negative("tilt_sigma", params.tilt_sigma)?;
    if params.tilt_sigma > MAX_SLOPE / 100.0 {
        return Err(Error::InvalidParameter {
            name: "tilt_sigma",
            value: params.tilt_sigma as f64,
            reason: "must be at most MAX_SLOPE / 100",
        });
    }
    let gx = ((width as f64 / params.cell_texels as f64).round() as usize).max(1);
    let gy = ((height as f64 / params.cell_texels as f64).round() as usize).max(1);
    let (cw, ch) = (width as f64 / gx as f64, height as f64 / gy as f64);
    let mut rng = stream(seed, 5, 0);
    let sigma = params.tilt_sigma as f64;
    let sites: Vec<([f64; 2], Vec2)> = (0..gx * gy)
        .map(|_| {
            let jitter = [rng.random::<f64>(), rng.random::<f64>()];
            let (gx_, gy_) = gaussian_pair(&mut rng);
            let slope = Vec2::new((sigma * gx_) as f32, (sigma * gy_) as f32);
            (jitter, slope)
        })
        .collect();
    let mut slopes = vec![Vec2::ZERO; width * height];
    slopes
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(j, row)| {
            let cy = j as f64 + 0.5;
            let b = (cy / ch).floor() as i64;
            // The 25 candidate sites of the current grid column, refreshed when the column changes.
            let mut cached_a = i64::MIN;
            let mut cand = [([0.0f64; 2], Vec2::ZERO); 25];
            for (i, out) in row.iter_mut().enumerate() {
                let cx = i as f64 + 0.5;
                let a = (cx / cw).floor() as i64;
                if a != cached_a {
                    cached_a = a;
                    let mut n = 0;
                    for db in -2..=2i64 {
                        for da in -2..=2i64 {
                            let (ca, cb) = (a + da, b + db);
                            let k = cb.rem_euclid(gy as i64) as usize * gx
                                + ca.rem_euclid(gx as i64) as usize;
                            let (jit, slope) = sites[k];
                            cand[n] = (
                                [(ca as f64 + jit[0]) * cw, (cb as f64 + jit[1]) * ch],
                                slope,
                            );
                            n += 1;
                        }
                    }
                }
                let mut best = (f64::INFINITY, Vec2::ZERO);
                for (p, slope) in &cand {
                    let d2 = (p[0] - cx).powi(2) + (p[1] - cy).powi(2);
                    if d2 < best.0 {
                        best = (d2, *slope);
                    }
                }
                *out = best.1;
            }
        });
    NormalMap::from_slopes(width, height, slopes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_is_normalised_and_symmetric() {
        for s in [0.3, 1.0, 4.5] {
            let k = kernel(s);
            let sum: f32 = k.iter().sum();
            assert!((sum - 1.0).abs() < 1e-6);
            for i in 0..k.len() {
                assert_eq!(k[i], k[k.len() - 1 - i]);
            }
        }
    }

    #[test]
    fn blur_preserves_the_mean_and_wraps() {
        // A single spike at the corner spreads symmetrically across the tile border.
        let (w, h) = (9, 7);
        let mut f = vec![0.0f32; w * h];
        f[0] = 1.0;
        let b = blur(&f, w, h, 1.0, 1.0);
        let sum: f32 = b.iter().sum();
        assert!((sum - 1.0).abs() < 1e-5);
        assert!((b[1] - b[w - 1]).abs() < 1e-7 && (b[w] - b[(h - 1) * w]).abs() < 1e-7);
    }

    #[test]
    fn groove_profile_peak_slope() {
        let s = Segment {
            p0: Vec2::new(0.0, 0.0),
            p1: Vec2::new(10.0, 0.0),
            half_width: 2.0,
            depth: 1.0,
        };
        // Finite-difference slope of the profile across the groove at r = w/√3.
        let r = 2.0 / 3f32.sqrt();
        let e = 1e-3;
        let g = (s.groove(Vec2::new(5.0, r + e)) - s.groove(Vec2::new(5.0, r - e))) / (2.0 * e);
        assert!((g - PROFILE_SLOPE / 2.0).abs() < 1e-3, "{g}");
        assert_eq!(s.groove(Vec2::new(5.0, 2.5)), 0.0);
        assert_eq!(s.groove(Vec2::new(5.0, 0.0)), -1.0);
    }
}
