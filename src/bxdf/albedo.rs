//! Directional albedo tables of the single-scattering microfacet BRDF with F = 1: E(μ, α) and its
//! cosine-weighted average E_avg(α), for GGX and Beckmann with height-correlated masking, looked up
//! bilinearly. The numbers are in `albedo_tables.rs`, written by `tools/albedo_tables.rs`.
//!
//! ## Grid
//! - μ = cos θo on [`ALBEDO_GRID`] uniform nodes μ_i = i / (n − 1), i = 0 … n − 1; the node μ = 0
//!   holds the value at μ = [`ALBEDO_MU_EPSILON`] (the limit of grazing views: a direction exactly
//!   on the horizon reflects nothing).
//! - α on [`ALBEDO_GRID`] nodes uniform in t = √α from t = √[`ALBEDO_ALPHA_MIN`] (the NDFs'
//!   smallest α) to t = 1: square-root spacing puts nodes where E changes fastest (small α,
//!   where the loss grows like α² at grazing views).
//! - E_avg(α_j) = 2 ∫₀¹ E_j(μ) μ dμ of the row's piecewise-linear interpolant, integrated exactly
//!   (Simpson's rule is exact for the quadratic E(μ) μ on each cell), so that the energy the
//!   compensation lobe returns, (1 − E(μo)), is exactly what its normalisation 1 / (1 − E_avg)
//!   assumes, whatever the rounding of the table.
//!
//! Interpolation is linear in μ and in t = √α (bilinear in (μ, t)); E_avg is linear in t, which is
//! the exact average of the bilinear interpolant at every α between nodes. Lookups clamp μ to
//! [0, 1] and α to [α_min, 1] and are total (non-finite input reads the μ = 0 or α_min node).

use super::albedo_tables::{BECKMANN_E, BECKMANN_E_AVG, GGX_E, GGX_E_AVG};
#[cfg(not(feature = "std"))]
use crate::float::Float as _;

/// Nodes per axis of the albedo tables (μ and √α).
pub const ALBEDO_GRID: usize = 64;

/// The smallest α of the tables (the NDFs' [`crate::ndf::MIN_ALPHA`]).
pub const ALBEDO_ALPHA_MIN: f32 = crate::ndf::MIN_ALPHA;

/// The largest α of the tables: energy compensation accepts α ≤ 1 (`r = 1` for α = r²).
pub const ALBEDO_ALPHA_MAX: f32 = 1.0;

/// The μ = cos θo at which the tables' μ = 0 node is evaluated (the grazing limit).
pub const ALBEDO_MU_EPSILON: f32 = 1e-4;

/// The tabulated directional albedo of one NDF family with F = 1 and height-correlated masking.
///
/// E(μ, α) = ∫ f_ss(wo, wi) cos θi dωi with cos θo = μ, the fraction of light the single-scattering
/// BRDF reflects; E_avg(α) = 2 ∫₀¹ E(μ, α) μ dμ (\[KullaConty2017\], the "average albedo").
///
/// # Reference
/// \[KullaConty2017\], the multiple-scattering microfacet section (tabulated E and E_avg).
#[derive(Debug)]
pub struct AlbedoTable {
    name: &'static str,
    e: &'static [[f32; ALBEDO_GRID]; ALBEDO_GRID],
    e_avg: &'static [f32; ALBEDO_GRID],
}

impl AlbedoTable {
    /// GGX (Trowbridge-Reitz), height-correlated Smith masking.
    pub const GGX: AlbedoTable = AlbedoTable {
        name: "ggx",
        e: &GGX_E,
        e_avg: &GGX_E_AVG,
    };

    /// Beckmann, height-correlated Smith masking.
    pub const BECKMANN: AlbedoTable = AlbedoTable {
        name: "beckmann",
        e: &BECKMANN_E,
        e_avg: &BECKMANN_E_AVG,
    };

    /// The NDF family's name (`"ggx"`, `"beckmann"`).
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The μ of node `i` (i / (n − 1); the value stored there is E at max(μ, [`ALBEDO_MU_EPSILON`])).
    pub fn mu_node(i: usize) -> f32 {
        i.min(ALBEDO_GRID - 1) as f32 / (ALBEDO_GRID - 1) as f32
    }

    /// The α of node `j`: t² with t uniform from √α_min to 1.
    pub fn alpha_node(j: usize) -> f32 {
        let t0 = ALBEDO_ALPHA_MIN.sqrt();
        let t = t0 + (1.0 - t0) * j.min(ALBEDO_GRID - 1) as f32 / (ALBEDO_GRID - 1) as f32;
        t * t
    }

    /// The stored E at node (μ_i, α_j).
    pub fn entry(&self, i: usize, j: usize) -> f32 {
        self.e[j.min(ALBEDO_GRID - 1)][i.min(ALBEDO_GRID - 1)]
    }

    /// The stored E_avg at node α_j.
    pub fn average_entry(&self, j: usize) -> f32 {
        self.e_avg[j.min(ALBEDO_GRID - 1)]
    }

    /// E(μ, α), bilinear in (μ, √α), with μ clamped to [0, 1] and α to [α_min, 1].
    pub fn albedo(&self, mu: f32, alpha: f32) -> f32 {
        let (i, fx) = cell(mu_coordinate(mu));
        let (j, fy) = cell(alpha_coordinate(alpha));
        let row = |j: usize| lerp(self.e[j][i], self.e[j][i + 1], fx);
        lerp(row(j), row(j + 1), fy)
    }

    /// E_avg(α), linear in √α, with α clamped to [α_min, 1].
    pub fn average_albedo(&self, alpha: f32) -> f32 {
        let (j, fy) = cell(alpha_coordinate(alpha));
        lerp(self.e_avg[j], self.e_avg[j + 1], fy)
    }
}

/// The grid coordinate of μ in [0, n − 1] (NaN → 0).
#[inline]
fn mu_coordinate(mu: f32) -> f32 {
    let x = mu * (ALBEDO_GRID - 1) as f32;
    if x > 0.0 {
        x.min((ALBEDO_GRID - 1) as f32)
    } else {
        0.0
    }
}

/// The grid coordinate of α in [0, n − 1] (NaN → 0).
#[inline]
fn alpha_coordinate(alpha: f32) -> f32 {
    let t0 = ALBEDO_ALPHA_MIN.sqrt();
    let y = (alpha.max(0.0).sqrt() - t0) / (1.0 - t0) * (ALBEDO_GRID - 1) as f32;
    if y > 0.0 {
        y.min((ALBEDO_GRID - 1) as f32)
    } else {
        0.0
    }
}

/// The cell index (≤ n − 2) and the fraction within it of a grid coordinate in [0, n − 1].
#[inline]
fn cell(x: f32) -> (usize, f32) {
    let i = (x as usize).min(ALBEDO_GRID - 2);
    (i, x - i as f32)
}

#[inline]
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// 2 ∫₀¹ E(μ) μ dμ of the piecewise-linear interpolant of `row` on the uniform μ nodes, exactly:
/// on a cell [a, b] of width h, ∫ E μ dμ = h/6 (E_a (2a + b) + E_b (a + 2b)) (Simpson, exact for
/// the quadratic E μ). The generator writes the tables' E_avg with this function.
pub fn average_of_row(row: &[f32; ALBEDO_GRID]) -> f64 {
    let h = 1.0 / (ALBEDO_GRID - 1) as f64;
    let mut sum = 0.0;
    for i in 0..ALBEDO_GRID - 1 {
        let (a, b) = (i as f64 * h, (i + 1) as f64 * h);
        let (ea, eb) = (row[i] as f64, row[i + 1] as f64);
        sum += h / 6.0 * (ea * (2.0 * a + b) + eb * (a + 2.0 * b));
    }
    2.0 * sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_span_the_documented_ranges() {
        assert_eq!(AlbedoTable::mu_node(0), 0.0);
        assert_eq!(AlbedoTable::mu_node(ALBEDO_GRID - 1), 1.0);
        assert!((AlbedoTable::alpha_node(0) - ALBEDO_ALPHA_MIN).abs() < 1e-9);
        assert!((AlbedoTable::alpha_node(ALBEDO_GRID - 1) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn lookup_at_nodes_returns_the_entries() {
        for t in [&AlbedoTable::GGX, &AlbedoTable::BECKMANN] {
            for j in [0, 7, ALBEDO_GRID - 1] {
                for i in [0, 13, ALBEDO_GRID - 1] {
                    let (mu, a) = (AlbedoTable::mu_node(i), AlbedoTable::alpha_node(j));
                    let got = t.albedo(mu, a);
                    assert!((got - t.entry(i, j)).abs() < 1e-5, "{} {i} {j}", t.name());
                }
                let avg = t.average_albedo(AlbedoTable::alpha_node(j));
                assert!((avg - t.average_entry(j)).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn average_matches_the_rows_interpolant() {
        for t in [&AlbedoTable::GGX, &AlbedoTable::BECKMANN] {
            for j in 0..ALBEDO_GRID {
                let avg = average_of_row(&t.e[j]);
                assert!((avg - t.e_avg[j] as f64).abs() < 1e-6, "{} {j}", t.name());
            }
        }
    }

    #[test]
    fn lookups_are_total() {
        for (mu, a) in [
            (f32::NAN, 0.3),
            (0.5, f32::NAN),
            (-1.0, -1.0),
            (2.0, 5.0),
            (f32::INFINITY, f32::INFINITY),
        ] {
            let e = AlbedoTable::GGX.albedo(mu, a);
            assert!(e.is_finite() && (0.0..=1.0).contains(&e), "{mu} {a}: {e}");
            assert!(AlbedoTable::BECKMANN.average_albedo(a).is_finite());
        }
    }
}
