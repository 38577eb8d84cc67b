//! Loading normal maps from image files (PNG 8/16-bit RGB(A), EXR float RGB(A)); feature `image`.
//!
//! Decoding: 8- and 16-bit channels c ∈ [0, 1] encode n = 2c − 1; float (EXR) channels are the normal's
//! components as stored. Alpha is ignored. The decoded vector is normalised (quantisation leaves it
//! slightly off unit length). The bottom row of the file becomes texel row 0 and the green channel is
//! read according to the [`TangentConvention`] (see the module docs of the normal map).

use super::normal_map::{NormalMap, NormalRepair, TangentConvention, check_repair, repaired_slope};
use crate::{Error, Result};
use glam::{Vec2, Vec3};
use image::DynamicImage;
use std::path::{Path, PathBuf};

impl NormalMap {
    /// Loads a normal map from a PNG (8- or 16-bit, RGB or RGBA) or EXR (float RGB or RGBA) file.
    ///
    /// See [`NormalMap::from_image_bytes`] for the decoding.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read; otherwise as [`NormalMap::from_image_bytes`], with the
    /// path as the name.
    pub fn load(
        path: impl AsRef<Path>,
        convention: TangentConvention,
        repair: NormalRepair,
    ) -> Result<NormalMap> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        NormalMap::from_image_bytes(&bytes, &path.display().to_string(), convention, repair)
    }

    /// Decodes a normal map from the bytes of an image file (format guessed from its content).
    ///
    /// `name` is used in error messages only (a file name, or a description). The bottom row of the
    /// picture becomes texel row 0 (v = 0); the green channel is read as +v for
    /// [`TangentConvention::OpenGl`] and negated for [`TangentConvention::DirectX`]. Integer channels are
    /// decoded as n = 2c − 1 with c = value / (2^bits − 1); float channels are taken as stored. Each
    /// normal is then normalised and converted to a slope. Memory use while decoding is bounded by the
    /// `image` crate's default limits (512 MiB).
    ///
    /// # Errors
    /// [`Error::Image`] (naming `name`) for undecodable bytes, an empty image, or an image that is not
    /// RGB/RGBA (e.g. greyscale); [`Error::InvalidParameter`] for a bad
    /// `ClampZ` bound; [`Error::InvalidTexel`] (naming `name`, the texel and the file pixel) for a
    /// non-finite or zero normal, or one with z ≤ 0 under [`NormalRepair::Reject`].
    pub fn from_image_bytes(
        bytes: &[u8],
        name: &str,
        convention: TangentConvention,
        repair: NormalRepair,
    ) -> Result<NormalMap> {
        check_repair(repair)?;
        let image_err = |reason: String| Error::Image {
            path: PathBuf::from(name),
            reason,
        };
        let img = image::load_from_memory(bytes).map_err(|e| image_err(e.to_string()))?;
        let (w, h) = (img.width() as usize, img.height() as usize);
        if w == 0 || h == 0 {
            return Err(image_err(format!("the image is empty ({w}×{h} pixels)")));
        }
        let int = |c: u16, max: f32| 2.0 * (c as f32 / max) - 1.0;
        let texel = |x: u32, y: u32| -> Option<Vec3> {
            Some(match &img {
                DynamicImage::ImageRgb8(i) => {
                    let p = i.get_pixel(x, y).0;
                    Vec3::new(
                        int(p[0] as u16, 255.0),
                        int(p[1] as u16, 255.0),
                        int(p[2] as u16, 255.0),
                    )
                }
                DynamicImage::ImageRgba8(i) => {
                    let p = i.get_pixel(x, y).0;
                    Vec3::new(
                        int(p[0] as u16, 255.0),
                        int(p[1] as u16, 255.0),
                        int(p[2] as u16, 255.0),
                    )
                }
                DynamicImage::ImageRgb16(i) => {
                    let p = i.get_pixel(x, y).0;
                    Vec3::new(int(p[0], 65535.0), int(p[1], 65535.0), int(p[2], 65535.0))
                }
                DynamicImage::ImageRgba16(i) => {
                    let p = i.get_pixel(x, y).0;
                    Vec3::new(int(p[0], 65535.0), int(p[1], 65535.0), int(p[2], 65535.0))
                }
                DynamicImage::ImageRgb32F(i) => Vec3::from_array(i.get_pixel(x, y).0),
                DynamicImage::ImageRgba32F(i) => {
                    let p = i.get_pixel(x, y).0;
                    Vec3::new(p[0], p[1], p[2])
                }
                _ => return None,
            })
        };
        if texel(0, 0).is_none() {
            return Err(image_err(format!(
                "not an RGB or RGBA image (colour type {:?}); a normal map needs three channels",
                img.color()
            )));
        }
        let y_sign = convention.y_sign();
        let mut slopes: Vec<Vec2> = Vec::with_capacity(w * h);
        for j in 0..h {
            let file_row = h - 1 - j;
            for i in 0..w {
                let n = texel(i as u32, file_row as u32).unwrap_or(Vec3::Z);
                let n = Vec3::new(n.x, n.y * y_sign, n.z);
                let s = repaired_slope(n, repair).map_err(|reason| Error::InvalidTexel {
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
        NormalMap::from_slopes(w, h, slopes).map_err(|e| match e {
            Error::InvalidTexel { x, y, reason, .. } => Error::InvalidTexel {
                source_name: name.to_string(),
                x,
                y,
                reason,
            },
            e => e,
        })
    }
}
