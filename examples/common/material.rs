//! The one material every method of the orb and compare harnesses renders: the interpolated normal
//! map with intrinsic roughness σ_ε, each position's slope spread by the isotropic slope Gaussian
//! N(0, σ_ε² I) (\[Chermain2019\] §5.2.2, σ_ε = 0.01), and how each glint model is given that σ_ε the
//! way its paper allows:
//!
//! - the Beckmann mixture (\[Chermain2019\] §3.2): the lobes' slope σ floored at σ_ε
//!   (`MixtureParams::sigma_min`). A floor, not a convolution: a lobe whose own σ is s has
//!   max(s, σ_ε) where the material has √(s² + σ_ε²), so a lobe with s ≈ σ_ε is up to √2 narrower;
//!   flat regions (s ≪ σ_ε) and wide lobes (s ≫ σ_ε) are exact;
//! - the inverse bin map (\[Atanasov2020\], smoothing of the authors' later full paper): every bin's
//!   mass spread by a Beckmann lobe of α = √2 σ_ε (`binmap::PatchOptions::smoothing_alpha`; the
//!   patch takes slope σ = α/√2, the same per-axis slope σ), and its masking lobe floored at σ_ε
//!   (`BinMapParams::sigma_min`). The lobe sits at the bin's centre, so
//!   the bin's own width is added to σ_ε rather than removed (near the pole a bin of n² is about
//!   √(2π)/n wide in slope, a uniform spread of σ ≈ √(π/6)/n: 2.8·10⁻³ at n = 255, 5.7·10⁻³ at
//!   127, so the default 255² renders √(σ_ε² + (2.8·10⁻³)²) ≈ 1.04 σ_ε);
//! - the position-normal distribution (\[Yan2016\]): the elements' intrinsic σ_r = σ_ε. Both are
//!   per-axis slope standard deviations in this crate (the paper states σ_r for projected normals,
//!   equal to slopes at the pole: docs/position_normal.md), so the match is exact up to the
//!   linearisation of the slope field;
//! - naive sampling and both references take σ_ε as an argument (`footprint_brdf`).
//!
//! Where a paper's own default differs (the bin map's one-bin resolution σ = 0, Yan's σ_r = 0.005
//! as rendered in \[Atanasov2020\] Fig. 1), the harnesses also show that variant, labelled
//! "paper default", beside the matched one.

use brdf::glint::binmap::{BinMapParams, PatchOptions as BinMapOptions};
use brdf::glint::{
    BinMap, Footprint, GlintModel, GlintNdf, GlintOptions, GlintPatch, GlintScratch,
};
use brdf::{Vec2, ndf::DEFAULT_SIGMA_MIN};
use std::sync::Arc;

/// σ_ε of the scene: the per-axis slope standard deviation of the material's micro-roughness
/// (\[Chermain2019\] §5.2.2).
pub const SIGMA_EPS: f32 = DEFAULT_SIGMA_MIN;

/// Beckmann roughness of a slope Gaussian of per-axis standard deviation σ: α = √2 σ (the slope
/// density of Beckmann α is N(0, α²/2 I)).
pub fn beckmann_alpha(sigma: f32) -> f32 {
    std::f32::consts::SQRT_2 * sigma
}

/// The bin map's per-query options that give its patches the slope σ `sigma` (0: one-bin resolution).
pub fn binmap_options(sigma: f32) -> BinMapOptions {
    BinMapOptions {
        smoothing_alpha: beckmann_alpha(sigma),
        ..BinMapOptions::default()
    }
}

/// The bin map of `map` at its default B and s with its masking lobe floored at σ = `sigma`
/// (`BinMapParams::sigma_min`): the harnesses' matched bin map, before its per-query smoothing
/// ([`binmap_options`]).
pub fn binmap_at(map: &brdf::glint::NormalMap, sigma: f32) -> brdf::Result<Arc<GlintModel>> {
    let params = BinMapParams {
        sigma_min: sigma,
        ..BinMapParams::default()
    };
    Ok(Arc::new(BinMap::build(map, params)?.into()))
}

/// The slope σ a bin map's patches carry with `options`, read back from a patch (0 for the one-bin
/// resolution).
pub fn binmap_sigma(map: &BinMap, options: &BinMapOptions) -> f32 {
    let fp = Footprint::isotropic_texels(Vec2::splat(0.5), 4.0, map.width(), map.height());
    map.patch_with(&fp, options, None)
        .smoothing_alpha()
        .map_or(0.0, |a| a / std::f32::consts::SQRT_2)
}

/// The slope σ of the material a [`GlintModel`] renders with `options`, read from the built model
/// (the mixture's lobe floor, the position-normal elements' σ_r, the procedural facets' α_f/√2) or
/// from one of its patches (the bin map's smoothing lobes).
pub fn model_sigma(model: &GlintModel, options: &GlintOptions) -> f32 {
    let fp = Footprint::isotropic_texels(Vec2::splat(0.5), 4.0, 64, 64);
    let scratch = GlintScratch::default();
    match model.patch_with(&fp, options, Some(&scratch)) {
        GlintPatch::Mixture(_) => match model {
            GlintModel::Mixture(m) => m.params().sigma_min,
            _ => f32::NAN,
        },
        GlintPatch::BinMap(p) => p
            .smoothing_alpha()
            .map_or(0.0, |a| a / std::f32::consts::SQRT_2),
        GlintPatch::PositionNormal(_) => match model {
            GlintModel::PositionNormal(m) => m.params().sigma_r,
            _ => f32::NAN,
        },
        GlintPatch::Procedural(_) => match model {
            GlintModel::Procedural(m) => m.params().facet_alpha / std::f32::consts::SQRT_2,
            _ => f32::NAN,
        },
        _ => f32::NAN,
    }
}

/// A [`GlintModel`] seen with fixed per-query options (the bin map's smoothing, the mixture's level
/// of detail), so that each configuration is a [`GlintNdf`] of its own.
#[derive(Clone, Debug)]
pub struct Configured {
    /// The model (shared by its configurations).
    pub model: Arc<GlintModel>,
    /// The options of its patches.
    pub options: GlintOptions,
}

impl Configured {
    /// `model` with the default per-query options.
    pub fn new(model: Arc<GlintModel>) -> Configured {
        Configured {
            model,
            options: GlintOptions::default(),
        }
    }

    /// A bin map whose patches carry slope σ `sigma` (0: the one-bin resolution).
    pub fn binmap(map: Arc<GlintModel>, sigma: f32) -> Configured {
        let mut c = Configured::new(map);
        c.options.bin_map = binmap_options(sigma);
        c
    }

    /// The slope σ of the material it renders ([`model_sigma`]).
    pub fn sigma(&self) -> f32 {
        model_sigma(&self.model, &self.options)
    }
}

impl GlintNdf for Configured {
    type Patch<'b>
        = GlintPatch<'b>
    where
        Self: 'b;

    /// The configured options: a query takes none of its own.
    type Options = ();

    fn patch_with<'b>(
        &'b self,
        footprint: &Footprint,
        _options: &(),
        scratch: Option<&'b GlintScratch>,
    ) -> GlintPatch<'b> {
        self.model.patch_with(footprint, &self.options, scratch)
    }
}

/// Whether two slope σ agree to f32 rounding (σ_ε goes through α = √2 σ and back).
pub fn same_sigma(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-6 * b.abs().max(1e-6)
}
