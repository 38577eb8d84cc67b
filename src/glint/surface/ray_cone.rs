//! Ray cones: footprints for secondary rays, where a renderer has no ray differentials.
//!
//! A ray cone follows one ray with two numbers: its width w (the side of the square cross-section
//! one pixel's rays cover, in scene units) and its spread angle γ (the full angle at which w grows
//! per unit distance). Camera rays start with w = 0 and γ = the angle of one pixel
//! ([`RayCone::pixel_spread`]); then, per path segment and vertex:
//!
//! 1. travel a distance t: w ← |w + γ t| ([`RayCone::propagate`]);
//! 2. at the hit, read the footprint ([`RayCone::footprint`]): the cross-section projected along the
//!    ray onto the tangent plane, then [`Footprint::from_surface_differentials`];
//! 3. leave the surface along a sampled direction: [`RayCone::bounce`], the one rule below.
//!
//! **The rule at a bounce** ([`RayCone::bounce`]), the same for every lobe:
//! 1. the curvature step, always: γ ← γ + 2 κ w with κ = 1/radius, positive where the surface
//!    bends away from the ray (convex), 0 on a flat surface ([`RayCone::reflect`]);
//! 2. then the roughness step, unless the sample is a delta lobe's ([`LobeFlags::SPECULAR`]): for a
//!    sample of density p, γ ← γ + the full angle of a cone of solid angle 1/p
//!    ([`RayCone::scatter`]).
//!
//! So at a **delta** bounce (a mirror) only the curvature step applies: the sample's pdf is a
//! convention, not a density, and a mirror adds no spread of its own. (The curvature step is a
//! reflection's; a ray refracted through a curved interface spreads otherwise, which the cone does
//! not model.) At a
//! **smooth** bounce (a glossy lobe of small roughness) both apply and the roughness step is small
//! (it scales as α, below), so the cone tends to the mirror's as α → 0. At a **rough** bounce (large
//! α, Lambert) both apply and the roughness step dominates (at least 2π/3 for Lambert).
//!
//! Why both at a non-delta bounce: the two spreads have different causes and their full angles add.
//! Across the footprint's width w the surface normal turns by κ w, so the mirror directions of the
//! footprint's points fan out over 2 κ w whatever the lobe; a lobe then spreads each point's
//! reflection over its own cone around that point's mirror direction. The beam leaving the
//! footprint covers the union of those cones, whose full angle is the sum of the two (to first
//! order), as for any two supports swept one along the other. The cone's spread is such a full
//! angle, not a standard deviation (which would add in quadrature). Dropping the curvature step at
//! rough bounces would make the cone jump down when a mirror is replaced by a lobe of tiny α;
//! dropping the roughness step would make rough bounces as sharp as mirrors.
//!
//! The width is the diameter of \[AkenineMoller2019\] and the spread the full cone angle of
//! \[AkenineMoller2019\] and \[AkenineMoller2021\] (the refraction chapter of Ray Tracing Gems II uses
//! half angles). The curvature term is first order and exact for a mirror at normal incidence; at
//! incidence θ a real mirror spreads the beam by 2κw/cos θ in the plane of incidence and by
//! 2κw cos θ across it, and the cone keeps one isotropic value, their geometric mean 2κw (the
//! reflected beam's area is right, its shape is not): tests/it/ray_cone.rs checks both against exact
//! ray differentials on a sphere.
//!
//! **Roughness rule.** The papers widen the cone at a rough surface by a term that grows with the
//! BRDF's roughness. Here the term comes from the sampled direction's pdf: a sample of density p per
//! steradian stands for the solid angle Ω = 1/p around it, and a cone of full angle γ covers the
//! solid angle 2π (1 − cos(γ/2)), so γ_BRDF = 2 acos(1 − Ω/2π) (≤ π: a cone wider than the hemisphere
//! a reflection leaves into means nothing here). It needs no roughness parameter, so it serves every
//! [`Bxdf`](crate::bxdf::Bxdf) of the crate alike (glint patches, layered, Lambert, whose density
//! ≤ 1/π adds at least 2π/3); for a microfacet lobe of roughness α the pdf near the peak scales as 1/α², so the added
//! spread scales as α, the roughness widening the papers describe; a near-mirror (huge p) adds
//! nothing. The same density-to-angle rule is what NVIDIA's RTX path tracer applies per scatter
//! event.
//!
//! # Reference
//! \[AkenineMoller2019\] (ray cones: width and spread propagation, the curvature term);
//! \[AkenineMoller2021\] §3 (curvature approximations, preferring underestimated spread in a Monte
//! Carlo path tracer); \[Igehy1999\] (the ray differentials tests compare against).

use super::footprint::{Footprint, finite_input};
use super::ray_differential::nonzero_normal;
use crate::Result;
use crate::bxdf::{BxdfSample, LobeFlags};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A ray cone: width (scene units) and full spread angle (radians) of the beam one pixel's rays
/// form around a ray. Cheap to copy. See the module docs for the propagation rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCone {
    width: f32,
    spread: f32,
}

/// The spread angle is kept in [−π, π]: a negative spread (a beam focused by a concave mirror)
/// shrinks the width until it refocuses; beyond π the linear growth w + γ t means nothing.
const MAX_SPREAD: f32 = PI;

/// A finite value or 0.
fn finite_or_zero(x: f32) -> f32 {
    if x.is_finite() { x } else { 0.0 }
}

impl RayCone {
    /// A cone of `width` (its magnitude is used) and full spread angle `spread` (clamped to
    /// [−π, π]). Non-finite values become 0.
    pub fn new(width: f32, spread: f32) -> RayCone {
        RayCone {
            width: finite_or_zero(width).abs(),
            spread: finite_or_zero(spread).clamp(-MAX_SPREAD, MAX_SPREAD),
        }
    }

    /// The cone of a camera ray: width 0 at the eye, spread `pixel_spread` (see
    /// [`RayCone::pixel_spread`]; scale it by 1/√(samples per pixel) as the footprint recipe does
    /// for ray differentials).
    pub fn from_camera(pixel_spread: f32) -> RayCone {
        RayCone::new(0.0, pixel_spread)
    }

    /// The angle one pixel subtends at the centre of a pinhole camera of vertical field of view
    /// `fov_y` (radians) and `height` pixels: atan(2 tan(fov_y/2) / height). 0 for a zero height or
    /// non-finite input.
    ///
    /// # Reference
    /// \[AkenineMoller2019\] (the camera's spread angle).
    pub fn pixel_spread(fov_y: f32, height: u32) -> f32 {
        if height == 0 {
            return 0.0;
        }
        finite_or_zero((2.0 * (0.5 * fov_y).tan() / height as f32).atan())
    }

    /// The width, ≥ 0.
    #[inline]
    pub fn width(&self) -> f32 {
        self.width
    }

    /// The full spread angle, in [−π, π].
    #[inline]
    pub fn spread(&self) -> f32 {
        self.spread
    }

    /// The cone after travelling `distance` along its ray: w' = |w + γ t| (a focused beam passes
    /// through its focus and widens again). A negative or non-finite distance counts as 0.
    ///
    /// # Reference
    /// \[AkenineMoller2019\] (width propagation).
    pub fn propagate(self, distance: f32) -> RayCone {
        let t = finite_or_zero(distance).max(0.0);
        RayCone::new(self.width + self.spread * t, self.spread)
    }

    /// The cone after a mirror reflection at a surface of curvature `curvature` (1/radius; > 0
    /// convex, bending away from the incoming ray, as a sphere seen from outside; < 0 concave; 0
    /// flat): γ' = γ + 2 κ w. Non-finite curvature counts as 0.
    ///
    /// First order in w κ; exact at normal incidence, the geometric mean of the in-plane and
    /// cross-plane spreads at oblique incidence (module docs).
    ///
    /// # Reference
    /// \[AkenineMoller2019\] (the surface spread angle β of a reflection).
    pub fn reflect(self, curvature: f32) -> RayCone {
        let k = finite_or_zero(curvature);
        RayCone::new(self.width, self.spread + 2.0 * k * self.width)
    }

    /// The cone after scattering into a direction sampled with density `pdf` (per steradian, the
    /// [`BxdfSample::pdf`](crate::bxdf::BxdfSample)): γ' = γ + [`RayCone::scatter_spread`]`(pdf)`.
    pub fn scatter(self, pdf: f32) -> RayCone {
        RayCone::new(self.width, self.spread + RayCone::scatter_spread(pdf))
    }

    /// The cone after leaving a surface of curvature `curvature` along `sample` (a BRDF's sample
    /// at the hit): the rule at a bounce (module docs), [`RayCone::reflect`]`(curvature)`, then
    /// [`RayCone::scatter`]`(sample.pdf)` unless the sample is a delta lobe's
    /// ([`LobeFlags::SPECULAR`]). Call it after [`RayCone::propagate`] and the footprint read at the
    /// hit.
    ///
    /// # Reference
    /// \[AkenineMoller2019\] (the curvature step); the roughness step is the module docs' own rule.
    pub fn bounce(self, curvature: f32, sample: &BxdfSample) -> RayCone {
        let reflected = self.reflect(curvature);
        if sample.flags.contains(LobeFlags::SPECULAR) {
            reflected
        } else {
            reflected.scatter(sample.pdf)
        }
    }

    /// The spread a rough BRDF adds for a sample of density `pdf`: the full angle of the cone of
    /// solid angle Ω = 1/pdf, 2 acos(1 − Ω/2π), at most π (Ω ≥ 2π, or pdf ≤ 0 or non-finite, which
    /// carries no information about the lobe's width). A near-specular sample (pdf → ∞) adds 0.
    pub fn scatter_spread(pdf: f32) -> f32 {
        if pdf == f32::INFINITY {
            return 0.0;
        }
        let omega = 1.0 / pdf;
        if !pdf.is_finite() || pdf <= 0.0 || omega >= 2.0 * PI {
            return MAX_SPREAD;
        }
        2.0 * (1.0 - omega / (2.0 * PI)).acos()
    }

    /// The cone's cross-section at a hit, as the two edges ∂p/∂x, ∂p/∂y of the parallelogram it
    /// covers on the tangent plane (what ray differentials give; world units): a square of side w
    /// perpendicular to the ray direction `dir`, projected along `dir` onto the plane of normal `n`.
    /// One edge is w along n × dir (in the plane already); the other is stretched by 1/|cos θ|
    /// (clamped at 10⁶: grazing footprints are clamped by [`Footprint`] anyway). Neither `dir` nor
    /// `n` need be unit; degenerate or non-finite ones give zero edges (the minimal footprint).
    pub fn surface_differentials(&self, dir: Vec3, n: Vec3) -> (Vec3, Vec3) {
        let (Some(d), Some(n)) = (dir.try_normalize(), n.try_normalize()) else {
            return (Vec3::ZERO, Vec3::ZERO);
        };
        let a = n
            .cross(d)
            .try_normalize()
            .unwrap_or_else(|| d.any_orthonormal_vector());
        let b = d.cross(a);
        let cos = n.dot(d);
        let cos = if cos.abs() < 1e-6 {
            1e-6f32.copysign(cos)
        } else {
            cos
        };
        let b = b - d * (n.dot(b) / cos);
        (a * self.width, b * self.width)
    }

    /// The footprint of the cone at a hit: [`Footprint::from_surface_differentials`] of the
    /// surface's `uv`, ∂p/∂u, ∂p/∂v and the edges of [`RayCone::surface_differentials`]`(dir, n)`.
    /// Any handedness of (∂p/∂u, ∂p/∂v); degenerate input gives the minimal footprint, never NaN
    /// ([`RayCone::try_footprint`] reports non-finite input instead).
    pub fn footprint(&self, uv: Vec2, dpdu: Vec3, dpdv: Vec3, dir: Vec3, n: Vec3) -> Footprint {
        let (dpdx, dpdy) = self.surface_differentials(dir, n);
        Footprint::from_surface_differentials(uv, dpdu, dpdv, dpdx, dpdy)
    }

    /// [`RayCone::footprint`] that refuses non-finite input: the same footprint, bit for bit, when
    /// every argument is finite and `dir` and `n` are not zero. (The cone itself is always finite:
    /// its constructors and steps replace non-finite values, as their docs say.)
    ///
    /// # Errors
    /// [`Error::InvalidFootprint`](crate::Error::InvalidFootprint) naming the first of `uv`,
    /// `dpdu`, `dpdv`, `dir`, `n` that is not finite, or `dir` or `n` if it is zero.
    pub fn try_footprint(
        &self,
        uv: Vec2,
        dpdu: Vec3,
        dpdv: Vec3,
        dir: Vec3,
        n: Vec3,
    ) -> Result<Footprint> {
        finite_input("uv", uv.extend(0.0))?;
        finite_input("dpdu", dpdu)?;
        finite_input("dpdv", dpdv)?;
        finite_input("dir", dir)?;
        if dir == Vec3::ZERO {
            return Err(crate::Error::InvalidFootprint {
                name: "dir",
                value: dir.to_array(),
                reason: "must not be zero",
            });
        }
        nonzero_normal(n)?;
        Ok(self.footprint(uv, dpdu, dpdv, dir, n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn total_on_bad_input() {
        let c = RayCone::new(f32::NAN, f32::INFINITY);
        assert_eq!((c.width(), c.spread()), (0.0, 0.0));
        let c = RayCone::new(-2.0, 10.0);
        assert_eq!((c.width(), c.spread()), (2.0, PI));
        assert_eq!(RayCone::new(1.0, 0.1).propagate(f32::NAN).width(), 1.0);
        assert_eq!(RayCone::new(1.0, 0.1).reflect(f32::NAN).spread(), 0.1);
        for pdf in [0.0, -1.0, f32::NAN, 1e-3] {
            assert_eq!(RayCone::scatter_spread(pdf), PI);
        }
        assert_eq!(RayCone::scatter_spread(f32::INFINITY), 0.0);
        let (a, b) = RayCone::new(1.0, 0.0).surface_differentials(Vec3::ZERO, Vec3::Z);
        assert_eq!((a, b), (Vec3::ZERO, Vec3::ZERO));
        let (a, b) = RayCone::new(1.0, 0.0).surface_differentials(Vec3::X, Vec3::Z);
        assert!(a.is_finite() && b.is_finite());
        assert_eq!(RayCone::pixel_spread(1.0, 0), 0.0);
    }

    #[test]
    fn scatter_spread_covers_the_solid_angle() {
        // Ω = 1/p; the cone of full angle γ covers 2π (1 − cos(γ/2)).
        for pdf in [0.2f32, 1.0, 10.0, 1e4] {
            let g = RayCone::scatter_spread(pdf);
            let omega = 2.0 * PI * (1.0 - (0.5 * g).cos());
            assert!((omega * pdf - 1.0).abs() < 1e-3, "{pdf}: {omega}");
        }
        // Lambert's largest density, 1/π, owns π sr: a cone of full angle 2π/3.
        assert!((RayCone::scatter_spread(1.0 / PI) - 2.0 * PI / 3.0).abs() < 1e-5);
    }

    #[test]
    fn normal_incidence_cross_section_is_the_square() {
        let (a, b) = RayCone::new(0.5, 0.0).surface_differentials(-Vec3::Z, Vec3::Z);
        assert!((a.length() - 0.5).abs() < 1e-6 && (b.length() - 0.5).abs() < 1e-6);
        assert!(a.dot(b).abs() < 1e-6 && a.z == 0.0 && b.z.abs() < 1e-6);
        // 60°: one edge stretched by 1/cos = 2.
        let d = Vec3::new(3f32.sqrt() / 2.0, 0.0, -0.5);
        let (a, b) = RayCone::new(0.5, 0.0).surface_differentials(d, Vec3::Z);
        let (lo, hi) = (a.length().min(b.length()), a.length().max(b.length()));
        assert!(
            (lo - 0.5).abs() < 1e-5 && (hi - 1.0).abs() < 1e-5,
            "{a} {b}"
        );
        assert!(a.z.abs() < 1e-6 && b.z.abs() < 1e-6);
    }
}
