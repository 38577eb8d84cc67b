//! A clear-coated material: any material of the crate under a smooth dielectric coat
//! ([`crate::bxdf::ClearCoat`]), e.g. car paint: metallic glint flakes over a paint base, under a
//! varnish.

use super::Material;
use crate::bxdf::{BaseAlbedo, ClearCoat};
use crate::error::{Error, Result};
use crate::glint::{Footprint, GlintScratch};
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// A material under a smooth dielectric clear coat of index η ([`ClearCoat`]): at each shading
/// point the inner material's BSDF (glints through their footprint, as without the coat) is
/// wrapped in the coat.
///
/// The coat needs the inner material's albedo and internal-reflection round trip
/// ([`BaseAlbedo`]); they are estimated once, here, from the inner material's BSDF at
/// [`ClearCoatMaterial::albedo_footprint`] ([`BaseAlbedo::estimate`], 1,536 samples), not per
/// shading point. For a glint material that is the patch of a whole uv period, whose P-NDF has
/// converged to the surface's mean: a single footprint's patch reflects more or less than that
/// mean, and the round trip of the mean is what the series uses for all of them.
#[derive(Clone, Debug)]
pub struct ClearCoatMaterial {
    inner: Arc<Material>,
    eta: f32,
    base_albedo: BaseAlbedo,
}

impl ClearCoatMaterial {
    /// `inner` under a clear coat of relative index `eta` (in (1, 3]; 1.5 for a typical
    /// varnish).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `eta` outside (1, 3], or naming `inner` when it is
    /// itself clear-coated (coats do not nest: one interface is modelled).
    pub fn new(inner: impl Into<Arc<Material>>, eta: f32) -> Result<ClearCoatMaterial> {
        let inner = inner.into();
        if matches!(*inner, Material::ClearCoat(_)) {
            return Err(Error::InvalidParameter {
                name: "inner",
                value: f64::NAN,
                reason: "must not be a clear-coated material",
            });
        }
        let scratch = GlintScratch::default();
        // Prepared for the normal view, the first of the estimate's directions.
        let bsdf = inner.uncoated_bsdf(&Self::albedo_footprint(), Vec3::Z, &scratch);
        let base_albedo = BaseAlbedo::estimate(&bsdf, eta);
        // Validates eta.
        ClearCoat::with_base_albedo(&bsdf, eta, base_albedo)?;
        drop(bsdf);
        Ok(ClearCoatMaterial {
            inner,
            eta,
            base_albedo,
        })
    }

    /// The footprint at which the inner material's albedo is estimated: centred on uv (½, ½),
    /// spreading over the whole unit square of uv (its differentials are (1, 0) and (0, 1)).
    pub fn albedo_footprint() -> Footprint {
        Footprint::from_differentials(Vec2::splat(0.5), Vec2::X, Vec2::Y)
    }

    /// The material under the coat.
    pub fn inner(&self) -> &Material {
        &self.inner
    }

    /// The coat's relative index η.
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// The inner material's albedo and round trip, as estimated at construction.
    pub fn base_albedo(&self) -> BaseAlbedo {
        self.base_albedo
    }
}
