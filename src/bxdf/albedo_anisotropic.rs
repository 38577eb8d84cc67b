//! Directional albedo tables of the single-scattering microfacet BRDF with an anisotropic NDF
//! (F = 1, height-correlated masking, GGX and Beckmann): E(μ, φ, αx, αy), and the slice of it at one
//! (αx, αy) that energy compensation reads.
//!
//! E depends on the azimuth φo of wo as well as on μ = cos θo: the masking of wo follows the
//! projected roughness α_o(φo) = √(αx² cos²φo + αy² sin²φo), and the lobe spreads around wo with the
//! other axis. The table holds E at every node of a 4D grid (the numbers are in
//! `albedo_anisotropic_ggx.bin` / `_beckmann.bin`, written by `tools/albedo_tables.rs`):
//!
//! - μ on [`ANISO_MU_NODES`] nodes uniform in s = √μ (dense toward grazing views, where E changes
//!   fastest); the node μ = 0 holds the value at [`ALBEDO_MU_EPSILON`](super::ALBEDO_MU_EPSILON).
//! - φ ∈ [0, π/2] on [`ANISO_PHI_NODES`] nodes clustered toward both axes (E is even in φ and in
//!   π − φ, so one quadrant covers all azimuths): φ = (π/2) g(t) on uniform t, with the map
//!   g(t) = ½ + asinh((2t − 1) c) / (2 asinh c) and c = 10, so steps grow from 0.96° at the axes
//!   to 8.9° at 45°. Near the smooth axis of a strongly anisotropic NDF the projected roughness
//!   α_o(φo) rises from the small α to the large one within φo ~ α_small / α_large (0.6° at 1:100),
//!   and E with it; uniform 5.6° steps missed that rise by up to 1.3 % (GGX) and 1.9 % (Beckmann)
//!   at θo = 85°, these nodes by 0.11 % and 0.25 % (linear interpolation in t against E at 0.25°
//!   steps, ten pairs in [0.01, 1], θo ≤ 85°).
//! - αx and αy each on [`ANISO_ALPHA_NODES`] nodes uniform in ln(α + [`ANISO_ALPHA_OFFSET`]) from
//!   [`ANISO_ALPHA_LOW`] to 1.
//!
//! Values are stored as u16 (E · 65535, rounding error ≤ 7.7·10⁻⁶): 2 × 247 KiB for the two
//! families (15² × 33 × 17 entries each).
//!
//! A slice ([`AnisotropicAlbedo`]) is built once per (αx, αy): Catmull-Rom interpolation in that α
//! coordinate over the 4 × 4 nearest α nodes (α below [`ANISO_ALPHA_LOW`] reads the lowest node), clamped
//! to [0, 1]; lookups in it are bilinear in (√μ, t). Its E_avg = (1/π) ∫ E(w) cos θ dω over μ AND φ is
//! the exact average of that bilinear interpolant (closed-form weights, [`AnisotropicAlbedo::average`]),
//! so the energy the compensation lobe returns is exactly what its normalisation assumes.

#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use core::f32::consts::FRAC_PI_2;
use glam::Vec3;

/// μ nodes of the anisotropic tables (uniform in √μ).
pub const ANISO_MU_NODES: usize = 17;

/// φ nodes of the anisotropic tables (on [0, π/2], clustered toward both axes: module docs).
pub const ANISO_PHI_NODES: usize = 33;

/// The clustering c of the φ nodes' map g (module docs): the step at the axes over the step at 45°
/// is g′(0) / g′(½) = 1 / √(1 + c²).
const PHI_CLUSTER: f32 = 10.0;

/// asinh([`PHI_CLUSTER`]) = ln(10 + √101).
const ASINH_PHI_CLUSTER: f32 = 2.998_223;

/// α nodes per axis of the anisotropic tables (uniform in ln(α + [`ANISO_ALPHA_OFFSET`]) on
/// [[`ANISO_ALPHA_LOW`], 1]).
pub const ANISO_ALPHA_NODES: usize = 15;

/// The offset c of the α coordinate ln(α + c): nodes close to geometric at small α (where the
/// loss at grazing views grows like α²) and close to uniform at large α (where E falls fastest at
/// normal incidence); a plain ln α grid left 1.2 % of error at GGX (0.2, 0.8), θo = 0°.
pub const ANISO_ALPHA_OFFSET: f32 = 0.015;

/// The smallest α node of the anisotropic tables; smaller α read this node (E there is within 0.2 %
/// of its α → 0 limit, 1, at θo ≤ 85°).
pub const ANISO_ALPHA_LOW: f32 = 0.005;

/// Entries per family: αx × αy × φ × μ.
pub const ANISO_ENTRIES: usize =
    ANISO_ALPHA_NODES * ANISO_ALPHA_NODES * ANISO_PHI_NODES * ANISO_MU_NODES;

/// Entries of one (αx, αy) slice: φ × μ.
const SLICE: usize = ANISO_PHI_NODES * ANISO_MU_NODES;

static GGX_BYTES: &[u8; 2 * ANISO_ENTRIES] = include_bytes!("albedo_anisotropic_ggx.bin");
static BECKMANN_BYTES: &[u8; 2 * ANISO_ENTRIES] = include_bytes!("albedo_anisotropic_beckmann.bin");

/// The tabulated directional albedo of one NDF family with an anisotropic NDF (module docs), read
/// through [`AnisotropicAlbedoTable::slice`].
///
/// # Reference
/// \[KullaConty2017\] (tabulated E and E_avg), extended over φo and (αx, αy).
#[derive(Debug)]
pub struct AnisotropicAlbedoTable {
    name: &'static str,
    bytes: &'static [u8; 2 * ANISO_ENTRIES],
}

impl AnisotropicAlbedoTable {
    /// GGX, height-correlated Smith masking.
    pub const GGX: AnisotropicAlbedoTable = AnisotropicAlbedoTable {
        name: "ggx",
        bytes: GGX_BYTES,
    };

    /// Beckmann, height-correlated Smith masking.
    pub const BECKMANN: AnisotropicAlbedoTable = AnisotropicAlbedoTable {
        name: "beckmann",
        bytes: BECKMANN_BYTES,
    };

    /// The NDF family's name (`"ggx"`, `"beckmann"`).
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The μ of node `i` (s² with s = i / (n − 1); the value stored there is E at
    /// max(μ, [`ALBEDO_MU_EPSILON`](super::ALBEDO_MU_EPSILON))).
    pub fn mu_node(i: usize) -> f32 {
        let s = i.min(ANISO_MU_NODES - 1) as f32 / (ANISO_MU_NODES - 1) as f32;
        s * s
    }

    /// The φ of node `k`: (π/2) g(k / (n − 1)), g the clustering map of the module docs (node 0 is
    /// φ = 0, node n − 1 is π/2, and node n − 1 − k is π/2 − node k).
    pub fn phi_node(k: usize) -> f32 {
        let t = k.min(ANISO_PHI_NODES - 1) as f64 / (ANISO_PHI_NODES - 1) as f64;
        (core::f64::consts::FRAC_PI_2 * phi_cluster(t)) as f32
    }

    /// The α of node `j`: uniform in ln(α + c) from [`ANISO_ALPHA_LOW`] (j = 0) to 1 (j = n − 1),
    /// c = [`ANISO_ALPHA_OFFSET`].
    pub fn alpha_node(j: usize) -> f32 {
        let j = j.min(ANISO_ALPHA_NODES - 1);
        if j == ANISO_ALPHA_NODES - 1 {
            return 1.0;
        }
        let (lo, hi) = alpha_log_range();
        let f = j as f32 / (ANISO_ALPHA_NODES - 1) as f32;
        (lo + (hi - lo) * f).exp() - ANISO_ALPHA_OFFSET
    }

    /// The flat index of node (αx_a, αy_b, φ_k, μ_i) (the generator's layout).
    pub fn index(a: usize, b: usize, k: usize, i: usize) -> usize {
        ((a * ANISO_ALPHA_NODES + b) * ANISO_PHI_NODES + k) * ANISO_MU_NODES + i
    }

    /// The stored E at node (αx_a, αy_b, φ_k, μ_i).
    pub fn entry(&self, a: usize, b: usize, k: usize, i: usize) -> f32 {
        let n = |x: usize, m: usize| x.min(m - 1);
        let at = 2 * Self::index(
            n(a, ANISO_ALPHA_NODES),
            n(b, ANISO_ALPHA_NODES),
            n(k, ANISO_PHI_NODES),
            n(i, ANISO_MU_NODES),
        );
        decode(u16::from_le_bytes([self.bytes[at], self.bytes[at + 1]]))
    }

    /// The table's slice at (αx, αy): Catmull-Rom in (ln αx, ln αy), clamped to [0, 1] (module docs).
    /// α is clamped to [[`ANISO_ALPHA_LOW`], 1]; non-finite α reads the lowest node.
    pub fn slice(&self, alpha_x: f32, alpha_y: f32) -> AnisotropicAlbedo {
        let wx = catmull_rom_weights(alpha_coordinate(alpha_x));
        let wy = catmull_rom_weights(alpha_coordinate(alpha_y));
        let mut e = [0.0f32; SLICE];
        for &(a, ca) in &wx {
            for &(b, cb) in &wy {
                let c = ca * cb;
                if c == 0.0 {
                    continue;
                }
                let base = 2 * Self::index(a, b, 0, 0);
                let raw = &self.bytes[base..base + 2 * SLICE];
                for (v, pair) in e.iter_mut().zip(raw.chunks_exact(2)) {
                    *v += c * decode(u16::from_le_bytes([pair[0], pair[1]]));
                }
            }
        }
        for v in &mut e {
            *v = v.clamp(0.0, 1.0);
        }
        let average = slice_average(&e);
        AnisotropicAlbedo { e, average }
    }
}

/// E of a stored u16.
#[inline]
fn decode(v: u16) -> f32 {
    v as f32 * (1.0 / 65535.0)
}

/// The u16 the generator stores for E (E clamped to [0, 1], rounded to the nearest 1/65535).
pub fn encode_albedo(e: f64) -> u16 {
    (e.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// asinh x (odd), from ln and sqrt (the crate's float functions).
fn asinh(x: f64) -> f64 {
    let a = x.abs();
    (a + (a * a + 1.0).sqrt()).ln().copysign(x)
}

/// The clustering map g: [0, 1] → [0, 1] of the φ nodes, g(t) = ½ + asinh((2t − 1) c) / (2 asinh c)
/// (odd about t = ½, so g(1 − t) = 1 − g(t)).
fn phi_cluster(t: f64) -> f64 {
    let c = PHI_CLUSTER as f64;
    0.5 + asinh((2.0 * t - 1.0) * c) / (2.0 * asinh(c))
}

/// The grid coordinate t ∈ [0, 1] of φ ∈ [0, π/2], the inverse of [`phi_cluster`]:
/// t = ½ + sinh((2g − 1) asinh c) / (2c) with g = φ / (π/2).
#[inline]
fn phi_coordinate(phi: f32) -> f32 {
    let y = (2.0 * phi * (1.0 / FRAC_PI_2) - 1.0) * ASINH_PHI_CLUSTER;
    let e = y.exp();
    0.5 + (e - 1.0 / e) * (0.25 / PHI_CLUSTER)
}

/// ln(α + c) at the lowest and the highest α node.
fn alpha_log_range() -> (f32, f32) {
    (
        (ANISO_ALPHA_LOW + ANISO_ALPHA_OFFSET).ln(),
        (1.0 + ANISO_ALPHA_OFFSET).ln(),
    )
}

/// The grid coordinate of α in [0, n − 1] (uniform in ln(α + c); NaN and α below the lowest node
/// → 0).
fn alpha_coordinate(alpha: f32) -> f32 {
    let n1 = (ANISO_ALPHA_NODES - 1) as f32;
    let (lo, hi) = alpha_log_range();
    let x = ((alpha.max(0.0) + ANISO_ALPHA_OFFSET).ln() - lo) / (hi - lo) * n1;
    if x > 0.0 { x.min(n1) } else { 0.0 }
}

/// The four (node, weight) pairs of uniform Catmull-Rom interpolation at grid coordinate `x`
/// ∈ [0, n − 1]; nodes beyond the ends repeat the end node (the weights still sum to 1 and
/// reproduce the node values).
fn catmull_rom_weights(x: f32) -> [(usize, f32); 4] {
    let n = ANISO_ALPHA_NODES;
    let j = (x as usize).min(n - 2);
    let t = x - j as f32;
    let (t2, t3) = (t * t, t * t * t);
    let w = [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ];
    let node = |d: isize| (j as isize + d).clamp(0, n as isize - 1) as usize;
    [
        (node(-1), w[0]),
        (node(0), w[1]),
        (node(1), w[2]),
        (node(2), w[3]),
    ]
}

/// The weights of 2 ∫₀¹ E(μ) μ dμ for E piecewise linear in s = √μ on the uniform s nodes:
/// 2 ∫ E μ dμ = 4 ∫₀¹ E(s) s³ ds, integrated exactly on each cell.
fn mu_weights() -> [f64; ANISO_MU_NODES] {
    let n1 = (ANISO_MU_NODES - 1) as f64;
    let h = 1.0 / n1;
    let mut w = [0.0f64; ANISO_MU_NODES];
    for i in 0..ANISO_MU_NODES - 1 {
        let (a, b) = (i as f64 * h, (i + 1) as f64 * h);
        let (p4, p5) = (b.powi(4) - a.powi(4), b.powi(5) - a.powi(5));
        // ∫ₐᵇ s³ (b − s) ds / h and ∫ₐᵇ s³ (s − a) ds / h.
        w[i] += 4.0 * (b * p4 / 4.0 - p5 / 5.0) / h;
        w[i + 1] += 4.0 * (p5 / 5.0 - a * p4 / 4.0) / h;
    }
    w
}

/// ∫ₐᵇ g(t) dt for the clustering map g ([`phi_cluster`]), in closed form:
/// ∫ asinh x dx = x asinh x − √(1 + x²) with x = (2t − 1) c.
fn phi_cluster_integral(a: f64, b: f64) -> f64 {
    let c = PHI_CLUSTER as f64;
    let f = |t: f64| {
        let x = (2.0 * t - 1.0) * c;
        x * asinh(x) - (1.0 + x * x).sqrt()
    };
    (b - a) / 2.0 + (f(b) - f(a)) / (4.0 * c * asinh(c))
}

/// (2/π) ∫₀^{π/2} E(φ) dφ = ∫₀¹ E(t) g′(t) dt for E piecewise linear in t on the uniform t nodes:
/// the weight of node k, ∫ hat_k(t) g′(t) dt, which integration by parts turns into
/// (I(t_k, t_k+1) − I(t_k−1, t_k)) / h with I the integral of g (the end nodes take their one side
/// and g(0) = 0, g(1) = 1).
fn phi_weight(k: usize) -> f64 {
    let n1 = (ANISO_PHI_NODES - 1) as f64;
    let t = |j: usize| j as f64 / n1;
    // ∫ (t − t_k−1) / h · g′ dt over the cell left of node k, and ∫ (t_k+1 − t) / h · g′ dt right of it.
    let left = if k > 0 {
        phi_cluster(t(k)) - phi_cluster_integral(t(k - 1), t(k)) * n1
    } else {
        0.0
    };
    let right = if k + 1 < ANISO_PHI_NODES {
        phi_cluster_integral(t(k), t(k + 1)) * n1 - phi_cluster(t(k))
    } else {
        0.0
    };
    left + right
}

/// E_avg = (1/π) ∫ E(w) cos θ dω of a slice's bilinear interpolant, exactly (in f64).
fn slice_average(e: &[f32; SLICE]) -> f32 {
    let wm = mu_weights();
    let mut sum = 0.0f64;
    for k in 0..ANISO_PHI_NODES {
        let row = &e[k * ANISO_MU_NODES..(k + 1) * ANISO_MU_NODES];
        let r: f64 = row.iter().zip(&wm).map(|(&v, &w)| v as f64 * w).sum();
        sum += phi_weight(k) * r;
    }
    sum as f32
}

/// The directional albedo of one anisotropic (αx, αy) as a function of wo: E(μ, φ) on the tables'
/// (√μ, t) grid, bilinear, and its exact cosine-weighted hemispherical average
/// ([`AnisotropicAlbedoTable::slice`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnisotropicAlbedo {
    /// E[φ_k][μ_i], flattened (φ-major).
    e: [f32; SLICE],
    average: f32,
}

impl AnisotropicAlbedo {
    /// E(w) for a direction `w` in the local frame: μ = w.z clamped to [0, 1], φ = atan2(|w.y|, |w.x|)
    /// (0 at normal incidence); bilinear in (√μ, t), t the φ nodes' grid coordinate (module docs). Total: non-finite input reads the μ = 0 node.
    #[inline]
    pub fn albedo(&self, w: Vec3) -> f32 {
        let mu = if w.z > 0.0 { w.z.min(1.0) } else { 0.0 };
        let x = mu.sqrt() * (ANISO_MU_NODES - 1) as f32;
        let phi = w.y.abs().atan2(w.x.abs());
        let y = if phi > 0.0 {
            (phi_coordinate(phi.min(FRAC_PI_2)) * (ANISO_PHI_NODES - 1) as f32)
                .clamp(0.0, (ANISO_PHI_NODES - 1) as f32)
        } else {
            0.0
        };
        let i = (x as usize).min(ANISO_MU_NODES - 2);
        let k = (y as usize).min(ANISO_PHI_NODES - 2);
        let (fx, fy) = (x - i as f32, y - k as f32);
        let at = |k: usize, i: usize| self.e[k * ANISO_MU_NODES + i];
        let row = |k: usize| at(k, i) + (at(k, i + 1) - at(k, i)) * fx;
        let (r0, r1) = (row(k), row(k + 1));
        r0 + (r1 - r0) * fy
    }

    /// E_avg = (1/π) ∫ E(w) cos θ dω over the hemisphere (μ and φ), the exact average of
    /// [`albedo`](Self::albedo).
    pub fn average(&self) -> f32 {
        self.average
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_span_the_documented_ranges() {
        assert_eq!(AnisotropicAlbedoTable::mu_node(0), 0.0);
        assert_eq!(AnisotropicAlbedoTable::mu_node(ANISO_MU_NODES - 1), 1.0);
        assert_eq!(
            AnisotropicAlbedoTable::phi_node(ANISO_PHI_NODES - 1),
            FRAC_PI_2
        );
        assert!((AnisotropicAlbedoTable::alpha_node(0) - ANISO_ALPHA_LOW).abs() < 1e-7);
        assert_eq!(
            AnisotropicAlbedoTable::alpha_node(ANISO_ALPHA_NODES - 1),
            1.0
        );
    }

    #[test]
    fn phi_nodes_are_symmetric_and_their_coordinate_inverts_them() {
        assert!((asinh(PHI_CLUSTER as f64) - ASINH_PHI_CLUSTER as f64).abs() < 1e-6);
        let n1 = (ANISO_PHI_NODES - 1) as f32;
        for k in 0..ANISO_PHI_NODES {
            let phi = AnisotropicAlbedoTable::phi_node(k);
            let mirror = AnisotropicAlbedoTable::phi_node(ANISO_PHI_NODES - 1 - k);
            assert!(
                (phi + mirror - FRAC_PI_2).abs() < 1e-6,
                "{k}: {phi} {mirror}"
            );
            let t = phi_coordinate(phi) * n1;
            assert!((t - k as f32).abs() < 1e-4, "{k}: {t}");
        }
        // Steps grow from the axes to 45°: 0.96° and 8.9°.
        let step = |k: usize| {
            (AnisotropicAlbedoTable::phi_node(k + 1) - AnisotropicAlbedoTable::phi_node(k))
                .to_degrees()
        };
        assert!((step(0) - 0.96).abs() < 0.01 && (step(ANISO_PHI_NODES / 2) - 8.86).abs() < 0.01);
    }

    #[test]
    fn phi_weights_integrate_g_prime() {
        // ∫ hat_k g′ dt by a fine midpoint rule in t.
        let n1 = (ANISO_PHI_NODES - 1) as f64;
        let m = 200_000;
        let mut w = [0.0f64; ANISO_PHI_NODES];
        for j in 0..m {
            let t = (j as f64 + 0.5) / m as f64;
            let dg = (phi_cluster(t + 0.5e-6) - phi_cluster(t - 0.5e-6)) / 1e-6;
            let x = t * n1;
            let k = (x as usize).min(ANISO_PHI_NODES - 2);
            let f = x - k as f64;
            w[k] += (1.0 - f) * dg / m as f64;
            w[k + 1] += f * dg / m as f64;
        }
        for (k, v) in w.iter().enumerate() {
            assert!(
                (v - phi_weight(k)).abs() < 1e-6,
                "{k}: {v} vs {}",
                phi_weight(k)
            );
        }
    }

    #[test]
    fn average_weights_integrate_constants_and_mu() {
        // 2 ∫ μ dμ = 1 and 2 ∫ μ · μ dμ = 2/3 (μ = s² is linear-in-s only at the nodes, so the second
        // is approximate: the rule's error for E = μ is O(h²)).
        let wm = mu_weights();
        assert!((wm.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let m: f64 = (0..ANISO_MU_NODES)
            .map(|i| wm[i] * AnisotropicAlbedoTable::mu_node(i) as f64)
            .sum();
        assert!((m - 2.0 / 3.0).abs() < 2e-3, "{m}");
        let p: f64 = (0..ANISO_PHI_NODES).map(phi_weight).sum();
        assert!((p - 1.0).abs() < 1e-12);
    }

    #[test]
    fn slice_at_a_node_reproduces_the_entries() {
        for t in [
            &AnisotropicAlbedoTable::GGX,
            &AnisotropicAlbedoTable::BECKMANN,
        ] {
            for (a, b) in [(0, 0), (3, 9), (14, 5), (14, 14)] {
                let s = t.slice(
                    AnisotropicAlbedoTable::alpha_node(a),
                    AnisotropicAlbedoTable::alpha_node(b),
                );
                for (k, i) in [(0, 16), (5, 3), (16, 9), (8, 1)] {
                    let (mu, phi) = (
                        AnisotropicAlbedoTable::mu_node(i),
                        AnisotropicAlbedoTable::phi_node(k),
                    );
                    let st = (1.0 - mu * mu).max(0.0).sqrt();
                    let w = Vec3::new(st * phi.cos(), st * phi.sin(), mu);
                    let d = (s.albedo(w) - t.entry(a, b, k, i)).abs();
                    assert!(d < 2e-5, "{} ({a}, {b}) ({k}, {i}): {d}", t.name());
                }
            }
        }
    }

    #[test]
    fn average_is_the_mean_of_the_interpolant() {
        // A fine midpoint rule over (μ, φ) of the slice's own lookup agrees with the closed form.
        let s = AnisotropicAlbedoTable::GGX.slice(0.03, 0.7);
        let (n, m) = (2000, 400);
        let mut sum = 0.0f64;
        for a in 0..n {
            let mu = (a as f64 + 0.5) / n as f64;
            for b in 0..m {
                let phi = (b as f64 + 0.5) / m as f64 * std::f64::consts::FRAC_PI_2;
                let st = (1.0 - mu * mu).sqrt();
                let w = Vec3::new((st * phi.cos()) as f32, (st * phi.sin()) as f32, mu as f32);
                sum += s.albedo(w) as f64 * 2.0 * mu;
            }
        }
        let avg = sum / (n * m) as f64;
        assert!(
            (avg - s.average() as f64).abs() < 2e-5,
            "{avg} vs {}",
            s.average()
        );
    }

    #[test]
    fn lookups_are_total_and_bounded() {
        let s = AnisotropicAlbedoTable::BECKMANN.slice(f32::NAN, 7.0);
        for w in [
            Vec3::NAN,
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(f32::INFINITY, 1.0, 0.5),
        ] {
            let e = s.albedo(w);
            assert!(e.is_finite() && (0.0..=1.0).contains(&e), "{w}: {e}");
        }
        assert!((0.0..=1.0).contains(&s.average()));
    }
}
