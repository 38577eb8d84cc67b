//! Camera ray differentials and the step every renderer writes with them: the offset rays through
//! the neighbouring pixels intersected with the tangent plane at a hit, ∂p/∂x and ∂p/∂y, then the
//! footprint.
//!
//! # Reference
//! \[Igehy1999\] (ray differentials); pbrt-v4's `RayDifferential` and
//! `SurfaceInteraction::ComputeDifferentials` (\[Pharr2023\] §10.1.1), which this follows.

use super::footprint::{Footprint, finite_input};
use crate::{Error, Result};
use glam::{Vec2, Vec3};

/// A camera ray and its two offset rays, through the neighbouring pixels at x + 1 and y + 1, as
/// pbrt's `RayDifferential` holds them (origins and directions in world space; directions need not
/// be unit). Cheap to copy.
///
/// # Example
/// ```
/// use brdf::glint::RayDifferential;
/// use brdf::{Vec2, Vec3};
///
/// // A pinhole camera at the origin looking down −z, one pixel = 10⁻³ at unit distance.
/// let ray = RayDifferential {
///     origin: Vec3::ZERO,
///     direction: -Vec3::Z,
///     rx_origin: Vec3::ZERO,
///     rx_direction: Vec3::new(1e-3, 0.0, -1.0),
///     ry_origin: Vec3::ZERO,
///     ry_direction: Vec3::new(0.0, -1e-3, -1.0),
/// };
/// // It hits the plane z = −2, parametrised by u = x, v = y, at p = (0, 0, −2).
/// let fp = ray.scaled(0.5).footprint(
///     Vec2::new(0.5, 0.5),
///     Vec3::X,
///     Vec3::Y,
///     Vec3::new(0.0, 0.0, -2.0),
///     Vec3::Z,
/// );
/// assert!((fp.duv_dx().x - 1e-3).abs() < 1e-7);
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayDifferential {
    /// The camera ray's origin.
    pub origin: Vec3,
    /// The camera ray's direction.
    pub direction: Vec3,
    /// The origin of the ray through the pixel at x + 1.
    pub rx_origin: Vec3,
    /// The direction of the ray through the pixel at x + 1.
    pub rx_direction: Vec3,
    /// The origin of the ray through the pixel at y + 1.
    pub ry_origin: Vec3,
    /// The direction of the ray through the pixel at y + 1.
    pub ry_direction: Vec3,
}

impl RayDifferential {
    /// The offset rays moved toward the camera ray by `s`: o_x ← o + (o_x − o) s, d_x ← d +
    /// (d_x − d) s (the same for y). With s = 1/√(samples per pixel) the footprints of a pixel's
    /// samples tile it rather than each covering it whole (pbrt's `ScaleDifferentials`).
    pub fn scaled(self, s: f32) -> RayDifferential {
        let (o, d) = (self.origin, self.direction);
        RayDifferential {
            rx_origin: o + (self.rx_origin - o) * s,
            rx_direction: d + (self.rx_direction - d) * s,
            ry_origin: o + (self.ry_origin - o) * s,
            ry_direction: d + (self.ry_direction - d) * s,
            ..self
        }
    }

    /// ∂p/∂x and ∂p/∂y at a hit p of normal n: each offset ray o + t d intersected with the
    /// tangent plane n · (x − p) = 0, at t = n · (p − o) / n · d, minus p (computed in `f64`).
    ///
    /// Neither n nor the directions need be unit. An offset ray parallel to the plane (n · d = 0, at
    /// a silhouette), a zero normal, or non-finite input gives a zero differential for that offset;
    /// the footprint is then set by the other one (widened to [`MAX_ANISOTROPY`]) or is the minimal
    /// one. An offset ray that meets the plane behind its origin (t < 0) is used as it is, as pbrt
    /// does.
    ///
    /// [`MAX_ANISOTROPY`]: crate::glint::MAX_ANISOTROPY
    ///
    /// # Reference
    /// \[Igehy1999\] §3; pbrt-v4's `SurfaceInteraction::ComputeDifferentials`.
    pub fn surface_differentials(&self, p: Vec3, n: Vec3) -> (Vec3, Vec3) {
        let f = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (p, n) = (f(p), f(n));
        let offset = |o: Vec3, d: Vec3| {
            let (o, d) = (f(o), f(d));
            // p − o is exact in f64 (a difference of two f32 values).
            let t = dot(n, std::array::from_fn(|i| p[i] - o[i])) / dot(n, d);
            let dp = Vec3::from_array(std::array::from_fn(|i| (o[i] + d[i] * t - p[i]) as f32));
            if dp.is_finite() { dp } else { Vec3::ZERO }
        };
        (
            offset(self.rx_origin, self.rx_direction),
            offset(self.ry_origin, self.ry_direction),
        )
    }

    /// The footprint of the hit at `p` (normal `n`, texture coordinate `uv`, parametrisation
    /// ∂p/∂u = `dpdu`, ∂p/∂v = `dpdv`): [`RayDifferential::surface_differentials`], then
    /// [`Footprint::from_surface_differentials`] (the least-squares solve for ∂uv/∂x, ∂uv/∂y).
    /// Total: degenerate or non-finite input gives the fallbacks of those two (the minimal
    /// footprint), never NaN; [`RayDifferential::try_footprint`] reports non-finite input instead.
    pub fn footprint(&self, uv: Vec2, dpdu: Vec3, dpdv: Vec3, p: Vec3, n: Vec3) -> Footprint {
        let (dpdx, dpdy) = self.surface_differentials(p, n);
        Footprint::from_surface_differentials(uv, dpdu, dpdv, dpdx, dpdy)
    }

    /// [`RayDifferential::footprint`] that refuses non-finite input: the same footprint, bit for
    /// bit, when every argument and both offset rays are finite and `n` is not zero.
    ///
    /// # Errors
    /// [`Error::InvalidFootprint`] naming the first argument (or offset-ray field) that is not
    /// finite, or `n` if it is zero.
    pub fn try_footprint(
        &self,
        uv: Vec2,
        dpdu: Vec3,
        dpdv: Vec3,
        p: Vec3,
        n: Vec3,
    ) -> Result<Footprint> {
        finite_input("rx_origin", self.rx_origin)?;
        finite_input("rx_direction", self.rx_direction)?;
        finite_input("ry_origin", self.ry_origin)?;
        finite_input("ry_direction", self.ry_direction)?;
        finite_input("p", p)?;
        nonzero_normal(n)?;
        finite_input("uv", uv.extend(0.0))?;
        finite_input("dpdu", dpdu)?;
        finite_input("dpdv", dpdv)?;
        Ok(self.footprint(uv, dpdu, dpdv, p, n))
    }
}

/// `Ok` if `n` is finite and not zero, else [`Error::InvalidFootprint`] naming `n`.
pub(crate) fn nonzero_normal(n: Vec3) -> Result<()> {
    finite_input("n", n)?;
    if n == Vec3::ZERO {
        return Err(Error::InvalidFootprint {
            name: "n",
            value: n.to_array(),
            reason: "must not be zero",
        });
    }
    Ok(())
}
