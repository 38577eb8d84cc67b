//! Normal maps: a tiled grid of per-texel slopes and the bilinearly interpolated surface they define.
//!
//! The texel-space, uv, tangent-frame and image-file conventions are documented once, in the public
//! docs of [`crate::glint`]; read them there.
//!
//! # Reference
//! \[Chermain2019\] §3 (slope representation, interpolated normals); \[Dupuy2013\] (slope moments, mipmaps).

use crate::frame::{normal_to_slope, normalize_robust, slope_to_normal};
use crate::glint::io::format::{self, Kind};
use crate::glint::surface::{MomentPyramid, SlopeMomentPyramid};
use crate::{Error, Result};
use glam::{Vec2, Vec3};

/// The largest slope magnitude a map may hold: |ñ| ≤ 10⁴, i.e. normals at least 10⁻⁴ above the horizon
/// (z ≥ 10⁻⁴, 89.994°). Larger slopes lose all precision in f32 sums of slope moments (x̃² ~ 10⁸ would
/// swamp the other terms) and describe a surface no renderer can shade meaningfully.
pub const MAX_SLOPE: f32 = crate::ndf::MAX_SLOPE;

/// How a normal map file encodes the direction of its green (Y) channel.
///
/// Texel row 0 is the bottom row of the picture (see the [`glint` module docs](crate::glint)), so +v points up in the
/// picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum TangentConvention {
    /// Green = +Y points **up** in the picture (OpenGL, Blender, Unity): taken as is.
    #[default]
    OpenGl,
    /// Green = +Y points **down** in the picture (DirectX, Unreal): the y component is negated on load
    /// (and on export).
    DirectX,
}

impl TangentConvention {
    /// The sign applied to a file's y component to bring it to the crate's tangent frame (+1 or −1).
    #[inline]
    pub fn y_sign(self) -> f32 {
        match self {
            TangentConvention::OpenGl => 1.0,
            TangentConvention::DirectX => -1.0,
        }
    }
}

/// What to do with a normal that is not strictly above the horizon (z ≤ 0).
///
/// Non-finite and zero-length normals are always rejected, whatever the repair.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum NormalRepair {
    /// Fail with [`Error::InvalidTexel`] naming the source and the texel.
    #[default]
    Reject,
    /// Normalise, raise z to at least `min_z` (0 < min_z ≤ 1), keep x and y, then renormalise:
    /// n' = normalize(x, y, max(z, min_z)) with (x, y, z) = n / ‖n‖. Normals already above `min_z` are only renormalised. The
    /// repaired normal keeps the azimuth of the original and its slope magnitude is at most
    /// √(x² + y²) / min_z. Must satisfy `min_z ≥ 1 / MAX_SLOPE` so that repaired slopes stay valid;
    /// at `min_z = 1 / MAX_SLOPE` a horizontal normal gets a slope of exactly [`MAX_SLOPE`] (a
    /// rounding excess is clipped), so every finite non-zero normal is repaired.
    ClampZ(f32),
}

/// A tiled normal map: per-texel slopes (f32) of a bilinearly interpolated surface.
///
/// See the [`glint` module docs](crate::glint) for the texel, uv and tangent-frame conventions. A map
/// holds its size and slopes only (cloning copies the slopes); its slope-moment mip chain is a value
/// of its own, built by [`NormalMap::moment_pyramid`].
#[derive(Clone)]
pub struct NormalMap {
    width: usize,
    height: usize,
    slopes: Vec<Vec2>,
}

impl std::fmt::Debug for NormalMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NormalMap")
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

/// Checks that a map size is usable and returns the texel count.
pub(crate) fn texel_count(width: usize, height: usize, len: usize) -> Result<usize> {
    let bad = |reason| Error::InvalidSize {
        width,
        height,
        reason,
    };
    if width == 0 || height == 0 {
        return Err(bad("width and height must be at least 1"));
    }
    // Texel indices are also handled as i64 (wrapping addressing): keep every size well inside.
    if width > (i32::MAX as usize) || height > (i32::MAX as usize) {
        return Err(bad("width and height must be below 2^31"));
    }
    let n = width
        .checked_mul(height)
        .ok_or(bad("width × height overflows"))?;
    if n != len {
        return Err(bad("the data length does not match width × height"));
    }
    Ok(n)
}

/// The slope of one unit-ish normal, validated (finite, z > 0, |slope| ≤ MAX_SLOPE) after an optional
/// z repair. `Err(reason)` says what is wrong.
///
/// Any non-zero finite vector is accepted, however short or long: its slope −(x, y)/z does not
/// depend on its length, and where the repair needs the unit vector it is normalised by
/// [`normalize_robust`] (scaled by its largest component first, so that a length of 10⁻³⁰ or 10³⁰
/// does not underflow or overflow its square). Under [`NormalRepair::ClampZ`] the slope magnitude is
/// at most √(x² + y²) / min_z ≤ 1 / min_z ≤ [`MAX_SLOPE`] in exact arithmetic, and a rounding excess
/// of a few ulps is clipped back to `MAX_SLOPE`, so that every repaired normal is valid.
pub(crate) fn repaired_slope(n: Vec3, repair: NormalRepair) -> std::result::Result<Vec2, String> {
    if !n.is_finite() {
        return Err(format!("non-finite normal {n:?}"));
    }
    let Some(u) = normalize_robust(n) else {
        return Err("zero-length normal".to_string());
    };
    // The slope −(x, y)/z does not depend on the length: it is taken from `n` itself (exact to one
    // rounding) unless the repair raises z, which needs the unit vector.
    let (n, clamp) = match repair {
        NormalRepair::Reject => (n, false),
        NormalRepair::ClampZ(min_z) if u.z < min_z => (Vec3::new(u.x, u.y, min_z), true),
        NormalRepair::ClampZ(_) => (n, true),
    };
    if n.z <= 0.0 {
        return Err(format!(
            "normal {n:?} is not above the horizon (z <= 0); use NormalRepair::ClampZ to repair it"
        ));
    }
    match normal_to_slope(n) {
        Some(s) if s.length() <= MAX_SLOPE => Ok(s),
        Some(s) if clamp => Ok(clip_to_max_slope(s)),
        _ => Err(format!(
            "normal {n:?} is too close to the horizon (slope magnitude above MAX_SLOPE = {MAX_SLOPE})"
        )),
    }
}

/// `s` scaled to magnitude [`MAX_SLOPE`] (as `f32` computes the length: at most `MAX_SLOPE`).
fn clip_to_max_slope(s: Vec2) -> Vec2 {
    let len = (s.x as f64).hypot(s.y as f64);
    let k = MAX_SLOPE as f64 / len;
    let mut c = Vec2::new((s.x as f64 * k) as f32, (s.y as f64 * k) as f32);
    while c.length() > MAX_SLOPE {
        c *= 1.0 - f32::EPSILON;
    }
    c
}

/// Validates a [`NormalRepair`] parameter.
pub(crate) fn check_repair(repair: NormalRepair) -> Result<()> {
    match repair {
        NormalRepair::Reject => Ok(()),
        NormalRepair::ClampZ(min_z) => {
            if (1.0 / MAX_SLOPE..=1.0).contains(&min_z) {
                Ok(())
            } else {
                Err(Error::InvalidParameter {
                    name: "min_z",
                    value: min_z as f64,
                    reason: "NormalRepair::ClampZ needs 1/MAX_SLOPE <= min_z <= 1",
                })
            }
        }
    }
}

/// normalize(−x̃, −ỹ, 1) for a stored slope (finite, |ñ| ≤ MAX_SLOPE, so 1 + |ñ|² neither overflows nor
/// vanishes): the same value as [`slope_to_normal`] without its fallback checks.
#[inline]
fn unit_normal(s: Vec2) -> Vec3 {
    Vec3::new(-s.x, -s.y, 1.0) / (1.0 + s.length_squared()).sqrt()
}

/// Wraps a texel index into [0, n).
#[inline]
fn wrap(i: i64, n: usize) -> usize {
    i.rem_euclid(n as i64) as usize
}

impl NormalMap {
    /// A map from per-texel slopes (row major, `width * height` entries).
    ///
    /// # Errors
    /// [`Error::InvalidSize`] for a zero size or a length mismatch; [`Error::InvalidTexel`] (source
    /// "slopes") for a non-finite slope or one larger than [`MAX_SLOPE`].
    pub fn from_slopes(width: usize, height: usize, slopes: Vec<Vec2>) -> Result<NormalMap> {
        texel_count(width, height, slopes.len())?;
        for (k, s) in slopes.iter().enumerate() {
            let reason = if !s.is_finite() {
                Some(format!("non-finite slope {s:?}"))
            } else if s.length() > MAX_SLOPE {
                Some(format!(
                    "slope {s:?} larger than MAX_SLOPE = {MAX_SLOPE} (normal too close to the horizon)"
                ))
            } else {
                None
            };
            if let Some(reason) = reason {
                return Err(Error::InvalidTexel {
                    source_name: "slopes".to_string(),
                    x: k % width,
                    y: k / width,
                    reason,
                });
            }
        }
        Ok(NormalMap {
            width,
            height,
            slopes,
        })
    }

    /// A map from per-texel normals (row major; need not be unit length: they are normalised, and
    /// any finite non-zero length is accepted, 10⁻³⁰ and 10³⁰ included).
    ///
    /// Normals with z ≤ 0 are rejected or repaired according to `repair`.
    ///
    /// # Errors
    /// [`Error::InvalidSize`] for a zero size or a length mismatch; [`Error::InvalidParameter`] for a bad
    /// `ClampZ` bound; [`Error::InvalidTexel`] (source "normals") for a non-finite, zero-length or
    /// (with [`NormalRepair::Reject`]) below-horizon normal.
    pub fn from_normals(
        width: usize,
        height: usize,
        normals: &[Vec3],
        repair: NormalRepair,
    ) -> Result<NormalMap> {
        texel_count(width, height, normals.len())?;
        check_repair(repair)?;
        let slopes = normals
            .iter()
            .enumerate()
            .map(|(k, &n)| {
                repaired_slope(n, repair).map_err(|reason| Error::InvalidTexel {
                    source_name: "normals".to_string(),
                    x: k % width,
                    y: k / width,
                    reason,
                })
            })
            .collect::<Result<Vec<Vec2>>>()?;
        NormalMap::from_slopes(width, height, slopes)
    }

    /// A map from a tiled height field (row major), by central differences with wrapping.
    ///
    /// ñ(i, j) = scale · ((h(i+1, j) − h(i−1, j)) / 2, (h(i, j+1) − h(i, j−1)) / 2).
    ///
    /// A height field z = h(u, v) has the normal ∝ (−∂h/∂u, −∂h/∂v, 1), whose slope (−x/z, −y/z) is the
    /// gradient (∂h/∂u, ∂h/∂v): the slope is the height gradient in texel units, times `scale` (heights
    /// are multiplied by `scale` to express them in texel widths). For a 1-texel-wide axis the
    /// difference wraps onto the texel itself and the slope along it is 0.
    ///
    /// # Errors
    /// [`Error::InvalidSize`] for a zero size or a length mismatch; [`Error::InvalidParameter`] for a
    /// non-finite `scale`; [`Error::InvalidTexel`] (source "heights") for a non-finite height or a
    /// resulting slope larger than [`MAX_SLOPE`].
    pub fn from_heights(
        width: usize,
        height: usize,
        heights: &[f32],
        scale: f32,
    ) -> Result<NormalMap> {
        texel_count(width, height, heights.len())?;
        crate::error::finite("scale", scale)?;
        if let Some(k) = heights.iter().position(|h| !h.is_finite()) {
            return Err(Error::InvalidTexel {
                source_name: "heights".to_string(),
                x: k % width,
                y: k / width,
                reason: format!("non-finite height {}", heights[k]),
            });
        }
        let h = |i: i64, j: i64| heights[wrap(j, height) * width + wrap(i, width)] as f64;
        let scale = scale as f64;
        let mut slopes = Vec::with_capacity(heights.len());
        for j in 0..height as i64 {
            for i in 0..width as i64 {
                let dx = 0.5 * (h(i + 1, j) - h(i - 1, j)) * scale;
                let dy = 0.5 * (h(i, j + 1) - h(i, j - 1)) * scale;
                slopes.push(Vec2::new(dx as f32, dy as f32));
            }
        }
        NormalMap::from_slopes(width, height, slopes).map_err(|e| match e {
            Error::InvalidTexel { x, y, reason, .. } => Error::InvalidTexel {
                source_name: "heights".to_string(),
                x,
                y,
                reason,
            },
            e => e,
        })
    }

    /// Width in texels.
    #[inline]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    #[inline]
    pub fn height(&self) -> usize {
        self.height
    }

    /// (width, height) as a `Vec2`, the factor from uv to texel units.
    #[inline]
    pub fn size_f32(&self) -> Vec2 {
        Vec2::new(self.width as f32, self.height as f32)
    }

    /// The stored slopes, row major (`[j * width + i]`).
    #[inline]
    pub fn slopes(&self) -> &[Vec2] {
        &self.slopes
    }

    /// The slope of texel (i, j), with wrapping (any i, j).
    #[inline]
    pub fn texel_slope(&self, i: i64, j: i64) -> Vec2 {
        self.slopes[wrap(j, self.height) * self.width + wrap(i, self.width)]
    }

    /// The unit normal of texel (i, j), with wrapping: normalize(−x̃, −ỹ, 1).
    #[inline]
    pub fn texel_normal(&self, i: i64, j: i64) -> Vec3 {
        unit_normal(self.texel_slope(i, j))
    }

    /// The unnormalised bilinear blend of the four texel normals around the texel position `p`.
    ///
    /// Non-finite coordinates are replaced by 0. The result has z > 0 (a convex combination of
    /// upper-hemisphere unit vectors).
    #[inline]
    fn blended_normal(&self, p: Vec2) -> Vec3 {
        let p = Vec2::select(p.is_finite_mask(), p, Vec2::ZERO);
        // Sample centres are at integer + ½: shift so that they fall on integers.
        let q = p - Vec2::splat(0.5);
        let base = q.floor();
        let f = q - base;
        // Wrap once (`as` saturates huge coordinates, so nothing overflows); the +1 neighbours wrap by
        // a comparison instead of a division.
        let i0 = wrap(base.x as i64, self.width);
        let j0 = wrap(base.y as i64, self.height);
        let i1 = if i0 + 1 == self.width { 0 } else { i0 + 1 };
        let j1 = if j0 + 1 == self.height { 0 } else { j0 + 1 };
        let (r0, r1) = (j0 * self.width, j1 * self.width);
        let n00 = unit_normal(self.slopes[r0 + i0]);
        let n10 = unit_normal(self.slopes[r0 + i1]);
        let n01 = unit_normal(self.slopes[r1 + i0]);
        let n11 = unit_normal(self.slopes[r1 + i1]);
        let bottom = n00 * (1.0 - f.x) + n10 * f.x;
        let top = n01 * (1.0 - f.x) + n11 * f.x;
        bottom * (1.0 - f.y) + top * f.y
    }

    /// The interpolated unit normal at texel position `p` (texel units, any real value: the map tiles).
    ///
    /// n(p) = normalize(Σ w_k n_k) over the four texels whose centres surround p, with bilinear weights
    /// w_k. Equal to the texel's normal at a texel centre; continuous across texel and tile borders.
    /// Non-finite coordinates are replaced by 0.
    ///
    /// # Reference
    /// \[Chermain2019\] §3 (the microsurface is the interpolated normal map).
    #[inline]
    pub fn normal_at_texel(&self, p: Vec2) -> Vec3 {
        self.blended_normal(p).try_normalize().unwrap_or(Vec3::Z)
    }

    /// The slope of the interpolated normal at texel position `p`: (−x/z, −y/z) of
    /// [`NormalMap::normal_at_texel`] (the normalisation cancels, so it is not performed).
    #[inline]
    pub fn slope_at_texel(&self, p: Vec2) -> Vec2 {
        normal_to_slope(self.blended_normal(p)).unwrap_or(Vec2::ZERO)
    }

    /// The interpolated unit normal at `uv` (uv = texel position / (width, height)).
    #[inline]
    pub fn normal_at(&self, uv: Vec2) -> Vec3 {
        self.normal_at_texel(uv * self.size_f32())
    }

    /// The slope of the interpolated normal at `uv`.
    #[inline]
    pub fn slope_at(&self, uv: Vec2) -> Vec2 {
        self.slope_at_texel(uv * self.size_f32())
    }

    /// The map as 8-bit RGB (3 bytes per texel, file order: top row of the picture first), with the usual
    /// encoding c = round(255 (n + 1) / 2) and the y channel written for `convention`. This is the layout
    /// [`NormalMap::from_image_bytes`] decodes (up to quantisation) once written as a PNG.
    pub fn to_rgb8(&self, convention: TangentConvention) -> Vec<u8> {
        let enc = |c: f32| ((c.clamp(-1.0, 1.0) + 1.0) * 127.5).round() as u8;
        let mut out = Vec::with_capacity(self.slopes.len() * 3);
        for row in (0..self.height).rev() {
            for i in 0..self.width {
                let n = slope_to_normal(self.slopes[row * self.width + i]);
                out.extend_from_slice(&[enc(n.x), enc(n.y * convention.y_sign()), enc(n.z)]);
            }
        }
        out
    }

    /// The slope-moment mip chain of the map, built now: O(texels), parallel over rows, owned by the
    /// caller (the map keeps no copy). Its levels and its trilinear lookup
    /// ([`SlopeMomentPyramid::filtered`]) are defined in [`SlopeMomentPyramid`]'s docs.
    ///
    /// Cost: O(texels) time and 20 bytes per texel per level, 26.7 per map texel in all (4/3 × 20:
    /// 28 MB at 1024², 447 MB at 4096²); 17.5 ms at 1024² and 0.30 s at 4096² on 2 cores (criterion,
    /// `cargo bench -p brdf-benches --bench glint -- moment_pyramid`, docs/glint.md).
    /// Build it once and share it between the threads that read it.
    ///
    /// # Reference
    /// \[Dupuy2013\] (LEAN/LEADR-style moment mipmaps); \[Chermain2019\] §4.2.2 (mipmapped moments for the
    /// approximate masking).
    pub fn moment_pyramid(&self) -> SlopeMomentPyramid {
        SlopeMomentPyramid::build(self.width, self.height, &self.slopes)
    }

    /// Number of levels of the slope-moment mip chain (level 0 = the map, the last level is 1 × 1).
    ///
    /// Each level halves both sizes (rounding down, never below 1) until both are 1.
    pub fn levels(&self) -> usize {
        MomentPyramid::level_sizes(self.width, self.height).len()
    }

    /// (width, height) of mip level `level`; `None` beyond the last level.
    pub fn level_size(&self, level: usize) -> Option<(usize, usize)> {
        MomentPyramid::level_sizes(self.width, self.height)
            .get(level)
            .copied()
    }
}

impl NormalMap {
    /// Writes the map in the crate's binary format (docs/format.md): its size and its slopes, exactly
    /// (f32 bits). The moment pyramid is not stored ([`NormalMap::moment_pyramid`] builds it).
    ///
    /// This is not an image: [`NormalMap::to_rgb8`] exports a picture. Wrap files in a
    /// `std::io::BufWriter` or not: the writer already writes in 64 KiB blocks.
    ///
    /// # Errors
    /// [`Error::Stream`] if the writer fails.
    pub fn save(&self, w: &mut impl std::io::Write) -> Result<()> {
        format::save(w, Kind::NormalMap, |e| {
            e.len(self.width)?;
            e.len(self.height)?;
            e.array(self.slopes.iter().map(|s| s.to_array()))
        })
    }

    /// Reads a map written by [`NormalMap::save`]; the slopes are bit-identical to the saved ones.
    /// Image files are decoded by `NormalMap::from_image_file` / `from_image_bytes` (feature
    /// `image`); `save` / `load` are the crate's own binary format, as for every glint model.
    ///
    /// # Errors
    /// [`Error::BadMagic`] (foreign bytes), [`Error::CorruptHeader`] (a damaged header, docs/format.md
    /// "Damaged or unsupported"), [`Error::UnsupportedVersion`], [`Error::WrongModelKind`],
    /// [`Error::Truncated`], [`Error::ChecksumMismatch`], [`Error::Stream`]; [`Error::InvalidFile`]
    /// for a size that is zero, too large or does not match the slope count, and for slopes that
    /// [`NormalMap::from_slopes`] refuses (non-finite or above [`MAX_SLOPE`]).
    pub fn load(r: &mut impl std::io::Read) -> Result<NormalMap> {
        let mut d = format::Decoder::open(r, Kind::NormalMap)?;
        let width = d.len("width", i32::MAX as usize)?;
        let height = d.len("height", i32::MAX as usize)?;
        let n = width.checked_mul(height).ok_or_else(|| {
            format::invalid(format!("width × height = {width} × {height} overflows"))
        })?;
        let slopes = d.array::<f32, 2>("slopes", n)?;
        d.finish()?;
        let slopes = slopes.into_iter().map(Vec2::from_array).collect();
        NormalMap::from_slopes(width, height, slopes)
            .map_err(|e| format::invalid(format!("stored normal map refused: {e}")))
    }
}

/// The mean slope and the 2 × 2 slope covariance of a set of moments
/// `[E\[x̃\], E\[ỹ\], E\[x̃²\], E\[ỹ²\], E\[x̃ỹ\]]`.
///
/// σx² = E\[x̃²\] − E\[x̃\]², σy² = E\[ỹ²\] − E\[ỹ\]², c = E\[x̃ỹ\] − E\[x̃\]E\[ỹ\], computed in f64. Rounding can make a
/// variance slightly negative: variances are clamped at 0 and the correlation is clamped so that the
/// matrix stays positive semi-definite (|c| ≤ σx σy). Adding a minimum roughness (e.g. σ_ε² on the
/// diagonal) is the caller's choice.
///
/// # Reference
/// \[Chermain2019\] eq. 5.
pub fn moments_mean_covariance(m: &[f32; 5]) -> (Vec2, glam::Mat2) {
    let [ex, ey, exx, eyy, exy] = m.map(|v| v as f64);
    let vx = (exx - ex * ex).max(0.0);
    let vy = (eyy - ey * ey).max(0.0);
    let bound = (vx * vy).sqrt();
    let c = (exy - ex * ey).clamp(-bound, bound);
    let mean = Vec2::new(ex as f32, ey as f32);
    let cov = glam::Mat2::from_cols(
        Vec2::new(vx as f32, c as f32),
        Vec2::new(c as f32, vy as f32),
    );
    (mean, cov)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tilted(width: usize, height: usize) -> NormalMap {
        let slopes = (0..width * height)
            .map(|k| Vec2::new((k % width) as f32 * 0.1, (k / width) as f32 * -0.05))
            .collect();
        NormalMap::from_slopes(width, height, slopes).unwrap()
    }

    #[test]
    fn wrapping_addressing() {
        let m = tilted(3, 2);
        assert_eq!(m.texel_slope(-1, 0), m.texel_slope(2, 0));
        assert_eq!(m.texel_slope(3, 5), m.texel_slope(0, 1));
        assert_eq!(m.texel_slope(-7, -3), m.texel_slope(2, 1));
    }

    #[test]
    fn exact_at_texel_centres() {
        let m = tilted(3, 2);
        for j in 0..2 {
            for i in 0..3 {
                let p = Vec2::new(i as f32 + 0.5, j as f32 + 0.5);
                let s = m.slope_at_texel(p);
                // Slope → normal → slope round trip: a few f32 ulps of the slope magnitude (≤ 0.3).
                assert!((s - m.texel_slope(i, j)).length() < 1e-6, "{s} at {p}");
            }
        }
    }

    #[test]
    fn bad_sizes_and_values() {
        assert!(matches!(
            NormalMap::from_slopes(0, 3, vec![]),
            Err(Error::InvalidSize { .. })
        ));
        assert!(NormalMap::from_slopes(2, 2, vec![Vec2::ZERO; 3]).is_err());
        let e =
            NormalMap::from_slopes(2, 1, vec![Vec2::ZERO, Vec2::new(f32::NAN, 0.0)]).unwrap_err();
        assert!(matches!(e, Error::InvalidTexel { x: 1, y: 0, .. }), "{e}");
        let e = NormalMap::from_normals(1, 1, &[Vec3::new(1.0, 0.0, -0.1)], NormalRepair::Reject)
            .unwrap_err();
        assert!(e.to_string().contains("normals"), "{e}");
        let m = NormalMap::from_normals(
            1,
            1,
            &[Vec3::new(1.0, 0.0, -0.1)],
            NormalRepair::ClampZ(0.5),
        )
        .unwrap();
        // Repaired: the unit normal (1, 0, −0.1)/√1.01 gets z = 0.5, so its slope is (−1/√1.01 / 0.5, 0).
        let expected = -1.0 / 1.01f32.sqrt() / 0.5;
        assert!((m.texel_slope(0, 0) - Vec2::new(expected, 0.0)).length() < 1e-6);
        assert!(NormalMap::from_normals(1, 1, &[Vec3::Z], NormalRepair::ClampZ(0.0)).is_err());
        assert!(NormalMap::from_normals(1, 1, &[Vec3::ZERO], NormalRepair::ClampZ(0.5)).is_err());
    }

    #[test]
    fn moments_helper_is_psd() {
        let (mean, cov) = moments_mean_covariance(&[1.0, 2.0, 1.0 - 1e-7, 4.0, 2.5]);
        assert_eq!(mean, Vec2::new(1.0, 2.0));
        assert!(cov.col(0).x >= 0.0 && cov.col(1).y >= 0.0);
        assert!(cov.col(1).x.abs() <= (cov.col(0).x * cov.col(1).y).sqrt() + 1e-12);
    }
}
