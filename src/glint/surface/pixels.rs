//! Normal maps from decoded pixels: channel slices of 8-bit, 16-bit or float RGB(A) texels, the
//! decoding shared with the image files of `image_io.rs` (feature `image`). Always available, so a
//! renderer that decodes its own images needs no image stack here.
//!
//! Decoding follows what renderers do (pbrt-v4 `NormalMap`, Mitsuba 3 `normalmap`): every channel
//! value c, integer or float, encodes the component n = 2c − 1 ([`FloatEncoding::Encoded`], the
//! default). Float data that store the vector itself are read with [`FloatEncoding::Raw`];
//! [`FloatEncoding::Detect`] picks one of the two only when the data leave no doubt and reports the
//! choice. Alpha is ignored. The decoded vector is normalised (quantisation leaves it slightly off
//! unit length), but a map whose decoded vectors are mostly far from unit length, or mostly below the
//! horizon, is refused ([`Error::ImplausibleNormals`]): it was almost certainly decoded with the wrong
//! encoding. Pixels come in picture order, top row first: the bottom row becomes texel row 0, and the
//! green channel is read according to the [`TangentConvention`] (see the module docs of the normal
//! map).

use super::normal_map::{NormalMap, NormalRepair, TangentConvention, check_repair, repaired_slope};
use crate::{Error, Result};
use glam::{Vec2, Vec3};

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

/// Options of the normal-map decoders: [`NormalMap::from_pixels_u8`] and its `u16` / `f32` forms, and
/// (feature `image`) `NormalMap::from_image_file_with` and `NormalMap::from_image_bytes_with`. `Default` gives
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
    /// The largest image accepted, in texels (width × height, read from a file's header before
    /// anything is decoded, or given with pixel slices); must be ≥ 1. Default
    /// [`DEFAULT_MAX_IMAGE_TEXELS`].
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

/// Checks the options that do not depend on the source: the repair bound, the length tolerance and
/// `max_texels`.
pub(crate) fn check_options(options: &ImageOptions) -> Result<()> {
    check_repair(options.repair)?;
    let tol = options.length_tolerance;
    if tol.is_nan() || tol < 0.0 {
        return Err(Error::InvalidParameter {
            name: "length_tolerance",
            value: tol as f64,
            reason: "must be >= 0 (infinity disables the check)",
        });
    }
    if options.max_texels == 0 {
        return Err(Error::InvalidParameter {
            name: "max_texels",
            value: 0.0,
            reason: "must be at least 1",
        });
    }
    Ok(())
}

/// Decodes RGB channel values c of a `w × h` picture (top row first, integer channels already
/// scaled to [0, 1]) into a map, with the checks of [`NormalMap::from_pixels_u8`]; the options must
/// have passed [`check_options`]. `name` names the source in errors.
pub(crate) fn decode_values(
    values: &[Vec3],
    w: usize,
    h: usize,
    float_channels: bool,
    name: &str,
    options: &ImageOptions,
) -> Result<(NormalMap, ImageDecoding)> {
    let tol = options.length_tolerance;
    let implausible = |reason: String| Error::ImplausibleNormals {
        source_name: name.to_string(),
        reason,
    };
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
        FloatEncoding::Detect => detect(values, tol).map_err(implausible)?,
        e => e,
    };
    let decode = match encoding {
        FloatEncoding::Raw => raw,
        _ => encoded,
    };
    let (off_unit_fraction, max_length_error, below_horizon) = plausibility(values, decode, tol);
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
            let s = repaired_slope(n, options.repair).map_err(|reason| Error::InvalidTexel {
                source_name: name.to_string(),
                x: i,
                y: j,
                reason: format!("{reason} (file pixel column {i}, row {file_row} from the top)"),
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

/// The RGB values of `width × height` pixels of `channels` (3 or 4) interleaved channels, each
/// channel value mapped by `scale`; validated against the options first.
fn pixel_values<T: Copy>(
    width: usize,
    height: usize,
    channels: usize,
    data: &[T],
    options: &ImageOptions,
    scale: impl Fn(T) -> f32,
) -> Result<Vec<Vec3>> {
    check_options(options)?;
    if !(channels == 3 || channels == 4) {
        return Err(Error::InvalidParameter {
            name: "channels",
            value: channels as f64,
            reason: "must be 3 (RGB) or 4 (RGBA, alpha ignored)",
        });
    }
    let bad = |reason| Error::InvalidSize {
        width,
        height,
        reason,
    };
    if width == 0 || height == 0 {
        return Err(bad("width and height must be at least 1"));
    }
    let texels = width
        .checked_mul(height)
        .ok_or(bad("width × height overflows"))?;
    if texels > options.max_texels {
        return Err(bad("more texels than ImageOptions::max_texels"));
    }
    if Some(data.len()) != texels.checked_mul(channels) {
        return Err(bad(
            "the data length does not match width × height × channels",
        ));
    }
    Ok(data
        .chunks_exact(channels)
        .map(|p| Vec3::new(scale(p[0]), scale(p[1]), scale(p[2])))
        .collect())
}

impl NormalMap {
    /// Decodes a normal map from 8-bit pixels: `width × height` texels of `channels` (3: RGB, 4:
    /// RGBA, alpha ignored) interleaved bytes, top row of the picture first (the layout of
    /// [`NormalMap::to_rgb8`] and of decoded PNG files). Each channel is c = value / 255, n = 2c − 1.
    ///
    /// The checks and the decoding are those of image files (module docs): the bottom row becomes
    /// texel row 0 (v = 0), the green channel is read as +v for [`TangentConvention::OpenGl`] and
    /// negated for [`TangentConvention::DirectX`], a map mostly off unit length or below the horizon
    /// is refused, each normal is normalised, repaired per [`ImageOptions::repair`] and converted to
    /// a slope.
    ///
    /// # Reference
    /// Decoding 2c − 1: pbrt-v4 (`NormalMap` lookups in `materials.h`), Mitsuba 3 (`normalmap` BSDF
    /// plugin).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for `channels` other than 3 or 4, a bad `ClampZ` bound, length
    /// tolerance or `max_texels` = 0; [`Error::InvalidSize`] for a zero size, more than
    /// [`ImageOptions::max_texels`] texels or a data length other than width × height × channels;
    /// [`Error::InvalidTexel`] (the texel and the pixel) for a zero normal or one with z ≤ 0 under
    /// [`NormalRepair::Reject`]; [`Error::ImplausibleNormals`] for a map mostly off unit length or
    /// below the horizon.
    pub fn from_pixels_u8(
        width: usize,
        height: usize,
        channels: usize,
        data: &[u8],
        options: &ImageOptions,
    ) -> Result<(NormalMap, ImageDecoding)> {
        let values = pixel_values(width, height, channels, data, options, |c| c as f32 / 255.0)?;
        decode_values(&values, width, height, false, "u8 pixels", options)
    }

    /// Decodes a normal map from 16-bit pixels, c = value / 65535; otherwise as
    /// [`NormalMap::from_pixels_u8`].
    ///
    /// # Errors
    /// As [`NormalMap::from_pixels_u8`].
    pub fn from_pixels_u16(
        width: usize,
        height: usize,
        channels: usize,
        data: &[u16],
        options: &ImageOptions,
    ) -> Result<(NormalMap, ImageDecoding)> {
        let values = pixel_values(width, height, channels, data, options, |c| {
            c as f32 / 65535.0
        })?;
        decode_values(&values, width, height, false, "u16 pixels", options)
    }

    /// Decodes a normal map from float pixels (as decoded from EXR files), according to
    /// [`ImageOptions::float_encoding`] (n = 2c − 1 by default, or the raw vector); otherwise as
    /// [`NormalMap::from_pixels_u8`].
    ///
    /// # Errors
    /// As [`NormalMap::from_pixels_u8`]; also [`Error::InvalidTexel`] for a non-finite value, and
    /// [`Error::ImplausibleNormals`] for [`FloatEncoding::Detect`] when the data do not decide.
    pub fn from_pixels_f32(
        width: usize,
        height: usize,
        channels: usize,
        data: &[f32],
        options: &ImageOptions,
    ) -> Result<(NormalMap, ImageDecoding)> {
        let values = pixel_values(width, height, channels, data, options, |c| c)?;
        decode_values(&values, width, height, true, "f32 pixels", options)
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
