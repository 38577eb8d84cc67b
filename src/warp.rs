//! Warps: maps from the unit square [0, 1]² onto the disk, the hemisphere, a cone and the plane, each
//! given as a triad — `square_to_*` (sample), `pdf_*` (its density) and `*_to_square` (its inverse).
//!
//! Conventions shared by every warp here:
//! - Inputs `u` are meant to lie in [0, 1)²; they are clamped into [0, 1]² first (NaN counts as 0), so
//!   that 0, 1 − ε, 1 and values slightly outside the square never produce NaN.
//! - Directions are unit vectors in the local frame (z = normal, see [`crate::frame`]); the inverses
//!   normalise their argument first and map zero-length or non-finite input to a documented point.
//! - Densities of directions are per unit solid angle; densities of points in the plane are per unit
//!   area. A density is 0 outside the warp's image and for non-finite input.
//!
//! The equal-area square ↔ hemisphere map ([`square_to_hemisphere_equal_area`]) is the one to use when
//! cells of a grid on the square must be regions of equal solid angle (hemisphere bins).

#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use core::f32::consts::{FRAC_1_PI, FRAC_PI_4, TAU};
use glam::{Vec2, Vec3};

/// The largest `f32` below 1 (1 − 2⁻²⁴): the upper end of a random number in [0, 1).
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Solid angle per unit area of the square under [`square_to_hemisphere_equal_area`]: 2π sr.
///
/// A region of area a in the unit square maps to a region of solid angle 2π·a on the hemisphere.
pub const EQUAL_AREA_SOLID_ANGLE_PER_AREA: f32 = TAU;

const INV_TAU: f32 = 1.0 / TAU;

/// Clamps into [0, 1]; NaN becomes 0.
#[inline]
fn clamp01(x: f32) -> f32 {
    if x > 0.0 { x.min(1.0) } else { 0.0 }
}

/// The azimuth φ = atan2(y, x) of a point as a fraction of a turn, in [0, 1].
#[inline]
fn azimuth_fraction(x: f32, y: f32) -> f32 {
    let f = y.atan2(x) * INV_TAU;
    clamp01(if f < 0.0 { f + 1.0 } else { f })
}

/// A point of the concentric disk in polar form, with 1 − r kept separately for precision near the rim.
struct DiskPolar {
    r: f32,
    one_minus_r: f32,
    cos_phi: f32,
    sin_phi: f32,
}

/// The Shirley–Chiu concentric map in polar form.
///
/// With (a, b) = 2u − 1: where |a| ≥ |b| the radius is |a| and the point is a·(cos ψ, sin ψ) with
/// ψ = (π/4)·b/a; elsewhere the radius is |b| and the point is b·(sin ψ, cos ψ) with ψ = (π/4)·a/b.
/// 1 − r = 1 − |2u − 1| = 2 min(u, 1 − u) is computed from u, without cancellation.
#[inline]
fn concentric_polar(u: Vec2) -> DiskPolar {
    let (ux, uy) = (clamp01(u.x), clamp01(u.y));
    let (a, b) = (2.0 * ux - 1.0, 2.0 * uy - 1.0);
    if a == 0.0 && b == 0.0 {
        return DiskPolar {
            r: 0.0,
            one_minus_r: 1.0,
            cos_phi: 1.0,
            sin_phi: 0.0,
        };
    }
    if a.abs() >= b.abs() {
        let (s, c) = (FRAC_PI_4 * (b / a)).sin_cos();
        let sign = a.signum();
        DiskPolar {
            r: a.abs(),
            one_minus_r: 2.0 * ux.min(1.0 - ux),
            cos_phi: sign * c,
            sin_phi: sign * s,
        }
    } else {
        let (s, c) = (FRAC_PI_4 * (a / b)).sin_cos();
        let sign = b.signum();
        DiskPolar {
            r: b.abs(),
            one_minus_r: 2.0 * uy.min(1.0 - uy),
            cos_phi: sign * s,
            sin_phi: sign * c,
        }
    }
}

/// Maps the unit square onto the unit disk with uniform density (Shirley–Chiu concentric map).
///
/// With (a, b) = 2u − 1: if |a| ≥ |b|, p = a·(cos ψ, sin ψ) with ψ = (π/4)·b/a; otherwise
/// p = b·(sin ψ, cos ψ) with ψ = (π/4)·a/b. The map is continuous, area-preserving up to the factor π
/// (Jacobian π/4 in (a, b)), sends concentric squares to concentric circles, the square's boundary to
/// the unit circle and (½, ½) to the centre.
///
/// Degenerate cases: `u` is clamped into [0, 1]² (NaN → 0).
///
/// # Reference
/// \[ShirleyChiu1997\] (the concentric map; the two-branch form above is the equivalent one without
/// the quadrant cases).
#[inline]
pub fn square_to_concentric_disk(u: Vec2) -> Vec2 {
    let d = concentric_polar(u);
    Vec2::new(d.r * d.cos_phi, d.r * d.sin_phi)
}

/// Inverse of [`square_to_concentric_disk`]: the point of [0, 1]² that maps to `p`.
///
/// If |x| ≥ |y|: a = sign(x)·‖p‖, b = a·atan(y/x)/(π/4); otherwise b = sign(y)·‖p‖,
/// a = b·atan(x/y)/(π/4); u = (a + 1, b + 1)/2.
///
/// Degenerate cases: points outside the disk are first moved radially onto the unit circle; the centre,
/// and non-finite input, give (½, ½).
///
/// # Reference
/// \[ShirleyChiu1997\].
#[inline]
pub fn concentric_disk_to_square(p: Vec2) -> Vec2 {
    if !p.is_finite() {
        return Vec2::splat(0.5);
    }
    let r = p.length().min(1.0);
    if r == 0.0 {
        return Vec2::splat(0.5);
    }
    let (a, b) = if p.x.abs() >= p.y.abs() {
        let a = r.copysign(p.x);
        (a, a * (p.y / p.x).atan() / FRAC_PI_4)
    } else {
        let b = r.copysign(p.y);
        (b * (p.x / p.y).atan() / FRAC_PI_4, b)
    };
    Vec2::new(clamp01(0.5 * (a + 1.0)), clamp01(0.5 * (b + 1.0)))
}

/// Density of [`square_to_concentric_disk`] per unit area: 1/π inside the unit disk, 0 outside.
///
/// The test is ‖p‖² ≤ 1 + 4ε (ε = `f32::EPSILON`), so that every point the sampler returns, whose norm
/// may exceed 1 by a rounding error, has density 1/π. Non-finite input gives 0.
///
/// # Reference
/// \[ShirleyChiu1997\].
#[inline]
pub fn pdf_concentric_disk(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 + 4.0 * f32::EPSILON {
        FRAC_1_PI
    } else {
        0.0
    }
}

/// Cosine-weighted direction on the upper hemisphere (Malley's method on the concentric disk).
///
/// p = [`square_to_concentric_disk`]`(u)`, ω = (p.x, p.y, √(1 − ‖p‖²)); density cos θ / π. The
/// square's boundary maps to the horizon (z = 0, density 0) and (½, ½) to the pole.
///
/// Degenerate cases: `u` is clamped into [0, 1]² (NaN → 0).
///
/// # Reference
/// \[Malley1988\] (project a uniform disk point onto the hemisphere); \[ShirleyChiu1997\] for the disk.
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_polar(u);
    // 1 − r² = (1 − r)(1 + r): accurate near the horizon, where r → 1.
    let z = (d.one_minus_r * (1.0 + d.r)).max(0.0).sqrt();
    Vec3::new(d.r * d.cos_phi, d.r * d.sin_phi, z)
}

/// Inverse of [`square_to_cosine_hemisphere`]: [`concentric_disk_to_square`] of (ω.x, ω.y).
///
/// Degenerate cases: `w` is normalised first; its z sign is ignored, so a direction below the horizon
/// maps to the point of its mirror image (x, y, −z). Zero-length or non-finite `w` gives (½, ½).
///
/// # Reference
/// \[Malley1988\], \[ShirleyChiu1997\].
#[inline]
pub fn cosine_hemisphere_to_square(w: Vec3) -> Vec2 {
    match w.try_normalize() {
        Some(w) => concentric_disk_to_square(Vec2::new(w.x, w.y)),
        None => Vec2::splat(0.5),
    }
}

/// Density of [`square_to_cosine_hemisphere`] per unit solid angle: max(cos θ, 0) / π.
///
/// `w` must be a unit vector. Directions below the horizon and non-finite input give 0.
///
/// # Reference
/// \[Malley1988\].
#[inline]
pub fn pdf_cosine_hemisphere(w: Vec3) -> f32 {
    if w.is_finite() {
        w.z.max(0.0) * FRAC_1_PI
    } else {
        0.0
    }
}

/// Uniform direction on the upper hemisphere by Archimedes' cylinder map: z = u.x, φ = 2π u.y.
///
/// ω = (sin θ cos φ, sin θ sin φ, z) with sin θ = √((1 − z)(1 + z)); density 1/(2π). The map is
/// equal-area too, but it has a seam (u.y = 0 and u.y = 1 meet at φ = 0) and squeezes the edge u.x = 1
/// into the pole; use [`square_to_hemisphere_equal_area`] when continuity matters (bins, stratification).
///
/// Degenerate cases: `u` is clamped into [0, 1]² (NaN → 0); u.x = 0 gives a horizon direction.
///
/// # Reference
/// Archimedes' hat-box theorem (dω = dz dφ); the sampling form as in \[Pharr2023\], Appendix A.5.
#[inline]
pub fn square_to_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = clamp01(u.x);
    let sin_theta = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
    let (s, c) = (TAU * clamp01(u.y)).sin_cos();
    Vec3::new(sin_theta * c, sin_theta * s, z)
}

/// Inverse of [`square_to_uniform_hemisphere`]: u = (z, φ / 2π) with φ ∈ [0, 2π).
///
/// Degenerate cases: `w` is normalised first; below the horizon z is clamped to 0 (the azimuth is
/// kept). At the pole the azimuth is undefined and u.y = 0. Zero-length or non-finite `w` gives
/// (1, 0), the preimage of the pole.
///
/// # Reference
/// \[Pharr2023\], Appendix A.5.
#[inline]
pub fn uniform_hemisphere_to_square(w: Vec3) -> Vec2 {
    match w.try_normalize() {
        Some(w) => Vec2::new(clamp01(w.z), azimuth_fraction(w.x, w.y)),
        None => Vec2::new(1.0, 0.0),
    }
}

/// Density of [`square_to_uniform_hemisphere`] per unit solid angle: 1/(2π) for z ≥ 0.
///
/// `w` must be a unit vector. Directions below the horizon and non-finite input give 0.
///
/// # Reference
/// \[Pharr2023\], Appendix A.5.
#[inline]
pub fn pdf_uniform_hemisphere(w: Vec3) -> f32 {
    if w.z >= 0.0 && w.is_finite() {
        INV_TAU
    } else {
        0.0
    }
}

/// Clamps a cone's cos θ_max into [−1, 1]; NaN becomes 1 (the degenerate cone).
#[inline]
fn cone_cos_max(cos_theta_max: f32) -> f32 {
    if cos_theta_max >= -1.0 {
        cos_theta_max.min(1.0)
    } else if cos_theta_max < -1.0 {
        -1.0
    } else {
        1.0
    }
}

/// Uniform direction in the cone of half-angle θ_max about +z.
///
/// 1 − cos θ = u.x (1 − cos θ_max), φ = 2π u.y, sin θ = √(t (2 − t)) with t = 1 − cos θ (no
/// cancellation for narrow cones); density 1 / (2π (1 − cos θ_max)). The returned cos θ is never below
/// cos θ_max, so every sample has a positive density.
///
/// Degenerate cases: `u` is clamped into [0, 1]² (NaN → 0); `cos_theta_max` is clamped into [−1, 1]
/// (−1 is the whole sphere) and NaN counts as 1; cos θ_max = 1 (an empty cone) always returns +z.
///
/// # Reference
/// \[Pharr2023\], Appendix A.5 (sampling cones).
#[inline]
pub fn square_to_uniform_cone(u: Vec2, cos_theta_max: f32) -> Vec3 {
    let c = cone_cos_max(cos_theta_max);
    let t = clamp01(u.x) * (1.0 - c);
    let cos_theta = (1.0 - t).max(c);
    let sin_theta = (t * (2.0 - t)).max(0.0).sqrt();
    let (s, co) = (TAU * clamp01(u.y)).sin_cos();
    Vec3::new(sin_theta * co, sin_theta * s, cos_theta)
}

/// Inverse of [`square_to_uniform_cone`]: u = ((1 − cos θ) / (1 − cos θ_max), φ / 2π).
///
/// 1 − cos θ is computed as sin²θ / (1 + cos θ) in the upper hemisphere (accurate near the pole).
///
/// Degenerate cases: `w` is normalised first; directions outside the cone give u.x = 1 (the rim, same
/// azimuth). At the pole u.y = 0. For the empty cone (cos θ_max = 1 or NaN) u.x = 0. Zero-length or
/// non-finite `w` gives (0, 0), the preimage of +z.
///
/// # Reference
/// \[Pharr2023\], Appendix A.5.
#[inline]
pub fn uniform_cone_to_square(w: Vec3, cos_theta_max: f32) -> Vec2 {
    let c = cone_cos_max(cos_theta_max);
    let Some(w) = w.try_normalize() else {
        return Vec2::ZERO;
    };
    let sin2 = w.x * w.x + w.y * w.y;
    let one_minus_cos = if w.z > 0.0 {
        sin2 / (1.0 + w.z)
    } else {
        1.0 - w.z
    };
    let ux = if c < 1.0 {
        clamp01(one_minus_cos / (1.0 - c))
    } else {
        0.0
    };
    Vec2::new(ux, azimuth_fraction(w.x, w.y))
}

/// Density of [`square_to_uniform_cone`] per unit solid angle: 1 / (2π (1 − cos θ_max)) inside the cone.
///
/// `w` must be a unit vector; "inside" means w.z ≥ cos θ_max. Outside the cone, for non-finite input,
/// and for the empty cone (cos θ_max = 1 or NaN, a Dirac delta with no finite density) the result is 0.
/// `cos_theta_max` is clamped into [−1, 1] as in the sampler.
///
/// # Reference
/// \[Pharr2023\], Appendix A.5.
#[inline]
pub fn pdf_uniform_cone(w: Vec3, cos_theta_max: f32) -> f32 {
    let c = cone_cos_max(cos_theta_max);
    if c < 1.0 && w.z >= c && w.is_finite() {
        1.0 / (TAU * (1.0 - c))
    } else {
        0.0
    }
}

/// A pair of independent standard normal variates (Box–Muller transform).
///
/// r = √(−2 ln(1 − u.x)), φ = 2π u.y, p = r (cos φ, sin φ); density exp(−‖p‖²/2) / (2π) per unit area.
/// Box–Muller needs its radial variate s = 1 − u.x in (0, 1]: u.x is clamped into [0, 1 − 2⁻²⁴]
/// ([`ONE_MINUS_EPSILON`]), so s ∈ [2⁻²⁴, 1] and ‖p‖ ≤ √(48 ln 2) ≈ 5.77. ln(1 − u.x) is evaluated as
/// `ln_1p(−u.x)`, exact near u.x = 0.
///
/// Degenerate cases: `u` is clamped as above (NaN → 0); u.x = 0 gives the origin.
///
/// # Reference
/// \[BoxMuller1958\].
#[inline]
pub fn square_to_gaussian_2d(u: Vec2) -> Vec2 {
    let ux = clamp01(u.x).min(ONE_MINUS_EPSILON);
    let r = (-2.0 * (-ux).ln_1p()).max(0.0).sqrt();
    let (s, c) = (TAU * clamp01(u.y)).sin_cos();
    Vec2::new(r * c, r * s)
}

/// Inverse of [`square_to_gaussian_2d`]: u = (1 − exp(−‖p‖²/2), φ / 2π).
///
/// 1 − exp(−x) is evaluated as `−exp_m1(−x)`, exact near the origin.
///
/// Degenerate cases: u.x is clamped to at most [`ONE_MINUS_EPSILON`] (points farther out than the
/// sampler's largest radius, including infinite ones, map to that radius). At the origin u.y = 0. NaN
/// input gives (0, 0).
///
/// # Reference
/// \[BoxMuller1958\].
#[inline]
pub fn gaussian_2d_to_square(p: Vec2) -> Vec2 {
    if p.is_nan() {
        return Vec2::ZERO;
    }
    let r2 = p.length_squared();
    let ux = (-(-0.5 * r2).exp_m1()).clamp(0.0, ONE_MINUS_EPSILON);
    Vec2::new(ux, azimuth_fraction(p.x, p.y))
}

/// Density of [`square_to_gaussian_2d`] per unit area: exp(−‖p‖²/2) / (2π).
///
/// The sampler's truncation at radius ≈ 5.77 (probability 2⁻²⁴ beyond it) is not reflected in this
/// density. Non-finite input gives 0.
///
/// # Reference
/// \[BoxMuller1958\].
#[inline]
pub fn pdf_gaussian_2d(p: Vec2) -> f32 {
    if p.is_finite() {
        (-0.5 * p.length_squared()).exp() * INV_TAU
    } else {
        0.0
    }
}

/// Equal-area, continuous bijection from the unit square onto the upper hemisphere.
///
/// Construction: the concentric map p = [`square_to_concentric_disk`]`(u)` (radius r = ‖p‖), followed by
/// the Lambert azimuthal equal-area projection scaled to the unit disk:
/// ω = (p·√(2 − r²), 1 − r²), i.e. z = 1 − r² and sin θ = r √(1 + z).
/// Both steps preserve area up to a constant: solid angle = 2π × area in the square
/// ([`EQUAL_AREA_SOLID_ANGLE_PER_AREA`]), so the cells of any n×n grid on the square are hemisphere
/// regions of equal solid angle 2π/n². The square's boundary maps exactly onto the horizon (z = 0)
/// and (½, ½) exactly onto the pole +z.
///
/// Degenerate cases: `u` is clamped into [0, 1]² (NaN → 0).
///
/// # Reference
/// \[ShirleyChiu1997\] for the disk; \[Snyder1987\], ch. 24 (Lambert azimuthal equal-area projection:
/// ρ = 2 sin(θ/2), here divided by √2 so that the hemisphere fills the unit disk).
#[inline]
pub fn square_to_hemisphere_equal_area(u: Vec2) -> Vec3 {
    let d = concentric_polar(u);
    // z = 1 − r² = (1 − r)(1 + r): exact 0 on the square's boundary, accurate near the horizon.
    let z = (d.one_minus_r * (1.0 + d.r)).clamp(0.0, 1.0);
    let sin_theta = d.r * (1.0 + z).sqrt();
    Vec3::new(sin_theta * d.cos_phi, sin_theta * d.sin_phi, z)
}

/// Inverse of [`square_to_hemisphere_equal_area`].
///
/// The disk point is p = (ω.x, ω.y) / √(1 + ω.z) (then ‖p‖² = 1 − ω.z = r², without cancellation
/// near the pole), followed by [`concentric_disk_to_square`]. Horizon directions map onto the square's
/// boundary and +z onto (½, ½).
///
/// Degenerate cases: `w` is normalised first. A direction below the horizon is clamped to the horizon
/// direction of the same azimuth (its nearest upper direction), so it lands on the square's boundary;
/// straight down (−z, no azimuth) counts as +x. Zero-length or non-finite `w` gives (½, ½).
///
/// # Reference
/// \[ShirleyChiu1997\], \[Snyder1987\].
#[inline]
pub fn hemisphere_to_square_equal_area(w: Vec3) -> Vec2 {
    let Some(w) = w.try_normalize() else {
        return Vec2::splat(0.5);
    };
    let p = if w.z >= 0.0 {
        Vec2::new(w.x, w.y) / (1.0 + w.z).sqrt()
    } else {
        Vec2::new(w.x, w.y).try_normalize().unwrap_or(Vec2::X)
    };
    concentric_disk_to_square(p)
}

/// Density of [`square_to_hemisphere_equal_area`] per unit solid angle: 1/(2π) for z ≥ 0.
///
/// Same as [`pdf_uniform_hemisphere`]: uniform u gives uniform directions. Below the horizon and for
/// non-finite input the density is 0.
///
/// # Reference
/// \[Snyder1987\].
#[inline]
pub fn pdf_hemisphere_equal_area(w: Vec3) -> f32 {
    pdf_uniform_hemisphere(w)
}

/// Mean of cos θ over the equal-area image ([`square_to_hemisphere_equal_area`]) of the rectangle
/// [x0, x1] × [y0, y1] ⊂ [0, 1]², in `f64`, exact up to rounding: with (a, b) = 2u − 1 the map gives
/// z = 1 − max(a², b²) (the concentric radius is max(|a|, |b|)), so the mean is 1 − the mean of
/// max(a², b²) over the rectangle in (a, b). An empty rectangle gives 1 (the value at its corner).
#[cfg(feature = "std")]
pub(crate) fn equal_area_mean_cos(x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    1.0 - mean_max_square(
        2.0 * x0 - 1.0,
        2.0 * x1 - 1.0,
        2.0 * y0 - 1.0,
        2.0 * y1 - 1.0,
    )
}

/// Mean of max(a², b²) over the rectangle [a0, a1] × [b0, b1] (exact up to rounding).
#[cfg(feature = "std")]
fn mean_max_square(a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    // g(a) = ∫_{b0}^{b1} max(a², b²) db in closed form: b² outside |b| < |a|, a² inside.
    let g = |a: f64| {
        let abs = a.abs();
        let (lo, hi) = (b0.max(-abs), b1.min(abs));
        let full = (b1.powi(3) - b0.powi(3)) / 3.0;
        if hi > lo {
            full - (hi.powi(3) - lo.powi(3)) / 3.0 + a * a * (hi - lo)
        } else {
            full
        }
    };
    // g is a polynomial of degree ≤ 3 between its breakpoints a ∈ {0, ±b0, ±b1}: 3-point
    // Gauss–Legendre (exact to degree 5) on each piece.
    let mut cuts = vec![a0, a1];
    for c in [0.0, b0, -b0, b1, -b1] {
        if c > a0 && c < a1 {
            cuts.push(c);
        }
    }
    cuts.sort_by(|x, y| x.total_cmp(y));
    const X: [f64; 3] = [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4];
    const W: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let mut total = 0.0;
    for pair in cuts.windows(2) {
        let (l, r) = (pair[0], pair[1]);
        let (mid, half) = (0.5 * (l + r), 0.5 * (r - l));
        total += half
            * X.iter()
                .zip(W)
                .map(|(x, w)| w * g(mid + half * x))
                .sum::<f64>();
    }
    total / ((a1 - a0) * (b1 - b0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_max_square_closed_forms() {
        // Whole square [−1, 1]²: the CDF of r = max(|a|, |b|) is r², so E[r²] = ∫ r² 2r dr = 1/2
        // (and the hemisphere's mean cosine is 1 − 1/2).
        assert!((mean_max_square(-1.0, 1.0, -1.0, 1.0) - 0.5).abs() < 1e-15);
        // A cell where |a| > |b| everywhere: the mean of a².
        let m = mean_max_square(0.5, 0.7, -0.1, 0.2);
        assert!((m - (0.7f64.powi(3) - 0.5f64.powi(3)) / 3.0 / 0.2).abs() < 1e-14);
    }
    use std::f64::consts::PI;

    /// Inputs of a round trip: an (n+1)² grid with the ends replaced by 0 and 1 − ε.
    fn grid(n: usize) -> Vec<Vec2> {
        let coord = |i: usize| {
            if i == n {
                ONE_MINUS_EPSILON
            } else {
                i as f32 / n as f32
            }
        };
        (0..=n)
            .flat_map(|i| (0..=n).map(move |j| Vec2::new(coord(i), coord(j))))
            .collect()
    }

    /// Awkward inputs: ends of the range, just outside, NaN and infinities.
    const EDGES: [f32; 9] = [
        0.0,
        ONE_MINUS_EPSILON,
        1.0,
        -1e-7,
        1.0 + 1e-6,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        0.5,
    ];

    fn edge_inputs() -> Vec<Vec2> {
        EDGES
            .iter()
            .flat_map(|&a| EDGES.iter().map(move |&b| Vec2::new(a, b)))
            .collect()
    }

    /// |Δu| of a round trip, with the azimuthal error scaled by the radius `r` (the azimuth is
    /// undefined at the centre, and its conditioning is 1/r).
    fn polar_error(u: Vec2, back: Vec2, r: f32) -> f32 {
        let dy = (back.y - u.y).abs();
        let dy = dy.min(1.0 - dy); // the azimuth wraps: 0 and 1 are the same
        (back.x - u.x).abs().max(dy * r)
    }

    // Round-trip bound for the concentric family: the forward map rounds ψ, sin and cos (≤ 1 ulp each
    // of values ≤ 1), the inverse rounds the norm, the quotient and atan (again ≤ 1 ulp of values ≤ 1,
    // and atan has derivative ≤ 1); u = (a + 1)/2 halves the error. Measured maximum on a 513² grid: 1.2e-7
    // (1 ulp). We allow 8 ulp(1) = 9.5e-7.
    const CONCENTRIC_TOL: f32 = 8.0 * f32::EPSILON;

    #[test]
    fn concentric_round_trip() {
        for u in grid(256) {
            let p = square_to_concentric_disk(u);
            assert!(p.length() <= 1.0 + 2.0 * f32::EPSILON, "{u} -> {p}");
            let back = concentric_disk_to_square(p);
            assert!(
                (back - u).abs().max_element() <= CONCENTRIC_TOL,
                "{u} -> {p} -> {back}"
            );
        }
        assert_eq!(square_to_concentric_disk(Vec2::splat(0.5)), Vec2::ZERO);
        assert_eq!(concentric_disk_to_square(Vec2::ZERO), Vec2::splat(0.5));
    }

    #[test]
    fn concentric_corners_and_sides() {
        // Corners go to the diagonals of the unit circle, side midpoints to the axes.
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let cases = [
            (Vec2::new(1.0, 1.0), Vec2::new(h, h)),
            (Vec2::new(0.0, 0.0), Vec2::new(-h, -h)),
            (Vec2::new(1.0, 0.5), Vec2::new(1.0, 0.0)),
            (Vec2::new(0.5, 1.0), Vec2::new(0.0, 1.0)),
            (Vec2::new(0.0, 0.5), Vec2::new(-1.0, 0.0)),
            (Vec2::new(0.5, 0.0), Vec2::new(0.0, -1.0)),
        ];
        for (u, expected) in cases {
            // sin/cos of π/4 and 0 in f32: within 2 ulp.
            assert!((square_to_concentric_disk(u) - expected).length() < 2.0 * f32::EPSILON);
        }
    }

    #[test]
    fn cosine_round_trip() {
        for u in grid(256) {
            let w = square_to_cosine_hemisphere(u);
            // |w|² = r² + (1 − r)(1 + r) up to ~3 roundings of values ≤ 1.
            assert!((w.length() - 1.0).abs() < 4.0 * f32::EPSILON, "{u} -> {w}");
            assert!(w.z >= 0.0);
            let back = cosine_hemisphere_to_square(w);
            // Concentric bound plus the normalisation of w (≤ 1 ulp of |w|), see CONCENTRIC_TOL.
            assert!(
                (back - u).abs().max_element() <= CONCENTRIC_TOL,
                "{u} -> {w} -> {back}"
            );
        }
    }

    #[test]
    fn uniform_hemisphere_round_trip() {
        for u in grid(256) {
            let w = square_to_uniform_hemisphere(u);
            assert!((w.length() - 1.0).abs() < 4.0 * f32::EPSILON, "{u} -> {w}");
            let back = uniform_hemisphere_to_square(w);
            // z: one rounding in the normalisation; azimuth: sin/cos/atan2 each ≤ 1 ulp of 2π, divided
            // by 2π, conditioned by 1/sin θ (hence the scaling by sin θ). Measured maximum 1.2e-7.
            let err = polar_error(u, back, (1.0 - w.z * w.z).max(0.0).sqrt());
            assert!(err <= 8.0 * f32::EPSILON, "{u} -> {w} -> {back}: {err}");
        }
    }

    #[test]
    fn cone_round_trip() {
        for cos_max in [0.99999f32, 0.9, 0.5, 0.0, -0.5, -1.0] {
            for u in grid(128) {
                let w = square_to_uniform_cone(u, cos_max);
                assert!((w.length() - 1.0).abs() < 4.0 * f32::EPSILON, "{u} -> {w}");
                assert!(w.z >= cos_max, "{u}: {w} outside cos {cos_max}");
                assert!(pdf_uniform_cone(w, cos_max) > 0.0);
                let back = uniform_cone_to_square(w, cos_max);
                // u.x = t / (1 − c): t = sin²θ/(1 + cos θ) carries ~4 roundings relative to t, i.e.
                // ≤ 4 ulp relative of u.x ≤ 1, plus the normalisation. Azimuth as for the
                // hemisphere, conditioned by 1/sin θ. Measured maximum 4.8e-7 (4 ulp).
                let r = (w.x * w.x + w.y * w.y).sqrt();
                let err = polar_error(u, back, r);
                assert!(
                    err <= 8.0 * f32::EPSILON,
                    "cos {cos_max}: {u} -> {w} -> {back}: {err}"
                );
            }
        }
    }

    #[test]
    fn cone_degenerate() {
        assert_eq!(square_to_uniform_cone(Vec2::new(0.7, 0.2), 1.0), Vec3::Z);
        assert_eq!(
            square_to_uniform_cone(Vec2::new(0.7, 0.2), f32::NAN),
            Vec3::Z
        );
        assert_eq!(pdf_uniform_cone(Vec3::Z, 1.0), 0.0);
        assert_eq!(pdf_uniform_cone(Vec3::Z, f32::NAN), 0.0);
        assert_eq!(uniform_cone_to_square(Vec3::Z, 1.0).x, 0.0);
        // Outside the cone: density 0, inverse on the rim.
        assert_eq!(pdf_uniform_cone(Vec3::X, 0.5), 0.0);
        assert_eq!(uniform_cone_to_square(Vec3::X, 0.5).x, 1.0);
        // cos θ_max < −1 is the whole sphere.
        // (1/(4π) through f32 arithmetic: two roundings.)
        let full = pdf_uniform_cone(-Vec3::Z, -3.0) as f64;
        assert!(
            (full * 4.0 * PI - 1.0).abs() < 2.0 * f32::EPSILON as f64,
            "{full}"
        );
    }

    #[test]
    fn gaussian_round_trip() {
        for u in grid(256) {
            let p = square_to_gaussian_2d(u);
            let back = gaussian_2d_to_square(p);
            // u.x: the forward map has relative error ~ a few ulp in ln(1 − u.x), the inverse a few
            // ulp in exp_m1; the absolute error of u.x is ≤ (1 − u.x)·|Δ ln(1 − u.x)| + ulp, below
            // 8 ulp(1) for every u.x ≤ 1 − 2⁻²⁴ (measured maximum 1.2e-7). Azimuth as above,
            // conditioned by 1/r.
            let err = polar_error(u, back, p.length().min(1.0));
            assert!(err <= 8.0 * f32::EPSILON, "{u} -> {p} -> {back}: {err}");
        }
        // The documented clamp: u.x = 1 behaves as 1 − 2⁻²⁴, radius √(48 ln 2).
        let r_max = (48.0f64 * 2f64.ln()).sqrt() as f32;
        let p = square_to_gaussian_2d(Vec2::new(1.0, 0.0));
        assert!((p.x - r_max).abs() < 4.0 * f32::EPSILON * r_max, "{p}");
        assert_eq!(
            gaussian_2d_to_square(Vec2::new(1e3, 0.0)).x,
            ONE_MINUS_EPSILON
        );
    }

    #[test]
    fn equal_area_round_trip() {
        for u in grid(512) {
            let w = square_to_hemisphere_equal_area(u);
            assert!((w.length() - 1.0).abs() < 4.0 * f32::EPSILON, "{u} -> {w}");
            assert!(w.z >= 0.0);
            let back = hemisphere_to_square_equal_area(w);
            // Concentric bound (see CONCENTRIC_TOL); the Lambert step adds a square root and a
            // quotient of values ≤ 2, ≤ 2 ulp. Measured maximum 1.5e-7.
            assert!(
                (back - u).abs().max_element() <= CONCENTRIC_TOL,
                "{u} -> {w} -> {back}"
            );
        }
    }

    #[test]
    fn equal_area_pole_and_horizon_are_exact() {
        assert_eq!(square_to_hemisphere_equal_area(Vec2::splat(0.5)), Vec3::Z);
        assert_eq!(hemisphere_to_square_equal_area(Vec3::Z), Vec2::splat(0.5));
        for i in 0..=64 {
            let t = i as f32 / 64.0;
            for u in [
                Vec2::new(0.0, t),
                Vec2::new(1.0, t),
                Vec2::new(t, 0.0),
                Vec2::new(t, 1.0),
            ] {
                let w = square_to_hemisphere_equal_area(u);
                assert_eq!(w.z, 0.0, "{u} -> {w}");
                let back = hemisphere_to_square_equal_area(w);
                let on_boundary = back.x == 0.0 || back.x == 1.0 || back.y == 0.0 || back.y == 1.0;
                assert!(on_boundary, "{u} -> {w} -> {back}");
            }
        }
        // Slightly below the horizon: clamped to the horizon, i.e. onto the boundary.
        let back = hemisphere_to_square_equal_area(Vec3::new(0.6, 0.8, -1e-4));
        assert!(back.x == 1.0 || back.y == 1.0, "{back}");
        assert_eq!(
            hemisphere_to_square_equal_area(-Vec3::Z),
            Vec2::new(1.0, 0.5)
        );
    }

    /// The map is continuous: neighbouring inputs give neighbouring directions, also across the
    /// diagonals where the concentric map switches branch and across the centre lines.
    #[test]
    fn equal_area_is_continuous() {
        let n = 400;
        let h = 1.0 / n as f32;
        // Largest stretch of the map: the concentric step stretches a unit of u by at most
        // 2·√(1 + (π/4)²) ≈ 2.54, the Lambert step a unit of disk radius by at most dθ/dr =
        // √2 / cos(θ/2) ≤ 2 (at the horizon; √(1 + z) ≤ √2 tangentially): ≤ 5.1 in all. Steps of h must
        // give direction changes below 5.1h (+ rounding); 8h leaves margin and still fails on any jump.
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new(i as f32 * h, j as f32 * h);
                let w = square_to_hemisphere_equal_area(u);
                let wx = square_to_hemisphere_equal_area(u + Vec2::new(h, 0.0));
                let wy = square_to_hemisphere_equal_area(u + Vec2::new(0.0, h));
                assert!(
                    (wx - w).length() < 8.0 * h && (wy - w).length() < 8.0 * h,
                    "{u}"
                );
            }
        }
    }

    /// The equal-area property, pointwise: |∂ω/∂u × ∂ω/∂v| = 2π, by central differences of the map
    /// itself (independent of the formula that says so).
    #[test]
    fn equal_area_jacobian_is_two_pi() {
        let h = 1e-3f32;
        let n = 40;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (a, b) = (2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
                // Skip points whose stencil straddles a diagonal (the map is only piecewise smooth
                // there) or leaves the square.
                if (a.abs() - b.abs()).abs() < 4.0 * h
                    || u.min_element() < h
                    || u.max_element() > 1.0 - h
                {
                    continue;
                }
                // Central difference in f64 of the f32 map.
                let d = |du: Vec2| {
                    let p = square_to_hemisphere_equal_area(u + du).to_array();
                    let m = square_to_hemisphere_equal_area(u - du).to_array();
                    [0, 1, 2].map(|k| (p[k] as f64 - m[k] as f64) / (2.0 * h as f64))
                };
                let (x, y) = (d(Vec2::new(h, 0.0)), d(Vec2::new(0.0, h)));
                let cross = [
                    x[1] * y[2] - x[2] * y[1],
                    x[2] * y[0] - x[0] * y[2],
                    x[0] * y[1] - x[1] * y[0],
                ];
                let jac = cross.iter().map(|c| c * c).sum::<f64>().sqrt();
                // Truncation O(h²·|ω'''|) ~ 1e-5 relative, rounding ~ ulp(1)/h ~ 1e-4 relative per
                // derivative: 1e-3 relative covers both with margin.
                assert!((jac / (2.0 * PI) - 1.0).abs() < 1e-3, "{u}: {jac}");
            }
        }
    }

    /// The equal-area property, cell by cell: directions drawn uniformly on the hemisphere by an
    /// independent generator (Archimedes, in f64) land in the cells of a 16×16 grid of the square
    /// equally often (chi-square at significance 0.01).
    #[test]
    fn equal_area_cells_have_equal_solid_angle() {
        use rand::{RngExt, SeedableRng};
        use statrs::distribution::{ChiSquared, ContinuousCDF};
        let n = 16;
        let draws = 400_000usize;
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
        let mut counts = vec![0u32; n * n];
        for _ in 0..draws {
            let z: f64 = rng.random();
            let phi: f64 = 2.0 * PI * rng.random::<f64>();
            let s = (1.0 - z * z).sqrt();
            let w = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32);
            let u = hemisphere_to_square_equal_area(w);
            let (i, j) = (
                ((u.x * n as f32) as usize).min(n - 1),
                ((u.y * n as f32) as usize).min(n - 1),
            );
            counts[i * n + j] += 1;
        }
        let expected = draws as f64 / (n * n) as f64;
        let chi2: f64 = counts
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        let p = 1.0 - ChiSquared::new((n * n - 1) as f64).unwrap().cdf(chi2);
        assert!(p > 0.01, "chi2 = {chi2}, p = {p}, counts = {counts:?}");
        // And no single cell is off by more than 5 standard deviations (binomial; per-cell
        // probability of a false alarm 5.7e-7, 1.5e-4 over the 256 cells).
        let sd = (expected * (1.0 - 1.0 / (n * n) as f64)).sqrt();
        for &c in &counts {
            assert!((c as f64 - expected).abs() < 5.0 * sd, "{counts:?}");
        }
    }

    #[test]
    fn edge_inputs_never_give_nan() {
        for u in edge_inputs() {
            let p = square_to_concentric_disk(u);
            assert!(
                p.is_finite() && p.length() <= 1.0 + 2.0 * f32::EPSILON,
                "{u} -> {p}"
            );
            for w in [
                square_to_cosine_hemisphere(u),
                square_to_uniform_hemisphere(u),
                square_to_hemisphere_equal_area(u),
                square_to_uniform_cone(u, 0.3),
                square_to_uniform_cone(u, f32::NAN),
            ] {
                assert!(
                    w.is_finite() && (w.length() - 1.0).abs() < 4.0 * f32::EPSILON,
                    "{u} -> {w}"
                );
            }
            assert!(square_to_gaussian_2d(u).is_finite(), "{u}");
            // Inverses and densities on non-finite or degenerate points.
            let v = Vec3::new(u.x, u.y, 0.5);
            for b in [
                concentric_disk_to_square(u),
                gaussian_2d_to_square(u),
                cosine_hemisphere_to_square(v),
                uniform_hemisphere_to_square(v),
                uniform_cone_to_square(v, 0.3),
                hemisphere_to_square_equal_area(v),
            ] {
                assert!(
                    b.is_finite() && b.min_element() >= 0.0 && b.max_element() <= 1.0,
                    "{u}: {b}"
                );
            }
            for d in [
                pdf_concentric_disk(u),
                pdf_gaussian_2d(u),
                pdf_cosine_hemisphere(v),
                pdf_uniform_hemisphere(v),
                pdf_uniform_cone(v, 0.3),
                pdf_hemisphere_equal_area(v),
            ] {
                assert!(d.is_finite() && d >= 0.0, "{u}: {d}");
            }
        }
        for w in [Vec3::ZERO, Vec3::NAN, Vec3::INFINITY] {
            assert_eq!(hemisphere_to_square_equal_area(w), Vec2::splat(0.5));
            assert_eq!(cosine_hemisphere_to_square(w), Vec2::splat(0.5));
            assert_eq!(uniform_hemisphere_to_square(w), Vec2::new(1.0, 0.0));
            assert_eq!(uniform_cone_to_square(w, 0.5), Vec2::ZERO);
            if !w.is_finite() {
                assert_eq!(pdf_uniform_hemisphere(w), 0.0);
                assert_eq!(pdf_cosine_hemisphere(w), 0.0);
                assert_eq!(pdf_uniform_cone(w, 0.5), 0.0);
            }
        }
    }

    /// Midpoint rule on [lo, hi] with n points (error O(((hi − lo)/n)²·f'')).
    fn midpoint(lo: f64, hi: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
        let h = (hi - lo) / n as f64;
        (0..n).map(|i| f(lo + (i as f64 + 0.5) * h)).sum::<f64>() * h
    }

    /// ∫ pdf dω over the hemisphere in (z, φ) coordinates (dω = dz dφ), midpoint in both.
    fn integrate_z_phi(z_lo: f64, pdf: impl Fn(Vec3) -> f32) -> f64 {
        midpoint(z_lo, 1.0, 400, |z| {
            let s = (1.0 - z * z).max(0.0).sqrt();
            midpoint(0.0, 2.0 * PI, 64, |phi| {
                pdf(Vec3::new(
                    (s * phi.cos()) as f32,
                    (s * phi.sin()) as f32,
                    z as f32,
                )) as f64
            })
        })
    }

    #[test]
    fn pdfs_integrate_to_one() {
        // Each density is constant or linear in z on its support and the grid starts at the edge of
        // the support, so the midpoint rule is exact up to rounding of the f32 density (relative
        // 1e-7 per term, 2.6e4 terms, 1e-5 is a safe bound).
        let tol = 1e-5;
        type Pdf = Box<dyn Fn(Vec3) -> f32>;
        let cases: [(&str, f64, Pdf); 5] = [
            ("cosine", 0.0, Box::new(pdf_cosine_hemisphere)),
            ("uniform", 0.0, Box::new(pdf_uniform_hemisphere)),
            ("equal-area", 0.0, Box::new(pdf_hemisphere_equal_area)),
            ("cone 0.8", 0.8, Box::new(|w| pdf_uniform_cone(w, 0.8))),
            ("cone -0.4", -0.4, Box::new(|w| pdf_uniform_cone(w, -0.4))),
        ];
        for (name, z_lo, pdf) in cases {
            let total = integrate_z_phi(z_lo, pdf);
            assert!((total - 1.0).abs() < tol, "{name}: {total}");
        }
        // The cone integrated over the whole sphere from z = −1: the density must vanish outside.
        let total = integrate_z_phi(-1.0, |w| pdf_uniform_cone(w, 0.5));
        // The cone's edge z = 0.5 falls on a cell boundary of the 400-cell grid on [−1, 1]
        // (cell width 0.005): exact up to rounding again.
        assert!((total - 1.0).abs() < tol, "cone over the sphere: {total}");
        // Disk and Gaussian in polar coordinates, ∫∫ pdf r dr dφ.
        let polar = |r_max: f64, n_r: usize, pdf: &dyn Fn(Vec2) -> f32| {
            midpoint(0.0, r_max, n_r, |r| {
                r * midpoint(0.0, 2.0 * PI, 64, |phi| {
                    pdf(Vec2::new((r * phi.cos()) as f32, (r * phi.sin()) as f32)) as f64
                })
            })
        };
        let disk = polar(1.0, 400, &pdf_concentric_disk);
        // r·(1/π) is linear in r: exact up to rounding.
        assert!((disk - 1.0).abs() < tol, "disk: {disk}");
        let gauss = polar(12.0, 4000, &pdf_gaussian_2d);
        // Midpoint error ≤ (b − a) h² max|f''| / 24 with h = 3e-3, |f''| ≤ 2/(2π)… ≈ 1e-6; the tail
        // beyond r = 12 is exp(−72).
        assert!((gauss - 1.0).abs() < 1e-5, "gaussian: {gauss}");
    }
}
