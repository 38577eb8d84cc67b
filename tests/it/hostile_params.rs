//! Hostile parameters for the normal-map inputs (docs/robustness.md, "Generators and repairs"):
//!
//! - every procedural generator, each parameter over the whole `f32` range (NaN, ±∞, subnormals,
//!   ±0, 10⁻³⁰ … `f32::MAX`) with the others at their defaults, on small maps: `Ok`, or an `Err`
//!   naming that parameter; never a panic, an abort on allocation or a hang (each call is timed
//!   against a bound far above the worst accepted case, which takes milliseconds here);
//! - map sizes beyond what a generator builds are refused, not allocated;
//! - `NormalRepair::ClampZ` at its documented minimum repairs every direction, and `from_normals`
//!   takes non-zero vectors of any finite length.

use crate::support;

use brdf::glint::{
    BrushedParams, FlakesParams, MAX_GENERATED_TEXELS, MAX_SLOPE, NormalMap, NormalRepair,
    ScratchedParams, brushed, bumpy, flakes, scratched,
};
use brdf::{Error, Vec2, Vec3};
use proptest::prelude::*;
use proptest::test_runner::TestRunner;
use std::time::{Duration, Instant};

/// The guard against hangs: far above the slowest accepted case on these maps (milliseconds at
/// opt-level 3; a generator that hangs never returns, one that loops for seconds fails here).
const TIME_LIMIT: Duration = Duration::from_secs(5);

/// Values of every class: special floats, the extremes, and ordinary ones.
fn special_values() -> Vec<f32> {
    vec![
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        0.0,
        -0.0,
        f32::from_bits(1),
        f32::MIN_POSITIVE,
        1e-30,
        1e-7,
        1e-3,
        0.25,
        0.5,
        0.999,
        1.0,
        1.5,
        3.0,
        7.0,
        16.0,
        17.0,
        100.0,
        101.0,
        1e4,
        1e5,
        1.000_001e5,
        1e9,
        1e30,
        f32::MAX,
        -1.0,
        -f32::MAX,
    ]
}

/// Any f32: the special values, and proptest's full-range floats (every class, every exponent).
fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => prop::sample::select(special_values()),
        2 => proptest::num::f32::ANY,
        1 => (-40.0f32..40.0).prop_map(|e| 10f32.powf(e)),
    ]
}

/// Runs `generate` on `value`, timed; the result must be a valid map or an error that names
/// `name`.
fn check<T>(
    what: &str,
    name: &str,
    value: f32,
    generate: impl FnOnce() -> Result<T, Error>,
) -> Result<(), TestCaseError> {
    let start = Instant::now();
    let r = generate();
    let took = start.elapsed();
    prop_assert!(
        took < TIME_LIMIT,
        "{what}: {name} = {value:e} took {took:?}"
    );
    if let Err(e) = r {
        let text = e.to_string();
        prop_assert!(
            matches!(e, Error::InvalidParameter { .. }) && text.contains(name),
            "{what}: {name} = {value:e}: the error does not name it: {text}"
        );
    }
    Ok(())
}

/// One property run over `any_f32()` plus every special value.
fn sweep(cases: u32, f: impl Fn(f32) -> Result<(), TestCaseError>) {
    for v in special_values() {
        f(v).unwrap();
    }
    TestRunner::new(support::proptest_config(cases))
        .run(&any_f32(), f)
        .unwrap();
}

/// The sizes swept: square, non-square, one texel wide.
const SIZES: [(usize, usize); 3] = [(16, 16), (24, 9), (1, 16)];

#[test]
fn bumpy_validates_every_parameter() {
    for (w, h) in SIZES {
        let corr = 3f32.min(w.min(h) as f32);
        sweep(48, |v| {
            check("bumpy", "rms_slope", v, || bumpy(w, h, v, corr, 1))
        });
        sweep(48, |v| {
            check("bumpy", "correlation_texels", v, || bumpy(w, h, 0.2, v, 1))
        });
    }
}

#[test]
fn brushed_validates_every_parameter() {
    let d = BrushedParams::default();
    for (w, h) in SIZES {
        let d = BrushedParams {
            length_texels: d.length_texels.min(w as f32),
            width_texels: d.width_texels.min(h as f32),
            ..d
        };
        sweep(48, |v| {
            check("brushed", "rms_slope", v, || {
                brushed(w, h, BrushedParams { rms_slope: v, ..d }, 2)
            })
        });
        sweep(48, |v| {
            check("brushed", "length_texels", v, || {
                brushed(
                    w,
                    h,
                    BrushedParams {
                        length_texels: v,
                        ..d
                    },
                    2,
                )
            })
        });
        sweep(48, |v| {
            check("brushed", "width_texels", v, || {
                brushed(
                    w,
                    h,
                    BrushedParams {
                        width_texels: v,
                        ..d
                    },
                    2,
                )
            })
        });
    }
}

#[test]
fn scratched_validates_every_parameter() {
    let d = ScratchedParams {
        base_correlation_texels: 4.0,
        ..ScratchedParams::default()
    };
    type Set = fn(ScratchedParams, f32) -> ScratchedParams;
    let fields: [(&str, Set); 10] = [
        ("density", |p, v| ScratchedParams { density: v, ..p }),
        ("width_texels", |p, v| ScratchedParams {
            width_texels: v,
            ..p
        }),
        ("max_slope", |p, v| ScratchedParams { max_slope: v, ..p }),
        ("length_texels", |p, v| ScratchedParams {
            length_texels: (v.min(25.0), v),
            ..p
        }),
        ("length_texels", |p, v| ScratchedParams {
            length_texels: (v, 150.0),
            ..p
        }),
        ("curved_fraction", |p, v| ScratchedParams {
            curved_fraction: v,
            ..p
        }),
        ("max_turn", |p, v| ScratchedParams { max_turn: v, ..p }),
        ("base_rms_slope", |p, v| ScratchedParams {
            base_rms_slope: v,
            ..p
        }),
        ("base_correlation_texels", |p, v| ScratchedParams {
            base_correlation_texels: v,
            ..p
        }),
        // Dense scratches: the rasteriser's budget names the three parameters together.
        ("density", |p, v| ScratchedParams {
            density: v,
            length_texels: (1e5, 1e5),
            ..p
        }),
    ];
    for (w, h) in [(32, 32), (24, 9), (1, 16)] {
        let d = ScratchedParams {
            width_texels: d.width_texels.min(w.min(h) as f32),
            base_correlation_texels: d.base_correlation_texels.min(w.min(h) as f32),
            ..d
        };
        for (name, set) in fields {
            sweep(24, |v| {
                check("scratched", name, v, || scratched(w, h, set(d, v), 5))
            });
        }
    }
}

#[test]
fn flakes_validates_every_parameter() {
    for (w, h) in SIZES {
        sweep(48, |v| {
            check("flakes", "cell_texels", v, || {
                flakes(
                    w,
                    h,
                    FlakesParams {
                        cell_texels: v,
                        tilt_sigma: 0.2,
                    },
                    6,
                )
            })
        });
        sweep(48, |v| {
            check("flakes", "tilt_sigma", v, || {
                flakes(
                    w,
                    h,
                    FlakesParams {
                        cell_texels: 4.0,
                        tilt_sigma: v,
                    },
                    6,
                )
            })
        });
    }
}

/// The issue's cases: a panic ("remainder with overflow"), an abort (6.1 GB for a 16² map) and a
/// hang (width 1e9; 1e4 already > 10 s).
#[test]
fn issue_cases() {
    for cell in [1e-30f32, 1e-3] {
        let e = flakes(
            16,
            16,
            FlakesParams {
                cell_texels: cell,
                tilt_sigma: 0.2,
            },
            6,
        )
        .unwrap_err();
        assert!(e.to_string().contains("cell_texels"), "{e}");
    }
    for width in [1e9f32, 1e4] {
        let start = Instant::now();
        let e = scratched(
            32,
            32,
            ScratchedParams {
                width_texels: width,
                ..ScratchedParams::default()
            },
            5,
        )
        .unwrap_err();
        assert!(start.elapsed() < TIME_LIMIT);
        assert!(e.to_string().contains("width_texels"), "{e}");
    }
}

/// Sizes a generator cannot build are refused before anything is allocated.
#[test]
fn huge_maps_are_refused() {
    let side = 1usize << 20;
    let size_error = |r: Result<NormalMap, Error>| {
        assert!(matches!(r, Err(Error::InvalidSize { .. })), "{r:?}");
    };
    size_error(bumpy(side, side, 0.2, 4.0, 1));
    size_error(brushed(side, side, BrushedParams::default(), 1));
    size_error(scratched(side, side, ScratchedParams::default(), 1));
    size_error(flakes(side, side, FlakesParams::default(), 1));
    size_error(bumpy(MAX_GENERATED_TEXELS + 1, 1, 0.2, 0.5, 1));
    size_error(bumpy(0, 4, 0.2, 1.0, 1));
}

// ---------------------------------------------------------------------------------------------
// Normal repair and normalisation
// ---------------------------------------------------------------------------------------------

/// `ClampZ(1e-4)`, the documented minimum, repairs every horizon direction (297 of 1,000 failed
/// before: rounding pushed the repaired slope past MAX_SLOPE) and every direction just above or
/// below it, keeping the azimuth.
#[test]
fn clamp_z_at_its_minimum_repairs_every_direction() {
    let repair = NormalRepair::ClampZ(1.0 / MAX_SLOPE);
    let mut normals = Vec::new();
    for k in 0..1000 {
        let phi = k as f32 * std::f32::consts::TAU / 1000.0;
        let (s, c) = phi.sin_cos();
        for z in [0.0f32, -0.0, 1e-30, 9.9e-5, 1e-4, 1.000_1e-4, -1e-4, -0.5] {
            let r = (1.0 - z * z).sqrt();
            normals.push(Vec3::new(r * c, r * s, z));
        }
    }
    // The issue's case first.
    normals.insert(0, Vec3::new(0.6, 0.8, 0.0));
    for n in &normals {
        let map =
            NormalMap::from_normals(1, 1, &[*n], repair).unwrap_or_else(|e| panic!("{n:?}: {e}"));
        let s = map.slopes()[0];
        assert!(s.length() <= MAX_SLOPE, "{n:?}: slope {s:?}");
        // The azimuth is kept: the slope points against the normal's horizontal part.
        let horizontal = Vec2::new(n.x, n.y);
        if horizontal.length() > 0.5 {
            assert!(s.dot(horizontal) < 0.0, "{n:?}: slope {s:?}");
        }
    }
    // All at once (the map checks every texel).
    let w = normals.len();
    NormalMap::from_normals(w, 1, &normals, repair).unwrap();
}

/// `from_normals` normalises any finite non-zero vector, however short or long (a length of 1e-30
/// was refused as zero-length: its squared length underflows), and refuses only exact zeros.
#[test]
fn from_normals_takes_every_non_zero_length() {
    let dirs = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.3, -0.4, 0.866),
        Vec3::new(-0.6, 0.0, 0.8),
    ];
    for d in dirs {
        let d = d.normalize();
        let want = NormalMap::from_normals(1, 1, &[d], NormalRepair::Reject)
            .unwrap()
            .slopes()[0];
        for scale in [1e-30f32, 1e-38, 1e-44, 1e-20, 1e20, 1e30, 1e38] {
            let n = d * scale;
            if n == Vec3::ZERO || !n.is_finite() {
                continue;
            }
            let got = NormalMap::from_normals(1, 1, &[n], NormalRepair::Reject)
                .unwrap_or_else(|e| panic!("{n:?}: {e}"))
                .slopes()[0];
            // Subnormal components keep only a few bits: compare loosely there.
            let tol = if scale < 1e-37 { 0.2 } else { 1e-5 };
            assert!(
                (got - want).length() <= tol * (1.0 + want.length()),
                "{n:?}: {got} vs {want}"
            );
        }
    }
    for zero in [Vec3::ZERO, Vec3::new(-0.0, 0.0, -0.0)] {
        let e = NormalMap::from_normals(1, 1, &[zero], NormalRepair::ClampZ(0.1)).unwrap_err();
        assert!(e.to_string().contains("zero-length"), "{e}");
    }
    // The smallest subnormal components still have a direction.
    let tiny = Vec3::new(0.0, 0.0, f32::from_bits(1));
    assert_eq!(
        NormalMap::from_normals(1, 1, &[tiny], NormalRepair::Reject)
            .unwrap()
            .slopes()[0],
        Vec2::ZERO
    );
}

proptest! {
    #![proptest_config(support::proptest_config(512))]

    /// Any finite non-zero vector is repaired by `ClampZ(min_z)` for every valid min_z, with a
    /// slope within MAX_SLOPE.
    #[test]
    fn clamp_z_repairs_any_finite_vector(
        x in any_f32(), y in any_f32(), z in any_f32(),
        min_z in prop_oneof![Just(1.0 / MAX_SLOPE), (1.0f32 / MAX_SLOPE)..=1.0],
    ) {
        let n = Vec3::new(x, y, z);
        let r = NormalMap::from_normals(1, 1, &[n], NormalRepair::ClampZ(min_z));
        if n.is_finite() && n != Vec3::ZERO {
            let map = r.map_err(|e| TestCaseError::fail(format!("{n:?} min_z {min_z}: {e}")))?;
            prop_assert!(map.slopes()[0].length() <= MAX_SLOPE);
        } else {
            prop_assert!(r.is_err());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Image decoding: a small file claiming a huge image
// ---------------------------------------------------------------------------------------------

/// CRC-32 (ISO-HDLC, as PNG chunks use), bitwise.
#[cfg(feature = "image")]
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// A valid w × 1 RGB PNG whose header is rewritten to claim w × `height` (the data stays one row).
#[cfg(feature = "image")]
fn png_claiming(w: u32, height: u32) -> Vec<u8> {
    let img = image::RgbImage::from_pixel(w, 1, image::Rgb([128, 128, 255]));
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .unwrap();
    // Signature (8), IHDR length (4), "IHDR" (4), width (4), height (4) …, CRC after 13 data bytes.
    bytes[20..24].copy_from_slice(&height.to_be_bytes());
    let crc = crc32(&bytes[12..29]);
    bytes[29..33].copy_from_slice(&crc.to_be_bytes());
    bytes
}

/// The issue's file: a ~1 KB PNG claiming 32 × 2²⁰ texels made the decoder allocate 128 MiB
/// (under the image crate's 512 MiB limit). It is now refused from its header, naming the cap; a
/// caller who wants such maps raises `ImageOptions::max_texels`.
#[cfg(feature = "image")]
#[test]
fn image_claiming_millions_of_texels_is_refused_from_its_header() {
    use brdf::glint::{DEFAULT_MAX_IMAGE_TEXELS, ImageOptions};
    let bytes = png_claiming(32, 1 << 20);
    assert!(bytes.len() < 2048, "{} bytes", bytes.len());
    let e = NormalMap::from_image_bytes_with(&bytes, "claims 32×2^20", &ImageOptions::default())
        .unwrap_err();
    assert!(
        matches!(e, Error::Image { .. }) && e.to_string().contains("max_texels"),
        "{e}"
    );
    const { assert!(32 << 20 > DEFAULT_MAX_IMAGE_TEXELS) };
    // Within the cap the same header passes the check and the decoder reports the missing rows.
    let small = png_claiming(32, 4);
    let e = NormalMap::from_image_bytes_with(&small, "claims 32×4", &ImageOptions::default())
        .unwrap_err();
    assert!(!e.to_string().contains("max_texels"), "{e}");
    // A genuine one-row map loads; a cap of 0 is refused.
    let ok = png_claiming(32, 1);
    NormalMap::from_image_bytes_with(&ok, "32×1", &ImageOptions::default()).unwrap();
    let e = NormalMap::from_image_bytes_with(
        &ok,
        "32×1",
        &ImageOptions {
            max_texels: 0,
            ..ImageOptions::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("max_texels"), "{e}");
    let e = NormalMap::from_image_bytes_with(
        &ok,
        "32×1",
        &ImageOptions {
            max_texels: 31,
            ..ImageOptions::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("max_texels"), "{e}");
}
