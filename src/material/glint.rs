//! A glint material: a glint model with its per-query options, its Fresnel term, the map's
//! placement on the surface and an optional Lambertian base under the glint layer.

use super::AnyFresnel;
use crate::error::{Error, Result};
use crate::glint::{Footprint, GlintModel, GlintOptions};
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// A glint microfacet material ([`GlintModel`] + [`GlintOptions`] + Fresnel), shaded per footprint
/// as `MicrofacetBrdf::new(model.patch_with(footprint, options, scratch), fresnel)`, or as that
/// layer over a Lambertian base ([`crate::bxdf::LayeredBrdf`]) when [`GlintMaterial::over_base`]
/// is set.
///
/// The model is shared (`Arc`): cloning the material, or making several materials of one map
/// (other Fresnel terms, other options), copies no map data. The options are the per-query
/// options of the model's patches, held by the material, never by the model or its file;
/// [`GlintMaterial::new`] starts from the defaults ([`GlintOptions::default`]).
///
/// **Placement.** The footprint given to [`Material::bsdf`](super::Material::bsdf) is in the
/// surface's (u, v); the map covers the unit square of uv scaled by [`GlintMaterial::uv_scale`]
/// (a scale of (4, 2) repeats the map 4 times along u and twice along v), so the model sees the
/// footprint `(uv, ∂uv/∂x, ∂uv/∂y) × scale`.
#[derive(Clone, Debug)]
pub struct GlintMaterial {
    model: Arc<GlintModel>,
    options: GlintOptions,
    fresnel: AnyFresnel,
    uv_scale: Vec2,
    base: Option<Vec3>,
    /// F_avg of the Fresnel term when the energy compensation is on
    /// ([`GlintMaterial::with_energy_compensation`]).
    compensation: Option<Vec3>,
}

impl GlintMaterial {
    /// `model` with the default per-query options and `fresnel`, the map once over the unit uv
    /// square, no base.
    pub fn new(model: impl Into<Arc<GlintModel>>, fresnel: impl Into<AnyFresnel>) -> GlintMaterial {
        let model = model.into();
        GlintMaterial {
            options: GlintOptions::default(),
            model,
            fresnel: fresnel.into(),
            uv_scale: Vec2::ONE,
            base: None,
            compensation: None,
        }
    }

    /// The same material with the energy its patches' single scattering loses given back
    /// ([`crate::bxdf::ViewCompensated`]: a Lambertian lobe F_ms (1 − E(wo))/π, E each patch's own
    /// albedo estimate toward the shading point's wo; beside the base term when the glints are a
    /// layer over a base, [`crate::bxdf::LayeredBrdf::with_energy_compensation`]). Opt-in like
    /// [`crate::bxdf::EnergyCompensated`]: a compensated glint surface's white furnace is flat in θo
    /// (within the estimate's error, docs/results.md "Energy compensation of glint patches")
    /// instead of darkening toward grazing views; not reciprocal. Costs one pass over the patch's
    /// lobes per shading point. F_avg is computed here, once.
    pub fn with_energy_compensation(mut self) -> GlintMaterial {
        self.compensation = Some(crate::bxdf::average_fresnel(&self.fresnel));
        self
    }

    /// The same material with per-query `options` (level of detail, masking, smoothing: see each
    /// model's `PatchOptions`).
    pub fn with_options(mut self, options: GlintOptions) -> GlintMaterial {
        self.options = options;
        self
    }

    /// The same material with the map repeated `scale.x` times along u and `scale.y` times along v.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `uv_scale` unless both components are finite and > 0.
    pub fn with_uv_scale(mut self, scale: Vec2) -> Result<GlintMaterial> {
        self.uv_scale = checked_uv_scale(scale)?;
        Ok(self)
    }

    /// The same material as a glint layer over a Lambertian base of RGB albedo `base`
    /// ([`crate::bxdf::LayeredBrdf`]: light the layer transmits reaches the base).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `base` unless every channel is finite and in [0, 1].
    pub fn over_base(mut self, base: Vec3) -> Result<GlintMaterial> {
        self.base = Some(crate::bxdf::unit_rgb("base", base)?);
        Ok(self)
    }

    /// The glint model.
    pub fn model(&self) -> &GlintModel {
        &self.model
    }

    /// The per-query options.
    pub fn options(&self) -> &GlintOptions {
        &self.options
    }

    /// The Fresnel term.
    pub fn fresnel(&self) -> AnyFresnel {
        self.fresnel
    }

    /// How many times the map repeats along u and v.
    pub fn uv_scale(&self) -> Vec2 {
        self.uv_scale
    }

    /// The Fresnel average F_avg the energy compensation uses, if it is on
    /// ([`GlintMaterial::with_energy_compensation`]).
    pub fn energy_compensation(&self) -> Option<Vec3> {
        self.compensation
    }

    /// The Lambertian base's albedo, if the glints are a layer over one.
    pub fn base(&self) -> Option<Vec3> {
        self.base
    }

    /// The footprint in the map's uv: `footprint` (surface uv) scaled by [`GlintMaterial::uv_scale`].
    pub fn map_footprint(&self, footprint: &Footprint) -> Footprint {
        let s = self.uv_scale;
        Footprint::from_differentials(
            footprint.center_uv() * s,
            footprint.duv_dx() * s,
            footprint.duv_dy() * s,
        )
    }
}

/// `scale` if both components are finite and > 0; [`Error::InvalidParameter`] naming `uv_scale`
/// otherwise.
pub(super) fn checked_uv_scale(scale: Vec2) -> Result<Vec2> {
    for s in [scale.x, scale.y] {
        if !(s.is_finite() && s > 0.0) {
            return Err(Error::InvalidParameter {
                name: "uv_scale",
                value: s as f64,
                reason: "must be finite and > 0",
            });
        }
    }
    Ok(scale)
}
