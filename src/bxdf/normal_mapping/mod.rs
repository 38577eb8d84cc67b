//! Shading-normal adapters: a BxDF evaluated about a shading normal (from a normal or bump map)
//! that differs from the geometric normal z of the local frame.
//!
//! Two adapters wrap any inner [`Bxdf`](super::Bxdf) and take the same validated
//! [`ShadingNormal`]:
//! - [`NormalMapTilt`], conventional normal mapping: the inner BxDF in the frame whose z is the
//!   shading normal, with the shading cosine, zero below either horizon (what pbrt-v4 and Mitsuba 3
//!   do). It loses energy and turns black where the view or the light is below the shading horizon.
//! - [`NormalMapMicrofacet`], microfacet-based normal mapping (\[Schussler2017\]): the shading normal
//!   becomes one facet ω_p of a two-facet microsurface whose other facet ω_t (perpendicular to ω_p,
//!   vertical) makes the mean normal the geometric one; light reaches ω_p directly or after a mirror
//!   bounce on ω_t. Reciprocal, energy conserving, no black regions; `eval` holds the walk's
//!   single-scattering paths, and over a Lambertian inner the whole walk in closed form (opt-in).
//!
//! docs/bxdf.md, "Normal mapping", compares them and gives the energy figures.

mod microfacet;
mod tilt;

pub use microfacet::NormalMapMicrofacet;
pub use tilt::NormalMapTilt;

use crate::error::{Error, Result};
use crate::frame::{Frame, normalize_robust};
use glam::Vec3;

/// A shading normal in the local geometric frame (z = geometric normal), with the tangent frame the
/// inner BxDF is evaluated in.
///
/// The normal is normalised at construction (interpolated and decoded normals are rarely unit; any
/// finite non-zero vector is accepted) and must then lie strictly above the geometric horizon
/// (z > 0): a shading normal at or below the horizon has no microsurface interpretation and is
/// rejected. The tangent (default: the geometric x axis) is made orthogonal to the normal
/// (Gram-Schmidt); it sets the axis along which an anisotropic inner BxDF's `alpha_x` acts. A
/// tangent parallel to the normal falls back to a continuous arbitrary one ([`Frame::from_normal`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingNormal {
    frame: Frame,
}

impl ShadingNormal {
    /// A shading normal `normal` with an optional `tangent`, both in the local geometric frame.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `normal` when it is not finite, has zero length, or its
    /// normalised z is not > 0; naming `tangent` when it is not finite.
    pub fn new(normal: Vec3, tangent: Option<Vec3>) -> Result<ShadingNormal> {
        let bad = |value: f32, reason| Error::InvalidParameter {
            name: "normal",
            value: value as f64,
            reason,
        };
        if !normal.is_finite() {
            return Err(bad(
                normal.max_element().max(-normal.min_element()),
                "must be finite",
            ));
        }
        let n = normalize_robust(normal).ok_or_else(|| bad(0.0, "must have a non-zero length"))?;
        if n.z <= 0.0 {
            return Err(bad(
                n.z,
                "normalised z must be > 0 (strictly above the geometric horizon)",
            ));
        }
        let t = tangent.unwrap_or(Vec3::X);
        if !t.is_finite() {
            return Err(Error::InvalidParameter {
                name: "tangent",
                value: t.max_element() as f64,
                reason: "must be finite",
            });
        }
        Ok(ShadingNormal {
            frame: Frame::from_normal_tangent(n, t),
        })
    }

    /// The unit shading normal (local geometric frame).
    pub fn normal(&self) -> Vec3 {
        self.frame.z
    }

    /// The shading frame: x = tangent, y = bitangent, z = shading normal, in the geometric frame.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// A direction of the geometric frame in the shading frame.
    #[inline]
    pub(crate) fn to_shading(self, w: Vec3) -> Vec3 {
        self.frame.to_local(w)
    }

    /// A direction of the shading frame in the geometric frame.
    #[inline]
    pub(crate) fn to_geometric(self, w: Vec3) -> Vec3 {
        self.frame.to_world(w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validates_and_normalises() {
        let s = ShadingNormal::new(Vec3::new(0.0, 3.0, 4.0), None).unwrap();
        assert!((s.normal() - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6);
        assert!((s.frame().x - Vec3::X).length() < 1e-6);
        for bad in [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.5, -0.1),
            Vec3::new(f32::NAN, 0.0, 1.0),
        ] {
            let e = ShadingNormal::new(bad, None).unwrap_err();
            assert!(e.to_string().contains("normal"), "{e}");
        }
        let e = ShadingNormal::new(Vec3::Z, Some(Vec3::splat(f32::INFINITY))).unwrap_err();
        assert!(e.to_string().contains("tangent"), "{e}");
        // A tangent along the normal falls back to an arbitrary orthonormal one.
        let s = ShadingNormal::new(Vec3::Z, Some(Vec3::Z)).unwrap();
        assert!(s.frame().x.dot(Vec3::Z).abs() < 1e-6);
    }
}
