//! Totality (docs/robustness.md): every public model under arbitrary input — directions (NaN, ±∞,
//! zero-length, unnormalised, cos θ down to 1e-7, wo = ±wi, wo = wi = n), random numbers (any f32, 0,
//! 1 − ε), parameters over their whole valid range (α from 1e-4 to 10, near-singular covariances), and
//! the glint models on empty-to-tiny, 1×N, non-square, flat and extremely rough maps seen through
//! zero, NaN, huge, far-away and extremely anisotropic footprints. Every value must be finite and
//! ≥ 0, every sample must carry a positive pdf (tests/it/support/totality.rs, shared with the fuzz
//! targets).
//!
//! More cases or another seed: `PROPTEST_CASES=2000 PROPTEST_RNG_SEED=7 cargo test --release --test
//! 'robustness*'`.

use crate::support;

use brdf::bxdf::{
    BlinnPhongNormalization, Masking, OriginalPhongNormalization, PhongNormalization, Sampling,
};
use brdf::fresnel::{ConductorFresnel, DielectricFresnel, NoFresnel, SchlickFresnel};
use brdf::glint::mixture::{MaskingMode, PatchOptions};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, BinMap, GlintNdf, PositionNormalBrdf, PositionNormalMap};
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, Ndf, SlopeGaussian};
use brdf::{BlinnPhongLobe, Bxdf, Lambert, MicrofacetBrdf, OriginalPhong, Phong, Vec2, Vec3};
use proptest::prelude::*;
use support::robustness::{
    any_alpha, any_dir, any_footprint, any_map, any_u, mixture_options, quick_mixture_params,
    small_bins,
};
use support::totality::{check_bxdf, check_ndf};

// ---------------------------------------------------------------------------------------------
// Totality of the analytic models and classic BRDFs
// ---------------------------------------------------------------------------------------------

fn microfacet_variants<'a, D: Ndf + Copy + 'a>(
    ndf: D,
    f0: f32,
    eta: f32,
) -> Vec<Box<dyn Bxdf + 'a>> {
    let mut v: Vec<Box<dyn Bxdf + 'a>> = vec![];
    for sampling in [Sampling::Normals, Sampling::VisibleNormals] {
        for masking in [Masking::Separable, Masking::HeightCorrelated] {
            let base = MicrofacetBrdf::new(ndf, NoFresnel)
                .with_sampling(sampling)
                .with_masking(masking);
            v.push(Box::new(base));
            let schlick = SchlickFresnel::new(Vec3::splat(f0)).unwrap();
            v.push(Box::new(
                MicrofacetBrdf::new(ndf, schlick)
                    .with_sampling(sampling)
                    .with_masking(masking),
            ));
        }
    }
    v.push(Box::new(MicrofacetBrdf::new(
        ndf,
        DielectricFresnel::new(eta).unwrap(),
    )));
    v.push(Box::new(MicrofacetBrdf::new(
        ndf,
        ConductorFresnel::new(Vec3::new(0.2, eta, 1.1), Vec3::new(3.9, 2.4, 0.0)).unwrap(),
    )));
    v
}

proptest! {
    #![proptest_config(support::proptest_config(400))]

    /// Beckmann, GGX, Blinn-Phong and the slope Gaussian as NDFs and inside every microfacet BRDF
    /// configuration (both samplers, both G2 forms, four Fresnel terms), α over [1e-4, 10].
    #[test]
    fn analytic_ndfs_are_total(
        ax in any_alpha(), ay in any_alpha(), gamma in 0.0f32..1e6,
        mx in -3.0f32..3.0, my in -3.0f32..3.0, log_sx in -4.0f32..1.0, log_sy in -4.0f32..1.0,
        rho in -1.0f32..=1.0, f0 in 0.0f32..=1.0, eta in 1e-3f32..10.0,
        wo in any_dir(), wi in any_dir(), uc in any_u(), u0 in any_u(), u1 in any_u(),
    ) {
        let u = Vec2::new(u0, u1);
        let (sx, sy) = (10f32.powf(log_sx), 10f32.powf(log_sy));
        // |ρ| up to 1: the covariance may be singular; the infallible moment constructor floors it.
        let c = rho * sx * sy;
        let sg = SlopeGaussian::from_moments(
            [mx, my, sx * sx + mx * mx, sy * sy + my * my, c + mx * my],
            brdf::ndf::DEFAULT_SIGMA_MIN,
        );
        let beckmann = Beckmann::new(ax, ay).unwrap();
        let ggx = Ggx::new(ax, ay).unwrap();
        let blinn = BlinnPhong::new(gamma).unwrap();
        let ndfs: [&dyn Ndf; 4] = [&beckmann, &ggx, &blinn, &sg];
        for ndf in ndfs {
            check_ndf(ndf, wo, wi, uc, u);
        }
        for b in microfacet_variants(beckmann, f0, eta)
            .into_iter()
            .chain(microfacet_variants(ggx, f0, eta))
            .chain(microfacet_variants(blinn, f0, eta))
            .chain(microfacet_variants(sg, f0, eta))
        {
            check_bxdf(b.as_ref(), wo, wi, uc, u);
        }
    }

    /// Lambert, every Phong normalisation (with and without Fresnel), original Phong and the
    /// Blinn-Phong lobe, γ over [0, 10⁴] (Arvo: integer γ ≤ 2000), albedos on the energy boundary.
    #[test]
    fn classic_brdfs_are_total(
        rho_d in 0.0f32..=1.0, split in 0.0f32..=1.0, gamma in 0.0f32..1e4,
        wo in any_dir(), wi in any_dir(), uc in any_u(), u0 in any_u(), u1 in any_u(),
    ) {
        let u = Vec2::new(u0, u1);
        let (d, s) = (Vec3::splat(rho_d), Vec3::splat((1.0 - rho_d) * split));
        check_bxdf(&Lambert::new(d).unwrap(), wo, wi, uc, u);
        for norm in [
            PhongNormalization::Unnormalized,
            PhongNormalization::EnergyConservingOriginal,
            PhongNormalization::EnergyConserving,
            PhongNormalization::EnergyNormalizedArvo,
            PhongNormalization::EnergyNormalizedMallettYuksel,
        ] {
            let g = if norm == PhongNormalization::EnergyNormalizedArvo { gamma.round().min(2000.0) } else { gamma };
            let p = Phong::new(d, s, g, norm).unwrap();
            check_bxdf(&p, wo, wi, uc, u);
            check_bxdf(&p.with_schlick_fresnel(), wo, wi, uc, u);
        }
        for norm in [OriginalPhongNormalization::Unnormalized, OriginalPhongNormalization::EnergyConserving] {
            check_bxdf(&OriginalPhong::new(d, s, gamma, norm).unwrap(), wo, wi, uc, u);
        }
        for norm in [BlinnPhongNormalization::RealTimeRendering, BlinnPhongNormalization::EnergyConserving] {
            check_bxdf(&BlinnPhongLobe::new(d, s, gamma, norm).unwrap(), wo, wi, uc, u);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Totality of the glint models
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(support::proptest_config(160))]

    /// Every glint model (mixture with exact, approximate and level-of-detail terms; bin map plain and
    /// smoothed; position-normal Gaussians) built on degenerate and extreme maps, patched through
    /// degenerate footprints, queried with arbitrary directions: as an NDF, inside `MicrofacetBrdf`,
    /// and (position-normal) in its published BRDF.
    #[test]
    fn glint_models_are_total(
        map in any_map(), footprint in any_footprint(), smoothing in any_alpha(),
        wo in any_dir(), wi in any_dir(), uc in any_u(), u0 in any_u(), u1 in any_u(),
    ) {
        let u = Vec2::new(u0, u1);
        let mixture = BeckmannMixture::build(&map, quick_mixture_params()).unwrap();
        // Per-query options are not validated: hostile ones (NaN, negative, infinite) must be total too.
        let hostile = PatchOptions {
            masking: MaskingMode::Exact,
            lod_lobes: f32::NAN,
            lod_tolerance: f32::NAN,
            lod_resolution: -1.0,
            sub_texel_area: f32::NAN,
            filtered_area: f32::NAN,
            filtered_tolerance: f32::NAN,
            cut_nodes: u32::MAX,
            cut_tolerance: f32::NAN,
            cut_area: f32::NAN,
        };
        for options in [
            mixture_options(MaskingMode::Exact, f32::INFINITY),
            mixture_options(MaskingMode::Approximate, f32::INFINITY),
            mixture_options(MaskingMode::Exact, 0.0),
            mixture_options(MaskingMode::Approximate, -1.0),
            hostile,
            PatchOptions { lod_tolerance: f32::INFINITY, lod_resolution: f32::NAN, ..hostile },
            PatchOptions { cut_nodes: 1, cut_tolerance: -1.0, ..hostile },
            PatchOptions { cut_nodes: 0, ..hostile },
        ] {
            let patch = mixture.patch_with(&footprint, &options, None);
            check_ndf(&patch, wo, wi, uc, u);
            check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), wo, wi, uc, u);
        }
        let bin_map = BinMap::build(&map, small_bins()).unwrap();
        for patch in [bin_map.patch(&footprint), bin_map.patch_with(&footprint, &brdf::glint::binmap::PatchOptions { smoothing_alpha: smoothing, ..Default::default() }, None)] {
            check_ndf(&patch, wo, wi, uc, u);
            check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), wo, wi, uc, u);
        }
        let pn = PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
        let patch = pn.patch(&footprint);
        check_ndf(&patch, wo, wi, uc, u);
        check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), wo, wi, uc, u);
        check_bxdf(&PositionNormalBrdf::new(&patch, NoFresnel), wo, wi, uc, u);
    }
}
