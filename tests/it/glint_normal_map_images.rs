//! Normal maps as image files: 8- and 16-bit PNG and EXR round trips within their quantisation, the
//! picture-row and tangent conventions, export, and errors that name the bad file (never a panic on
//! mutated files).

#![cfg(feature = "image")]

use crate::support;

use brdf::glint::{NormalMap, NormalRepair, TangentConvention};
use brdf::{Error, Vec2, Vec3};
use rand::RngExt;
use std::path::PathBuf;
use support::noise_map as random_map;

/// A temporary directory under target/ for the files these tests write.
fn tmp_dir() -> PathBuf {
    support::tmp_dir("glint_normal_map_images")
}

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
        let map = NormalMap::from_image_file(&path, conv, NormalRepair::Reject).unwrap();
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
            NormalMap::from_image_file(&path, TangentConvention::OpenGl, NormalRepair::Reject)
                .unwrap();
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
        NormalMap::from_image_file_with(&path, &options).unwrap().0
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
    let map =
        NormalMap::from_image_file(&path, TangentConvention::OpenGl, NormalRepair::Reject).unwrap();
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
    let back = NormalMap::from_image_file(&path, TangentConvention::DirectX, NormalRepair::Reject)
        .unwrap();
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
    let e = NormalMap::from_image_file(&missing, conv, NormalRepair::Reject).unwrap_err();
    assert!(
        matches!(e, Error::Io { .. }) && e.to_string().contains("does_not_exist.png"),
        "{e}"
    );
    // Not an image.
    let junk = dir.join("junk.png");
    std::fs::write(&junk, b"this is not a png").unwrap();
    let e = NormalMap::from_image_file(&junk, conv, NormalRepair::Reject).unwrap_err();
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
    let e = NormalMap::from_image_file(&grey, conv, NormalRepair::Reject).unwrap_err();
    assert!(
        matches!(e, Error::Image { .. }) && e.to_string().contains("grey.png"),
        "{e}"
    );
    // Empty (0 × 0 pixels), written as a valid PNG header with zero width by hand (encoders
    // refuse it): refused by the decoder or by our own check, and the error names the file.
    let empty = dir.join("empty.png");
    std::fs::write(&empty, png_rgb8_header_only(0, 1)).unwrap();
    let e = NormalMap::from_image_file(&empty, conv, NormalRepair::Reject).unwrap_err();
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
    let e = NormalMap::from_image_file(&below, conv, NormalRepair::Reject).unwrap_err();
    assert!(
        matches!(e, Error::InvalidTexel { x: 1, y: 1, .. }) && e.to_string().contains("below.png"),
        "{e}"
    );
    // …which ClampZ repairs.
    let m = NormalMap::from_image_file(&below, conv, NormalRepair::ClampZ(0.2)).unwrap();
    assert!(m.texel_normal(1, 1).z > 0.19);
    // Non-finite EXR values, whatever the repair.
    let nan = dir.join("nan.exr");
    image::Rgb32FImage::from_raw(1, 1, vec![0.0, f32::NAN, 1.0])
        .unwrap()
        .save(&nan)
        .unwrap();
    let e = NormalMap::from_image_file(&nan, conv, NormalRepair::ClampZ(0.5)).unwrap_err();
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
    let e =
        NormalMap::from_image_bytes(&good[..good.len() / 2], "half", conv, NormalRepair::Reject)
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
