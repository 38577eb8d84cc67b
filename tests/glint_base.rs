//! Normal maps, footprints, procedural maps, hemisphere bins and the ground-truth P-NDF.
//!
//! Expected values come from independent formulas written here (f64 bilinear interpolation, plane
//! geometry, closed-form areas), never from the code under test. Each tolerance says where it comes
//! from.

mod support;

use brdf::glint::{NormalMap, NormalRepair, TangentConvention};
use brdf::{Error, Vec2, Vec3};
use rand::RngExt;
use std::path::PathBuf;

/// A temporary directory under target/ for files written by these tests.
fn tmp_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("glint_base");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A map of random slopes (each component uniform in [−r, r]).
fn random_map(width: usize, height: usize, r: f32, seed: u64) -> NormalMap {
    let mut rng = support::rng(seed);
    let slopes = (0..width * height)
        .map(|_| Vec2::new(rng.random_range(-r..r), rng.random_range(-r..r)))
        .collect();
    NormalMap::from_slopes(width, height, slopes).unwrap()
}

/// The interpolated normal written independently in f64: bilinear blend of the four unit normals
/// whose sample centres (i + ½, j + ½) surround p, renormalised.
fn reference_normal(map: &NormalMap, p: [f64; 2]) -> [f64; 3] {
    let (w, h) = (map.width() as i64, map.height() as i64);
    let unit = |i: i64, j: i64| -> [f64; 3] {
        let s = map.slopes()[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize];
        let (x, y) = (-(s.x as f64), -(s.y as f64));
        let l = (x * x + y * y + 1.0).sqrt();
        [x / l, y / l, 1.0 / l]
    };
    let (qx, qy) = (p[0] - 0.5, p[1] - 0.5);
    let (i, j) = (qx.floor() as i64, qy.floor() as i64);
    let (fx, fy) = (qx - qx.floor(), qy - qy.floor());
    let mut b = [0.0; 3];
    for (di, dj, wgt) in [
        (0, 0, (1.0 - fx) * (1.0 - fy)),
        (1, 0, fx * (1.0 - fy)),
        (0, 1, (1.0 - fx) * fy),
        (1, 1, fx * fy),
    ] {
        let n = unit(i + di, j + dj);
        for k in 0..3 {
            b[k] += wgt * n[k];
        }
    }
    let l = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    [b[0] / l, b[1] / l, b[2] / l]
}

fn dist3(a: Vec3, b: [f64; 3]) -> f64 {
    ((a.x as f64 - b[0]).powi(2) + (a.y as f64 - b[1]).powi(2) + (a.z as f64 - b[2]).powi(2)).sqrt()
}

// ---------------------------------------------------------------------------------------------
// Normal maps: interpolation
// ---------------------------------------------------------------------------------------------

#[test]
fn interpolation_matches_an_independent_bilinear_blend() {
    let map = random_map(5, 3, 1.0, 1);
    let mut rng = support::rng(2);
    for _ in 0..2000 {
        // Positions over several tiles, negative ones included.
        let p = [
            rng.random_range(-12.0..12.0f64) as f32 as f64,
            rng.random_range(-7.0..7.0f64) as f32 as f64,
        ];
        let n = map.normal_at_texel(Vec2::new(p[0] as f32, p[1] as f32));
        // f32 arithmetic on O(1) values through a handful of operations: 1e-5 is ~100 ulps.
        assert!(dist3(n, reference_normal(&map, p)) < 1e-5, "at {p:?}");
        assert!((n.length() - 1.0).abs() < 1e-6);
        // uv and texel-space views agree.
        let uv = Vec2::new(p[0] as f32 / 5.0, p[1] as f32 / 3.0);
        assert!((map.normal_at(uv) - n).length() < 1e-5);
        // The slope is the slope of the normal.
        let s = map.slope_at_texel(Vec2::new(p[0] as f32, p[1] as f32));
        assert!((s - Vec2::new(-n.x / n.z, -n.y / n.z)).length() < 1e-4 * (1.0 + s.length()));
    }
}

#[test]
fn interpolation_is_exact_at_texel_centres() {
    let map = random_map(4, 7, 2.0, 3);
    for j in 0..7i64 {
        for i in 0..4i64 {
            let s = map.slope_at_texel(Vec2::new(i as f32 + 0.5, j as f32 + 0.5));
            let t = map.texel_slope(i, j);
            // Slope → normal → slope in f32: a few ulps of slopes of magnitude ≤ 2.9.
            assert!((s - t).length() < 2e-6 * (1.0 + t.length()), "{s} vs {t}");
            // Also at the same centre one tile away in each direction.
            let s2 = map.slope_at_texel(Vec2::new(i as f32 + 0.5 - 4.0, j as f32 + 0.5 + 7.0));
            assert!((s2 - t).length() < 2e-6 * (1.0 + t.length()));
        }
    }
}

#[test]
fn interpolation_is_continuous_across_texel_and_tile_borders() {
    let map = random_map(3, 2, 1.0, 4);
    let eps = 1e-3f32;
    // The normal field is Lipschitz: a step δ changes the blend by ≤ 2δ·max|n_a − n_b| ≤ 4δ and the
    // renormalisation by at most a factor 1/min|blend| ≤ 1/min z ≈ 1.7 (slopes ≤ √2 per texel): 7·2ε.
    let bound = 7.0 * 2.0 * eps;
    // The largest jump between two neighbouring texel normals, to show the bound is meaningful.
    let mut jump = 0.0f32;
    for j in 0..2 {
        for i in 0..3 {
            jump = jump.max((map.texel_normal(i, j) - map.texel_normal(i + 1, j)).length());
        }
    }
    assert!(jump > 10.0 * bound, "test map too smooth: {jump}");
    let mut rng = support::rng(5);
    for _ in 0..500 {
        let y = rng.random_range(0.0..2.0f32);
        // Vertical texel borders x = 0, 1, 2, 3 (x = 0 and 3 are tile borders) and the sample-centre lines.
        for x in [0.0f32, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0] {
            let a = map.normal_at_texel(Vec2::new(x - eps, y));
            let b = map.normal_at_texel(Vec2::new(x + eps, y));
            assert!((a - b).length() < bound, "x = {x}, y = {y}: {a} vs {b}");
        }
        let x = rng.random_range(0.0..3.0f32);
        for y in [0.0f32, 1.0, 2.0] {
            let a = map.normal_at_texel(Vec2::new(x, y - eps));
            let b = map.normal_at_texel(Vec2::new(x, y + eps));
            assert!((a - b).length() < bound, "x = {x}, y = {y}");
        }
    }
    // Tiling: one tile away gives the same normal (up to the f32 rounding of p + size).
    for _ in 0..100 {
        let p = Vec2::new(rng.random_range(0.0..3.0f32), rng.random_range(0.0..2.0f32));
        let a = map.normal_at_texel(p);
        let b = map.normal_at_texel(p + Vec2::new(3.0, -2.0));
        assert!((a - b).length() < 1e-5);
    }
}

#[test]
fn non_finite_positions_do_not_produce_nan() {
    let map = random_map(2, 2, 1.0, 6);
    for p in [
        Vec2::new(f32::NAN, 0.3),
        Vec2::new(f32::INFINITY, f32::NEG_INFINITY),
        Vec2::new(1e30, -1e30),
    ] {
        assert!(map.normal_at_texel(p).is_finite());
        assert!(map.slope_at_texel(p).is_finite());
        assert!(map.normal_at(p).is_finite());
    }
}

#[test]
fn single_texel_map_is_flat() {
    let s = Vec2::new(0.3, -0.2);
    let map = NormalMap::from_slopes(1, 1, vec![s]).unwrap();
    for p in [Vec2::ZERO, Vec2::new(0.37, 0.91), Vec2::new(-5.2, 8.1)] {
        assert!((map.slope_at(p) - s).length() < 1e-6);
    }
}

// ---------------------------------------------------------------------------------------------
// Normal maps: constructors
// ---------------------------------------------------------------------------------------------

#[test]
fn from_heights_gives_the_gradient_of_a_tilted_plane() {
    // h = a x + b y (texel units). Central differences are exact on a plane away from the wrap seam.
    let (a, b, scale) = (0.3f32, -0.7f32, 2.0f32);
    let (w, h) = (8, 6);
    let heights: Vec<f32> = (0..w * h)
        .map(|k| a * (k % w) as f32 + b * (k / w) as f32)
        .collect();
    let map = NormalMap::from_heights(w, h, &heights, scale).unwrap();
    for j in 1..h as i64 - 1 {
        for i in 1..w as i64 - 1 {
            // The surface z = scale·h: its tangent vectors (1, 0, scale·a) and (0, 1, scale·b) must be
            // orthogonal to the normal (plane geometry, independent of the slope convention).
            let n = map.texel_normal(i, j);
            let tx = Vec3::new(1.0, 0.0, scale * a);
            let ty = Vec3::new(0.0, 1.0, scale * b);
            // Heights up to ~5 lose ~1e-6 in f32 differences: 1e-5 on O(1) dot products.
            assert!(n.dot(tx).abs() < 1e-5 && n.dot(ty).abs() < 1e-5, "{n}");
            assert!(n.z > 0.0);
            // The slope is the scaled gradient.
            let s = map.texel_slope(i, j);
            assert!((s - Vec2::new(scale * a, scale * b)).length() < 1e-5, "{s}");
        }
    }
    // The normal leans away from the uphill direction: uphill along +x means n.x < 0.
    assert!(map.texel_normal(3, 3).x < 0.0 && map.texel_normal(3, 3).y > 0.0);
    // Wrapping: on a periodic field h = sin(2π i / w) texel 0 uses h(w − 1) and h(1).
    let per: Vec<f32> = (0..w * h)
        .map(|k| (2.0 * std::f32::consts::PI * (k % w) as f32 / w as f32).sin())
        .collect();
    let map = NormalMap::from_heights(w, h, &per, 1.0).unwrap();
    let expected = 0.5 * ((2.0 * std::f64::consts::PI / w as f64).sin() * 2.0);
    assert!((map.texel_slope(0, 2).x as f64 - expected).abs() < 1e-6);
    assert_eq!(map.texel_slope(0, 2).y, 0.0);
}

#[test]
fn constructors_reject_bad_input() {
    assert!(matches!(
        NormalMap::from_heights(2, 2, &[0.0; 3], 1.0),
        Err(Error::InvalidSize { .. })
    ));
    assert!(matches!(
        NormalMap::from_heights(2, 2, &[0.0, 1.0, f32::NAN, 0.0], 1.0),
        Err(Error::InvalidTexel { x: 0, y: 1, .. })
    ));
    assert!(NormalMap::from_heights(2, 2, &[0.0; 4], f32::INFINITY).is_err());
    // A huge height step gives a slope above MAX_SLOPE.
    assert!(NormalMap::from_heights(3, 1, &[0.0, 0.0, 1e6], 1.0).is_err());
    assert!(NormalMap::from_slopes(1, 1, vec![Vec2::new(2e4, 0.0)]).is_err());
    assert!(matches!(
        NormalMap::from_normals(
            2,
            1,
            &[Vec3::Z, Vec3::new(0.0, 0.0, -1.0)],
            NormalRepair::Reject
        ),
        Err(Error::InvalidTexel { x: 1, y: 0, .. })
    ));
    assert!(
        NormalMap::from_normals(
            1,
            1,
            &[Vec3::new(0.0, f32::NAN, 1.0)],
            NormalRepair::ClampZ(0.1)
        )
        .is_err()
    );
    assert!(NormalMap::from_normals(0, 0, &[], NormalRepair::Reject).is_err());
}

// ---------------------------------------------------------------------------------------------
// Normal maps: image files
// ---------------------------------------------------------------------------------------------

/// Random unit normals with z ≥ 0.3, in texel order.
fn random_normals(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = support::rng(seed);
    (0..n)
        .map(|_| {
            loop {
                let v = Vec3::new(
                    rng.random_range(-1.0..1.0f32),
                    rng.random_range(-1.0..1.0f32),
                    rng.random_range(0.3..1.0f32),
                );
                if v.length() <= 1.0 {
                    break v.normalize();
                }
            }
        })
        .collect()
}

/// Texel row j is picture row (height − 1 − j); the green channel is negated for DirectX.
fn picture_order(
    normals: &[Vec3],
    width: usize,
    height: usize,
    convention: TangentConvention,
) -> Vec<[f32; 3]> {
    let sign = if convention == TangentConvention::DirectX {
        -1.0
    } else {
        1.0
    };
    let mut out = Vec::with_capacity(normals.len());
    for r in 0..height {
        for i in 0..width {
            let n = normals[(height - 1 - r) * width + i];
            out.push([n.x, n.y * sign, n.z]);
        }
    }
    out
}

#[cfg(feature = "image")]
mod images {
    use super::*;

    const W: usize = 7;
    const H: usize = 5;

    fn q8(c: f32) -> u8 {
        ((c + 1.0) * 0.5 * 255.0).round() as u8
    }
    fn q16(c: f32) -> u16 {
        ((c + 1.0) * 0.5 * 65535.0).round() as u16
    }

    #[test]
    fn png8_round_trip_within_quantisation() {
        let normals = random_normals(W * H, 10);
        for (alpha, conv) in [
            (false, TangentConvention::OpenGl),
            (true, TangentConvention::DirectX),
        ] {
            let px = picture_order(&normals, W, H, conv);
            let path = tmp_dir().join(format!("rt8_{alpha}.png"));
            if alpha {
                let raw: Vec<u8> = px
                    .iter()
                    .flat_map(|p| [q8(p[0]), q8(p[1]), q8(p[2]), 200])
                    .collect();
                image::RgbaImage::from_raw(W as u32, H as u32, raw)
                    .unwrap()
                    .save(&path)
                    .unwrap();
            } else {
                let raw: Vec<u8> = px.iter().flat_map(|p| p.map(q8)).collect();
                image::RgbImage::from_raw(W as u32, H as u32, raw)
                    .unwrap()
                    .save(&path)
                    .unwrap();
            }
            let map = NormalMap::load(&path, conv, NormalRepair::Reject).unwrap();
            assert_eq!((map.width(), map.height()), (W, H));
            // Each component is off by ≤ 1/255 after decoding (half a step of 2/255), so the vector
            // error is ≤ √3/255, and normalising at most doubles it for a unit target.
            let tol = 2.0 * 3f32.sqrt() / 255.0 + 1e-6;
            for j in 0..H {
                for i in 0..W {
                    let got = map.texel_normal(i as i64, j as i64);
                    let want = normals[j * W + i];
                    assert!((got - want).length() <= tol, "({i}, {j}): {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn png16_round_trip_within_quantisation() {
        let normals = random_normals(W * H, 11);
        for alpha in [false, true] {
            let px = picture_order(&normals, W, H, TangentConvention::OpenGl);
            let path = tmp_dir().join(format!("rt16_{alpha}.png"));
            if alpha {
                let raw: Vec<u16> = px
                    .iter()
                    .flat_map(|p| [q16(p[0]), q16(p[1]), q16(p[2]), 65535])
                    .collect();
                image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(W as u32, H as u32, raw)
                    .unwrap()
                    .save(&path)
                    .unwrap();
            } else {
                let raw: Vec<u16> = px.iter().flat_map(|p| p.map(q16)).collect();
                image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(W as u32, H as u32, raw)
                    .unwrap()
                    .save(&path)
                    .unwrap();
            }
            let map =
                NormalMap::load(&path, TangentConvention::OpenGl, NormalRepair::Reject).unwrap();
            // As for 8 bits with a step of 2/65535, plus f32 round-off (1e-6).
            let tol = 2.0 * 3f32.sqrt() / 65535.0 + 1e-6;
            for (k, want) in normals.iter().enumerate() {
                let got = map.texel_normal((k % W) as i64, (k / W) as i64);
                assert!((got - *want).length() <= tol, "{k}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn exr_round_trip_is_exact_and_conventions_flip_y() {
        // Non-unit stored vectors on purpose: the slope −x/z does not depend on the length.
        let normals: Vec<Vec3> = random_normals(W * H, 12).iter().map(|n| *n * 1.7).collect();
        let px = picture_order(&normals, W, H, TangentConvention::OpenGl);
        let raw: Vec<f32> = px.iter().flatten().copied().collect();
        let path = tmp_dir().join("rt.exr");
        image::Rgb32FImage::from_raw(W as u32, H as u32, raw)
            .unwrap()
            .save(&path)
            .unwrap();
        // Raw-vector file (not the default 2c − 1 encoding), unnormalised on purpose: length check off.
        let load = |convention| {
            let options = brdf::glint::ImageOptions {
                convention,
                float_encoding: brdf::glint::FloatEncoding::Raw,
                length_tolerance: f32::INFINITY,
                ..Default::default()
            };
            NormalMap::load_with(&path, &options).unwrap().0
        };
        let gl = load(TangentConvention::OpenGl);
        let dx = load(TangentConvention::DirectX);
        for (k, n) in normals.iter().enumerate() {
            let want = Vec2::new(-n.x / n.z, -n.y / n.z);
            assert_eq!(gl.slopes()[k], want, "texel {k}");
            // Reading the same file as DirectX negates the y slope, nothing else.
            assert_eq!(dx.slopes()[k], Vec2::new(want.x, -want.y), "texel {k}");
        }
    }

    #[test]
    fn bottom_picture_row_is_texel_row_zero() {
        // A 1×2 picture: top pixel tilted toward +x (red high), bottom pixel flat.
        let path = tmp_dir().join("rows.png");
        image::RgbImage::from_raw(1, 2, vec![255, 128, 128, 128, 128, 255])
            .unwrap()
            .save(&path)
            .unwrap();
        let map = NormalMap::load(&path, TangentConvention::OpenGl, NormalRepair::Reject).unwrap();
        assert!(
            map.texel_slope(0, 0).length() < 0.01,
            "row 0 = bottom pixel (flat)"
        );
        assert!(
            map.texel_slope(0, 1).x < -0.5,
            "row 1 = top pixel (normal toward +x)"
        );
    }

    #[test]
    fn to_rgb8_is_the_inverse_of_loading() {
        let map = random_map(6, 4, 0.8, 13);
        let rgb = map.to_rgb8(TangentConvention::DirectX);
        let path = tmp_dir().join("export.png");
        image::RgbImage::from_raw(6, 4, rgb)
            .unwrap()
            .save(&path)
            .unwrap();
        let back =
            NormalMap::load(&path, TangentConvention::DirectX, NormalRepair::Reject).unwrap();
        let tol = 2.0 * 3f32.sqrt() / 255.0 + 1e-6; // 8-bit quantisation, as above
        for j in 0..4 {
            for i in 0..6 {
                let d = (back.texel_normal(i, j) - map.texel_normal(i, j)).length();
                assert!(d <= tol, "({i}, {j}): {d}");
            }
        }
    }

    /// A PNG of the given size with an 8-bit RGB IHDR, an empty IDAT and IEND (CRCs computed), for
    /// sizes that encoders refuse to write.
    fn png_rgb8_header_only(width: u32, height: u32) -> Vec<u8> {
        fn crc32(bytes: &[u8]) -> u32 {
            let mut c = 0xFFFF_FFFFu32;
            for &b in bytes {
                c ^= b as u32;
                for _ in 0..8 {
                    c = if c & 1 == 1 {
                        0xEDB8_8320 ^ (c >> 1)
                    } else {
                        c >> 1
                    };
                }
            }
            !c
        }
        let chunk = |kind: &[u8], data: &[u8]| {
            let mut v = (data.len() as u32).to_be_bytes().to_vec();
            let body: Vec<u8> = kind.iter().chain(data).copied().collect();
            v.extend_from_slice(&body);
            v.extend_from_slice(&crc32(&body).to_be_bytes());
            v
        };
        let mut ihdr = width.to_be_bytes().to_vec();
        ihdr.extend_from_slice(&height.to_be_bytes());
        ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        png.extend(chunk(b"IHDR", &ihdr));
        png.extend(chunk(
            b"IDAT",
            &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
        ));
        png.extend(chunk(b"IEND", &[]));
        png
    }

    #[test]
    fn bad_files_give_errors_naming_the_file() {
        let dir = tmp_dir();
        let conv = TangentConvention::OpenGl;
        // Missing file.
        let missing = dir.join("does_not_exist.png");
        let e = NormalMap::load(&missing, conv, NormalRepair::Reject).unwrap_err();
        assert!(
            matches!(e, Error::Io { .. }) && e.to_string().contains("does_not_exist.png"),
            "{e}"
        );
        // Not an image.
        let junk = dir.join("junk.png");
        std::fs::write(&junk, b"this is not a png").unwrap();
        let e = NormalMap::load(&junk, conv, NormalRepair::Reject).unwrap_err();
        assert!(
            matches!(e, Error::Image { .. }) && e.to_string().contains("junk.png"),
            "{e}"
        );
        // Greyscale.
        let grey = dir.join("grey.png");
        image::GrayImage::from_raw(2, 2, vec![1, 2, 3, 4])
            .unwrap()
            .save(&grey)
            .unwrap();
        let e = NormalMap::load(&grey, conv, NormalRepair::Reject).unwrap_err();
        assert!(
            matches!(e, Error::Image { .. }) && e.to_string().contains("grey.png"),
            "{e}"
        );
        // Empty (0 × 0 pixels), written as a valid PNG header with zero width by hand (encoders
        // refuse it): refused by the decoder or by our own check, and the error names the file.
        let empty = dir.join("empty.png");
        std::fs::write(&empty, png_rgb8_header_only(0, 1)).unwrap();
        let e = NormalMap::load(&empty, conv, NormalRepair::Reject).unwrap_err();
        assert!(
            matches!(e, Error::Image { .. }) && e.to_string().contains("empty.png"),
            "{e}"
        );
        // A normal below the horizon (blue = 0 → z = −1) at picture pixel (1, 0) = texel (1, 1).
        let below = dir.join("below.png");
        image::RgbImage::from_raw(
            2,
            2,
            vec![128, 128, 255, 128, 128, 0, 128, 128, 255, 128, 128, 255],
        )
        .unwrap()
        .save(&below)
        .unwrap();
        let e = NormalMap::load(&below, conv, NormalRepair::Reject).unwrap_err();
        assert!(
            matches!(e, Error::InvalidTexel { x: 1, y: 1, .. })
                && e.to_string().contains("below.png"),
            "{e}"
        );
        // …which ClampZ repairs.
        let m = NormalMap::load(&below, conv, NormalRepair::ClampZ(0.2)).unwrap();
        assert!(m.texel_normal(1, 1).z > 0.19);
        // Non-finite EXR values, whatever the repair.
        let nan = dir.join("nan.exr");
        image::Rgb32FImage::from_raw(1, 1, vec![0.0, f32::NAN, 1.0])
            .unwrap()
            .save(&nan)
            .unwrap();
        let e = NormalMap::load(&nan, conv, NormalRepair::ClampZ(0.5)).unwrap_err();
        assert!(
            matches!(e, Error::InvalidTexel { .. }) && e.to_string().contains("nan.exr"),
            "{e}"
        );
        // Empty and truncated bytes.
        assert!(NormalMap::from_image_bytes(&[], "empty", conv, NormalRepair::Reject).is_err());
        image::RgbImage::from_raw(1, 1, vec![128, 128, 255])
            .unwrap()
            .save(dir.join("one.png"))
            .unwrap();
        let good = std::fs::read(dir.join("one.png")).unwrap();
        let e = NormalMap::from_image_bytes(
            &good[..good.len() / 2],
            "half",
            conv,
            NormalRepair::Reject,
        )
        .unwrap_err();
        assert!(e.to_string().contains("half"), "{e}");
    }

    #[test]
    fn mutated_files_never_panic() {
        // A small fuzz run: random byte edits of a valid PNG and EXR decode to Ok or Err, never panic.
        let dir = tmp_dir();
        let p = dir.join("fuzz_base.png");
        image::RgbImage::from_raw(3, 2, (0..18).map(|k| 100 + k as u8).collect())
            .unwrap()
            .save(&p)
            .unwrap();
        let e = dir.join("fuzz_base.exr");
        image::Rgb32FImage::from_raw(2, 2, (0..12).map(|k| 0.1 * k as f32).collect())
            .unwrap()
            .save(&e)
            .unwrap();
        let mut rng = support::rng(14);
        for base in [std::fs::read(&p).unwrap(), std::fs::read(&e).unwrap()] {
            for _ in 0..150 {
                let mut b = base.clone();
                for _ in 0..rng.random_range(1..6) {
                    let k = rng.random_range(0..b.len());
                    b[k] = rng.random();
                }
                let _ = NormalMap::from_image_bytes(
                    &b,
                    "fuzz",
                    TangentConvention::OpenGl,
                    NormalRepair::Reject,
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Normal maps: slope-moment mip chain
// ---------------------------------------------------------------------------------------------

#[test]
fn moment_levels_preserve_the_map_average() {
    for (w, h) in [(8, 8), (5, 3), (7, 1), (1, 6)] {
        let map = random_map(w, h, 1.5, 20 + w as u64);
        // Independent f64 average of the five moments over all texels.
        let mut mean = [0.0f64; 5];
        for s in map.slopes() {
            let (x, y) = (s.x as f64, s.y as f64);
            for (m, v) in mean.iter_mut().zip([x, y, x * x, y * y, x * y]) {
                *m += v / (w * h) as f64;
            }
        }
        let l0 = map.moments(0).unwrap();
        assert_eq!(l0.len(), w * h);
        let s = map.slopes()[1 % (w * h)];
        assert_eq!(l0[1 % (w * h)], [s.x, s.y, s.x * s.x, s.y * s.y, s.x * s.y]);
        assert_eq!(map.level_size(map.levels() - 1), Some((1, 1)));
        assert_eq!(map.level_size(map.levels()), None);
        for l in 0..map.levels() {
            let (lw, lh) = map.level_size(l).unwrap();
            let data = map.moments(l).unwrap();
            assert_eq!(data.len(), lw * lh);
            // Every level is an area-weighted average, so its texel average is the map average
            // (f32 storage of O(1) values: 1e-5).
            for k in 0..5 {
                let avg: f64 = data.iter().map(|m| m[k] as f64).sum::<f64>() / (lw * lh) as f64;
                assert!((avg - mean[k]).abs() < 1e-5, "{w}×{h} level {l} moment {k}");
            }
            // Second moments dominate squared means (a convex combination of point masses).
            for m in data {
                assert!(m[2] >= m[0] * m[0] - 1e-5 && m[3] >= m[1] * m[1] - 1e-5);
            }
        }
    }
}

#[test]
fn filtered_moments_levels_and_interpolation() {
    let map = random_map(8, 8, 1.0, 30);
    let l0 = map.moments(0).unwrap();
    // At a texel centre with a one-texel region: the texel itself.
    let m = map.filtered_moments(Vec2::new(3.5, 2.5), 0.5);
    for k in 0..5 {
        assert!((m[k] - l0[2 * 8 + 3][k]).abs() < 1e-6);
    }
    // Halfway between two level-0 centres: their average.
    let m = map.filtered_moments(Vec2::new(4.0, 2.5), 0.25);
    for k in 0..5 {
        let want = 0.5 * (l0[2 * 8 + 3][k] + l0[2 * 8 + 4][k]);
        assert!((m[k] - want).abs() < 1e-6);
    }
    // A region as large as the map: the 1×1 level, i.e. the map average, anywhere.
    let top = map.moments(map.levels() - 1).unwrap()[0];
    for c in [Vec2::ZERO, Vec2::new(3.3, 7.9), Vec2::new(-100.0, 40.0)] {
        let m = map.filtered_moments(c, 1e6);
        for k in 0..5 {
            assert!((m[k] - top[k]).abs() < 1e-6);
        }
    }
    // Radius 1 (λ = 1): exactly level 1 at a level-1 texel centre (level-1 texel (1, 1) is centred at
    // level-0 position (3, 3)), which is the 2×2 box of level-0 texels (2..4)².
    let m = map.filtered_moments(Vec2::new(3.0, 3.0), 1.0);
    for k in 0..5 {
        let want: f32 = [(2, 2), (3, 2), (2, 3), (3, 3)]
            .iter()
            .map(|&(i, j)| l0[j * 8 + i][k])
            .sum::<f32>()
            / 4.0;
        assert!((m[k] - want).abs() < 1e-6, "{k}");
    }
    // Degenerate arguments stay finite.
    for r in [f32::NAN, -1.0, 0.0, f32::INFINITY] {
        assert!(
            map.filtered_moments(Vec2::new(f32::NAN, 1.0), r)
                .iter()
                .all(|v| v.is_finite())
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Footprints
// ---------------------------------------------------------------------------------------------

mod footprints {
    use super::*;
    use brdf::glint::{Footprint, MAX_ANISOTROPY, MAX_EXTENT_PERIODS, MIN_WIDTH_TEXELS};

    /// (aaᵀ + bbᵀ)/12 in f64, the covariance of a uniform point of the parallelogram (each of the
    /// independent coordinates s, t ~ U[−½, ½] has variance 1/12).
    fn cov_of(a: Vec2, b: Vec2) -> [f64; 3] {
        let (ax, ay, bx, by) = (a.x as f64, a.y as f64, b.x as f64, b.y as f64);
        [
            (ax * ax + bx * bx) / 12.0,
            (ax * ay + bx * by) / 12.0,
            (ay * ay + by * by) / 12.0,
        ]
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-30)
    }

    #[test]
    fn unclamped_views_are_the_differentials() {
        let (w, h) = (300usize, 120usize);
        let mut rng = support::rng(40);
        for _ in 0..200 {
            let uv = Vec2::new(rng.random_range(0.0..1.0f32), rng.random_range(0.0..1.0f32));
            // Edges of 0.5–20 texels at random angles, aspect well below 32.
            let ang = rng.random_range(0.0..6.3f32);
            let len_a = rng.random_range(2.0..20.0f32);
            let len_b = rng.random_range(0.5..1.0f32) * len_a;
            let skew = rng.random_range(0.6..1.5f32);
            let ea = Vec2::new(ang.cos(), ang.sin()) * len_a;
            let eb = Vec2::new(-(ang + skew).sin(), (ang + skew).cos()) * len_b;
            let size = Vec2::new(w as f32, h as f32);
            let f = Footprint::from_differentials(uv, ea / size, eb / size);
            let (c, a, b) = f.parallelogram_texels(w, h);
            // Only f32 rounding of the uv ↔ texel scaling: 1e-5 relative.
            assert!((c - uv * size).length() < 1e-4);
            assert!((a - ea).length() < 1e-5 * len_a && (b - eb).length() < 1e-5 * len_a);
            let det = (ea.x as f64 * eb.y as f64 - ea.y as f64 * eb.x as f64).abs();
            assert!(
                close(f.area_texels(w, h) as f64, det, 1e-5),
                "{} vs {det}",
                f.area_texels(w, h)
            );
            let (gc, cov) = f.gaussian_texels(w, h);
            assert_eq!(gc, c);
            let want = cov_of(ea, eb);
            let scale = want[0].max(want[2]);
            for (got, want) in [
                (cov.col(0).x, want[0]),
                (cov.col(1).x, want[1]),
                (cov.col(1).y, want[2]),
            ] {
                assert!((got as f64 - want).abs() < 1e-5 * scale);
            }
            // Same area in both views: |det[a b]| = 12 √det Σ.
            let det_cov = want[0] * want[2] - want[1] * want[1];
            assert!(close(12.0 * det_cov.sqrt(), det, 1e-9));
            // uv views are the texel views scaled by 1/size.
            let (cu, au, bu) = f.parallelogram_uv(w, h);
            assert_eq!(cu, f.center_uv());
            assert!((au * size - a).length() < 1e-4 && (bu * size - b).length() < 1e-4);
            let (_, cov_uv) = f.gaussian_uv(w, h);
            assert!((cov_uv.col(0).x as f64 * (w * w) as f64 - want[0]).abs() < 1e-5 * scale);
            assert!((cov_uv.col(1).x as f64 * (w * h) as f64 - want[1]).abs() < 1e-5 * scale);
        }
    }

    #[test]
    fn helpers_have_the_requested_area_and_orientation() {
        let (w, h) = (512usize, 256usize);
        for n in [1.0f32, 16.0, 256.0, 4096.0] {
            let f = Footprint::isotropic_texels(Vec2::new(0.3, 0.6), n, w, h);
            // f32 sqrt and products: 1e-5 relative.
            assert!(close(f.area_texels(w, h) as f64, n as f64, 1e-5));
            let (_, cov) = f.gaussian_texels(w, h);
            // A square of side s has Σ = s²/12 I.
            assert!(close(cov.col(0).x as f64, n as f64 / 12.0, 1e-5));
            assert!(close(cov.col(1).y as f64, n as f64 / 12.0, 1e-5));
            assert!(cov.col(1).x.abs() < 1e-6 * n);
        }
        for (aspect, angle) in [(4.0f32, 0.3f32), (10.0, 2.0), (1.5, -1.0)] {
            let area = 100.0;
            let f = Footprint::anisotropic_texels(Vec2::new(0.5, 0.5), area, aspect, angle, w, h);
            assert!(close(f.area_texels(w, h) as f64, area as f64, 1e-5));
            let (major, minor) = f.widths_texels(w, h);
            assert!(close((major / minor) as f64, aspect as f64, 1e-5));
            // The major axis points along `angle`: Σ d = λ1 d with λ1 = major²/12.
            let (_, cov) = f.gaussian_texels(w, h);
            let d = Vec2::new(angle.cos(), angle.sin());
            let sd = cov * d;
            let l1 = major * major / 12.0;
            assert!((sd - d * l1).length() < 1e-4 * l1, "{sd} vs {}", d * l1);
        }
    }

    #[test]
    fn clamps() {
        let (w, h) = (64usize, 32usize);
        // Anisotropy: a 1000:1 needle keeps its major width and gets minor = major / 32.
        let f = Footprint::anisotropic_texels(Vec2::new(0.5, 0.5), 4.0, 1000.0, 0.7, w, h);
        let (major, minor) = f.widths_texels(w, h);
        let want_major = (4.0f32 * 1000.0).sqrt();
        assert!(close(major as f64, want_major as f64, 1e-5));
        assert!(close(
            minor as f64,
            (want_major / MAX_ANISOTROPY) as f64,
            1e-5
        ));
        // The clamped parallelogram still has the clamped Gaussian's covariance and area.
        let (_, a, b) = f.parallelogram_texels(w, h);
        let (_, cov) = f.gaussian_texels(w, h);
        let pc = cov_of(a, b);
        let s = pc[0].max(pc[2]);
        assert!((pc[0] - cov.col(0).x as f64).abs() < 1e-5 * s);
        assert!((pc[1] - cov.col(1).x as f64).abs() < 1e-5 * s);
        assert!((pc[2] - cov.col(1).y as f64).abs() < 1e-5 * s);
        let det = (a.x * b.y - a.y * b.x).abs() as f64;
        assert!(close(det, (major * minor) as f64, 1e-4));
        // Its major axis kept its direction.
        let d = Vec2::new(0.7f32.cos(), 0.7f32.sin());
        assert!(((cov * d) - d * major * major / 12.0).length() < 1e-3 * major * major / 12.0);

        // Minimum extent: a point-like footprint becomes a 0.01-texel square.
        let f = Footprint::isotropic_texels(Vec2::new(0.1, 0.2), 1e-12, w, h);
        let (major, minor) = f.widths_texels(w, h);
        assert!(
            close(major as f64, MIN_WIDTH_TEXELS as f64, 1e-6)
                && close(minor as f64, MIN_WIDTH_TEXELS as f64, 1e-6)
        );
        assert!(close(f.area_texels(w, h) as f64, 1e-4, 1e-5));

        // Maximum extent: 2 × max(w, h) texels along every axis.
        let f = Footprint::from_differentials(Vec2::ZERO, Vec2::new(1e6, 0.0), Vec2::new(0.0, 3e5));
        let (major, minor) = f.widths_texels(w, h);
        let max = MAX_EXTENT_PERIODS * 64.0;
        assert!(close(major as f64, max as f64, 1e-6) && close(minor as f64, max as f64, 1e-6));
    }

    #[test]
    fn degenerate_differentials_fall_back_to_the_minimal_footprint() {
        let (w, h) = (16usize, 16usize);
        let bad = [
            (Vec2::new(f32::NAN, 0.0), Vec2::new(0.0, 0.1)),
            (Vec2::new(0.1, 0.0), Vec2::new(f32::INFINITY, 0.1)),
            (Vec2::ZERO, Vec2::ZERO),
        ];
        for (dx, dy) in bad {
            for uv in [
                Vec2::new(0.5, 0.5),
                Vec2::new(f32::NAN, 0.2),
                Vec2::new(-3.25, 7.5),
            ] {
                let f = Footprint::from_differentials(uv, dx, dy);
                let c = f.center_uv();
                assert!(c.is_finite() && c.cmpge(Vec2::ZERO).all() && c.cmplt(Vec2::ONE).all());
                let (major, minor) = f.widths_texels(w, h);
                assert!(
                    close(major as f64, MIN_WIDTH_TEXELS as f64, 1e-6),
                    "{major}"
                );
                assert!(
                    close(minor as f64, MIN_WIDTH_TEXELS as f64, 1e-6),
                    "{minor}"
                );
                let (gc, cov) = f.gaussian_texels(w, h);
                let (pc, a, b) = f.parallelogram_texels(w, h);
                assert!(gc.is_finite() && pc.is_finite() && a.is_finite() && b.is_finite());
                assert!(cov.determinant() > 0.0 && cov.is_finite());
            }
        }
        // Collinear edges: the minor axis is widened by the anisotropy clamp, not NaN.
        let f = Footprint::from_differentials(
            Vec2::new(0.5, 0.5),
            Vec2::new(0.1, 0.1),
            Vec2::new(0.2, 0.2),
        );
        let (major, minor) = f.widths_texels(w, h);
        assert!(close((major / minor) as f64, MAX_ANISOTROPY as f64, 1e-5));
        // uv wraps into [0, 1).
        let f = Footprint::from_differentials(Vec2::new(-3.25, 7.5), Vec2::ZERO, Vec2::ZERO);
        assert_eq!(f.center_uv(), Vec2::new(0.75, 0.5));
    }
}

// ---------------------------------------------------------------------------------------------
// Procedural maps
// ---------------------------------------------------------------------------------------------

mod procedural {
    use super::*;
    use brdf::glint::{
        BrushedParams, FlakesParams, ScratchedParams, brushed, bumpy, flakes, scratched,
    };

    /// (√E[x̃²], √E[ỹ²]) over the texels, in f64.
    fn rms_xy(map: &NormalMap) -> (f64, f64) {
        let n = map.slopes().len() as f64;
        let (mut a, mut b) = (0.0, 0.0);
        for s in map.slopes() {
            a += (s.x as f64).powi(2);
            b += (s.y as f64).powi(2);
        }
        ((a / n).sqrt(), (b / n).sqrt())
    }

    #[test]
    fn bumpy_has_the_requested_rms_slope() {
        for (w, h, rms, corr, seed) in [
            (256, 256, 0.3f32, 4.0f32, 1u64),
            (384, 200, 0.05, 6.0, 2),
            (256, 256, 1.0, 2.0, 3),
        ] {
            let map = bumpy(w, h, rms, corr, seed).unwrap();
            let (rx, ry) = rms_xy(&map);
            // Combined RMS is exact by construction (f32 rounding only).
            let both = (0.5 * (rx * rx + ry * ry)).sqrt();
            assert!((both / rms as f64 - 1.0).abs() < 1e-4, "{both}");
            // Per axis: the field spans (w/ℓ)(h/ℓ) ≥ 1600 correlation areas, so the relative fluctuation
            // of an axis' mean square is ~ 1/√1600 = 2.5 %, of its RMS half that; 5 % is > 3 σ.
            assert!(
                (rx / rms as f64 - 1.0).abs() < 0.05,
                "{w}×{h}: rms x {rx} vs {rms}"
            );
            assert!(
                (ry / rms as f64 - 1.0).abs() < 0.05,
                "{w}×{h}: rms y {ry} vs {rms}"
            );
            // Mean slope of a periodic height field is 0 (central differences telescope).
            let mean: f64 = map.slopes().iter().map(|s| s.x as f64).sum::<f64>() / (w * h) as f64;
            assert!(mean.abs() < 1e-5, "{mean}");
        }
    }

    #[test]
    fn bumpy_correlation_length_is_honoured() {
        // Height autocorrelation ∝ exp(−r²/ℓ²) means the slope field decorrelates over ~ℓ: the
        // correlation of x̃ between texels ℓ apart along y is exp(−1) ≈ 0.37 for the continuous field
        // (∂²/∂x² of exp(−(x²+y²)/ℓ²) at x = 0 is ∝ exp(−y²/ℓ²)). Allow ±0.1 (sampling of ~64² areas
        // and finite differences).
        let l = 8.0f32;
        let map = bumpy(512, 512, 0.2, l, 9).unwrap();
        let s = map.slopes();
        let (mut c, mut v) = (0.0f64, 0.0f64);
        for j in 0..512usize {
            for i in 0..512usize {
                let a = s[j * 512 + i].x as f64;
                let b = s[((j + l as usize) % 512) * 512 + i].x as f64;
                c += a * b;
                v += a * a;
            }
        }
        let rho = c / v;
        assert!((rho - (-1.0f64).exp()).abs() < 0.1, "ρ(ℓ) = {rho}");
    }

    #[test]
    fn brushed_is_strongly_anisotropic() {
        let p = BrushedParams::default();
        let map = brushed(512, 512, p, 4).unwrap();
        let (rx, ry) = rms_xy(&map);
        assert!((ry / p.rms_slope as f64 - 1.0).abs() < 1e-4, "{ry}");
        // Documented: ratio about 13 with the defaults; require > 8.
        assert!(ry / rx > 8.0, "ratio {}", ry / rx);
    }

    #[test]
    fn flakes_are_piecewise_constant_gaussian_tilts() {
        let p = FlakesParams::default();
        let map = flakes(384, 384, p, 5).unwrap();
        let mut distinct: Vec<[u32; 2]> = map
            .slopes()
            .iter()
            .map(|s| [s.x.to_bits(), s.y.to_bits()])
            .collect();
        distinct.sort_unstable();
        distinct.dedup();
        // 32 × 32 sites; a jittered Voronoi cell is never empty in practice, a few may be.
        assert!(
            distinct.len() > 1000 && distinct.len() <= 1024,
            "{}",
            distinct.len()
        );
        // The sites' slopes are N(0, σ²) per axis: the sample SD of n ≈ 1024 values has a relative
        // standard error 1/√(2n) ≈ 2.2 %; allow 9 % (4 SE).
        let n = distinct.len() as f64;
        let sd = |k: usize| {
            (distinct
                .iter()
                .map(|d| (f32::from_bits(d[k]) as f64).powi(2))
                .sum::<f64>()
                / n)
                .sqrt()
        };
        for k in 0..2 {
            assert!(
                (sd(k) / p.tilt_sigma as f64 - 1.0).abs() < 0.09,
                "axis {k}: {}",
                sd(k)
            );
        }
        // Neighbouring texels mostly share their flake: ~2/12 of horizontal neighbours differ.
        let s = map.slopes();
        let changes = (0..384 * 383).filter(|&k| s[k] != s[k + 1]).count() as f64 / (384.0 * 383.0);
        assert!(changes > 0.05 && changes < 0.3, "{changes}");
    }

    #[test]
    fn scratches_are_bounded_grooves() {
        let p = ScratchedParams {
            base_rms_slope: 0.0,
            ..ScratchedParams::default()
        };
        let map = scratched(256, 256, p, 6).unwrap();
        let mut max = 0.0f32;
        let mut nonzero = 0usize;
        for s in map.slopes() {
            max = max.max(s.x.abs()).max(s.y.abs());
            nonzero += (s.length() > 0.0) as usize;
        }
        // The height is a minimum of profiles with |h'| ≤ max_slope, so it is max_slope-Lipschitz and
        // so is every central difference (+ f32 rounding).
        assert!(
            max <= p.max_slope * (1.0 + 1e-4) && max > 0.3 * p.max_slope,
            "{max}"
        );
        // 40 scratches of mean length 87 texels and width ~3 (+2 texels of differences)
        // cover roughly 40·90·5/65536 ≈ 27 % of the map; overlaps reduce it. Allow 8–40 %.
        let frac = nonzero as f64 / 65536.0;
        assert!(frac > 0.08 && frac < 0.4, "{frac}");
        // No scratches and no base: flat.
        let flat = scratched(
            64,
            64,
            ScratchedParams {
                density: 0.0,
                base_rms_slope: 0.0,
                ..p
            },
            7,
        )
        .unwrap();
        assert!(flat.slopes().iter().all(|s| *s == Vec2::ZERO));
        // With the default base the map is rough everywhere.
        let rough = scratched(128, 128, ScratchedParams::default(), 8).unwrap();
        assert!(rough.slopes().iter().filter(|s| s.length() == 0.0).count() < 10);
    }

    #[test]
    fn generators_are_deterministic_whatever_the_thread_count() {
        let run = || {
            vec![
                bumpy(96, 80, 0.2, 3.0, 11).unwrap(),
                brushed(96, 80, BrushedParams::default(), 11).unwrap(),
                scratched(96, 80, ScratchedParams::default(), 11).unwrap(),
                flakes(96, 80, FlakesParams::default(), 11).unwrap(),
            ]
        };
        let a = run();
        let b = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(run);
        let c = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap()
            .install(run);
        for ((x, y), z) in a.iter().zip(&b).zip(&c) {
            assert_eq!(x.slopes(), y.slopes());
            assert_eq!(x.slopes(), z.slopes());
        }
        // Different seeds differ.
        assert_ne!(
            bumpy(32, 32, 0.2, 3.0, 1).unwrap().slopes(),
            bumpy(32, 32, 0.2, 3.0, 2).unwrap().slopes()
        );
    }

    #[test]
    fn generators_tile() {
        // Across the tile border the slopes are as continuous as inside: compare the mean jump between
        // columns 0 and w−1 with the mean jump between interior neighbours (same statistics ⇒ ratio ≈ 1).
        let map = bumpy(128, 128, 0.2, 6.0, 12).unwrap();
        let s = map.slopes();
        let jump = |i0: usize, i1: usize| -> f64 {
            (0..128)
                .map(|j| (s[j * 128 + i0] - s[j * 128 + i1]).length() as f64)
                .sum::<f64>()
                / 128.0
        };
        let border = jump(127, 0);
        let inner = (1..127).map(|i| jump(i - 1, i)).sum::<f64>() / 126.0;
        assert!(border < 2.0 * inner, "border {border} vs inner {inner}");
    }

    #[test]
    fn generators_reject_bad_parameters() {
        assert!(bumpy(64, 64, 0.0, 4.0, 1).is_err());
        assert!(bumpy(64, 64, f32::NAN, 4.0, 1).is_err());
        assert!(bumpy(64, 64, 0.2, 100.0, 1).is_err());
        assert!(bumpy(0, 64, 0.2, 4.0, 1).is_err());
        assert!(bumpy(1, 1, 0.2, 1.0, 1).is_err());
        assert!(
            brushed(
                64,
                64,
                BrushedParams {
                    width_texels: -1.0,
                    ..Default::default()
                },
                1
            )
            .is_err()
        );
        assert!(
            scratched(
                64,
                64,
                ScratchedParams {
                    curved_fraction: 2.0,
                    ..Default::default()
                },
                1
            )
            .is_err()
        );
        assert!(
            scratched(
                64,
                64,
                ScratchedParams {
                    length_texels: (50.0, 20.0),
                    ..Default::default()
                },
                1
            )
            .is_err()
        );
        assert!(
            flakes(
                64,
                64,
                FlakesParams {
                    cell_texels: 0.0,
                    ..Default::default()
                },
                1
            )
            .is_err()
        );
        assert!(
            flakes(
                64,
                64,
                FlakesParams {
                    tilt_sigma: f32::INFINITY,
                    ..Default::default()
                },
                1
            )
            .is_err()
        );
    }

    /// 4096² of each generator in seconds (run: `cargo test --release --test glint_base -- --ignored
    /// big_maps --nocapture`); the timed figures are in benches/glint.rs.
    #[test]
    #[ignore]
    fn big_maps() {
        let t = std::time::Instant::now();
        bumpy(4096, 4096, 0.2, 8.0, 1).unwrap();
        println!("bumpy 4096²: {:?}", t.elapsed());
        let t = std::time::Instant::now();
        brushed(4096, 4096, BrushedParams::default(), 1).unwrap();
        println!("brushed 4096²: {:?}", t.elapsed());
        let t = std::time::Instant::now();
        scratched(4096, 4096, ScratchedParams::default(), 1).unwrap();
        println!("scratched 4096²: {:?}", t.elapsed());
        let t = std::time::Instant::now();
        flakes(4096, 4096, FlakesParams::default(), 1).unwrap();
        println!("flakes 4096²: {:?}", t.elapsed());
    }
}

// ---------------------------------------------------------------------------------------------
// Hemisphere bins
// ---------------------------------------------------------------------------------------------

mod bins {
    use super::*;
    use brdf::glint::HemisphereBins;

    /// Uniform directions on the hemisphere written here (Archimedes: z uniform in [0, 1]).
    fn uniform_dir(rng: &mut impl rand::Rng) -> Vec3 {
        let z: f64 = rng.random();
        let phi = std::f64::consts::TAU * rng.random::<f64>();
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32)
    }

    #[test]
    fn bins_have_equal_solid_angle_and_exact_mean_cosine() {
        for n in [8usize, 7] {
            let bins = HemisphereBins::new(n).unwrap();
            assert_eq!(bins.len(), n * n);
            assert!((bins.solid_angle() * (n * n) as f64 - std::f64::consts::TAU).abs() < 1e-12);
            let mut rng = support::rng(50 + n as u64);
            let total = 10_000 * n * n;
            let mut count = vec![0usize; n * n];
            let mut zsum = vec![0.0f64; n * n];
            for _ in 0..total {
                let w = uniform_dir(&mut rng);
                let b = bins.bin_of(w).unwrap();
                count[b] += 1;
                zsum[b] += w.z as f64;
            }
            for b in 0..n * n {
                // Binomial count with mean 10⁴ and SD ≤ 100: 5 SD = 500 (failure odds ~1e-5 over the bins).
                assert!(
                    (count[b] as f64 - 10_000.0).abs() < 500.0,
                    "n = {n}, bin {b}: {}",
                    count[b]
                );
                // Sample mean of z in the bin: SD of z within a bin ≤ 0.2, SE ≤ 0.002; 5 SE.
                let mean = zsum[b] / count[b] as f64;
                assert!(
                    (mean - bins.mean_cos(b)).abs() < 0.01,
                    "bin {b}: {mean} vs {}",
                    bins.mean_cos(b)
                );
            }
            // Projected solid angle of the hemisphere: Σ ΔΩ · mean cos = π (exact integration).
            let proj: f64 = (0..n * n)
                .map(|b| bins.mean_cos(b) * bins.solid_angle())
                .sum();
            assert!((proj - std::f64::consts::PI).abs() < 1e-12, "{proj}");
        }
    }

    #[test]
    fn bins_are_a_bijection_with_the_square_cells() {
        for n in [1usize, 2, 5, 16, 33] {
            let bins = HemisphereBins::new(n).unwrap();
            for b in 0..bins.len() {
                for a in [0.05f32, 0.3, 0.5, 0.7, 0.95] {
                    for c in [0.05f32, 0.5, 0.95] {
                        let w = bins.sample_in_bin(b, Vec2::new(a, c));
                        assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= 0.0);
                        assert_eq!(bins.bin_of(w), Some(b), "n = {n}, bin {b}, u = ({a}, {c})");
                    }
                }
                assert_eq!(bins.bin_of(bins.center(b)), Some(b));
            }
        }
        // Odd n: the pole is the centre of the central bin.
        let bins = HemisphereBins::new(7).unwrap();
        assert_eq!(bins.bin_of(Vec3::Z), Some(3 * 7 + 3));
        assert!((bins.center(3 * 7 + 3) - Vec3::Z).length() < 1e-6);
        // Invalid directions.
        assert_eq!(bins.bin_of(Vec3::new(0.0, 0.0, -1.0)), None);
        assert_eq!(bins.bin_of(Vec3::ZERO), None);
        assert_eq!(bins.bin_of(Vec3::new(f32::NAN, 0.0, 1.0)), None);
        assert!(
            bins.bin_of(Vec3::X).is_some(),
            "horizon directions belong to boundary bins"
        );
        assert!(HemisphereBins::new(0).is_err() && HemisphereBins::new(5000).is_err());
    }
}

// ---------------------------------------------------------------------------------------------
// Ground truth
// ---------------------------------------------------------------------------------------------

mod reference {
    use super::*;
    use brdf::glint::{
        BinnedPndf, Footprint, HemisphereBins, Kernel, binned_pndf, bumpy, flakes, naive_brdf,
        tv_distance,
    };
    use brdf::ndf::{Ndf, SlopeGaussian};

    /// A piecewise-constant NDF read from a reference (d only; enough for tv_distance).
    struct Tabulated<'a>(&'a BinnedPndf);
    impl Ndf for Tabulated<'_> {
        fn d(&self, m: Vec3) -> f32 {
            self.0.d_at(m) as f32
        }
        fn lambda(&self, _w: Vec3) -> f32 {
            0.0
        }
        fn sample_normal(&self, _u: Vec2) -> Vec3 {
            Vec3::Z
        }
        fn sample_visible(&self, _wo: Vec3, _u: Vec2) -> Vec3 {
            Vec3::Z
        }
    }

    /// D = 1/π: the "Lambertian" NDF (∫ cos/π dω = 1).
    struct Uniform;
    impl Ndf for Uniform {
        fn d(&self, m: Vec3) -> f32 {
            if m.z > 0.0 {
                std::f32::consts::FRAC_1_PI
            } else {
                0.0
            }
        }
        fn lambda(&self, _w: Vec3) -> f32 {
            0.0
        }
        fn sample_normal(&self, _u: Vec2) -> Vec3 {
            Vec3::Z
        }
        fn sample_visible(&self, _wo: Vec3, _u: Vec2) -> Vec3 {
            Vec3::Z
        }
    }

    fn check_normalised(r: &BinnedPndf) {
        let dw = r.bins().solid_angle();
        let s: f64 = r
            .d()
            .iter()
            .zip(r.cos_theta())
            .map(|(d, c)| d * c * dw)
            .sum();
        // Σ mass = 1 by construction; the f64 sum of up to 4096 terms rounds at ~1e-13.
        assert!((s - 1.0).abs() < 1e-12, "Σ D cos ΔΩ = {s}");
        let m: f64 = r.mass().iter().sum();
        assert!((m - 1.0).abs() < 1e-12);
        for (b, &c) in r.cos_theta().iter().enumerate() {
            assert!(c > 0.0 && c <= 1.0, "bin {b}: cos {c}");
        }
    }

    #[test]
    fn flat_map_puts_all_mass_in_the_bin_of_its_normal() {
        let s0 = Vec2::new(0.4, -0.25);
        let map = NormalMap::from_slopes(8, 8, vec![s0; 64]).unwrap();
        let n0 = brdf::frame::slope_to_normal(s0);
        let bins = HemisphereBins::new(32).unwrap();
        for kernel in [Kernel::Gaussian, Kernel::Parallelogram] {
            let f = Footprint::isotropic_texels(Vec2::new(0.3, 0.7), 16.0, 8, 8);
            let r = binned_pndf(&map, &f, kernel, &bins, 20_000, 1);
            let b0 = bins.bin_of(n0).unwrap();
            assert_eq!(r.mass()[b0], 1.0);
            // D = 1/(cos θ0 ΔΩ) in that bin (f32 normal → 1e-6 relative).
            let want = 1.0 / (n0.z as f64 * bins.solid_angle());
            assert!((r.d()[b0] / want - 1.0).abs() < 1e-6);
            assert!((r.cos_theta()[b0] - n0.z as f64).abs() < 1e-6);
            assert_eq!(r.std_error()[b0], 0.0);
            check_normalised(&r);
            // The uniform NDF against a Dirac: TV = 1 − its mass in that bin, ΔΩ · mean cos / π (exact
            // bin integral), if its total mass is 1. tv_distance's midpoint grid errs on the total by
            // ~1e-4 at k = 4 (measured); the error falls as k⁻² for the smooth cos/π, so k = 64 brings it
            // to ~5e-7: tolerance 5e-6.
            let tv = tv_distance(&Uniform, &r, 64 * 64);
            let want = 1.0 - bins.solid_angle() * bins.mean_cos(b0) / std::f64::consts::PI;
            assert!((tv - want).abs() < 5e-6, "{tv} vs {want}");
            let coarse = tv_distance(&Uniform, &r, 16);
            assert!((coarse - want).abs() < 1e-3, "{coarse} vs {want}");
        }
    }

    #[test]
    fn reference_is_normalised_and_deterministic() {
        let map = bumpy(64, 48, 0.35, 4.0, 3).unwrap();
        let bins = HemisphereBins::new(24).unwrap();
        let f = Footprint::anisotropic_texels(Vec2::new(0.2, 0.9), 300.0, 3.0, 0.4, 64, 48);
        for kernel in [Kernel::Gaussian, Kernel::Parallelogram] {
            let r = binned_pndf(&map, &f, kernel, &bins, 100_000, 7);
            check_normalised(&r);
            assert_eq!(r.samples(), 16 * 79 * 79);
            let again = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap()
                .install(|| binned_pndf(&map, &f, kernel, &bins, 100_000, 7));
            assert_eq!(r.d(), again.d());
            assert_eq!(r.mass(), again.mass());
            let other_seed = binned_pndf(&map, &f, kernel, &bins, 100_000, 8);
            assert_ne!(r.mass(), other_seed.mass());
            // Different seeds agree within the noise floor (two independent estimates: √2 × each).
            let tv = r.tv_to(&other_seed).unwrap();
            assert!(
                tv < 4.0 * (r.tv_error() + other_seed.tv_error()),
                "{tv} vs {}",
                r.tv_error()
            );
        }
    }

    #[test]
    fn reference_converges() {
        // Error against a 64× denser run; for plain Monte Carlo it halves when the samples ×4 (stratified
        // sampling may do better). 0.6 leaves room for the dense run's own error (1/8 of the coarse one).
        let map = bumpy(64, 64, 0.3, 4.0, 5).unwrap();
        let bins = HemisphereBins::new(16).unwrap();
        let f = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 256.0, 64, 64);
        for kernel in [Kernel::Gaussian, Kernel::Parallelogram] {
            let n = 16 * 32 * 32;
            let dense = binned_pndf(&map, &f, kernel, &bins, 64 * n, 100);
            let r1 = binned_pndf(&map, &f, kernel, &bins, n, 1);
            let r4 = binned_pndf(&map, &f, kernel, &bins, 4 * n, 2);
            let (e1, e4) = (r1.tv_to(&dense).unwrap(), r4.tv_to(&dense).unwrap());
            eprintln!(
                "{kernel:?}: error {e1:.2e} → {e4:.2e}; estimated {:.2e} → {:.2e}",
                r1.tv_error(),
                r4.tv_error()
            );
            assert!(e4 < 0.6 * e1, "{kernel:?}: {e1} → {e4}");
            // The reported noise floor predicts the actual error within a factor 2 (the batch estimate
            // of each bin's SE has ~18 % error; summed over ~100 occupied bins it averages out).
            for (e, r) in [(e1, &r1), (e4, &r4)] {
                let ratio = e / r.tv_error();
                assert!(
                    ratio > 0.5 && ratio < 2.0,
                    "{kernel:?}: actual {e} vs estimated {}",
                    r.tv_error()
                );
            }
        }
    }

    #[test]
    fn kernels_differ_and_footprint_size_matters() {
        // The whole map seen through a big footprint vs. one texel: the small footprint concentrates
        // the mass (lower entropy), the big one spreads it. Both views of the same footprint agree
        // closely for large footprints (same mean and covariance over a statistically uniform field).
        let map = bumpy(64, 64, 0.3, 3.0, 6).unwrap();
        let bins = HemisphereBins::new(16).unwrap();
        let big = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 4096.0, 64, 64);
        let small = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 1.0, 64, 64);
        let g = binned_pndf(&map, &big, Kernel::Gaussian, &bins, 400_000, 1);
        let p = binned_pndf(&map, &big, Kernel::Parallelogram, &bins, 400_000, 1);
        let s = binned_pndf(&map, &small, Kernel::Gaussian, &bins, 400_000, 1);
        let occupied = |r: &BinnedPndf| r.mass().iter().filter(|&&m| m > 1e-3).count();
        assert!(
            occupied(&s) * 3 < occupied(&g),
            "{} vs {}",
            occupied(&s),
            occupied(&g)
        );
        let tv_gp = g.tv_to(&p).unwrap();
        let tv_gs = g.tv_to(&s).unwrap();
        eprintln!(
            "occupied {} vs {}; tv gauss/para {tv_gp:.3}, big/small {tv_gs:.3}",
            occupied(&s),
            occupied(&g)
        );
        assert!(tv_gp < 0.1 && tv_gs > 0.5, "{tv_gp} {tv_gs}");
    }

    #[test]
    fn tv_distance_of_the_reference_to_itself_and_to_other_maps() {
        let bins = HemisphereBins::new(32).unwrap();
        let a = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
        let b = flakes(64, 64, brdf::glint::FlakesParams::default(), 1).unwrap();
        let f = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 1024.0, 64, 64);
        let ra = binned_pndf(&a, &f, Kernel::Gaussian, &bins, 200_000, 1);
        let rb = binned_pndf(&b, &f, Kernel::Gaussian, &bins, 200_000, 1);
        // Itself, as a piecewise-constant model: the only difference is the cosine inside each bin
        // (grid mean vs the samples' harmonic mean). Over a bin of width ~2/32 in the square the cosine
        // varies by ≤ 0.1 (slope of z = 1 − r² is ≤ 2 per unit of the square, cell side 1/32 → Δz ≤
        // 0.0625 per axis); relative to cos ≥ 0.5 (where almost all mass of this map lies) ≤ 0.2 and
        // only the within-bin *mean* differences enter, bounded by half of it: TV ≤ ½ · 0.1.
        let self_tv = tv_distance(&Tabulated(&ra), &ra, 16);
        assert!(self_tv < 0.05, "{self_tv}");
        // Two different maps are far apart, far above the noise floor.
        let cross = tv_distance(&Tabulated(&rb), &ra, 16);
        assert!(cross > 0.3 && cross > 20.0 * ra.tv_error(), "{cross}");
        assert!((cross - ra.tv_to(&rb).unwrap()).abs() < 0.1);
        // A Gaussian slope lobe with the map's texel moments approximates a large footprint of a
        // Gaussian field; the same lobe twice as wide does not.
        let big = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 4096.0, 64, 64);
        let r = binned_pndf(&a, &big, Kernel::Gaussian, &bins, 400_000, 2);
        let m = a.moments(a.levels() - 1).unwrap()[0];
        let fit = SlopeGaussian::from_moments(m, 0.01);
        let wide =
            SlopeGaussian::from_moments([m[0], m[1], 4.0 * m[2], 4.0 * m[3], 4.0 * m[4]], 0.01);
        let (t_fit, t_wide) = (tv_distance(&fit, &r, 16), tv_distance(&wide, &r, 16));
        eprintln!(
            "self {self_tv:.4}, cross {cross:.3}, fit {t_fit:.3}, wide {t_wide:.3}, floor {:.4}",
            ra.tv_error()
        );
        assert!(
            t_fit < 0.15 && t_wide > 2.0 * t_fit,
            "fit {t_fit}, wide {t_wide}"
        );
    }

    /// Beckmann Λ for α, written here in f64 (Walter 2007 eq. 27 / Heitz 2014 eq. 72).
    fn beckmann_lambda(alpha: f64, w: Vec3) -> f64 {
        let cos = w.z as f64;
        let tan = (1.0 - cos * cos).max(0.0).sqrt() / cos;
        if tan == 0.0 {
            return 0.0;
        }
        let a = 1.0 / (alpha * tan);
        0.5 * (libm::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt())
    }

    #[test]
    fn naive_brdf_on_a_flat_map_is_the_beckmann_brdf() {
        let map = NormalMap::from_slopes(2, 2, vec![Vec2::ZERO; 4]).unwrap();
        let sigma = 0.2f64;
        let alpha = 2f64.sqrt() * sigma;
        for (to, po, ti, pi) in [
            (30.0, 0.0, 30.0, 180.0),
            (60.0, 20.0, 10.0, 150.0),
            (75.0, 90.0, 70.0, 270.0),
            (0.0, 0.0, 20.0, 45.0),
        ] {
            let (wo, wi) = (support::dir(to, po), support::dir(ti, pi));
            let f = naive_brdf(&map, Vec2::new(0.3, 0.3), wo, wi, sigma as f32) as f64;
            let h = (wo + wi).normalize();
            let (ch, cht) = (
                h.z as f64,
                (1.0 - (h.z as f64).powi(2)) / (h.z as f64).powi(2),
            );
            let d = (-cht / (alpha * alpha)).exp()
                / (std::f64::consts::PI * alpha * alpha * ch.powi(4));
            let g = 1.0 / (1.0 + beckmann_lambda(alpha, wo)) / (1.0 + beckmann_lambda(alpha, wi));
            let want = d * g / (4.0 * wo.z as f64 * wi.z as f64);
            // f32 lobe arithmetic on values up to ~10: 1e-4 relative.
            assert!(
                (f / want - 1.0).abs() < 1e-4,
                "({to}, {po}, {ti}, {pi}): {f} vs {want}"
            );
        }
        assert_eq!(
            naive_brdf(&map, Vec2::ZERO, Vec3::Z, Vec3::new(0.0, 0.0, -1.0), 0.01),
            0.0
        );
        assert_eq!(naive_brdf(&map, Vec2::ZERO, Vec3::Z, Vec3::Z, 0.0), 0.0);
        assert_eq!(naive_brdf(&map, Vec2::ZERO, Vec3::NAN, Vec3::Z, 0.01), 0.0);
        assert!(naive_brdf(&map, Vec2::NAN, Vec3::Z, Vec3::Z, 0.01).is_finite());
    }

    #[test]
    fn naive_brdf_peaks_at_the_mirror_direction_of_the_local_normal() {
        // A map tilted toward +x: the specular peak for normal view is the mirror about the normal.
        let s0 = Vec2::new(-0.3, 0.1);
        let map = NormalMap::from_slopes(4, 4, vec![s0; 16]).unwrap();
        let n0 = brdf::frame::slope_to_normal(s0);
        let wo = support::dir(20.0, 200.0);
        let mirror = 2.0 * wo.dot(n0) * n0 - wo;
        let mut best = (0.0f32, Vec3::Z);
        for t in 0..90 {
            for p in 0..360 {
                let wi = support::dir(t as f64, p as f64);
                let f = naive_brdf(&map, Vec2::new(0.5, 0.5), wo, wi, 0.01);
                if f > best.0 {
                    best = (f, wi);
                }
            }
        }
        // Grid of 1°: the argmax is within ~1° of the mirror direction (the lobe has width 2σε ≈ 1.1°).
        assert!(
            best.1.dot(mirror) > (2.0f32).to_radians().cos(),
            "{} vs {mirror}",
            best.1
        );
    }
}
