//! A normal-mapped material: a footprint-independent material shaded about the normal a
//! [`NormalMap`] gives at the shading point's uv, through one of the crate's shading-normal
//! adapters.

use super::Material;
use crate::bxdf::ShadingNormal;
use crate::error::{Error, Result};
use crate::glint::{Footprint, NormalMap};
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// Which shading-normal adapter a [`NormalMappedMaterial`] uses (docs/bxdf.md, "Normal mapping").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum NormalMapping {
    /// Microfacet-based normal mapping ([`crate::bxdf::NormalMapMicrofacet`], \[Schussler2017\]):
    /// energy conserving, reciprocal, never black at grazing views. The default.
    #[default]
    Microfacet,
    /// Conventional normal mapping ([`crate::bxdf::NormalMapTilt`]): the base BRDF about the
    /// shading normal with the shading cosine, black below either horizon (what most renderers do).
    Tilt,
}

/// A base material shaded about the interpolated normal of a normal map at the shading point
/// ([`NormalMap::normal_at`] at the footprint's centre, in the map's uv), through a
/// [`NormalMapping`] adapter. The map and the base are shared (`Arc`).
///
/// The map's tangent-space normal is read in the local shading frame (x along ∂p/∂u, y along
/// ∂p/∂v, z the normal). Where the map's normal is not strictly above the geometric horizon (only
/// possible for an unrepaired map), the base is shaded about the geometric normal.
#[derive(Clone, Debug)]
pub struct NormalMappedMaterial {
    map: Arc<NormalMap>,
    base: Arc<Material>,
    mapping: NormalMapping,
    uv_scale: Vec2,
}

impl NormalMappedMaterial {
    /// `base` shaded about the normals of `map` with the default adapter
    /// ([`NormalMapping::Microfacet`]), the map once over the unit uv square.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `base` when the base depends on the footprint itself
    /// (a glint or an already normal-mapped material): a glint model already resolves the
    /// normal map, and adapters do not nest; or when it is clear-coated (a coat is flat over
    /// its base: put the normal-mapped material under the coat instead).
    pub fn new(
        map: impl Into<Arc<NormalMap>>,
        base: impl Into<Arc<Material>>,
    ) -> Result<NormalMappedMaterial> {
        let base = base.into();
        if base.uses_footprint() || matches!(*base, Material::ClearCoat(_)) {
            return Err(Error::InvalidParameter {
                name: "base",
                value: f64::NAN,
                reason: "must not be a glint, normal-mapped or clear-coated material",
            });
        }
        Ok(NormalMappedMaterial {
            map: map.into(),
            base,
            mapping: NormalMapping::default(),
            uv_scale: Vec2::ONE,
        })
    }

    /// The same material with another adapter.
    pub fn with_mapping(mut self, mapping: NormalMapping) -> NormalMappedMaterial {
        self.mapping = mapping;
        self
    }

    /// The same material with the map repeated `scale.x` times along u and `scale.y` times along v.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `uv_scale` unless both components are finite and > 0.
    pub fn with_uv_scale(mut self, scale: Vec2) -> Result<NormalMappedMaterial> {
        self.uv_scale = super::glint::checked_uv_scale(scale)?;
        Ok(self)
    }

    /// The normal map.
    pub fn map(&self) -> &NormalMap {
        &self.map
    }

    /// The base material.
    pub fn base(&self) -> &Material {
        &self.base
    }

    /// The adapter.
    pub fn mapping(&self) -> NormalMapping {
        self.mapping
    }

    /// How many times the map repeats along u and v.
    pub fn uv_scale(&self) -> Vec2 {
        self.uv_scale
    }

    /// The shading normal at `footprint`'s centre, or `None` where the map's normal is not
    /// strictly above the horizon.
    pub fn shading_normal(&self, footprint: &Footprint) -> Option<ShadingNormal> {
        let n: Vec3 = self.map.normal_at(footprint.center_uv() * self.uv_scale);
        ShadingNormal::new(n, None).ok()
    }
}
