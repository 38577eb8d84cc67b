//! Normal maps from pixel slices (no `image` feature needed): the 8-bit layout written by
//! `NormalMap::to_rgb8` decodes back to the map within 8-bit quantisation, the 16-bit and float
//! forms decode the same normals, and malformed slices are refused with an error.

use brdf::Error;
use brdf::glint::{FloatEncoding, ImageOptions, NormalMap, TangentConvention, bumpy};

#[test]
fn pixel_slices_round_trip() {
    let map = bumpy(16, 8, 0.3, 2.0, 3).unwrap();
    for conv in [TangentConvention::OpenGl, TangentConvention::DirectX] {
        let options = ImageOptions {
            convention: conv,
            ..ImageOptions::default()
        };
        let rgb = map.to_rgb8(conv);
        let (back, report) = NormalMap::from_pixels_u8(16, 8, 3, &rgb, &options).unwrap();
        assert!(!report.float_channels && report.encoding == FloatEncoding::Encoded);
        // 8-bit quantisation moves each component by at most 1/255: normals agree to ~√3/255.
        for j in 0..8 {
            for i in 0..16 {
                let d = (back.texel_normal(i, j) - map.texel_normal(i, j)).length();
                assert!(d < 0.01, "texel ({i}, {j}): {d}");
            }
        }
        // The same values as 16-bit (×257 maps v/255 to exactly the same c) and as floats.
        let wide: Vec<u16> = rgb.iter().map(|&c| c as u16 * 257).collect();
        let floats: Vec<f32> = rgb.iter().map(|&c| c as f32 / 255.0).collect();
        let (m16, _) = NormalMap::from_pixels_u16(16, 8, 3, &wide, &options).unwrap();
        let (m32, r32) = NormalMap::from_pixels_f32(16, 8, 3, &floats, &options).unwrap();
        assert!(r32.float_channels);
        for (a, b) in back.slopes().iter().zip(m16.slopes()) {
            assert!((*a - *b).length() < 1e-5);
        }
        for (a, b) in back.slopes().iter().zip(m32.slopes()) {
            assert!((*a - *b).length() < 1e-5);
        }
    }
    // RGBA: alpha is ignored.
    let rgb = map.to_rgb8(TangentConvention::OpenGl);
    let rgba: Vec<u8> = rgb.chunks(3).flat_map(|p| [p[0], p[1], p[2], 7]).collect();
    let o = ImageOptions::default();
    let (a, _) = NormalMap::from_pixels_u8(16, 8, 3, &rgb, &o).unwrap();
    let (b, _) = NormalMap::from_pixels_u8(16, 8, 4, &rgba, &o).unwrap();
    assert_eq!(a.slopes(), b.slopes());
}

#[test]
fn malformed_pixel_slices_are_refused() {
    let o = ImageOptions::default();
    let flat = [128u8, 128, 255].repeat(4);
    assert!(NormalMap::from_pixels_u8(2, 2, 3, &flat, &o).is_ok());
    let size = |r: Result<_, Error>| matches!(r, Err(Error::InvalidSize { .. }));
    assert!(size(
        NormalMap::from_pixels_u8(2, 2, 3, &flat[..11], &o).map(drop)
    ));
    assert!(size(NormalMap::from_pixels_u8(0, 2, 3, &[], &o).map(drop)));
    assert!(size(
        NormalMap::from_pixels_u8(usize::MAX, 2, 3, &flat, &o).map(drop)
    ));
    let small = ImageOptions { max_texels: 3, ..o };
    assert!(size(
        NormalMap::from_pixels_u8(2, 2, 3, &flat, &small).map(drop)
    ));
    assert!(matches!(
        NormalMap::from_pixels_u8(3, 2, 2, &flat, &o),
        Err(Error::InvalidParameter {
            name: "channels",
            ..
        })
    ));
    // Raw vectors read as 2c − 1 are off unit length: refused as implausible, not silently used.
    let raw = [0.0f32, 0.0, 1.0].repeat(4);
    assert!(matches!(
        NormalMap::from_pixels_f32(2, 2, 3, &raw, &o),
        Err(Error::ImplausibleNormals { .. })
    ));
    let raw_ok = ImageOptions {
        float_encoding: FloatEncoding::Raw,
        ..o
    };
    assert!(NormalMap::from_pixels_f32(2, 2, 3, &raw, &raw_ok).is_ok());
    let nan = [f32::NAN, 0.5, 1.0].repeat(4);
    assert!(matches!(
        NormalMap::from_pixels_f32(2, 2, 3, &nan, &o),
        Err(Error::InvalidTexel { .. })
    ));
}
