//! Energy ≤ 1 (docs/robustness.md) for the physically based models, estimated by their own samplers
//! on random cases: the analytic microfacet BRDFs, Lambert, the energy-conserving Phong and
//! Blinn-Phong lobes, and `MicrofacetBrdf` over every glint model on random maps and footprints.

use crate::support;

use brdf::bxdf::{BlinnPhongNormalization, Masking, PhongNormalization, Sampling};
use brdf::fresnel::NoFresnel;
use brdf::glint::mixture::MaskingMode;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, BinMap, GlintNdf, PositionNormalMap};
use brdf::ndf::{Beckmann, Ggx, Ndf};
use brdf::{BlinnPhongLobe, Lambert, MicrofacetBrdf, Phong, Vec3};
use proptest::prelude::*;
use support::robustness::{
    albedo, any_alpha, any_footprint, any_map, assert_energy, grazing_dir, grazing_dir_from,
    mixture_options, quick_mixture_params, small_bins,
};

proptest! {
    #![proptest_config(support::proptest_config(48))]

    /// ∫ f cos θi ≤ 1 for the analytic microfacet BRDFs (F = 1, both G2 forms, D cos sampling so that
    /// the sample weights vary), Lambert, the energy-conserving and energy-normalised Phong and the
    /// energy-conserving Blinn-Phong lobe, with ρd + ρs ≤ 1, θo up to 89.99°.
    #[test]
    fn analytic_energy_at_most_one(
        alpha in any_alpha(), aniso in 0.25f32..=1.0, gamma in 0.0f32..1e3,
        rho_d in 0.0f32..=1.0, wo in grazing_dir(),
    ) {
        let cos = |w: Vec3| w.z.max(0.0);
        for masking in [Masking::Separable, Masking::HeightCorrelated] {
            let b = MicrofacetBrdf::new(Beckmann::new(alpha, alpha * aniso).unwrap(), NoFresnel)
                .with_masking(masking)
                .with_sampling(Sampling::Normals);
            assert_energy(&format!("beckmann α={alpha} {masking:?} wo={wo}"), albedo(&b, wo, &cos));
            let g = MicrofacetBrdf::new(Ggx::new(alpha, alpha * aniso).unwrap(), NoFresnel)
                .with_masking(masking)
                .with_sampling(Sampling::Normals);
            assert_energy(&format!("ggx α={alpha} {masking:?} wo={wo}"), albedo(&g, wo, &cos));
        }
        let (d, s) = (Vec3::splat(rho_d), Vec3::splat(1.0 - rho_d));
        assert_energy("lambert", albedo(&Lambert::new(Vec3::ONE).unwrap(), wo, &cos));
        for norm in [
            PhongNormalization::EnergyConservingOriginal,
            PhongNormalization::EnergyConserving,
            PhongNormalization::EnergyNormalizedMallettYuksel,
        ] {
            let p = Phong::new(d, s, gamma, norm).unwrap();
            assert_energy(&format!("phong {norm:?} γ={gamma} wo={wo}"), albedo(&p, wo, &cos));
        }
        let b = BlinnPhongLobe::new(d, s, gamma, BlinnPhongNormalization::EnergyConserving).unwrap();
        assert_energy(&format!("blinn-phong lobe γ={gamma} wo={wo}"), albedo(&b, wo, &cos));
    }

    /// ∫ f cos θi ≤ 1 with the geometric cosine (the renderer's measure, README "Conventions") for
    /// `MicrofacetBrdf` over the mixture with exact and approximate terms, the bin map (plain and
    /// smoothed) and the position-normal patch, on random maps and footprints, θo up to 89.9°, both
    /// G2 forms. The published position-normal BRDF (the baseline's known error) is left out.
    #[test]
    fn glint_energy_at_most_one(
        map in any_map(), footprint in any_footprint(), smoothing in 0.01f32..1.0,
        wo in grazing_dir_from(1.75e-3), // θo ≤ 89.9°
    ) {
        let mixture = BeckmannMixture::build(&map, quick_mixture_params()).unwrap();
        let exact = mixture_options(MaskingMode::Exact, f32::INFINITY);
        let approximate = mixture_options(MaskingMode::Approximate, f32::INFINITY);
        let bin_map = BinMap::build(&map, small_bins()).unwrap();
        let pn = PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
        let (mix, mix_approx, bins, smoothed, pnp) = (
            mixture.patch_with(&footprint, &exact, None),
            mixture.patch_with(&footprint, &approximate, None),
            bin_map.patch(&footprint),
            bin_map.patch_with(&footprint, &brdf::glint::binmap::PatchOptions { smoothing_alpha: smoothing, ..Default::default() }, None),
            pn.patch(&footprint),
        );
        let patches: [(&str, &dyn Ndf); 5] = [
            ("mixture", &mix), ("mixture approximate", &mix_approx), ("bin map", &bins),
            ("smoothed bin map", &smoothed), ("position-normal", &pnp),
        ];
        let cos = |w: Vec3| w.z.max(0.0);
        for (name, patch) in patches {
            for masking in [Masking::Separable, Masking::HeightCorrelated] {
                let b = MicrofacetBrdf::new(patch, NoFresnel).with_masking(masking);
                assert_energy(&format!("{name} {masking:?} wo={wo}"), albedo(&b, wo, &cos));
            }
        }
    }
}
