//! The mip chain of slope moments of a normal map (mean slope and second moments per texel): the
//! public [`SlopeMomentPyramid`], built by [`NormalMap::moment_pyramid`](super::NormalMap::moment_pyramid),
//! where the definitions are documented, and the crate's chain behind it, which the bin map also keeps
//! (coarse levels only) and stores.

use glam::Vec2;
use rayon::prelude::*;

/// One level of the chain: `width × height` texels of `[E\[x̃\], E\[ỹ\], E\[x̃²\], E\[ỹ²\], E\[x̃ỹ\]]`, row major.
#[derive(Clone, Debug)]
pub(crate) struct MomentLevel {
    pub width: usize,
    pub height: usize,
    pub data: Vec<[f32; 5]>,
}

/// The whole chain, level 0 (the map) to the 1 × 1 level.
#[derive(Clone, Debug)]
pub(crate) struct MomentPyramid {
    levels: Vec<MomentLevel>,
    /// Index of `levels[0]` in the full chain (0 unless built by [`MomentPyramid::build_from`]).
    first: usize,
}

/// For a reduction of `n` texels to `m` (m ≤ n) along one axis: for each output texel, the input
/// texels its interval [o n/m, (o+1) n/m) overlaps, with the overlap fraction as weight (sums to 1).
fn axis_weights(n: usize, m: usize) -> Vec<Vec<(usize, f64)>> {
    let ratio = n as f64 / m as f64;
    (0..m)
        .map(|o| {
            let lo = o as f64 * ratio;
            let hi = ((o + 1) as f64 * ratio).min(n as f64);
            let first = lo.floor() as usize;
            let last = (hi.ceil() as usize).min(n);
            (first..last)
                .filter_map(|k| {
                    let w = (hi.min(k as f64 + 1.0) - lo.max(k as f64)) / ratio;
                    (w > 0.0).then_some((k, w))
                })
                .collect()
        })
        .collect()
}

impl MomentPyramid {
    /// Sizes of every level: each halves both sizes (rounding down, at least 1) until 1 × 1.
    pub fn level_sizes(width: usize, height: usize) -> Vec<(usize, usize)> {
        let mut sizes = vec![(width, height)];
        let (mut w, mut h) = (width, height);
        while w > 1 || h > 1 {
            w = (w / 2).max(1);
            h = (h / 2).max(1);
            sizes.push((w, h));
        }
        sizes
    }

    /// Builds the chain from the map's slopes (parallel over rows, deterministic).
    pub fn build(width: usize, height: usize, slopes: &[Vec2]) -> MomentPyramid {
        Self::build_from(width, height, slopes, 0)
    }

    /// Builds levels `first..` of the chain (`first` clamped to the last level), for models that keep
    /// coarse moments only; their lookups use level `first` for every finer level of detail. Each
    /// level is reduced from the one below it, so the finer levels are computed too (the values are
    /// those of [`MomentPyramid::build`], bit for bit), but each is dropped once the next is made.
    pub fn build_from(width: usize, height: usize, slopes: &[Vec2], first: usize) -> MomentPyramid {
        let base: Vec<[f32; 5]> = slopes
            .par_iter()
            .map(|s| [s.x, s.y, s.x * s.x, s.y * s.y, s.x * s.y])
            .collect();
        Self::build_from_moments(width, height, base, first)
    }

    /// [`MomentPyramid::build_from`] from level-0 moments given per texel (`width × height`, row
    /// major): for models whose texel's slope distribution is not one slope (the bin map's
    /// sub-texel bins).
    pub fn build_from_moments(
        width: usize,
        height: usize,
        base: Vec<[f32; 5]>,
        first: usize,
    ) -> MomentPyramid {
        let sizes = Self::level_sizes(width, height);
        let first = first.min(sizes.len() - 1);
        let mut current = MomentLevel {
            width,
            height,
            data: base,
        };
        let mut levels = Vec::with_capacity(sizes.len() - first);
        for (l, &(w, h)) in sizes.iter().enumerate().skip(1) {
            let next = downsample(&current, w, h);
            let done = std::mem::replace(&mut current, next);
            if l > first {
                levels.push(done);
            }
        }
        levels.push(current);
        MomentPyramid { levels, first }
    }

    /// The chain of stored parts (crate-private, for the bin map's loader): `levels` are levels
    /// `first..` of the full chain. The caller checks the sizes against [`MomentPyramid::level_sizes`].
    pub(crate) fn from_parts(first: usize, levels: Vec<MomentLevel>) -> MomentPyramid {
        MomentPyramid { levels, first }
    }

    /// Index of the first kept level in the full chain, and the kept levels (for saving).
    pub(crate) fn parts(&self) -> (usize, &[MomentLevel]) {
        (self.first, &self.levels)
    }

    /// Bytes held by the moments (20 per level texel).
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|l| 20 * l.data.len()).sum()
    }

    /// Level `l`, if it exists.
    pub fn level(&self, l: usize) -> Option<&MomentLevel> {
        self.levels.get(l)
    }

    /// Trilinear lookup (see [`SlopeMomentPyramid::filtered`] for the definition).
    pub fn filtered(&self, width: usize, height: usize, center: Vec2, radius: f32) -> [f32; 5] {
        let center = Vec2::select(center.is_finite_mask(), center, Vec2::ZERO);
        let first = self.first as f32;
        let top = (self.first + self.levels.len() - 1) as f32;
        // NaN and non-positive radii select level 0 (the finest kept); +∞ selects the top level.
        let lod = if radius > 0.0 {
            (2.0 * radius).log2().clamp(first, top)
        } else {
            first
        } - first;
        let l0 = lod.floor();
        let t = (lod - l0) as f64;
        let l0 = l0 as usize;
        let a = self.bilinear(l0, width, height, center);
        let out = if t > 0.0 && l0 + 1 < self.levels.len() {
            let b = self.bilinear(l0 + 1, width, height, center);
            std::array::from_fn(|k| a[k] * (1.0 - t) + b[k] * t)
        } else {
            a
        };
        out.map(|v| v as f32)
    }

    /// Bilinear lookup within level `l` at a level-0 texel position, with wrapping.
    fn bilinear(&self, l: usize, width: usize, height: usize, center: Vec2) -> [f64; 5] {
        let level = &self.levels[l];
        // Level texels are (width / w_l) × (height / h_l) level-0 texels wide.
        let px = center.x as f64 * level.width as f64 / width as f64 - 0.5;
        let py = center.y as f64 * level.height as f64 / height as f64 - 0.5;
        let (bx, by) = (px.floor(), py.floor());
        let (fx, fy) = (px - bx, py - by);
        let at = |i: f64, j: f64| {
            let i = (i as i64).rem_euclid(level.width as i64) as usize;
            let j = (j as i64).rem_euclid(level.height as i64) as usize;
            level.data[j * level.width + i]
        };
        let c = [
            (at(bx, by), (1.0 - fx) * (1.0 - fy)),
            (at(bx + 1.0, by), fx * (1.0 - fy)),
            (at(bx, by + 1.0), (1.0 - fx) * fy),
            (at(bx + 1.0, by + 1.0), fx * fy),
        ];
        std::array::from_fn(|k| c.iter().map(|(m, w)| m[k] as f64 * w).sum())
    }
}

/// The slope-moment mip chain of a normal map, level 0 (the map) to the 1 × 1 level: per texel
/// `[E\[x̃\], E\[ỹ\], E\[x̃²\], E\[ỹ²\], E\[x̃ỹ\]]`.
///
/// A plain value, built by [`NormalMap::moment_pyramid`](super::NormalMap::moment_pyramid) (O(texels),
/// parallel) and owned by the caller; it holds no reference to the map. Level 0 holds each texel's
/// own slope and its products (x̃, ỹ, x̃², ỹ², x̃ỹ): the texel's slope is taken as constant over the
/// texel. Level l + 1 has size (max(1, ⌊w/2⌋), max(1, ⌊h/2⌋)) and each of its texels is the
/// area-weighted average of the level-l texels its rectangle of the uv square overlaps: for even
/// sizes exactly the 2 × 2 box; an odd size spreads 3 texels over the new texels with fractional
/// weights (still a convex combination, so E\[x̃²\] ≥ E\[x̃\]² is preserved). Averages are
/// accumulated in f64 and stored in f32. Level sizes: [`NormalMap::level_size`](super::NormalMap::level_size).
///
/// # Reference
/// \[Dupuy2013\] (LEAN/LEADR-style moment mipmaps); \[Chermain2019\] §4.2.2 (mipmapped moments for the
/// approximate masking).
#[derive(Clone)]
pub struct SlopeMomentPyramid {
    /// Level-0 size (the map's), the unit of [`SlopeMomentPyramid::filtered`]'s arguments.
    width: usize,
    height: usize,
    /// The full chain (`first` = 0).
    chain: MomentPyramid,
}

impl std::fmt::Debug for SlopeMomentPyramid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SlopeMomentPyramid")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("levels", &self.levels())
            .finish_non_exhaustive()
    }
}

impl SlopeMomentPyramid {
    /// The whole chain of a `width × height` map's slopes (the caller passes a valid map).
    pub(crate) fn build(width: usize, height: usize, slopes: &[Vec2]) -> SlopeMomentPyramid {
        SlopeMomentPyramid {
            width,
            height,
            chain: MomentPyramid::build(width, height, slopes),
        }
    }

    /// Number of levels (level 0 = the map, the last level is 1 × 1); the same as
    /// [`NormalMap::levels`](super::NormalMap::levels).
    pub fn levels(&self) -> usize {
        self.chain.levels.len()
    }

    /// The slope moments of every texel of mip level `level` (row major), `None` beyond the last level:
    /// `[E\[x̃\], E\[ỹ\], E\[x̃²\], E\[ỹ²\], E\[x̃ỹ\]]`. The levels are defined in the
    /// [type's docs](SlopeMomentPyramid).
    ///
    /// # Reference
    /// \[Dupuy2013\] (LEAN/LEADR-style moment mipmaps); \[Chermain2019\] §4.2.2 (mipmapped moments for the
    /// approximate masking).
    pub fn level(&self, level: usize) -> Option<&[[f32; 5]]> {
        self.chain.level(level).map(|l| l.data.as_slice())
    }

    /// Trilinearly filtered slope moments around a texel position.
    ///
    /// `center_texel` is in level-0 texel units (any real value: the map tiles); `radius_texels` is the
    /// half-width of the region to average, in level-0 texels. The level of detail is
    /// λ = clamp(log₂(2 · radius), 0, levels − 1) (a region 2^l texels wide matches level l, whose texels
    /// are 2^l level-0 texels wide for power-of-two sizes). Within a level the moments are interpolated
    /// bilinearly between texel centres with wrapping (same convention as the normals: level texel
    /// (i, j) has its centre at (i + ½, j + ½) level texels); between the levels ⌊λ⌋ and ⌈λ⌉ linearly.
    ///
    /// The result is a convex combination of level-0 texel moments, so it is a valid set of moments
    /// (variances E\[x̃²\] − E\[x̃\]² ≥ 0 up to rounding). NaN or non-positive radii select level 0, +∞ the
    /// 1 × 1 level;
    /// a non-finite centre is replaced by 0. See [`moments_mean_covariance`](super::moments_mean_covariance)
    /// to turn the result into a mean slope and a covariance.
    ///
    /// # Reference
    /// \[Chermain2019\] §4.2.2; \[Dupuy2013\] §4.
    pub fn filtered(&self, center_texel: Vec2, radius_texels: f32) -> [f32; 5] {
        self.chain
            .filtered(self.width, self.height, center_texel, radius_texels)
    }
}

/// Area-weighted reduction of one level to `w × h` texels (f64 accumulation, parallel over output rows).
fn downsample(prev: &MomentLevel, w: usize, h: usize) -> MomentLevel {
    let wx = axis_weights(prev.width, w);
    let wy = axis_weights(prev.height, h);
    let mut data = vec![[0.0f32; 5]; w * h];
    data.par_chunks_mut(w).enumerate().for_each(|(oy, row)| {
        let mut acc = vec![[0.0f64; 5]; w];
        for &(iy, wyk) in &wy[oy] {
            let src = &prev.data[iy * prev.width..(iy + 1) * prev.width];
            for (ox, a) in acc.iter_mut().enumerate() {
                for &(ix, wxk) in &wx[ox] {
                    let weight = wxk * wyk;
                    for k in 0..5 {
                        a[k] += src[ix][k] as f64 * weight;
                    }
                }
            }
        }
        for (dst, a) in row.iter_mut().zip(&acc) {
            *dst = a.map(|v| v as f32);
        }
    });
    MomentLevel {
        width: w,
        height: h,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_partition_each_input() {
        for (n, m) in [(8, 4), (5, 2), (7, 3), (3, 1), (1, 1), (9, 4)] {
            let wts = axis_weights(n, m);
            // Each output's weights sum to 1 (a convex combination)…
            for o in &wts {
                let s: f64 = o.iter().map(|p| p.1).sum();
                assert!((s - 1.0).abs() < 1e-12, "{n}->{m}: {s}");
            }
            // …and every input contributes a total of m/n (its area share), so averages are preserved.
            for k in 0..n {
                let s: f64 = wts.iter().flatten().filter(|p| p.0 == k).map(|p| p.1).sum();
                assert!(
                    (s - m as f64 / n as f64).abs() < 1e-12,
                    "{n}->{m} input {k}: {s}"
                );
            }
        }
    }

    #[test]
    fn level_sizes_reach_one() {
        assert_eq!(
            MomentPyramid::level_sizes(5, 2),
            vec![(5, 2), (2, 1), (1, 1)]
        );
        assert_eq!(MomentPyramid::level_sizes(1, 1), vec![(1, 1)]);
        assert_eq!(MomentPyramid::level_sizes(8, 8).len(), 4);
    }
}
