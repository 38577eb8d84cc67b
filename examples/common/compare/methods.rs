//! The glint methods compared, each behind [`Method`] (an object-safe view of
//! `brdf::glint::GlintNdf` plus the method's own BRDF), and [`builders`], the list the comparison
//! runs: the Beckmann mixture, the inverse bin map and the position-normal baseline, each given the
//! scene's σ_ε the way its paper allows ([`crate::common::material`]), and the bin map and the
//! position-normal baseline also at their papers' own σ ("paper default" rows).

use super::Settings;
use crate::common::Res;
use crate::common::material::{SIGMA_EPS, binmap_options, binmap_sigma};
use brdf::MicrofacetBrdf;
use brdf::bxdf::{Bxdf, Masking};
use brdf::fresnel::NoFresnel;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintNdf, NormalMap, PositionNormalBrdf, PositionNormalMap,
};
use brdf::ndf::Ndf;
use std::sync::Arc;

/// One glint method at one setting, object-safe: the patch of a footprint as `&(dyn Ndf + Sync)`, and the
/// method's BRDF for that footprint.
pub trait Method: Sync {
    /// Legend label, e.g. "mixture (exact)".
    fn label(&self) -> String;
    /// The slope σ of the material the method renders, read from the built method.
    fn sigma(&self) -> f32;
    /// For a paper's own setting kept beside the σ_ε-matched one, the paper's σ it was built with
    /// (its σ differs from the scene's on purpose, and its label says so); `None` for a method
    /// meant to render the scene's σ_ε.
    fn paper_default(&self) -> Option<f32> {
        None
    }
    /// Bytes held per texel of the map (the method's own structures).
    fn bytes_per_texel(&self) -> f64;
    /// Calls `f` with the footprint's patch.
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync)));
    /// Calls `f` with the footprint's BRDF (F = 1). Default: `MicrofacetBrdf` on the patch with
    /// separable G2 (\[Chermain2019\] eq. 7, 16).
    fn with_brdf(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Bxdf + Sync))) {
        self.with_patch(footprint, &mut |p| {
            f(&MicrofacetBrdf::new(p, NoFresnel).with_masking(Masking::Separable))
        });
    }
}

/// The Beckmann mixture with given patch options.
struct Mixture {
    mix: Arc<BeckmannMixture>,
    options: PatchOptions,
    label: &'static str,
}

impl Method for Mixture {
    fn label(&self) -> String {
        self.label.to_string()
    }
    fn sigma(&self) -> f32 {
        self.mix.params().sigma_min
    }
    /// Everything the built mixture holds (`memory().total()`): every row is the same model at
    /// other patch options, so they share its memory.
    fn bytes_per_texel(&self) -> f64 {
        let (w, h) = self.mix.map_size();
        self.mix.memory().total() as f64 / (w * h) as f64
    }
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync))) {
        f(&self.mix.patch_with(footprint, &self.options, None))
    }
}

/// Builds a method family from a map: the methods (settings sharing one build) and the build time.
pub type Builder = fn(&NormalMap, &Settings) -> Res<Vec<Box<dyn Method>>>;

/// The Beckmann mixture of \[Chermain2019\] with its lobe floor at the scene's σ_ε (the paper's
/// default): exact terms, approximate terms, the default level of detail (only when a footprint
/// exceeds it: otherwise it is the exact variant), and the single filtered Beckmann lobe (the
/// cheapest model).
fn mixture_methods(map: &NormalMap, _settings: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let params = MixtureParams {
        sigma_min: SIGMA_EPS,
        ..MixtureParams::default()
    };
    let mix = Arc::new(BeckmannMixture::build(map, params)?);
    // Tolerance 0 and no sub-texel lobe: these rows are the full mixture (or the filtered lobe),
    // not a level of detail.
    let opts = |masking, lod_lobes| PatchOptions {
        masking,
        lod_lobes,
        lod_tolerance: 0.0,
        sub_texel_area: 0.0,
        filtered_area: f32::INFINITY,
        cut_nodes: 0,
        ..PatchOptions::default()
    };
    let inf = f32::INFINITY;
    let m = |options, label| -> Box<dyn Method> {
        Box::new(Mixture {
            mix: mix.clone(),
            options,
            label,
        })
    };
    let mut methods = vec![
        m(opts(MaskingMode::Exact, inf), "mixture (exact)"),
        m(opts(MaskingMode::Approximate, inf), "mixture (approx.)"),
    ];
    methods.push(m(PatchOptions::default(), "mixture (defaults)"));
    methods.push(m(
        PatchOptions {
            sub_texel_area: f32::INFINITY,
            ..PatchOptions::default()
        },
        "sub-texel lobe",
    ));
    methods.push(m(opts(MaskingMode::Approximate, 0.0), "filtered lobe"));
    Ok(methods)
}

/// The inverse bin map of \[Atanasov2020\] at one bin count, its patches at one slope σ (0: the
/// one-bin resolution of the talk; > 0: every bin's mass spread by a Beckmann lobe of α = √2 σ).
struct BinMapMethod {
    map: Arc<BinMap>,
    options: brdf::glint::binmap::PatchOptions,
    /// The paper's σ for a "paper default" row.
    paper_sigma: Option<f32>,
}

impl Method for BinMapMethod {
    fn label(&self) -> String {
        let (n, s) = (self.map.params().bins_per_axis, self.map.subdivisions());
        if let Some(p) = self.paper_sigma {
            format!("bin map (B = {n}², s = {s}, σ = {p}, paper default)")
        } else {
            format!(
                "bin map (B = {n}², s = {s}, smoothed α = {:.4})",
                self.options.smoothing_alpha
            )
        }
    }
    fn sigma(&self) -> f32 {
        binmap_sigma(&self.map, &self.options)
    }
    fn paper_default(&self) -> Option<f32> {
        self.paper_sigma
    }
    fn bytes_per_texel(&self) -> f64 {
        self.map.memory().total() as f64 / (self.map.width() * self.map.height()) as f64
    }
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync))) {
        f(&self.map.patch_with(footprint, &self.options, None))
    }
}

/// The bin map at its default B = 255², s = 2, smoothed to the scene's σ_ε (α = √2 σ_ε) and, as the
/// paper default, unsmoothed; and the talk's map (127², one normal per texel), unsmoothed.
fn binmap_methods(map: &NormalMap, _: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let mut methods: Vec<Box<dyn Method>> = Vec::new();
    for (n, s) in [(255, 2), (127, 1)] {
        let params = BinMapParams {
            bins_per_axis: n,
            subdivisions: s,
            sigma_min: SIGMA_EPS,
            ..BinMapParams::default()
        };
        let bm = Arc::new(BinMap::build(map, params)?);
        // (σ, the paper's σ for a paper-default row): the talk's one-bin resolution is σ = 0.
        let rows: &[(f32, Option<f32>)] = if n == 255 {
            &[(SIGMA_EPS, None), (0.0, Some(0.0))]
        } else {
            &[(0.0, Some(0.0))]
        };
        for &(sigma, paper_sigma) in rows {
            methods.push(Box::new(BinMapMethod {
                map: bm.clone(),
                options: binmap_options(sigma),
                paper_sigma,
            }));
        }
    }
    Ok(methods)
}

/// The position-normal distributions of \[Yan2016\] (the baseline) at one sampling rate, with the BRDF
/// as published (a footprint-independent Smith term, cosines in the denominator).
struct PositionNormalMethod {
    map: Arc<PositionNormalMap>,
    /// The paper's σ_r for a "paper default" row.
    paper_sigma: Option<f32>,
}

impl Method for PositionNormalMethod {
    fn label(&self) -> String {
        let p = self.map.params();
        let default = if self.paper_sigma.is_some() {
            ", paper default"
        } else {
            ""
        };
        format!(
            "position-normal (rate {}, σ_r = {}{default}, published BRDF)",
            p.sampling_rate, p.sigma_r
        )
    }
    fn sigma(&self) -> f32 {
        self.map.params().sigma_r
    }
    fn paper_default(&self) -> Option<f32> {
        self.paper_sigma
    }
    fn bytes_per_texel(&self) -> f64 {
        let m = self.map.memory();
        let (w, h) = self.map.map_size();
        (m.element_bytes + m.hierarchy_bytes) as f64 / (w * h) as f64
    }
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync))) {
        f(&self.map.patch(footprint))
    }
    fn with_brdf(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Bxdf + Sync))) {
        f(&PositionNormalBrdf::new(
            self.map.patch(footprint),
            NoFresnel,
        ))
    }
}

/// The position-normal baseline with σ_r = σ_ε at its default rate (1 element per texel) and at
/// rate 2, and at rate 1 with the paper's σ_r = 0.005 (the paper default).
fn position_normal_methods(map: &NormalMap, _: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let mut methods: Vec<Box<dyn Method>> = Vec::new();
    let paper = PositionNormalParams::DEFAULT_SIGMA_R;
    for (rate, sigma_r, paper_sigma) in [
        (1, SIGMA_EPS, None),
        (2, SIGMA_EPS, None),
        (1, paper, Some(paper)),
    ] {
        let params = PositionNormalParams {
            sampling_rate: rate,
            sigma_r,
            ..PositionNormalParams::default()
        };
        methods.push(Box::new(PositionNormalMethod {
            map: Arc::new(PositionNormalMap::build(map, params)?),
            paper_sigma,
        }));
    }
    Ok(methods)
}

/// Every method family compared, with a name for the build-time table.
pub fn builders() -> Vec<(&'static str, Builder)> {
    vec![
        ("Beckmann mixture", mixture_methods as Builder),
        ("inverse bin map", binmap_methods as Builder),
        ("position-normal", position_normal_methods as Builder),
    ]
}
