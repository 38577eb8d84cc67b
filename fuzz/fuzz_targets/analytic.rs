//! The analytic NDFs and classic BRDFs with arbitrary parameters: construction refuses what it must,
//! and everything built is total on arbitrary directions.
#![no_main]

use arbitrary::Arbitrary;
use brdf::fresnel::{ConductorFresnel, DielectricFresnel, NoFresnel};
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, SlopeGaussian};
use brdf::{Lambert, Mat2, MicrofacetBrdf, Phong, PhongNormalization, Vec2, Vec3};
use brdf_fuzz::{Probe, check_bxdf, check_ndf};
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug)]
struct Input {
    alpha: (f32, f32),
    gamma: f32,
    mean: (f32, f32),
    cov: (f32, f32, f32),
    rho: (f32, f32),
    eta: f32,
    k: f32,
    normalization: u8,
    probe: Probe,
}

fuzz_target!(|input: Input| {
    let p = &input.probe;
    if let Ok(ndf) = Beckmann::new(input.alpha.0, input.alpha.1) {
        check_ndf(&ndf, p);
        check_bxdf(&MicrofacetBrdf::new(ndf, NoFresnel), p);
    }
    if let Ok(ndf) = Ggx::new(input.alpha.0, input.alpha.1) {
        check_ndf(&ndf, p);
        if let Ok(fresnel) = ConductorFresnel::new(Vec3::splat(input.eta), Vec3::splat(input.k)) {
            check_bxdf(&MicrofacetBrdf::new(ndf, fresnel), p);
        }
    }
    if let Ok(ndf) = BlinnPhong::new(input.gamma) {
        check_ndf(&ndf, p);
        if let Ok(fresnel) = DielectricFresnel::new(input.eta) {
            check_bxdf(&MicrofacetBrdf::new(ndf, fresnel), p);
        }
    }
    let cov = Mat2::from_cols_array(&[input.cov.0, input.cov.2, input.cov.2, input.cov.1]);
    if let Ok(ndf) = SlopeGaussian::new(Vec2::new(input.mean.0, input.mean.1), cov) {
        check_ndf(&ndf, p);
        check_bxdf(&MicrofacetBrdf::new(ndf, NoFresnel), p);
    }
    if let Ok(lambert) = Lambert::new(Vec3::splat(input.rho.0)) {
        check_bxdf(&lambert, p);
    }
    let normalization = match input.normalization % 5 {
        0 => PhongNormalization::Unnormalized,
        1 => PhongNormalization::EnergyConservingOriginal,
        2 => PhongNormalization::EnergyConserving,
        3 => PhongNormalization::EnergyNormalizedArvo,
        _ => PhongNormalization::EnergyNormalizedMallettYuksel,
    };
    if let Ok(phong) = Phong::new(
        Vec3::splat(input.rho.0),
        Vec3::splat(input.rho.1),
        input.gamma,
        normalization,
    ) {
        check_bxdf(&phong, p);
        check_bxdf(&phong.with_schlick_fresnel(), p);
    }
});
