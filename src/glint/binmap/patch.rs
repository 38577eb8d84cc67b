//! The bin-map P-NDF of one footprint: bin masses through the forest (with periodic images),
//! D = mass / (|H| c̄), the smoothed variant, the masking lobe and the samplers.
//!
//! # Reference
//! \[Atanasov2020\] §2 (D_A^H), §2.1 (sampling), §2.2 (evaluation through 𝓑⁻¹).

use super::clip::{Overlap, Parallelogram};
use super::forest::QueryStats;
use super::{BinFacet, BinMap, EXACT_MASKING_TEXELS};
use crate::glint::{Footprint, MIN_WIDTH_TEXELS};
use crate::math::finite_or_zero;
use crate::ndf::{Ndf, SlopeGaussian};
use crate::warp::square_to_gaussian_2d;
use glam::{Mat2, Vec2, Vec3};

/// Mass left outside the truncation radius of each smoothing lobe: the isotropic slope Gaussian of σ
/// has exp(−R²/(2σ²)) of its mass beyond R, so R = √(−2 ln 10⁻⁶) σ ≈ 5.26 σ. The smoothed D and
/// its pdf miss at most this fraction of the mass.
const SMOOTH_TAIL: f64 = 1e-6;

/// The P-NDF of a [`BinMap`] seen through one parallelogram footprint A.
///
/// **D.** For a half vector h in bin j:
///
/// D(h) = mass_j / (|H| c̄_j),  mass_j = (1/|A|) Σ_k I_{H_j}(t_k) |A ∩ T_k|,
///
/// with |H| = 2π/B and c̄_j the bin's mean cosine. The talk's D_A^H = mass_j/|H| integrates to 1
/// against dω; dividing by c̄_j makes ∫_{H_j} D cos θ dω = mass_j, hence ∫ D cos θ dω = Σ mass_j = 1
/// (the crate's convention), D being constant per bin. |A ∩ T_k| sums over the periodic images of
/// texel k (the map tiles), so footprints crossing the border or larger than the map are exact.
///
/// **Smoothed variant** ([`BinMap::patch_smoothed`]): D(h) = Σ_j mass_j D_j(h) with D_j the
/// Beckmann lobe of slope σ = α/√2 centred on the slope of bin j's centre (D_j = P22_j / cos⁴θ,
/// ∫ D_j cos = 1), over the bins whose centre slope lies within 5.26 σ of h's slope (≤ 10⁻⁶ of each
/// lobe left out). Cost ∝ (n α)² lookups per evaluation.
///
/// **Masking** (the talk defines none). For footprints of at most [`EXACT_MASKING_TEXELS`] texels,
/// Smith terms of the bin-map D itself, from the footprint's bins enumerated once per patch
/// (O(|A|), through 𝓑). Each bin's D is constant, so with m̄_j = (1/|H|) ∫_{H_j} m dω the bin's mean
/// direction vector (tabulated per bin at build), the projected area A(w) = max(Σ_j mass_j ⟨w, m̄_j⟩
/// / c̄_j, 0) is exact, and so is V(w) = ∫⟨w, m⟩⁺ D dm = Σ_j (mass_j / c̄_j) (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω
/// for every bin that faces w entirely; for a bin cut by w's horizon (within about one bin width of
/// grazing) the bin's term is replaced by an upper bound, so that G1 = A/V can only err low and the
/// BRDF never gains energy (see `visible_part`).
/// Λ = V/A − 1, the same construction as the mixture's exact terms (\[Chermain2019\] eq. 13-17).
/// For the smoothed variant the sums run over the smoothing lobes instead, exactly as for a mixture:
/// V(w) = Σ_j mass_j V_j(w) and A(w) = max(Σ_j mass_j (cos θ − w_xy·μ_j), 0), μ_j the centre slope
/// of bin j (the unsmoothed bins' V under-counted the smoothed D's visible area: white furnace up to
/// 1.25 at grazing angles before). Larger footprints use the Smith terms of
/// the footprint's filtered-moment Beckmann lobe ([`SlopeGaussian::from_moments`] of the map's
/// moment mip chain at the footprint centre and radius ½√|A|, σ floored at `sigma_min`), whose
/// first two slope moments approximate the footprint's (second moments raised by σ² for the
/// smoothed variant). See docs/binmap.md and the white furnace in
/// tests/binmap.rs. The lobe's V is replaced by Scarf's moment bound
/// ([`BinMapPatch::moment_bound_visible_area`]) and A by its signed projected area, so Λ is
/// conservative (a Gaussian's V can be below a spiky distribution's with the same moments).
///
/// **Sampling.** [`Ndf::sample_normal`]: a uniform point y of A from u, its texel (wrapped), the
/// texel's bin through 𝓑, then a uniform direction in that bin (or a draw of the bin's smoothing
/// lobe) from a second pair of numbers hashed from the bits of u. Its density is mass_j/|H| (or
/// Σ mass_j D_j cos θ), returned by [`Ndf::pdf_normal`]; for the unsmoothed patch it differs from
/// D(m) cos θ_m by the factor c̄_j / cos θ_m (1 on average over the bin). The bin map has no
/// visible-normal sampler: [`Ndf::sample_visible`] draws from `sample_normal` and
/// [`Ndf::pdf_visible`] returns `pdf_normal`, so a `MicrofacetBrdf` stays unbiased with either
/// sampling mode (docs/binmap.md).
///
/// Total: invalid directions give 0; a degenerate footprint falls back to a square of side
/// [`MIN_WIDTH_TEXELS`].
#[derive(Clone, Debug)]
pub struct BinMapPatch<'a> {
    map: &'a BinMap,
    /// The footprint in texel units (one image, centre in [0, width) × [0, height)).
    para: Parallelogram,
    /// Translations bringing each periodic image of the map's tile that meets A onto the map.
    images: Vec<[f64; 2]>,
    lobe: SlopeGaussian,
    /// Exact masking terms for footprints of at most [`EXACT_MASKING_TEXELS`].
    exact: Option<ExactMasking>,
    /// Smoothing lobes' slope σ, if any.
    sigma: Option<f64>,
}

impl<'a> BinMapPatch<'a> {
    pub(super) fn new(map: &'a BinMap, footprint: &Footprint, alpha: Option<f32>) -> Self {
        let (c, a, b) = footprint.parallelogram_texels(map.width, map.height);
        let f = |v: Vec2| [v.x as f64, v.y as f64];
        let para = Parallelogram::new(f(c), f(a), f(b)).unwrap_or_else(|| {
            let c = if c.is_finite() { f(c) } else { [0.0, 0.0] };
            let w = MIN_WIDTH_TEXELS as f64;
            Parallelogram::new(c, [w, 0.0], [0.0, w]).unwrap_or_else(|| {
                Parallelogram::new([0.0, 0.0], [w, 0.0], [0.0, w]).expect("a square is valid")
            })
        });
        let images = Self::images(&para, map.width as f64, map.height as f64);
        let center = Vec2::new(para.center()[0] as f32, para.center()[1] as f32);
        let radius = 0.5 * (para.area() as f32).sqrt();
        let sigma = alpha.map(|a| a as f64 / std::f64::consts::SQRT_2);
        let mut moments = map.moments.filtered(map.width, map.height, center, radius);
        if let Some(s) = sigma {
            // Smoothing convolves the slope distribution with N(0, σ² I): the second moments grow
            // by σ².
            moments[2] += (s * s) as f32;
            moments[3] += (s * s) as f32;
        }
        let lobe = SlopeGaussian::from_moments(moments, map.params.sigma_min);
        let exact = (para.area() <= EXACT_MASKING_TEXELS as f64)
            .then(|| ExactMasking::new(map, &para, &images, sigma));
        BinMapPatch {
            map,
            para,
            images,
            lobe,
            exact,
            sigma,
        }
    }

    /// The translations (−p·width, −q·height) of every tile (p, q) that A's bounding box meets.
    fn images(para: &Parallelogram, w: f64, h: f64) -> Vec<[f64; 2]> {
        let (lo, hi) = para.bounds();
        let (p0, p1) = ((lo[0] / w).floor() as i64, (hi[0] / w).floor() as i64);
        let (q0, q1) = ((lo[1] / h).floor() as i64, (hi[1] / h).floor() as i64);
        let mut out = Vec::with_capacity(((p1 - p0 + 1) * (q1 - q0 + 1)).max(1) as usize);
        for q in q0..=q1 {
            for p in p0..=p1 {
                out.push([-(p as f64) * w, -(q as f64) * h]);
            }
        }
        out
    }

    /// The footprint's area |A| in texels² (after the footprint's clamps).
    pub fn area_texels(&self) -> f64 {
        self.para.area()
    }

    /// Number of periodic images of the map that the footprint meets (1 for a footprint inside the
    /// map).
    pub fn image_count(&self) -> usize {
        self.images.len()
    }

    /// Scarf's bound of the visible area from the masking lobe's first two moments
    /// ([`SlopeGaussian::visible_area_bound`]): conservative, so the white furnace stays ≤ 1 whatever
    /// the footprint's slope distribution when the moments are the footprint's.
    pub fn moment_bound_visible_area(&self, w: Vec3) -> f32 {
        self.lobe.visible_area_bound(w)
    }

    /// Whether the masking terms are computed from the footprint's bins (|A| ≤
    /// [`EXACT_MASKING_TEXELS`]) rather than from the masking lobe.
    pub fn has_exact_masking(&self) -> bool {
        self.exact.is_some()
    }

    /// The masking lobe (the footprint's filtered-moment Beckmann lobe).
    pub fn masking_lobe(&self) -> &SlopeGaussian {
        &self.lobe
    }

    /// The smoothing lobes' roughness α, `None` for the bin-resolution patch.
    pub fn smoothing_alpha(&self) -> Option<f32> {
        self.sigma.map(|s| (s * std::f64::consts::SQRT_2) as f32)
    }

    /// Σ_k I_{H_j}(t_k) |A ∩ T_k| in texels²: the overlap of A with the texels of bin j, summed over
    /// the periodic images, with the traversal statistics. 0 for an empty or out-of-range bin.
    pub fn bin_overlap_with_stats(&self, bin: usize) -> (f64, QueryStats) {
        let mut stats = QueryStats::default();
        let Some(e) = self.map.table.get(bin) else {
            return (0.0, stats);
        };
        let view = self.map.tree_view();
        let mut sum = 0.0;
        for &d in &self.images {
            let p = self.para.translated(d);
            sum += view.area(&p, e.start as usize, e.end as usize, e.root, &mut stats);
        }
        (sum, stats)
    }

    /// mass_j = Σ_k I_{H_j}(t_k) |A ∩ T_k| / |A| = ∫_{H_j} D cos θ dω for the unsmoothed patch
    /// (\[Atanasov2020\] §2, times |H|). Σ_j mass_j = 1.
    pub fn bin_mass(&self, bin: usize) -> f64 {
        self.bin_overlap_with_stats(bin).0 / self.para.area()
    }

    /// The bin-resolution D of bin j: mass_j / (|H| c̄_j).
    fn bin_d(&self, bin: usize) -> f64 {
        let mass = self.bin_mass(bin);
        if mass <= 0.0 {
            return 0.0;
        }
        let c = self.map.facets[bin].mean.z as f64;
        mass / (self.map.bins.solid_angle() * c)
    }

    /// The smoothed D(h) = Σ_j mass_j D_j(h) in f64 (see the type's docs), for a unit upper h.
    fn smoothed_d(&self, h: Vec3, sigma: f64) -> f64 {
        let Some(s) = crate::frame::normal_to_slope(h) else {
            return 0.0;
        };
        let (sx, sy) = (s.x as f64, s.y as f64);
        let r = (-2.0 * SMOOTH_TAIL.ln()).sqrt() * sigma;
        let inv2s2 = 0.5 / (sigma * sigma);
        let norm = inv2s2 / std::f64::consts::PI; // 1/(2πσ²)
        let cos4 = (h.z as f64).powi(4);
        let mut sum = 0.0;
        self.for_bins_near(h, r, |bin| {
            let c = self.map.center_slope[bin];
            let (dx, dy) = (sx - c.x as f64, sy - c.y as f64);
            let q = dx * dx + dy * dy;
            if q <= r * r {
                let mass = self.bin_mass(bin);
                if mass > 0.0 {
                    sum += mass * norm * (-q * inv2s2).exp();
                }
            }
        });
        sum / cos4
    }

    /// Calls `f` for every bin of the square-grid window that holds every bin whose centre is within
    /// angle `r` of `h` (a superset).
    ///
    /// The angle between two normals is at most the distance of their slopes (the gnomonic map is
    /// expanding), so slope radius r bounds the angle. The equal-area map moves a point of the unit
    /// square by at least π/2 rad of direction per unit of square distance along the grid axes (radial
    /// rate 2/√(2 − ρ²)·2 ≥ 2√2, tangential rate √(2 − ρ²)·π/2 ≥ π/2, ρ the concentric radius); the
    /// window uses 1 rad per unit, plus one cell, as a margin.
    fn for_bins_near(&self, h: Vec3, r: f64, mut f: impl FnMut(usize)) {
        let bins = &self.map.bins;
        let n = bins.n();
        let u = crate::warp::hemisphere_to_square_equal_area(h);
        let half = (r * n as f64).ceil() as i64 + 1;
        let (ci, cj) = (
            (u.x as f64 * n as f64) as i64,
            (u.y as f64 * n as f64) as i64,
        );
        let clampi = |v: i64| v.clamp(0, n as i64 - 1) as usize;
        for j in clampi(cj - half)..=clampi(cj + half) {
            for i in clampi(ci - half)..=clampi(ci + half) {
                f(j * n + i);
            }
        }
    }

    /// The point of A at parameters u ∈ [0, 1)², wrapped into the map, and its texel index.
    fn texel_at(&self, u: Vec2) -> usize {
        let p = self.para.point(u.x as f64 - 0.5, u.y as f64 - 0.5);
        let (w, h) = (self.map.width, self.map.height);
        let i = (p[0].floor() as i64).rem_euclid(w as i64) as usize;
        let j = (p[1].floor() as i64).rem_euclid(h as i64) as usize;
        j * w + i
    }

    /// A direction in the texel's bin (or from its smoothing lobe) from the second pair `v`.
    fn direction_for_bin(&self, bin: usize, v: Vec2) -> Vec3 {
        match self.sigma {
            None => {
                // Rounding of the equal-area map can put a draw on the very edge of the cell into
                // the neighbouring bin (~1e-6 of draws): those take the bin's centre instead.
                let m = self.map.bins.sample_in_bin(bin, v);
                if self.map.bins.bin_of(m) == Some(bin) {
                    m
                } else {
                    self.map.bins.center(bin)
                }
            }
            Some(sigma) => {
                let g = square_to_gaussian_2d(v);
                let c = self.map.center_slope[bin];
                let s = c + g * sigma as f32;
                crate::frame::slope_to_normal(s)
            }
        }
    }

    /// D(m) in f64, 0 for invalid or below-horizon m.
    fn d_f64(&self, m: Vec3) -> f64 {
        if !(m.is_finite() && m.z > 0.0) {
            return 0.0;
        }
        let Some(m) = m.try_normalize() else {
            return 0.0;
        };
        match self.sigma {
            None => self.map.bins.bin_of(m).map_or(0.0, |b| self.bin_d(b)),
            Some(sigma) => self.smoothed_d(m, sigma),
        }
    }
}

/// The footprint's bins with their masses, for masking terms computed from the bin-map D itself.
#[derive(Clone, Debug)]
struct ExactMasking {
    /// Per non-empty bin j of the unsmoothed patch, its [`BinFacet`] scaled by s_j = mass_j / c̄_j.
    facets: Vec<BinFacet>,
    /// Per non-empty bin j of the smoothed patch, mass_j and its smoothing lobe D_j.
    lobes: Vec<(f32, SlopeGaussian)>,
    /// A(w) = max(w · a, 0): Σ_j s_j m̄_j (unsmoothed); Σ_j mass_j (−μ_j, 1) (smoothed, μ_j the
    /// lobe's mean slope).
    a: Vec3,
}

impl ExactMasking {
    /// Enumerates the texels of A (every periodic image), their exact overlaps and bins through 𝓑:
    /// O(|A|) once per patch.
    fn new(
        map: &BinMap,
        para: &Parallelogram,
        images: &[[f64; 2]],
        sigma: Option<f64>,
    ) -> ExactMasking {
        let (w, h) = (map.width as i64, map.height as i64);
        let mut acc: Vec<(u32, f64)> = Vec::new();
        for &d in images {
            let p = para.translated(d);
            let (lo, hi) = p.bounds();
            let (i0, i1) = ((lo[0].floor() as i64).max(0), (hi[0].ceil() as i64).min(w));
            let (j0, j1) = ((lo[1].floor() as i64).max(0), (hi[1].ceil() as i64).min(h));
            for j in j0..j1 {
                for i in i0..i1 {
                    let (x, y) = (i as f64, j as f64);
                    let ov = match p.classify(x, y, x + 1.0, y + 1.0) {
                        Overlap::Outside => continue,
                        Overlap::Inside => 1.0,
                        Overlap::Partial => p.clipped_area(x, y, x + 1.0, y + 1.0),
                    };
                    if ov > 0.0 {
                        acc.push((map.bin_map[(j * w + i) as usize], ov));
                    }
                }
            }
        }
        acc.sort_unstable_by_key(|e| e.0);
        let inv_area = 1.0 / para.area();
        let mut facets = Vec::new();
        let mut lobes = Vec::new();
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
                lobes.push((m as f32, lobe));
                continue;
            }
            let f = map.facets[bin];
            let scale = mass * inv_area / map.facets[bin].mean.z as f64;
            for (ai, m) in a.iter_mut().zip(f.mean.to_array()) {
                *ai += m as f64 * scale;
            }
            let s = scale as f32;
            facets.push(BinFacet {
                mean: f.mean * s,
                center: f.center * s,
                radius: f.radius * s,
            });
        }
        ExactMasking {
            facets,
            lobes,
            a: Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32),
        }
    }

    /// V(w) = Σ_j s_j (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω, exact for the bins that face w entirely and bounded
    /// from above for those that w's horizon cuts (type docs).
    fn visible_area(&self, w: Vec3) -> f32 {
        let facets: f64 = self.facets.iter().map(|f| visible_part(f, w) as f64).sum();
        let lobes: f64 = self
            .lobes
            .iter()
            .map(|(m, lobe)| *m as f64 * lobe.visible_area(w) as f64)
            .sum();
        finite_or_zero(facets + lobes)
    }
}

/// One bin's (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω, scaled by s_j (every field of `f` carries the factor).
///
/// If ⟨w, c_j⟩ ≥ r_j the whole bin faces w and the integral is linear: ⟨w, m̄_j⟩, exact. Otherwise
/// (w's horizon cuts the bin, which happens only within r_j ≈ 1.5·√(2π)/n rad of grazing for a pole
/// bin) it is bounded from above by both ⟨w, m̄_j⟩ + (r_j − ⟨w, c_j⟩) (the mean of ⟨w, m⟩ plus the
/// largest ⟨w, m⟩⁻ in the bin) and ⟨w, c_j⟩ + r_j (the largest ⟨w, m⟩⁺). An upper bound of V is a
/// lower bound of G1 = A/V: the BRDF may lose a little energy at grazing angles but never creates
/// any (the white furnace in tests/robustness.rs and tests/binmap.rs).
#[inline]
fn visible_part(f: &BinFacet, w: Vec3) -> f32 {
    let (lin, c) = (w.dot(f.mean), w.dot(f.center));
    if c >= f.radius {
        lin.max(0.0)
    } else {
        (lin + f.radius - c).min(c + f.radius).max(0.0)
    }
}

/// Two further uniform numbers derived from the bits of `u` (SplitMix64 finaliser), for the direction
/// within the bin: independent of the point in A for every practical purpose, deterministic in `u`.
fn rehash(u: Vec2) -> Vec2 {
    let mut z =
        ((u.x.to_bits() as u64) << 32 | u.y.to_bits() as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut next = || {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut x = z;
        x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        x ^= x >> 31;
        (x >> 40) as f32 / (1u64 << 24) as f32
    };
    Vec2::new(next(), next())
}

impl Ndf for BinMapPatch<'_> {
    /// D(h) = mass_j / (|H| c̄_j) for the bin j ∋ h, or the smoothed Σ_j mass_j D_j(h).
    ///
    /// # Reference
    /// \[Atanasov2020\] §2 (D_A^H), divided by the bin's mean cosine (type docs).
    fn d(&self, m: Vec3) -> f32 {
        finite_or_zero(self.d_f64(m))
    }

    /// Λ(w) = V(w)/A(w) − 1 (exact terms) or the masking lobe's Λ (type docs); `f32::MAX` when
    /// A(w) ≤ 0 < w_z, 0 for invalid w.
    fn lambda(&self, w: Vec3) -> f32 {
        crate::ndf::lambda_from_areas(self, w)
    }

    /// A(w) = max(w · Σ_j mass_j m̄_j / c̄_j, 0) (exact terms) or the masking lobe's
    /// max(cos θ − w_xy·μ, 0).
    fn projected_area(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        match &self.exact {
            Some(e) => finite_or_zero(w.dot(e.a) as f64),
            None => self.lobe.signed_projected_area(w).max(0.0),
        }
    }

    /// V(w) = Σ_j (mass_j / c̄_j) (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω (exact terms, bounded from above for bins
    /// cut by w's horizon) or the masking lobe's V.
    fn visible_area(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        match &self.exact {
            Some(e) => e.visible_area(w),
            None => self.moment_bound_visible_area(w),
        }
    }

    /// A point of A from `u`, its texel's bin through 𝓑, a direction in the bin (or the bin's
    /// smoothing lobe) from numbers hashed from `u` (type docs).
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let u = Vec2::select(u.is_finite_mask(), u, Vec2::splat(0.5))
            .clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON / 2.0));
        let k = self.texel_at(u);
        let bin = self.map.bin_map[k] as usize;
        self.direction_for_bin(bin, rehash(u))
    }

    /// The density of [`Ndf::sample_normal`]: mass_j / |H| (unsmoothed) or D(m) cos θ_m (smoothed).
    fn pdf_normal(&self, m: Vec3) -> f32 {
        if !(m.is_finite() && m.z > 0.0) {
            return 0.0;
        }
        let Some(m) = m.try_normalize() else {
            return 0.0;
        };
        match self.sigma {
            None => self.map.bins.bin_of(m).map_or(0.0, |b| {
                finite_or_zero(self.bin_mass(b) / self.map.bins.solid_angle())
            }),
            Some(_) => finite_or_zero(self.d_f64(m) * m.z as f64),
        }
    }

    /// No visible-normal sampler: draws from [`Ndf::sample_normal`] (type docs).
    fn sample_visible(&self, _wo: Vec3, u: Vec2) -> Vec3 {
        self.sample_normal(u)
    }

    /// The density of [`Ndf::sample_visible`], i.e. [`Ndf::pdf_normal`].
    fn pdf_visible(&self, _wo: Vec3, m: Vec3) -> f32 {
        self.pdf_normal(m)
    }
}
