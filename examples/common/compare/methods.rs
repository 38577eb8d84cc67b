//! The glint methods compared, each behind [`Method`] (an object-safe view of
//! `brdf::glint::GlintNdf` plus the method's own BRDF), and [`builders`], the list the comparison
//! runs: the Beckmann mixture, the inverse bin map and the position-normal baseline.

use super::Settings;
use crate::common::Res;
use brdf::MicrofacetBrdf;
use brdf::bxdf::{Bxdf, Masking};
use brdf::fresnel::NoFresnel;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{DEFAULT_LOD_LOBES, MaskingMode, MixtureParams, PatchOptions};
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
    /// Only the moment mip chain counts (the filtered lobe alone needs nothing else).
    mip_only: bool,
}

impl Method for Mixture {
    fn label(&self) -> String {
        self.label.to_string()
    }
    fn bytes_per_texel(&self) -> f64 {
        let m = self.mix.memory();
        let (w, h) = self.mix.map_size();
        let bytes = if self.mip_only {
            m.mip_bytes
        } else {
            m.lobe_bytes + m.hierarchy_bytes + m.mip_bytes
        };
        bytes as f64 / (w * h) as f64
    }
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync))) {
        f(&self.mix.patch_with(footprint, &self.options, None))
    }
}

/// Builds a method family from a map: the methods (settings sharing one build) and the build time.
pub type Builder = fn(&NormalMap, &Settings) -> Res<Vec<Box<dyn Method>>>;

/// The Beckmann mixture of \[Chermain2019\] at its defaults: exact terms, approximate terms, the
/// default level of detail (only when a footprint exceeds it: otherwise it is the exact variant),
/// and the single filtered Beckmann lobe (the cheapest model).
fn mixture_methods(map: &NormalMap, settings: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let mix = Arc::new(BeckmannMixture::build(map, MixtureParams::default())?);
    // Tolerance 0: these rows are the full mixture (or the filtered lobe), not a level of detail.
    let opts = |masking, lod_lobes| PatchOptions {
        masking,
        lod_lobes,
        lod_tolerance: 0.0,
        ..PatchOptions::default()
    };
    let inf = f32::INFINITY;
    let m = |options, label, mip_only| -> Box<dyn Method> {
        Box::new(Mixture {
            mix: mix.clone(),
            options,
            label,
            mip_only,
        })
    };
    let mut methods = vec![
        m(opts(MaskingMode::Exact, inf), "mixture (exact)", false),
        m(
            opts(MaskingMode::Approximate, inf),
            "mixture (approx.)",
            false,
        ),
    ];
    if settings.areas.iter().any(|&a| a > DEFAULT_LOD_LOBES) {
        methods.push(m(PatchOptions::default(), "mixture (default LOD)", false));
    }
    methods.push(m(
        opts(MaskingMode::Approximate, 0.0),
        "filtered lobe",
        true,
    ));
    Ok(methods)
}

/// The inverse bin map of \[Atanasov2020\] at one bin count, optionally smoothed by a Beckmann lobe.
struct BinMapMethod {
    map: Arc<BinMap>,
    /// Beckmann α of the smoothed variant (`None`: one-bin resolution, the talk's model).
    smoothing: Option<f32>,
}

impl Method for BinMapMethod {
    fn label(&self) -> String {
        let (n, s) = (self.map.params().bins_per_axis, self.map.subdivisions());
        match self.smoothing {
            None => format!("bin map (B = {n}², s = {s})"),
            Some(a) => format!("bin map (B = {n}², s = {s}, smoothed α = {a})"),
        }
    }
    fn bytes_per_texel(&self) -> f64 {
        self.map.memory().total() as f64 / (self.map.width() * self.map.height()) as f64
    }
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync))) {
        match self.smoothing {
            None => f(&self.map.patch(footprint)),
            Some(a) => f(&self.map.patch_with(
                footprint,
                &brdf::glint::binmap::PatchOptions { smoothing_alpha: a },
                None,
            )),
        }
    }
}

/// The bin map at B = 63², 127² and 255² (the default) with the default sub-texel resolution
/// (s = 2), the talk's one normal per texel (127², s = 1), and 127², s = 2 smoothed by α = 0.02
/// (the smoothed cost grows with (n α)², so it is shown at 127² rather than the default 255²).
fn binmap_methods(map: &NormalMap, _: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let mut methods: Vec<Box<dyn Method>> = Vec::new();
    for (n, s) in [(63, 2), (127, 1), (127, 2), (255, 2)] {
        let params = BinMapParams {
            bins_per_axis: n,
            subdivisions: s,
            ..BinMapParams::default()
        };
        let bm = Arc::new(BinMap::build(map, params)?);
        methods.push(Box::new(BinMapMethod {
            map: bm.clone(),
            smoothing: None,
        }));
        if n == 127 && s == 2 {
            methods.push(Box::new(BinMapMethod {
                map: bm,
                smoothing: Some(0.02),
            }));
        }
    }
    Ok(methods)
}

/// The position-normal distributions of \[Yan2016\] (the baseline) at one sampling rate, with the BRDF
/// as published (a footprint-independent Smith term, cosines in the denominator).
struct PositionNormalMethod {
    map: Arc<PositionNormalMap>,
}

impl Method for PositionNormalMethod {
    fn label(&self) -> String {
        format!(
            "position-normal (rate {}, published BRDF)",
            self.map.params().sampling_rate
        )
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

/// The position-normal baseline at its default rate (1 element per texel) and at rate 2.
fn position_normal_methods(map: &NormalMap, _: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let mut methods: Vec<Box<dyn Method>> = Vec::new();
    for rate in [1, 2] {
        let params = PositionNormalParams {
            sampling_rate: rate,
            ..PositionNormalParams::default()
        };
        methods.push(Box::new(PositionNormalMethod {
            map: Arc::new(PositionNormalMap::build(map, params)?),
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
