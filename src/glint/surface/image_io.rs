//! Loading normal maps from image files (PNG 8/16-bit RGB(A), EXR float RGB(A)); feature `image`.
//!
//! Decoding follows what renderers do (pbrt-v4 `NormalMap`, Mitsuba 3 `normalmap`): every channel
//! value c, integer or float, encodes the component n = 2c − 1 ([`FloatEncoding::Encoded`], the
//! default). Float files that store the vector itself are read with [`FloatEncoding::Raw`];
//! [`FloatEncoding::Detect`] picks one of the two only when the file leaves no doubt and reports the
//! choice. Alpha is ignored. The decoded vector is normalised (quantisation leaves it slightly off
//! unit length), but a map whose decoded vectors are mostly far from unit length, or mostly below the
//! horizon, is refused ([`Error::ImplausibleNormals`]): it was almost certainly decoded with the wrong
//! encoding. The bottom row of the file becomes texel row 0 and the green channel is read according to
//! the [`TangentConvention`] (see the module docs of the normal map).

use super::normal_map::{NormalMap, NormalRepair, TangentConvention, check_repair, repaired_slope};
use crate::{Error, Result};
use glam::{Vec2, Vec3};
use image::DynamicImage;
use std::path::{Path, PathBuf};

/// Default tolerance on the length of decoded normals: a texel whose decoded vector has
/// |‖n‖ − 1| > 0.1 counts as "off unit length" (see [`ImageOptions::length_tolerance`]).
///
/// 8-bit quantisation moves a unit vector's length by at most √3/255 ≈ 0.007, so a correctly decoded
/// map is far inside; a map decoded with the wrong encoding is far outside: a raw flat normal
/// (0, 0, 1) read as 2c − 1 has length √3 ≈ 1.73, an encoded flat normal (½, ½, 1) read raw has
/// length √1.5 ≈ 1.22.
pub const DEFAULT_LENGTH_TOLERANCE: f32 = 0.1;

/// The largest fraction of texels that may be off unit length, or below the horizon, before a map is
/// refused as implausible: ½ ("mostly").
pub const MAX_IMPLAUSIBLE_FRACTION: f32 = 0.5;

/// A float channel value below this proves a raw-vector file to [`FloatEncoding::Detect`]: encoded
/// values lie in [0, 1], and filtering or compression of an encoded file does not take them 0.01
/// below 0.
pub const RAW_EVIDENCE_BELOW: f32 = -0.01;

/// Default [`ImageOptions::max_texels`]: 2²⁴ texels (4096², or 8192 × 2048).
///
/// The decoder's own buffer is bounded by the `image` crate's limit (512 MiB), but a decoded map
/// then takes about 20 more bytes per texel in this crate (f32 channels, then slopes), and a
/// compressed file as small as a kilobyte can claim millions of texels (a flat map compresses that
/// well, so the file size proves nothing). At this cap a file costs at most ~340 MiB here plus
/// ≤ 256 MiB of decoding (RGBA f32); larger maps need the cap raised explicitly.
pub const DEFAULT_MAX_IMAGE_TEXELS: usize = 1 << 24;

/// How the channels of a float (EXR) normal map encode the normal. Integer (PNG) channels are always
/// read as c = value / (2^bits − 1), n = 2c − 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum FloatEncoding {
    /// n = 2c − 1, as pbrt-v4 and Mitsuba 3 decode every normal map, float ones included (default).
    #[default]
    Encoded,
    /// n = c: the file stores the vector itself (components in [−1, 1], e.g. written by a tool that
    /// exports raw normals).
    Raw,
    /// Choose from the data: [`FloatEncoding::Raw`] if some channel value is below
    /// [`RAW_EVIDENCE_BELOW`] (impossible for an encoded file); otherwise the one encoding under which
    /// most decoded vectors are unit length (within the tolerance) when the other fails that test.
    /// If both or neither pass, the map is refused with [`Error::ImplausibleNormals`] asking for an
    /// explicit encoding. The choice is reported in [`ImageDecoding::encoding`].
    Detect,
}

/// Options of [`NormalMap::load_with`] and [`NormalMap::from_image_bytes_with`]. `Default` gives
/// OpenGL tangents, [`NormalRepair::Reject`], [`FloatEncoding::Encoded`],
/// [`DEFAULT_LENGTH_TOLERANCE`] and [`DEFAULT_MAX_IMAGE_TEXELS`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageOptions {
    /// Direction of the green channel.
    pub convention: TangentConvention,
    /// What to do with a normal at or below the horizon.
    pub repair: NormalRepair,
    /// Encoding of float channels.
    pub float_encoding: FloatEncoding,
    /// A decoded vector with |‖n‖ − 1| above this counts as off unit length; a map with more than
    /// [`MAX_IMPLAUSIBLE_FRACTION`] of such texels is refused. `f32::INFINITY` disables the check
    /// (for files that store unnormalised vectors on purpose); must not be NaN or negative.
    pub length_tolerance: f32,
    /// The largest image accepted, in texels (width × height, read from the file's header before
    /// anything is decoded); must be ≥ 1. Default [`DEFAULT_MAX_IMAGE_TEXELS`].
    pub max_texels: usize,
}

impl Default for ImageOptions {
    fn default() -> Self {
        ImageOptions {
            convention: TangentConvention::OpenGl,
            repair: NormalRepair::Reject,
            float_encoding: FloatEncoding::Encoded,
            length_tolerance: DEFAULT_LENGTH_TOLERANCE,
            max_texels: DEFAULT_MAX_IMAGE_TEXELS,
        }
    }
}

/// What the decoder did with a file: the encoding used and the statistics it was checked against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDecoding {
    /// Whether the channels were float (EXR) or integer (PNG).
    pub float_channels: bool,
    /// The encoding used: [`FloatEncoding::Encoded`] or [`FloatEncoding::Raw`] (never `Detect`).
    pub encoding: FloatEncoding,
    /// Number of texels.
    pub texels: usize,
    /// Fraction of texels whose decoded vector is off unit length by more than the tolerance.
    pub off_unit_fraction: f32,
    /// Largest |‖n‖ − 1| of any decoded vector.
    pub max_length_error: f32,
    /// Number of texels whose decoded normal has z ≤ 0 (rejected or repaired per
    /// [`ImageOptions::repair`]).
    pub below_horizon: usize,
}

/// Fractions of texels off unit length (by more than `tol`) and below the horizon, and the largest
/// length error, of vectors decoded with `decode`.
fn plausibility(values: &[Vec3], decode: impl Fn(Vec3) -> Vec3, tol: f32) -> (f32, f32, usize) {
    let (mut off, mut below, mut max_err) = (0usize, 0usize, 0.0f32);
    for &c in values {
        let n = decode(c);
        let err = (n.length() - 1.0).abs();
        max_err = max_err.max(err);
        if err > tol {
            off += 1;
        }
        if n.z <= 0.0 {
            below += 1;
        }
    }
    let n = values.len().max(1) as f32;
    (off as f32 / n, max_err, below)
}

#[inline]
fn encoded(c: Vec3) -> Vec3 {
    2.0 * c - Vec3::ONE
}

#[inline]
fn raw(c: Vec3) -> Vec3 {
    c
}

/// The file's channel values c (RGB, alpha dropped) in picture order (top row first), integer
/// channels scaled to [0, 1], and whether they were float. `None` for other colour types.
fn channels(img: &DynamicImage) -> Option<(Vec<Vec3>, bool)> {
    fn collect<P: image::Pixel>(
        i: &image::ImageBuffer<P, Vec<P::Subpixel>>,
        f: impl Fn(&[P::Subpixel]) -> Vec3,
    ) -> Vec<Vec3> {
        i.pixels().map(|p| f(p.channels())).collect()
    }
    let u8c = |p: &[u8]| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0;
    let u16c = |p: &[u16]| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 65535.0;
    let f32c = |p: &[f32]| Vec3::new(p[0], p[1], p[2]);
    Some(match img {
        DynamicImage::ImageRgb8(i) => (collect(i, u8c), false),
        DynamicImage::ImageRgba8(i) => (collect(i, u8c), false),
        DynamicImage::ImageRgb16(i) => (collect(i, u16c), false),
        DynamicImage::ImageRgba16(i) => (collect(i, u16c), false),
        DynamicImage::ImageRgb32F(i) => (collect(i, f32c), true),
        DynamicImage::ImageRgba32F(i) => (collect(i, f32c), true),
        _ => return None,
    })
}

impl NormalMap {
    /// Loads a normal map from a PNG (8- or 16-bit, RGB or RGBA) or EXR (float RGB or RGBA) file with
    /// the default float encoding ([`FloatEncoding::Encoded`], n = 2c − 1, as pbrt-v4 and Mitsuba 3).
    ///
    /// See [`NormalMap::from_image_bytes_with`] for the decoding; [`NormalMap::load_with`] takes the
    /// other options and reports what was decoded.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read; otherwise as [`NormalMap::from_image_bytes_with`],
    /// with the path as the name.
    pub fn load(
        path: impl AsRef<Path>,
        convention: TangentConvention,
        repair: NormalRepair,
    ) -> Result<NormalMap> {
        let options = ImageOptions {
            convention,
            repair,
            ..ImageOptions::default()
        };
        Ok(NormalMap::load_with(path, &options)?.0)
    }

    /// Loads a normal map from an image file with explicit options, and reports the decoding.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read; otherwise as [`NormalMap::from_image_bytes_with`],
    /// with the path as the name.
    pub fn load_with(
        path: impl AsRef<Path>,
        options: &ImageOptions,
    ) -> Result<(NormalMap, ImageDecoding)> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        NormalMap::from_image_bytes_with(&bytes, &path.display().to_string(), options)
    }

    /// Decodes a normal map from the bytes of an image file (format guessed from its content), with
    /// the default options but for the tangent convention and the repair.
    ///
    /// # Errors
    /// As [`NormalMap::from_image_bytes_with`].
    pub fn from_image_bytes(
        bytes: &[u8],
        name: &str,
        convention: TangentConvention,
        repair: NormalRepair,
    ) -> Result<NormalMap> {
        let options = ImageOptions {
            convention,
            repair,
            ..ImageOptions::default()
        };
        Ok(NormalMap::from_image_bytes_with(bytes, name, &options)?.0)
    }

    /// Decodes a normal map from the bytes of an image file, and reports the decoding.
    ///
    /// `name` is used in error messages only (a file name, or a description). The bottom row of the
    /// picture becomes texel row 0 (v = 0); the green channel is read as +v for
    /// [`TangentConvention::OpenGl`] and negated for [`TangentConvention::DirectX`]. Integer channels
    /// are scaled to c = value / (2^bits − 1) ∈ [0, 1] and decoded as n = 2c − 1; float channels
    /// according to [`ImageOptions::float_encoding`]. The map is then checked as a whole: if more than
    /// [`MAX_IMPLAUSIBLE_FRACTION`] of the decoded vectors are off unit length by more than
    /// [`ImageOptions::length_tolerance`], or have z ≤ 0, the file was decoded with the wrong encoding
    /// (or is not a normal map) and is refused. Each normal is then normalised, repaired per
    /// [`ImageOptions::repair`] and converted to a slope. An image of more than
    /// [`ImageOptions::max_texels`] texels is refused from its header, before decoding; memory use
    /// is then at most ~20 bytes per texel here plus the decoder's buffer, which the `image`
    /// crate's default limits also bound (512 MiB).
    ///
    /// # Reference
    /// Decoding 2c − 1 for every format: pbrt-v4 (`NormalMap` lookups in `materials.h`), Mitsuba 3
    /// (`normalmap` BSDF plugin).
    ///
    /// # Errors
    /// [`Error::Image`] (naming `name`) for undecodable bytes, an empty image, an image of more
    /// than [`ImageOptions::max_texels`] texels, or an image that is not RGB/RGBA (e.g. greyscale);
    /// [`Error::InvalidParameter`] for a bad `ClampZ` bound, length tolerance or `max_texels` = 0; [`Error::InvalidTexel`] (naming `name`, the texel and the file pixel) for a
    /// non-finite or zero normal, or one with z ≤ 0 under [`NormalRepair::Reject`];
    /// [`Error::ImplausibleNormals`] (naming `name`, with the statistics and the likely cause) for a
    /// map mostly off unit length or below the horizon, or for [`FloatEncoding::Detect`] when the data
    /// do not decide.
    pub fn from_image_bytes_with(
        bytes: &[u8],
        name: &str,
        options: &ImageOptions,
    ) -> Result<(NormalMap, ImageDecoding)> {
        check_repair(options.repair)?;
        let tol = options.length_tolerance;
        if tol.is_nan() || tol < 0.0 {
            return Err(Error::InvalidParameter {
                name: "length_tolerance",
                value: tol as f64,
                reason: "must be >= 0 (infinity disables the check)",
            });
        }
        let image_err = |reason: String| Error::Image {
            path: PathBuf::from(name),
            reason,
        };
        let implausible = |reason: String| Error::ImplausibleNormals {
            source_name: name.to_string(),
            reason,
        };
        if options.max_texels == 0 {
            return Err(Error::InvalidParameter {
                name: "max_texels",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        let reader = || {
            image::ImageReader::new(std::io::Cursor::new(bytes))
                .with_guessed_format()
                .map_err(|e| image_err(e.to_string()))
        };
        let (w, h) = reader()?
            .into_dimensions()
            .map_err(|e| image_err(e.to_string()))?;
        let texels = w as u64 * h as u64;
        if texels > options.max_texels as u64 {
            return Err(image_err(format!(
                "the image claims {w}×{h} = {texels} texels, more than ImageOptions::max_texels = {} \
                 (raise it to load larger maps)",
                options.max_texels
            )));
        }
        let img = reader()?.decode().map_err(|e| image_err(e.to_string()))?;
        let (w, h) = (img.width() as usize, img.height() as usize);
        if w == 0 || h == 0 {
            return Err(image_err(format!("the image is empty ({w}×{h} pixels)")));
        }
        let Some((values, float_channels)) = channels(&img) else {
            return Err(image_err(format!(
                "not an RGB or RGBA image (colour type {:?}); a normal map needs three channels",
                img.color()
            )));
        };
        drop(img);
        // Non-finite values are a texel error whatever the encoding: report the first one.
        if let Some(k) = values.iter().position(|c| !c.is_finite()) {
            let (i, file_row) = (k % w, k / w);
            return Err(Error::InvalidTexel {
                source_name: name.to_string(),
                x: i,
                y: h - 1 - file_row,
                reason: format!(
                    "non-finite channel values {:?} (file pixel column {i}, row {file_row} from the top)",
                    values[k]
                ),
            });
        }
        let encoding = if float_channels {
            options.float_encoding
        } else {
            FloatEncoding::Encoded
        };
        let encoding = match encoding {
            FloatEncoding::Detect => detect(&values, tol).map_err(implausible)?,
            e => e,
        };
        let decode = match encoding {
            FloatEncoding::Raw => raw,
            _ => encoded,
        };
        let (off_unit_fraction, max_length_error, below_horizon) =
            plausibility(&values, decode, tol);
        let report = ImageDecoding {
            float_channels,
            encoding,
            texels: values.len(),
            off_unit_fraction,
            max_length_error,
            below_horizon,
        };
        let hint = if !float_channels {
            "integer channels always encode n = 2c − 1: is this a normal map?"
        } else if encoding == FloatEncoding::Raw {
            "decoded as raw vectors: if the file stores colours n = 2c − 1, use FloatEncoding::Encoded"
        } else {
            "decoded as n = 2c − 1: if the file stores raw vectors, use FloatEncoding::Raw"
        };
        if off_unit_fraction > MAX_IMPLAUSIBLE_FRACTION {
            return Err(implausible(format!(
                "{:.1} % of the decoded normals are off unit length by more than {tol} (largest \
                 error {max_length_error:.3}); {hint}",
                100.0 * off_unit_fraction
            )));
        }
        let below_fraction = below_horizon as f32 / values.len() as f32;
        if below_fraction > MAX_IMPLAUSIBLE_FRACTION {
            return Err(implausible(format!(
                "{:.1} % of the decoded normals are at or below the horizon (z <= 0); {hint}",
                100.0 * below_fraction
            )));
        }
        let y_sign = options.convention.y_sign();
        let mut slopes: Vec<Vec2> = Vec::with_capacity(w * h);
        for j in 0..h {
            let file_row = h - 1 - j;
            for i in 0..w {
                let n = decode(values[file_row * w + i]);
                let n = Vec3::new(n.x, n.y * y_sign, n.z);
                let s =
                    repaired_slope(n, options.repair).map_err(|reason| Error::InvalidTexel {
                        source_name: name.to_string(),
                        x: i,
                        y: j,
                        reason: format!(
                            "{reason} (file pixel column {i}, row {file_row} from the top)"
                        ),
                    })?;
                slopes.push(s);
            }
        }
        let map = NormalMap::from_slopes(w, h, slopes).map_err(|e| match e {
            Error::InvalidTexel { x, y, reason, .. } => Error::InvalidTexel {
                source_name: name.to_string(),
                x,
                y,
                reason,
            },
            e => e,
        })?;
        Ok((map, report))
    }
}

/// [`FloatEncoding::Detect`]: raw if some value is below [`RAW_EVIDENCE_BELOW`]; otherwise the only
/// encoding under which at most [`MAX_IMPLAUSIBLE_FRACTION`] of the vectors are off unit length.
fn detect(values: &[Vec3], tol: f32) -> std::result::Result<FloatEncoding, String> {
    if values.iter().any(|c| c.min_element() < RAW_EVIDENCE_BELOW) {
        return Ok(FloatEncoding::Raw);
    }
    let (enc_off, _, _) = plausibility(values, encoded, tol);
    let (raw_off, _, _) = plausibility(values, raw, tol);
    let ok = |f: f32| f <= MAX_IMPLAUSIBLE_FRACTION;
    match (ok(enc_off), ok(raw_off)) {
        (true, false) => Ok(FloatEncoding::Encoded),
        (false, true) => Ok(FloatEncoding::Raw),
        (both, _) => Err(format!(
            "cannot detect the float encoding: {} ({:.1} % of the vectors off unit length as \
             n = 2c − 1, {:.1} % as raw vectors); pass FloatEncoding::Encoded or FloatEncoding::Raw",
            if both {
                "both encodings fit"
            } else {
                "neither encoding fits"
            },
            100.0 * enc_off,
            100.0 * raw_off
        )),
    }
}
