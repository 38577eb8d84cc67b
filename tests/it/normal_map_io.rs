//! Normal maps read as renderers read them: float (EXR) files decoded as n = 2c − 1 by default (pbrt-v4,
//! Mitsuba 3), raw-vector files on request or by conservative detection, implausible maps refused.
//!
//! Every file is written here with the `image` crate from normals drawn here; expected slopes are
//! computed here from those normals (−x/z, −y/z), never by the code under test.
#![cfg(feature = "image")]

use crate::support;

use brdf::glint::{FloatEncoding, ImageOptions, NormalMap, NormalRepair, TangentConvention};
use brdf::{Error, Vec3};
use rand::RngExt;
use std::path::PathBuf;

const W: usize = 8;
const H: usize = 5;

fn tmp_dir() -> PathBuf {
    support::tmp_dir("normal_map_io")
}

/// Unit normals with |slope| components up to `r` (random tilts in every azimuth).
fn normals(n: usize, r: f32, seed: u64) -> Vec<Vec3> {
    let mut rng = support::rng(seed);
    (0..n)
        .map(|_| Vec3::new(rng.random_range(-r..r), rng.random_range(-r..r), 1.0).normalize())
        .collect()
}

/// Writes an RGB float EXR whose texel row j (bottom row = 0) holds `f(normals[j * W + i])`.
fn write_exr(name: &str, normals: &[Vec3], f: impl Fn(Vec3) -> Vec3) -> PathBuf {
    let mut raw = Vec::with_capacity(W * H * 3);
    for file_row in 0..H {
        let j = H - 1 - file_row;
        for i in 0..W {
            raw.extend_from_slice(&f(normals[j * W + i]).to_array());
        }
    }
    let path = tmp_dir().join(name);
    image::Rgb32FImage::from_raw(W as u32, H as u32, raw)
        .unwrap()
        .save(&path)
        .unwrap();
    path
}

fn colour(n: Vec3) -> Vec3 {
    (n + Vec3::ONE) * 0.5
}

fn with_encoding(float_encoding: FloatEncoding) -> ImageOptions {
    ImageOptions {
        float_encoding,
        ..ImageOptions::default()
    }
}

/// Largest distance between the map's texel normals and the expected unit normals.
fn max_normal_error(map: &NormalMap, want: &[Vec3]) -> f32 {
    (0..W * H)
        .map(|k| (map.texel_normal((k % W) as i64, (k / W) as i64) - want[k]).length())
        .fold(0.0, f32::max)
}

/// f32 bound for c = (n + 1)/2 stored and decoded as 2c − 1: each of the two roundings moves a component
/// by at most 2⁻²⁴ (|c| ≤ 1), times 2 for the decode, so ≤ 3·2⁻²³ per component, ≤ √3 · 3·2⁻²³ for the
/// vector; normalising a vector that close to a unit one moves it by at most twice that; plus 1e-7 for
/// the normalisation's own rounding. A wrong decoding is off by more than 0.1.
const ENCODED_TOL: f32 = 2.0 * 1.7321 * 3.0 / 8_388_608.0 + 1e-7;

#[test]
fn encoded_exr_is_decoded_as_two_c_minus_one_by_default() {
    let n = normals(W * H, 0.8, 1);
    let path = write_exr("encoded.exr", &n, colour);
    // `from_image_file` (the default) and `from_image_file_with` (reporting) agree, and the report says what was done.
    let map =
        NormalMap::from_image_file(&path, TangentConvention::OpenGl, NormalRepair::Reject).unwrap();
    let err = max_normal_error(&map, &n);
    assert!(err <= ENCODED_TOL, "{err}");
    let (map2, report) = NormalMap::from_image_file_with(&path, &ImageOptions::default()).unwrap();
    assert_eq!(map.slopes(), map2.slopes());
    assert!(report.float_channels);
    assert_eq!(report.encoding, FloatEncoding::Encoded);
    assert_eq!(report.texels, W * H);
    assert_eq!(report.off_unit_fraction, 0.0);
    assert_eq!(report.below_horizon, 0);
    assert!(report.max_length_error < 1e-5, "{report:?}");
}

#[test]
fn raw_exr_needs_the_raw_option_and_the_default_refuses_it() {
    let n = normals(W * H, 0.8, 2);
    let path = write_exr("raw.exr", &n, |v| v);
    let (map, report) =
        NormalMap::from_image_file_with(&path, &with_encoding(FloatEncoding::Raw)).unwrap();
    assert_eq!(report.encoding, FloatEncoding::Raw);
    // Raw floats are the vector itself: the slope −x/z is exact up to one division's rounding.
    for (k, v) in n.iter().enumerate() {
        let s = map.slopes()[k];
        let want = [-(v.x as f64) / v.z as f64, -(v.y as f64) / v.z as f64];
        assert!(
            (s.x as f64 - want[0]).abs() <= 2e-7 * (1.0 + want[0].abs())
                && (s.y as f64 - want[1]).abs() <= 2e-7 * (1.0 + want[1].abs()),
            "texel {k}: {s} vs {want:?}"
        );
    }
    // Read as the renderers' default (2c − 1), a raw map is far off unit length: refused, with a hint.
    let e =
        NormalMap::from_image_file(&path, TangentConvention::OpenGl, NormalRepair::ClampZ(0.05))
            .unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::ImplausibleNormals { .. }), "{e}");
    assert!(
        msg.contains("raw.exr") && msg.contains("FloatEncoding::Raw"),
        "{msg}"
    );
}

#[test]
fn encoded_exr_read_as_raw_is_refused() {
    // Colours in [0, 1] taken as vectors give normals tilted toward (+x, +y), slopes
    // around (−0.5, −0.5); the lengths (≈ 1.22 for flat texels) give it away.
    let n = normals(W * H, 0.3, 3);
    let path = write_exr("encoded_as_raw.exr", &n, colour);
    let e = NormalMap::from_image_file_with(&path, &with_encoding(FloatEncoding::Raw)).unwrap_err();
    assert!(matches!(e, Error::ImplausibleNormals { .. }), "{e}");
    assert!(e.to_string().contains("FloatEncoding::Encoded"), "{e}");
}

#[test]
fn detection_is_conservative_and_reported() {
    let detect = with_encoding(FloatEncoding::Detect);
    // Raw with negative components: certain.
    let n = normals(W * H, 0.8, 4);
    let p = write_exr("detect_raw_neg.exr", &n, |v| v);
    assert_eq!(
        NormalMap::from_image_file_with(&p, &detect)
            .unwrap()
            .1
            .encoding,
        FloatEncoding::Raw
    );
    // Raw without negative components (a flat map): decided by the lengths (√3 as 2c − 1, 1 raw).
    let flat = vec![Vec3::Z; W * H];
    let p = write_exr("detect_raw_flat.exr", &flat, |v| v);
    let (map, report) = NormalMap::from_image_file_with(&p, &detect).unwrap();
    assert_eq!(report.encoding, FloatEncoding::Raw);
    assert!(map.slopes().iter().all(|s| *s == brdf::Vec2::ZERO));
    // Encoded: decided by the lengths (√1.5 for a flat texel read raw).
    let n = normals(W * H, 0.8, 5);
    let p = write_exr("detect_encoded.exr", &n, colour);
    let (map, report) = NormalMap::from_image_file_with(&p, &detect).unwrap();
    assert_eq!(report.encoding, FloatEncoding::Encoded);
    assert!(max_normal_error(&map, &n) <= ENCODED_TOL);
    // Ambiguous: c = (a, a, b) with |c| = 1 and |2c − 1| = 1 (2a + b = 3/2, 2a² + b² = 1, so
    // a = (6 − √6)/12): both readings are unit vectors, so detection refuses to guess.
    let a = (6.0 - 6f64.sqrt()) / 12.0;
    let b = 1.5 - 2.0 * a;
    let c = Vec3::new(a as f32, a as f32, b as f32);
    assert!((c.length() - 1.0).abs() < 1e-6 && ((2.0 * c - Vec3::ONE).length() - 1.0).abs() < 1e-6);
    let p = write_exr("detect_ambiguous.exr", &vec![Vec3::ZERO; W * H], |_| c);
    let e = NormalMap::from_image_file_with(&p, &detect).unwrap_err();
    assert!(
        matches!(e, Error::ImplausibleNormals { .. }) && e.to_string().contains("both"),
        "{e}"
    );
    // …but an explicit encoding is taken as given.
    assert!(NormalMap::from_image_file_with(&p, &with_encoding(FloatEncoding::Encoded)).is_ok());
    // Neither: vectors of length 3 whichever way they are read.
    let p = write_exr("detect_neither.exr", &flat, |_| Vec3::new(0.0, 0.0, 3.0));
    let e = NormalMap::from_image_file_with(&p, &detect).unwrap_err();
    assert!(e.to_string().contains("neither"), "{e}");
}

#[test]
fn mostly_below_the_horizon_is_refused_even_with_repair() {
    // Unit vectors, so the length test passes; 60 % of them point below the horizon.
    let mut n = normals(W * H, 0.5, 6);
    let below = W * H * 6 / 10;
    for v in n.iter_mut().take(below) {
        v.z = -v.z;
    }
    let p = write_exr("below.exr", &n, colour);
    let repair = ImageOptions {
        repair: NormalRepair::ClampZ(0.1),
        ..ImageOptions::default()
    };
    let e = NormalMap::from_image_file_with(&p, &repair).unwrap_err();
    assert!(
        matches!(e, Error::ImplausibleNormals { .. }) && e.to_string().contains("horizon"),
        "{e}"
    );
    // A minority (40 %) below the horizon is left to the per-texel repair, and counted.
    let mut n = normals(W * H, 0.5, 7);
    let minority = W * H * 4 / 10;
    for v in n.iter_mut().take(minority) {
        v.z = -v.z;
    }
    let p = write_exr("below_minority.exr", &n, colour);
    let (map, report) = NormalMap::from_image_file_with(&p, &repair).unwrap();
    assert_eq!(report.below_horizon, minority);
    assert!((0..W * H).all(|k| map.texel_normal((k % W) as i64, (k / W) as i64).z >= 0.1 - 1e-6));
}

#[test]
fn png_maps_are_checked_too_and_bad_options_are_errors() {
    // An 8-bit picture that is not a normal map (mid-grey: every vector ≈ 0).
    let path = tmp_dir().join("grey_rgb.png");
    image::RgbImage::from_raw(4, 4, vec![128; 48])
        .unwrap()
        .save(&path)
        .unwrap();
    let e = NormalMap::from_image_file(&path, TangentConvention::OpenGl, NormalRepair::ClampZ(0.1))
        .unwrap_err();
    assert!(
        matches!(e, Error::ImplausibleNormals { .. }) && e.to_string().contains("integer"),
        "{e}"
    );
    // Integer channels ignore the float encoding (always 2c − 1).
    let flat = tmp_dir().join("flat.png");
    image::RgbImage::from_raw(2, 2, [128u8, 128, 255].repeat(4))
        .unwrap()
        .save(&flat)
        .unwrap();
    let (_, report) =
        NormalMap::from_image_file_with(&flat, &with_encoding(FloatEncoding::Raw)).unwrap();
    assert!(!report.float_channels);
    assert_eq!(report.encoding, FloatEncoding::Encoded);
    for tol in [f32::NAN, -1.0] {
        let o = ImageOptions {
            length_tolerance: tol,
            ..ImageOptions::default()
        };
        let e = NormalMap::from_image_file_with(&flat, &o).unwrap_err();
        assert!(e.to_string().contains("length_tolerance"), "{e}");
    }
}
