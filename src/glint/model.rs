//! Any glint model behind one type: what a renderer's material list holds at run time.
//!
//! [`GlintNdf`] has a generic associated patch type, so it is not a trait object; a renderer that
//! chooses the model per material at run time (from a scene file, say) holds a [`GlintModel`]
//! instead, usually behind an `Arc` shared by the materials that use the same map. Its patch,
//! [`GlintPatch`], is an [`Ndf`] like every model's patch, so the one-line glint BRDF stays
//! `MicrofacetBrdf::new(model.patch(&footprint), fresnel)`.

use super::{
    BeckmannMixture, BinMap, BinMapPatch, Footprint, GlintNdf, GlintScratch, MixturePatch,
    PositionNormalMap, PositionNormalPatch,
};
use crate::ndf::Ndf;
use glam::{Vec2, Vec3};

/// One of the crate's glint models, chosen at run time.
///
/// # Example
/// ```
/// use std::sync::Arc;
/// use brdf::bxdf::{Bxdf, MicrofacetBrdf};
/// use brdf::fresnel::SchlickFresnel;
/// use brdf::glint::{BinMap, BinMapParams, Footprint, GlintModel, GlintNdf, GlintScratch};
/// use brdf::{Vec2, Vec3};
///
/// let map = brdf::glint::scratched(64, 64, Default::default(), 7)?;
/// let materials: Vec<Arc<GlintModel>> =
///     vec![Arc::new(BinMap::build(&map, BinMapParams::default())?.into())];
/// let mut scratch = GlintScratch::default(); // one per render thread
/// let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.7), 25.0, 64, 64);
/// let brdf = MicrofacetBrdf::new(
///     materials[0].patch_in(&fp, &mut scratch),
///     SchlickFresnel::new(Vec3::splat(0.9))?,
/// );
/// let f = brdf.eval(Vec3::new(0.3, 0.0, 0.954), Vec3::new(-0.3, 0.0, 0.954));
/// assert!(f.is_finite());
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum GlintModel {
    /// The Beckmann mixture of \[Chermain2019\] (its patch options as built).
    Mixture(BeckmannMixture),
    /// The inverse bin map of \[Atanasov2020\], one bin's resolution.
    BinMap(BinMap),
    /// The inverse bin map with every bin's mass spread by a Beckmann lobe of roughness `alpha`
    /// ([`BinMap::patch_smoothed`]).
    SmoothedBinMap {
        /// The bin map.
        map: BinMap,
        /// Beckmann roughness of the per-bin lobe.
        alpha: f32,
    },
    /// The position-normal Gaussians of \[Yan2016\] (the baseline).
    PositionNormal(PositionNormalMap),
}

impl From<BeckmannMixture> for GlintModel {
    fn from(m: BeckmannMixture) -> Self {
        GlintModel::Mixture(m)
    }
}

impl From<BinMap> for GlintModel {
    fn from(m: BinMap) -> Self {
        GlintModel::BinMap(m)
    }
}

impl From<PositionNormalMap> for GlintModel {
    fn from(m: PositionNormalMap) -> Self {
        GlintModel::PositionNormal(m)
    }
}

impl GlintModel {
    /// The model's name, for logs and charts.
    pub fn name(&self) -> &'static str {
        match self {
            GlintModel::Mixture(_) => "Beckmann mixture",
            GlintModel::BinMap(_) => "bin map",
            GlintModel::SmoothedBinMap { .. } => "smoothed bin map",
            GlintModel::PositionNormal(_) => "position-normal",
        }
    }
}

impl GlintNdf for GlintModel {
    type Patch<'a> = GlintPatch<'a>;

    fn patch(&self, footprint: &Footprint) -> GlintPatch<'_> {
        match self {
            GlintModel::Mixture(m) => GlintPatch::Mixture(m.patch(footprint)),
            GlintModel::BinMap(m) => GlintPatch::BinMap(m.patch(footprint)),
            GlintModel::SmoothedBinMap { map, alpha } => {
                GlintPatch::BinMap(map.patch_smoothed(footprint, *alpha))
            }
            GlintModel::PositionNormal(m) => GlintPatch::PositionNormal(m.patch(footprint)),
        }
    }

    fn patch_in<'a>(
        &'a self,
        footprint: &Footprint,
        scratch: &'a mut GlintScratch,
    ) -> GlintPatch<'a> {
        match self {
            GlintModel::Mixture(m) => GlintPatch::Mixture(m.patch_in(footprint, scratch)),
            GlintModel::BinMap(m) => GlintPatch::BinMap(m.patch_in(footprint, scratch)),
            GlintModel::SmoothedBinMap { map, alpha } => {
                GlintPatch::BinMap(map.patch_smoothed_in(footprint, *alpha, scratch))
            }
            GlintModel::PositionNormal(m) => {
                GlintPatch::PositionNormal(m.patch_in(footprint, scratch))
            }
        }
    }
}

/// The patch of a [`GlintModel`]: the P-NDF of one footprint, whichever model made it.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum GlintPatch<'a> {
    /// A [`MixturePatch`].
    Mixture(MixturePatch<'a>),
    /// A [`BinMapPatch`] (plain or smoothed).
    BinMap(BinMapPatch<'a>),
    /// A [`PositionNormalPatch`].
    PositionNormal(PositionNormalPatch<'a>),
}

/// Forwards one `Ndf` method to the variant's patch.
macro_rules! forward {
    ($self:ident, $p:ident => $e:expr) => {
        match $self {
            GlintPatch::Mixture($p) => $e,
            GlintPatch::BinMap($p) => $e,
            GlintPatch::PositionNormal($p) => $e,
        }
    };
}

impl Ndf for GlintPatch<'_> {
    #[inline]
    fn d(&self, m: Vec3) -> f32 {
        forward!(self, p => p.d(m))
    }
    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        forward!(self, p => p.lambda(w))
    }
    #[inline]
    fn projected_area(&self, w: Vec3) -> f32 {
        forward!(self, p => p.projected_area(w))
    }
    #[inline]
    fn visible_area(&self, w: Vec3) -> f32 {
        forward!(self, p => p.visible_area(w))
    }
    #[inline]
    fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        forward!(self, p => p.g1(w, m))
    }
    #[inline]
    fn g2(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        forward!(self, p => p.g2(wo, wi, m))
    }
    #[inline]
    fn g2_height_correlated(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        forward!(self, p => p.g2_height_correlated(wo, wi, m))
    }
    #[inline]
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        forward!(self, p => p.sample_normal(u))
    }
    #[inline]
    fn pdf_normal(&self, m: Vec3) -> f32 {
        forward!(self, p => p.pdf_normal(m))
    }
    #[inline]
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        forward!(self, p => p.sample_visible(wo, u))
    }
    #[inline]
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        forward!(self, p => p.pdf_visible(wo, m))
    }
}
