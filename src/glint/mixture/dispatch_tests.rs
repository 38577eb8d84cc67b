//! The runtime dispatch (docs/mixture.md, "Runtime dispatch"): the per-query loops over lobe blocks
//! compiled for the baseline target and, on CPUs that have it, for AVX2 must give **bit-identical**
//! results (no FMA, same operation order), so a renderer's images do not depend on the CPU it runs
//! on. A unit test, since the copy a patch runs is crate-private (`MixturePatch::with_simd`).
//!
//! Every comparison is `to_bits` equality: any rounding difference between the two copies (a fused
//! multiply-add, a reassociated sum) fails the test. On CPUs without AVX2, or with
//! `BRDF_SIMD=baseline`, there is only one copy: the test prints a note and checks nothing else.

use super::{BeckmannMixture, LobeStorage, MaskingMode, MixtureParams, MixturePatch, PatchOptions};
use crate::glint::{
    BrushedParams, FlakesParams, Footprint, GlintNdf, NormalMap, ScratchedParams, brushed, bumpy,
    flakes, scratched,
};
use crate::ndf::Ndf;
use glam::{Vec2, Vec3};
use rand::{RngExt, SeedableRng};

/// The four procedural maps at `n`² with the gallery's parameters and seeds (as tests/it/support's
/// `procedural_maps`).
fn procedural_maps(n: usize) -> Vec<(&'static str, NormalMap)> {
    vec![
        ("bumpy", bumpy(n, n, 0.25, 4.0, 1).unwrap()),
        (
            "brushed",
            brushed(n, n, BrushedParams::default(), 2).unwrap(),
        ),
        (
            "scratched",
            scratched(n, n, ScratchedParams::default(), 3).unwrap(),
        ),
        ("flakes", flakes(n, n, FlakesParams::default(), 4).unwrap()),
    ]
}

const N: usize = 64;

/// A direction in the upper hemisphere with polar angle up to `max_deg`, uniform in cos θ.
fn direction(rng: &mut impl RngExt, max_deg: f32) -> Vec3 {
    let c = 1.0 - rng.random::<f32>() * (1.0 - max_deg.to_radians().cos());
    let s = (1.0 - c * c).max(0.0).sqrt();
    let p = std::f32::consts::TAU * rng.random::<f32>();
    Vec3::new(s * p.cos(), s * p.sin(), c)
}

/// The first query whose results differ between the two patches, if any; the number of values
/// compared.
fn first_difference(
    avx2: &MixturePatch,
    base: &MixturePatch,
    rng: &mut impl RngExt,
) -> (Option<String>, usize) {
    let mut compared = 0;
    let mut check = |what: &str, q: Vec3, a: &[f32], b: &[f32]| -> Option<String> {
        compared += a.len();
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        (bits(a) != bits(b)).then(|| format!("{what} at {q:?}: avx2 {a:?}, baseline {b:?}"))
    };
    for k in 0..64 {
        // Half vectors: half drawn from the patch's own D_P cos (where D_P is large), half uniform
        // to 85° (tails, empty slope regions).
        let m = if k % 2 == 0 {
            avx2.sample_normal(Vec2::new(rng.random(), rng.random()))
        } else {
            direction(rng, 85.0)
        };
        let (da, ta) = avx2.d_with_stats(m);
        let (db, tb) = base.d_with_stats(m);
        if ta != tb {
            return (
                Some(format!("lanes touched at {m:?}: {ta} vs {tb}")),
                compared,
            );
        }
        if let Some(e) = check("d", m, &[da], &[db]) {
            return (Some(e), compared);
        }
        if let Some(e) = check(
            "pdf_normal",
            m,
            &[avx2.pdf_normal(m)],
            &[base.pdf_normal(m)],
        ) {
            return (Some(e), compared);
        }
        // Views to 89.9° (grazing: the ramp term of every lobe is formed).
        let wo = direction(rng, if k % 4 == 1 { 89.9 } else { 80.0 });
        let u = Vec2::new(rng.random(), rng.random());
        let sa = avx2.sample_visible(wo, u);
        let sb = base.sample_visible(wo, u);
        let pairs: [(&str, Vec<f32>, Vec<f32>); 5] = [
            ("lambda", vec![avx2.lambda(wo)], vec![base.lambda(wo)]),
            (
                "visible_area_exact",
                vec![avx2.visible_area_exact(wo)],
                vec![base.visible_area_exact(wo)],
            ),
            (
                "sample_visible",
                sa.to_array().to_vec(),
                sb.to_array().to_vec(),
            ),
            (
                "pdf_visible (own sample)",
                vec![avx2.pdf_visible(wo, sa)],
                vec![base.pdf_visible(wo, sa)],
            ),
            (
                "pdf_visible (half vector)",
                vec![avx2.pdf_visible(wo, m)],
                vec![base.pdf_visible(wo, m)],
            ),
        ];
        for (what, a, b) in pairs {
            if let Some(e) = check(what, wo, &a, &b) {
                return (Some(e), compared);
            }
        }
    }
    (None, compared)
}

/// `d`, `lambda`, `visible_area_exact`, `sample_visible`, `pdf_visible` and `pdf_normal` agree bit
/// for bit between the AVX2 and the baseline copies of the block loops, on the four procedural maps
/// at 64², for sub-texel to whole-map (folded, wrapping) footprints, isotropic and anisotropic, with
/// the level of detail off (exact masking) and at its defaults (merged levels, approximate masking),
/// in full and in compact storage (whose blocks are decoded inside the dispatched loops).
#[test]
fn avx2_and_baseline_are_bit_identical() {
    let options = [
        PatchOptions {
            masking: MaskingMode::Exact,
            lod_lobes: f32::INFINITY,
            lod_tolerance: 0.0,
            ..PatchOptions::default()
        },
        PatchOptions::default(),
    ];
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(15);
    let mut compared = 0;
    let mut patches = 0;
    let maps = procedural_maps(N);
    let storages = [LobeStorage::Full, LobeStorage::Compact];
    for ((name, map), storage) in storages
        .iter()
        .flat_map(|&st| maps.iter().map(move |m| (m, st)))
    {
        let params = MixtureParams {
            storage,
            ..MixtureParams::default()
        };
        let mix = BeckmannMixture::build(map, params).unwrap();
        for (oi, &o) in options.iter().enumerate() {
            for k in 0..12 {
                // 0.25 to 8192 texels (twice the map: both axes folded), centres anywhere.
                let area = 0.25 * 2f32.powf(15.0 * k as f32 / 11.0);
                let aspect = if k % 3 == 0 {
                    1.0
                } else {
                    1.0 + 7.0 * rng.random::<f32>()
                };
                let angle = 3.2 * rng.random::<f32>();
                let c = Vec2::new(rng.random(), rng.random());
                let f = Footprint::anisotropic_texels(c, area, aspect, angle, N, N);
                let avx2 = mix.patch_with(&f, &o, None).with_simd(false);
                if avx2.simd_name() != "avx2" {
                    println!(
                        "note: this CPU has no AVX2 (or BRDF_SIMD=baseline is set): one copy of \
                         the block loops only, nothing to compare"
                    );
                    return;
                }
                let base = avx2.clone().with_simd(true);
                assert_eq!(base.simd_name(), "baseline");
                let (diff, n) = first_difference(&avx2, &base, &mut rng);
                if let Some(e) = diff {
                    panic!(
                        "{name}, {storage:?}, options {oi}, {area} texels, aspect {aspect}: {e}"
                    );
                }
                compared += n;
                patches += 1;
            }
        }
    }
    println!("{patches} patches, {compared} values bit-identical between avx2 and baseline");
}
