//! Loading normal maps from image files (PNG 8/16-bit RGB(A), EXR float RGB(A)); feature `image`.
//! The `image` crate decodes the file into channel values; everything after that is the decoding of
//! pixel slices (`pixels.rs`), which is always available.
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

use super::normal_map::{NormalMap, NormalRepair, TangentConvention};
#[cfg(doc)]
use super::pixels::{FloatEncoding, MAX_IMPLAUSIBLE_FRACTION};
use super::pixels::{ImageDecoding, ImageOptions, check_options, decode_values};
use crate::{Error, Result};
use glam::Vec3;
use image::DynamicImage;
use std::path::{Path, PathBuf};

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
    /// See [`NormalMap::from_image_bytes_with`] for the decoding; [`NormalMap::from_image_file_with`] takes the
    /// other options and reports what was decoded.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read; otherwise as [`NormalMap::from_image_bytes_with`],
    /// with the path as the name.
    pub fn from_image_file(
        path: impl AsRef<Path>,
        convention: TangentConvention,
        repair: NormalRepair,
    ) -> Result<NormalMap> {
        let options = ImageOptions {
            convention,
            repair,
            ..ImageOptions::default()
        };
        Ok(NormalMap::from_image_file_with(path, &options)?.0)
    }

    /// Loads a normal map from an image file with explicit options, and reports the decoding.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read; otherwise as [`NormalMap::from_image_bytes_with`],
    /// with the path as the name.
    pub fn from_image_file_with(
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
        check_options(options)?;
        let image_err = |reason: String| Error::Image {
            path: PathBuf::from(name),
            reason,
        };
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
        decode_values(&values, w, h, float_channels, name, options)
    }
}
