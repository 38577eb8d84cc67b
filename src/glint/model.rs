//! Any glint model behind one type: what a renderer's material list holds at run time, and the one
//! registry of the crate's glint models.
//!
//! [`GlintNdf`] has a generic associated patch type, so it is not a trait object; a renderer that
//! chooses the model per material at run time (from a scene file, say) holds a [`GlintModel`]
//! instead, usually behind an `Arc` shared by the materials that use the same map. Its patch,
//! [`GlintPatch`], is an [`Ndf`](crate::ndf::Ndf) like every model's patch, so the one-line glint BRDF stays
//! `MicrofacetBrdf::new(model.patch(&footprint), fresnel)`.
//!
//! The `glint_models!` invocation at the end of this file is the registry: one line per model
//! generates its [`GlintModel`] and [`GlintPatch`] variants, its [`GlintOptions`] field, the `From`
//! conversion, and the save / load dispatch (which requires the model to implement the crate's file
//! format).

use super::io::format::{Kind, Stored};
use super::io::header;
use super::{
    BeckmannMixture, BinMap, Footprint, GlintNdf, GlintScratch, PositionNormalMap, ProceduralGlints,
};
use crate::bxdf::AlbedoEstimate;
use crate::error::{Error, Result};
use crate::ndf::forward_ndf;
use glam::{Vec2, Vec3};
use std::io::{Read, Write};

/// Generates [`GlintModel`], [`GlintPatch`], [`GlintOptions`] and their impls from one line per
/// model: `Variant(ModelType), options_field, "display name";`.
macro_rules! glint_models {
    ($( $(#[$doc:meta])* $variant:ident($model:ty), $field:ident, $name:literal; )+) => {
        /// One of the crate's glint models, chosen at run time.
        ///
        /// # Example
        /// ```
        /// use std::sync::Arc;
        /// use brdf::bxdf::{Bxdf, MicrofacetBrdf};
        /// use brdf::fresnel::SchlickFresnel;
        /// use brdf::glint::binmap::BinMapParams;
        /// use brdf::glint::{BinMap, Footprint, GlintModel, GlintNdf, GlintScratch};
        /// use brdf::{Vec2, Vec3};
        ///
        /// let map = brdf::glint::scratched(64, 64, Default::default(), 7)?;
        /// let materials: Vec<Arc<GlintModel>> =
        ///     vec![Arc::new(BinMap::build(&map, BinMapParams::default())?.into())];
        /// let scratch = GlintScratch::default(); // one per render thread
        /// let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.7), 25.0, 64, 64);
        /// let brdf = MicrofacetBrdf::new(
        ///     materials[0].patch_in(&fp, &scratch),
        ///     SchlickFresnel::new(Vec3::splat(0.9))?,
        /// );
        /// let f = brdf.eval(Vec3::new(0.3, 0.0, 0.954), Vec3::new(-0.3, 0.0, 0.954));
        /// assert!(f.is_finite());
        /// # Ok::<(), brdf::Error>(())
        /// ```
        #[derive(Clone, Debug)]
        #[non_exhaustive]
        pub enum GlintModel {
            $( $(#[$doc])* $variant($model), )+
        }

        /// The patch of a [`GlintModel`]: the P-NDF of one footprint, whichever model made it.
        #[derive(Clone, Debug)]
        #[non_exhaustive]
        // The patches are held by value: boxing the largest would allocate per shading point.
        #[allow(clippy::large_enum_variant)]
        pub enum GlintPatch<'a> {
            $(
                #[doc = concat!("The patch of a [`GlintModel::", stringify!($variant), "`].")]
                $variant(<$model as GlintNdf>::Patch<'a>),
            )+
        }

        /// Per-query options of a [`GlintModel`]'s patches: one field per model, each that model's
        /// own options type; a patch uses the field of its model. `Default` gives every model's
        /// documented defaults (what [`GlintNdf::patch`] uses). Kept by the renderer with its
        /// material and passed to every query: no model or file holds options.
        #[derive(Clone, Debug, Default)]
        #[non_exhaustive]
        pub struct GlintOptions {
            $(
                #[doc = concat!("Options of [`GlintModel::", stringify!($variant), "`] patches.")]
                pub $field: <$model as GlintNdf>::Options,
            )+
        }

        $(
            impl From<$model> for GlintModel {
                fn from(m: $model) -> Self {
                    GlintModel::$variant(m)
                }
            }
        )+

        /// The estimate of the model that made the patch (src/glint/compensation.rs).
        impl AlbedoEstimate for GlintPatch<'_> {
            fn albedo_estimate(&self, wo: Vec3) -> f32 {
                match self {
                    $( GlintPatch::$variant(p) => p.albedo_estimate(wo), )+
                }
            }
        }

        impl GlintPatch<'_> {
            /// Prepares the patch for the view direction `wo` (shading frame): what every query at
            /// that wo shares (the exact V(wo), and the bin map's visible normalisation), computed
            /// here once by the variant's own `prepare_view`; queries at any other view compute
            /// their own, and every value is the unprepared patch's, bit for bit. `Material::bsdf`
            /// calls it with the shading point's wo; a renderer that builds patches itself calls
            /// it once per shading point before its `eval_pdf` and `sample` queries.
            pub fn prepare_view(&mut self, wo: Vec3) {
                match self {
                    $( GlintPatch::$variant(p) => p.prepare_view(wo), )+
                }
            }

            /// The form of the patch (which of its model's levels of detail serves it, and
            /// whether its work grows with the footprint): the variant's own `form`.
            pub fn form(&self) -> super::PatchForm {
                match self {
                    $( GlintPatch::$variant(p) => p.form(), )+
                }
            }
        }

        impl GlintModel {
            /// The names of the registered models, in registry order (for logs, charts and
            /// completeness tests).
            pub const NAMES: &'static [&'static str] = &[$($name),+];

            /// The model's name, for logs and charts.
            pub fn name(&self) -> &'static str {
                match self {
                    $( GlintModel::$variant(_) => $name, )+
                }
            }

            /// Writes the model in the crate's file format (docs/format.md): the same bytes as the
            /// model's own `save`.
            ///
            /// # Errors
            /// [`Error::Stream`].
            pub fn save(&self, w: &mut impl Write) -> Result<()> {
                match self {
                    $( GlintModel::$variant(m) => <$model as Stored>::save_to(m, w), )+
                }
            }

            /// Reads whichever glint model a file holds (written by [`GlintModel::save`] or by a
            /// model's own `save`), with every check of that model's `load`. The header is judged
            /// as every loader judges it (docs/format.md, "Damaged or unsupported"): foreign bytes
            /// are [`Error::BadMagic`], a damaged header [`Error::CorruptHeader`].
            ///
            /// # Errors
            /// [`Error::WrongModelKind`] for an intact file of no glint model (a normal map, say),
            /// and every error of the model's `load`.
            pub fn load(r: &mut impl Read) -> Result<Self> {
                let kinds = [$(<$model as Stored>::KINDS),+].concat();
                let header = header::read_header(r, &kinds, "glint model")?;
                let mut whole = (&header.bytes[..]).chain(r);
                $(
                    if <$model as Stored>::KINDS.contains(&header.kind) {
                        return <$model as Stored>::load_from(&mut whole).map(GlintModel::$variant);
                    }
                )+
                Err(Error::WrongModelKind {
                    expected: "glint model".into(),
                    found: Kind::name(header.kind as u32),
                })
            }

            /// The size of the normal map the model was built from, (width, height) in texels:
            /// the texels a footprint is measured in ([`GlintModel::footprint_texels`]).
            pub fn map_size(&self) -> (usize, usize) {
                match self {
                    $( GlintModel::$variant(m) => m.map_size(), )+
                }
            }

            /// Texels per unit of uv along u and v, (width, height): the scale that turns a
            /// footprint's ∂uv/∂x, ∂uv/∂y into texels (texels per pixel = |det(D ∂uv/∂x,
            /// D ∂uv/∂y)| with D = diag(texel_scale), before the footprint's clamps).
            pub fn texel_scale(&self) -> Vec2 {
                let (w, h) = self.map_size();
                Vec2::new(w as f32, h as f32)
            }

            /// The area of `footprint` in texels of the model's map, as the model sees it (with
            /// the footprint's clamps: [`Footprint::area_texels`]). For a footprint made from one
            /// pixel's ray differentials this is the texels per pixel that the docs' guides and
            /// charts are given in.
            pub fn footprint_texels(&self, footprint: &Footprint) -> f32 {
                let (w, h) = self.map_size();
                footprint.area_texels(w, h)
            }
        }

        impl GlintNdf for GlintModel {
            type Patch<'a> = GlintPatch<'a>;
            type Options = GlintOptions;

            fn patch_with<'a>(
                &'a self,
                footprint: &Footprint,
                options: &GlintOptions,
                scratch: Option<&'a GlintScratch>,
            ) -> GlintPatch<'a> {
                match self {
                    $(
                        GlintModel::$variant(m) => {
                            GlintPatch::$variant(m.patch_with(footprint, &options.$field, scratch))
                        }
                    )+
                }
            }
        }

        /// Forwards one `Ndf` method to the variant's patch.
        macro_rules! forward {
            ($self_:ident, $p:ident => $e:expr) => {
                match $self_ {
                    $( GlintPatch::$variant($p) => $e, )+
                }
            };
        }
    };
}

glint_models! {
    /// The Beckmann mixture of \[Chermain2019\] ([`crate::glint::mixture`]).
    Mixture(BeckmannMixture), mixture, "Beckmann mixture";
    /// The inverse bin map of \[Atanasov2020\] ([`crate::glint::binmap`]).
    BinMap(BinMap), bin_map, "bin map";
    /// The position-normal Gaussians of \[Yan2016\], the baseline ([`crate::glint::position_normal`]).
    PositionNormal(PositionNormalMap), position_normal, "position-normal";
    /// Procedural glints without a normal map ([`crate::glint::procedural`]).
    Procedural(ProceduralGlints), procedural, "procedural";
}

forward_ndf!(['a] GlintPatch<'a>, forward);
