//! The exact masking terms of a small footprint's patch: the footprint's bins enumerated through
//! 𝓑 once per patch (masses, facets, cell corners), the projected area A(w) and the visible area
//! V(w), exact for the bins that face w entirely and bounded from above for the bins that w's
//! horizon cuts (a sub-bin quadrature bound on a proven Lipschitz constant of the equal-area map).
//!
//! # Reference
//! \[Chermain2019\] eq. 13-17 (exact Smith terms of a sum of lobes), over the bins of
//! \[Atanasov2020\] §2.

use super::BinMap;
use super::clip::{Overlap, Parallelogram};
use super::facets::{BinFacet, corners_of};
use crate::glint::HemisphereBins;
use crate::glint::scratch::Lent;
use crate::math::finite_or_zero;
use crate::ndf::{Ndf, SlopeGaussian};
use crate::warp::square_to_hemisphere_equal_area;
use glam::{Mat2, Vec2, Vec3};

/// A Lipschitz constant L of the equal-area map u ↦ m(u) from the unit square to the hemisphere:
/// |m(u) − m(u')| ≤ L |u − u'|.
///
/// Proof: (a, b) = 2u − 1 (factor 2); on the concentric sector |a| ≥ |b| the disk point has radius
/// r = |a| and angle φ = (π/4) b/a, so a step (da, db) moves it by da radially and by
/// (π/4)(db − (b/a) da) tangentially (|b/a| ≤ 1); the Lambert map z = 1 − r² stretches radial steps
/// by 2/√(2 − r²) ≤ 2 and tangential ones by √(2 − r²) ≤ √2. The Jacobian's operator norm is at
/// most its Frobenius norm, 2 √(2² + 2 (π/4)² (1 + 1)) = 2 √(4 + π²/4) = 5.0863. The map is
/// continuous and piecewise smooth (the four sectors), so the chord is at most the arc along the
/// image of a straight segment, at most L × its length. 5.09 rounds up.
pub(super) const EQUAL_AREA_LIPSCHITZ: f32 = 5.09;

/// Sub-cells per axis of the horizon-cut bins' quadrature bound (see [`visible_part`]): the bound's
/// excess over the true visible area shrinks as 1/k per cut bin (64 map evaluations per cut bin).
const SUB_BIN_GRID: usize = 8;

/// Sub-cells per axis into which each horizon-cut sub-cell of a heavy bin is split again (see
/// [`visible_part`], item 4).
const SUB_BIN_REFINE: usize = 4;

/// A bin is refined at the horizon when it holds at least this share of the footprint's
/// Σ_j s_j (so at most 1/share bins per direction): where a bin carries much of the mass (the pole
/// bin of a mostly flat map) the whole-bin excess of the k × k bound is a visible part of V at
/// grazing angles (3 % on the scratched map at 89° with 127² bins: docs/results.md), elsewhere it is
/// negligible and not worth r² more evaluations.
const REFINE_SHARE: f32 = 1.0 / 32.0;

/// Absolute allowance for `f32` rounding in a sub-cell centre and its dot product (a few ulp of 1).
const DOT_ROUNDING: f32 = 1e-6;

/// A buffer of a patch: taken from the caller's [`GlintScratch`](crate::glint::GlintScratch) (one
/// pool per element type) or fresh, given back with its capacity when the patch drops, so patches
/// allocate nothing once the pools have grown to the largest footprint. A clone owns its buffer.
pub(super) type Buf<'a, T> = Lent<'a, Vec<T>>;

/// Sorts the (bin, overlap) pairs of a footprint by bin and returns the sorted slice: an LSD radix
/// sort on the bytes of the bin index (1-3 passes of a 256-bucket counting sort for B = `bins`,
/// O(N) against O(N log N) for a comparison sort; the 4096-texel patch spent ~25 % of its time
/// sorting 16 384 pairs), using the second half of `acc` as the ping-pong buffer. Short lists use
/// the comparison sort (the counting passes cost 256 buckets each).
fn sort_by_bin(acc: &mut Vec<(u32, f64)>, bins: usize) -> &[(u32, f64)] {
    let len = acc.len();
    if len < 256 {
        acc.sort_unstable_by_key(|e| e.0);
        return acc;
    }
    let passes = match bins.saturating_sub(1) {
        0..=0xFF => 1,
        0x100..=0xFFFF => 2,
        0x1_0000..=0xFF_FFFF => 3,
        _ => 4,
    };
    acc.resize(2 * len, (0, 0.0));
    let (mut src, mut dst) = acc.split_at_mut(len);
    for pass in 0..passes {
        let shift = 8 * pass;
        let mut start = [0usize; 256];
        for e in src.iter() {
            start[((e.0 >> shift) & 0xFF) as usize] += 1;
        }
        let mut sum = 0;
        for c in start.iter_mut() {
            let n = *c;
            *c = sum;
            sum += n;
        }
        for e in src.iter() {
            let d = ((e.0 >> shift) & 0xFF) as usize;
            dst[start[d]] = *e;
            start[d] += 1;
        }
        std::mem::swap(&mut src, &mut dst);
    }
    src
}

/// One bin of the footprint, for the exact masking terms and the visible-normal sampler.
#[derive(Clone, Copy, Debug)]
pub(super) struct PatchBin {
    pub(super) bin: u32,
    /// mass_j = Σ_k I_{H_j}(t_k) |A ∩ T_k| / |A|, the same sum as the forest's query of bin j.
    pub(super) mass: f64,
    /// s_j = mass_j / c̄_j: the bin's D times |H|.
    pub(super) scale: f32,
    /// The bin's tabulated facet (mean direction, centre, radius; unscaled).
    pub(super) facet: BinFacet,
    /// The directions of the cell's corners (0, 0), (1, 0), (0, 1), (1, 1) in cell coordinates.
    pub(super) corners: [Vec3; 4],
}

/// The footprint's bins with their masses, for masking terms computed from the bin-map D itself.
#[derive(Clone, Debug)]
pub(super) struct ExactMasking<'a> {
    /// Per non-empty bin of the unsmoothed patch, sorted by bin index.
    pub(super) bins: Buf<'a, PatchBin>,
    /// Per non-empty bin j of the smoothed patch, mass_j and its smoothing lobe D_j.
    pub(super) lobes: Buf<'a, (f32, SlopeGaussian)>,
    /// A(w) = max(w · a, 0): Σ_j s_j m̄_j (unsmoothed); Σ_j mass_j (−μ_j, 1) (smoothed, μ_j the
    /// lobe's mean slope).
    pub(super) a: Vec3,
    /// [`REFINE_SHARE`] × Σ_j s_j: bins with s_j at least this get the refined horizon bound.
    heavy_scale: f32,
}

impl<'a> ExactMasking<'a> {
    /// Enumerates the sub-texels of A (every periodic image), their exact overlaps and bins through
    /// 𝓑: O(s² |A|) once per patch. `acc` is a work buffer.
    pub(super) fn new(
        map: &BinMap,
        para: &Parallelogram,
        images: &[[f64; 2]],
        sigma: Option<f64>,
        acc: &mut Vec<(u32, f64)>,
        mut bins: Buf<'a, PatchBin>,
        mut lobes: Buf<'a, (f32, SlopeGaussian)>,
    ) -> ExactMasking<'a> {
        let (w, h) = (map.grid_w as i64, map.grid_h as i64);
        acc.clear();
        for &d in images {
            let p = para.translated(d);
            let (lo, hi) = p.bounds();
            let (i0, i1) = ((lo[0].floor() as i64).max(0), (hi[0].ceil() as i64).min(w));
            let (j0, j1) = ((lo[1].floor() as i64).max(0), (hi[1].ceil() as i64).min(h));
            // 𝓑's rows are asked for a few rows ahead of the row read (a hint), so that their
            // loads overlap.
            const AHEAD: i64 = 4;
            let span = |j: i64| ((j * w + i0) as usize, (j * w + i1) as usize);
            for j in j0..(j0 + AHEAD).min(j1) {
                let (a, b) = span(j);
                map.bin_map.prefetch(a, b);
            }
            for j in j0..j1 {
                if j + AHEAD < j1 {
                    let (a, b) = span(j + AHEAD);
                    map.bin_map.prefetch(a, b);
                }
                for i in i0..i1 {
                    let (x, y) = (i as f64, j as f64);
                    let ov = match p.classify(x, y, x + 1.0, y + 1.0) {
                        Overlap::Outside => continue,
                        Overlap::Inside => 1.0,
                        Overlap::Partial => p.overlap_area(x, y, x + 1.0, y + 1.0),
                    };
                    if ov > 0.0 {
                        let bin = map.bin_map.get((j * w + i) as usize).unwrap_or(0);
                        acc.push((bin as u32, ov));
                    }
                }
            }
        }
        let acc = sort_by_bin(acc, map.bins.len());
        let inv_area = 1.0 / para.area();
        let (bins_out, lobes_out) = (&mut *bins, &mut *lobes);
        bins_out.clear();
        lobes_out.clear();
        let mut a = [0.0f64; 3];
        let mut k = 0;
        while k < acc.len() {
            let bin = acc[k].0 as usize;
            let mut mass = 0.0;
            while k < acc.len() && acc[k].0 as usize == bin {
                mass += acc[k].1;
                k += 1;
            }
            let smoothing = sigma.and_then(|s| {
                let var = (s * s) as f32;
                SlopeGaussian::new(map.center_slope[bin], Mat2::from_diagonal(Vec2::splat(var)))
                    .ok()
            });
            if let Some(lobe) = smoothing {
                // ∫ (w·m) D_j dm = w_z − w_xy·μ_j for a slope Gaussian of mean μ_j.
                let (m, mu) = (mass * inv_area, lobe.mean());
                a[0] -= m * mu.x as f64;
                a[1] -= m * mu.y as f64;
                a[2] += m;
                lobes_out.push((m as f32, lobe));
                continue;
            }
            let f = map.facets[bin];
            let scale = mass * inv_area / f.mean.z as f64;
            for (ai, m) in a.iter_mut().zip(f.mean.to_array()) {
                *ai += m as f64 * scale;
            }
            // The cell's corner directions from the map's corner grid: what
            // `sample_in_bin(bin, corner)` returns, bit for bit, without the equal-area map.
            bins_out.push(PatchBin {
                bin: bin as u32,
                mass: mass * inv_area,
                scale: scale as f32,
                facet: f,
                corners: corners_of(&map.corners, &map.bins, bin),
            });
        }
        let total: f32 = bins.as_slice().iter().map(|b| b.scale).sum();
        ExactMasking {
            bins,
            lobes,
            a: Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32),
            heavy_scale: REFINE_SHARE * total,
        }
    }

    /// mass_j of `bin` from the footprint's listed bins (0 for a bin the footprint does not touch),
    /// or `None` when the patch lists no bins (smoothed): a binary search instead of the bin's forest
    /// query, which sums the same overlaps in another order (equal to f64 rounding).
    #[inline]
    pub(super) fn bin_mass(&self, bin: usize) -> Option<f64> {
        let bins = self.bins.as_slice();
        if bins.is_empty() {
            return None;
        }
        let found = u32::try_from(bin)
            .ok()
            .and_then(|b| bins.binary_search_by_key(&b, |p| p.bin).ok());
        Some(found.map_or(0.0, |k| bins[k].mass))
    }

    /// V(w) = Σ_j s_j (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω, exact for the bins that face w entirely and bounded
    /// from above for those that w's horizon cuts (type docs).
    pub(super) fn visible_area(&self, bins: &HemisphereBins, w: Vec3) -> f32 {
        let facets: f64 = self
            .bins
            .as_slice()
            .iter()
            .map(|b| {
                let refine = b.scale >= self.heavy_scale;
                b.scale as f64 * visible_part(bins, b, w, refine) as f64
            })
            .sum();
        let lobes: f64 = self
            .lobes
            .as_slice()
            .iter()
            .map(|(m, lobe)| *m as f64 * lobe.visible_area(w) as f64)
            .sum();
        finite_or_zero(facets + lobes)
    }
}

/// One bin's (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω (unscaled): exact when the bin faces w entirely, an upper
/// bound when w's horizon cuts it.
///
/// If ⟨w, c_j⟩ ≥ r_j the whole bin faces w and the integral is linear: ⟨w, m̄_j⟩, exact. Otherwise
/// the smallest of three upper bounds:
/// 1. the coarse bound min(⟨w, m̄_j⟩ + r_j − ⟨w, c_j⟩, ⟨w, c_j⟩ + r_j)⁺ (the mean of ⟨w, m⟩ plus the
///    largest ⟨w, m⟩⁻ in the bin; the largest ⟨w, m⟩⁺);
/// 2. and 3., a sub-bin quadrature bound: the bin's cell is split into k × k equal sub-cells
///    (k = [`SUB_BIN_GRID`]), each the image of a square of side h = 1/(n k) and so of solid angle
///    |H|/k² (the map is equal-area). Every direction of a sub-cell is within ρ = L h/√2 of the
///    sub-cell's centre image m_c ([`EQUAL_AREA_LIPSCHITZ`]), so ⟨w, m⟩ ∈ [⟨w, m_c⟩ − ρ, ⟨w, m_c⟩ + ρ]
///    there. Hence, with x⁺ = x + x⁻,
///    (2) (1/|H|) ∫ ⟨w, m⟩⁺ = ⟨w, m̄_j⟩ + (1/|H|) ∫ ⟨w, m⟩⁻ ≤ ⟨w, m̄_j⟩ + (1/k²) Σ_c (ρ − ⟨w, m_c⟩)⁺,
///    (3) (1/|H|) ∫ ⟨w, m⟩⁺ ≤ (1/k²) Σ_c (⟨w, m_c⟩ + ρ)⁺.
///    (2) is tight where most of the bin faces w, (3) where most of it does not; the excess of the
///    smaller is at most ρ per sub-cell on the minority side plus 2ρ per cut sub-cell, O(1/k) of the
///    bin's radius (the coarse bound's excess is O(r_j)). ρ carries [`DOT_ROUNDING`] for `f32`.
/// 4. With `refine` (the footprint's heavy bins, see [`REFINE_SHARE`]), every sub-cell that the
///    horizon may cross (|⟨w, m_c⟩| < ρ) is replaced in (2) and (3) by its r × r sub-cells
///    (r = [`SUB_BIN_REFINE`]), each of solid angle |H|/(k r)² and radius ρ/r by the same Lipschitz
///    argument: the sums run over a finer partition of the same bin, so both stay upper bounds. The
///    excess is carried by the cells the horizon may cross: about r times as many, each r² times
///    smaller with an r times smaller ρ, so it shrinks about r²-fold, for r² evaluations per such
///    sub-cell (a few k of them).
///
/// An upper bound of V is a lower bound of G1 = A/V: the BRDF may lose a little energy at grazing
/// angles but never creates any (the white furnaces in tests/it/robustness_energy.rs and
/// tests/it/binmap_furnace.rs).
#[inline]
fn visible_part(bins: &HemisphereBins, b: &PatchBin, w: Vec3, refine: bool) -> f32 {
    let f = &b.facet;
    let (lin, c) = (w.dot(f.mean), w.dot(f.center));
    if c >= f.radius {
        return lin.max(0.0);
    }
    let coarse = (lin + f.radius - c).min(c + f.radius).max(0.0);
    if coarse <= 0.0 {
        return 0.0;
    }
    let n = bins.n();
    let k = SUB_BIN_GRID;
    let (i, j) = bins.cell(b.bin as usize);
    let rho =
        EQUAL_AREA_LIPSCHITZ * std::f32::consts::FRAC_1_SQRT_2 / (n * k) as f32 + DOT_ROUNDING;
    let (mut neg, mut pos) = (0.0f32, 0.0f32);
    let inv = 1.0 / (n * k) as f32;
    let r = SUB_BIN_REFINE;
    let (inv_r, inv_r2) = (1.0 / r as f32, 1.0 / (r * r) as f32);
    let rho_fine =
        EQUAL_AREA_LIPSCHITZ * std::f32::consts::FRAC_1_SQRT_2 / (n * k * r) as f32 + DOT_ROUNDING;
    for sb in 0..k {
        for sa in 0..k {
            let corner = Vec2::new((i * k + sa) as f32, (j * k + sb) as f32);
            let cm = w.dot(square_to_hemisphere_equal_area((corner + 0.5) * inv));
            if refine && cm.abs() < rho {
                // The horizon may cross this sub-cell: bound its r × r sub-cells instead (each of
                // solid angle |H|/(k r)², radius ρ/r), a finer partition of the same bin.
                let (mut nf, mut pf) = (0.0f32, 0.0f32);
                for tb in 0..r {
                    for ta in 0..r {
                        let off = Vec2::new((ta as f32 + 0.5) * inv_r, (tb as f32 + 0.5) * inv_r);
                        let cf = w.dot(square_to_hemisphere_equal_area((corner + off) * inv));
                        nf += (rho_fine - cf).max(0.0);
                        pf += (cf + rho_fine).max(0.0);
                    }
                }
                neg += nf * inv_r2;
                pos += pf * inv_r2;
            } else {
                neg += (rho - cm).max(0.0);
                pos += (cm + rho).max(0.0);
            }
        }
    }
    let inv_k2 = 1.0 / (k * k) as f32;
    coarse.min(lin + neg * inv_k2).min(pos * inv_k2).max(0.0)
}

/// The proven radius of a whole bin around its centre image: L/(n √2) (see
/// [`EQUAL_AREA_LIPSCHITZ`]), plus rounding.
#[inline]
pub(super) fn bin_lipschitz_radius(bins: &HemisphereBins) -> f32 {
    EQUAL_AREA_LIPSCHITZ * std::f32::consts::FRAC_1_SQRT_2 / bins.n() as f32 + DOT_ROUNDING
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// `visible_part` against a fine midpoint quadrature of (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω on Q × Q
    /// equal sub-cells, for bins cut by the horizon of random near-grazing w. ⟨w, m⟩⁺ is 1-Lipschitz
    /// in m, so the quadrature is within ρ_Q = L/(n Q √2) of the integral: the bound must be ≥
    /// quadrature − ρ_Q (− 1e-6 for f32 sums). And its mean excess over the quadrature must be
    /// well below the coarse bound's (the reason for the sub-bin bound).
    #[test]
    fn horizon_bound_is_an_upper_bound_and_tighter_than_the_coarse_one() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
        let q = 96usize;
        for n in [15usize, 63, 127] {
            let bins = HemisphereBins::new(n).unwrap();
            let rho_q = EQUAL_AREA_LIPSCHITZ * std::f32::consts::FRAC_1_SQRT_2 / (n * q) as f32;
            let (mut ex_fine, mut ex_coarse, mut ex_refined, mut cut) =
                (0.0f64, 0.0f64, 0.0f64, 0usize);
            while cut < 150 {
                let theta = rng.random_range(1.2f32..std::f32::consts::FRAC_PI_2);
                let phi = rng.random_range(0.0f32..std::f32::consts::TAU);
                let w = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                // A point on w's horizon (great circle ⟂ w) in the upper hemisphere.
                let e1 = w.cross(Vec3::Z).normalize();
                let e2 = w.cross(e1).normalize();
                let t = rng.random_range(0.0f32..std::f32::consts::TAU);
                let m0 = e1 * t.cos() + e2 * t.sin();
                if m0.z <= 1e-3 {
                    continue;
                }
                let Some(bin) = bins.bin_of(m0) else { continue };
                let facet = BinFacet::new(&bins, bin);
                let b = PatchBin {
                    bin: bin as u32,
                    mass: 1.0,
                    scale: 1.0,
                    facet,
                    corners: [Vec3::Z; 4],
                };
                let (lin, c) = (w.dot(facet.mean), w.dot(facet.center));
                if c >= facet.radius {
                    continue;
                }
                cut += 1;
                let bound = visible_part(&bins, &b, w, false);
                let refined = visible_part(&bins, &b, w, true);
                let coarse = (lin + facet.radius - c).min(c + facet.radius).max(0.0);
                let (i, j) = bins.cell(bin);
                let mut sum = 0.0f64;
                for sb in 0..q {
                    for sa in 0..q {
                        let u = Vec2::new(
                            (i as f32 + (sa as f32 + 0.5) / q as f32) / n as f32,
                            (j as f32 + (sb as f32 + 0.5) / q as f32) / n as f32,
                        );
                        sum += w.dot(square_to_hemisphere_equal_area(u)).max(0.0) as f64;
                    }
                }
                let quad = sum / (q * q) as f64;
                assert!(
                    bound as f64 >= quad - rho_q as f64 - 1e-6,
                    "n={n} bin={bin} w={w}: bound {bound} < integral {quad} − {rho_q}"
                );
                assert!(
                    refined as f64 >= quad - rho_q as f64 - 1e-6,
                    "n={n} bin={bin} w={w}: refined bound {refined} < integral {quad} − {rho_q}"
                );
                assert!(bound <= coarse, "n={n}: {bound} > coarse {coarse}");
                assert!(refined <= bound, "n={n}: refined {refined} > {bound}");
                ex_fine += bound as f64 - quad;
                ex_refined += refined as f64 - quad;
                ex_coarse += coarse as f64 - quad;
            }
            println!(
                "n = {n}: mean excess {:.2e} (coarse {:.2e}, refined {:.2e})",
                ex_fine / 150.0,
                ex_coarse / 150.0,
                ex_refined / 150.0
            );
            // Measured: excess 1.1e-2 / 2.6e-3 / 1.2e-3 against the coarse bound's 0.12 / 0.028 / 0.014
            // for n = 15 / 63 / 127 (about 11× tighter); 3× is a regression bound.
            assert!(ex_fine < ex_coarse / 3.0, "n={n}: {ex_fine} vs {ex_coarse}");
            // Refining the cut sub-cells 4 × 4: measured 4.4e-3 / 1.1e-3 / 4.9e-4 (2.4-2.5× below
            // the k × k bound; the rest of the excess is the ρ of the uncut sub-cells on the
            // minority side of the horizon). 1.5× is a regression bound.
            assert!(
                ex_refined < ex_fine / 1.5,
                "n={n}: {ex_refined} vs {ex_fine}"
            );
        }
    }
}
