//! The bin-map P-NDF of one footprint: the patch and its construction (periodic images, masking
//! lobe, exact masking terms for small footprints), bin masses (from the footprint's listed bins
//! when it has exact masking terms, through the forest otherwise), D = mass / (|H| c̄) and the
//! smoothed variant. The exact masking terms are in `masking`, the samplers and the
//! [`Ndf`](crate::ndf::Ndf) implementation in `sampling`.
//!
//! # Reference
//! \[Atanasov2020\] §2 (D_A^H), §2.2 (evaluation through 𝓑⁻¹).

use super::clip::Parallelogram;
use super::footprint_moments::footprint_moments;
use super::forest::QueryStats;
use super::masking::{Buf, ExactMasking, PatchBin};
use super::{BinMap, PatchOptions};
use crate::glint::kernels::prepared_view::PreparedView;
use crate::glint::scratch::Lent;
use crate::glint::{Footprint, GlintScratch, HemisphereBins, MIN_WIDTH_TEXELS};
use crate::ndf::SlopeGaussian;
use glam::{Vec2, Vec3};

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
/// (the crate's convention), D being constant per bin. T_k are the sub-texels of the map's s × s
/// subdivision ([`BinMapParams::subdivisions`](super::BinMapParams::subdivisions); the texels when
/// s = 1) and t_k their normals; |A ∩ T_k| sums over the periodic images of T_k (the map tiles), so
/// footprints crossing the border or larger than the map are exact.
///
/// **Smoothed variant** ([`PatchOptions::smoothing_alpha`](super::PatchOptions) > 0): D(h) = Σ_j mass_j D_j(h) with D_j the
/// Beckmann lobe of slope σ = α/√2 centred on the slope of bin j's centre (D_j = P22_j / cos⁴θ,
/// ∫ D_j cos = 1), over the bins whose centre slope lies within 5.26 σ of h's slope (≤ 10⁻⁶ of each
/// lobe left out). Cost per evaluation: O(lobes of the footprint) for footprints with exact masking
/// terms (their lobes are listed at patch construction), otherwise ∝ (n α)² bin lookups over a
/// window of bins around h (whichever is smaller).
///
/// **Masking** (the talk defines none). For footprints of at most `exact_masking_texels` texels,
/// Smith terms of the bin-map D itself, from the footprint's bins enumerated once per patch
/// (O(s² |A|), through 𝓑). Each bin's D is constant, so with m̄_j = (1/|H|) ∫_{H_j} m dω the bin's mean
/// direction vector (tabulated per bin at build), the projected area A(w) = max(Σ_j mass_j ⟨w, m̄_j⟩
/// / c̄_j, 0) is exact, and so is V(w) = ∫⟨w, m⟩⁺ D dm = Σ_j (mass_j / c̄_j) (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω
/// for every bin that faces w entirely; for a bin cut by w's horizon (within about one bin width of
/// grazing) the bin's term is replaced by an upper bound (a sub-bin quadrature bound built on a
/// proven Lipschitz constant of the equal-area map, about 11× tighter than a whole-bin bound), so
/// that G1 = A/V can only err low and the BRDF never gains energy (see `visible_part`).
/// Λ = V/A − 1, the same construction as the mixture's exact terms (\[Chermain2019\] eq. 13-17).
/// For the smoothed variant the sums run over the smoothing lobes instead, exactly as for a mixture:
/// V(w) = Σ_j mass_j V_j(w) and A(w) = max(Σ_j mass_j (cos θ − w_xy·μ_j), 0), μ_j the centre slope
/// of bin j (the unsmoothed bins' V under-counted the smoothed D's visible area: white furnace up to
/// 1.25 at grazing angles before). Larger footprints use the Smith terms of
/// the footprint's filtered-moment Beckmann lobe ([`SlopeGaussian::from_moments`] of the bins'
/// moment mip chain read over the footprint's exact cell overlaps, at most 256 cells of 2 × 2
/// texels, σ floored at `sigma_min`; src/glint/binmap/footprint_moments.rs), whose first two slope
/// moments are the footprint's D's but for its boundary cells (second moments raised by σ² for the
/// smoothed variant, whose lobes sit at the bins' centres rather than spread over them: its second
/// moments are then over-counted by the bins' own spread, the safe side of Scarf's bound). See docs/binmap.md and the white furnace in
/// tests/it/binmap_furnace.rs. The lobe's V is replaced by Scarf's moment bound
/// ([`BinMapPatch::moment_bound_visible_area`]) and A by its signed projected area, so Λ is
/// conservative (a Gaussian's V can be below a spiky distribution's with the same moments).
///
/// **Sampling.** [`Ndf::sample_normal`]: a uniform point y of A from u, its sub-texel (wrapped),
/// the sub-texel's bin through 𝓑, then a uniform direction in that bin (or a draw of the bin's
/// smoothing lobe) from a second pair of numbers hashed from the bits of u. Its density is
/// mass_j/|H| (or Σ mass_j D_j cos θ), returned by [`Ndf::pdf_normal`]; for the unsmoothed patch it
/// differs from D(m) cos θ_m by the factor c̄_j / cos θ_m (1 on average over the bin).
///
/// [`Ndf::sample_visible`] (footprints with exact masking terms): the unsmoothed patch chooses bin j
/// with probability s_j ν_j(wo) / Σ_k s_k ν_k(wo), s_j = mass_j / c̄_j, where ν_j is the mean of the
/// bin's four corner values v = ⟨wo, corner⟩⁺ + ε (ε = 5 % of the bin's proven radius, so that the
/// density is positive wherever ⟨wo, m⟩ > 0; bins with no direction facing wo get 0), then a point
/// of the bin's cell with the bilinear density of v (the equal-area map turns it into a density per
/// steradian by 1/|H|). ν_j approximates the bin's visible projected area (1/|H|) ∫⟨wo, m⟩⁺ to
/// second order in the bin's size and the bilinear density approximates ⟨wo, m⟩⁺ within it, so the
/// sample weight D ⟨wo, m⟩ / pdf is nearly constant; [`Ndf::pdf_visible`] returns this density
/// exactly. The smoothed patch chooses lobe j ∝ mass_j V_j(wo) and draws its visible normal:
/// density ⟨wo, m⟩⁺ Σ_j mass_j D_j(m) / Σ_j mass_j V_j(wo). Footprints above
/// `exact_masking_texels` (no bin list) and views nothing faces draw from `sample_normal`, with
/// `pdf_normal` as their density. Cost O(bins of the footprint) per call. docs/binmap.md.
///
/// Total: invalid directions give 0; a degenerate footprint falls back to a square of side
/// [`MIN_WIDTH_TEXELS`].
///
/// [`Ndf::sample_normal`]: crate::ndf::Ndf::sample_normal
/// [`Ndf::pdf_normal`]: crate::ndf::Ndf::pdf_normal
/// [`Ndf::sample_visible`]: crate::ndf::Ndf::sample_visible
/// [`Ndf::pdf_visible`]: crate::ndf::Ndf::pdf_visible
#[derive(Clone, Debug)]
pub struct BinMapPatch<'a> {
    pub(super) map: &'a BinMap,
    /// The footprint in sub-texel units (one image, centre in [0, s·width) × [0, s·height)).
    pub(super) para: Parallelogram,
    /// Translations bringing each periodic image of the map's tile that meets A onto the map.
    images: Buf<'a, [f64; 2]>,
    pub(super) lobe: SlopeGaussian,
    /// Exact masking terms for footprints of at most `exact_masking_texels`.
    pub(super) exact: Option<ExactMasking<'a>>,
    /// Smoothing lobes' slope σ, if any.
    pub(super) sigma: Option<f64>,
    /// With exact terms, V(wo) and the visible sampler's normalisation at the view the patch was
    /// prepared for ([`BinMapPatch::prepare_view`]).
    pub(super) view_area: PreparedView,
    pub(super) view_total: PreparedView,
}

/// The buffers of one patch under construction: the footprint's periodic images and, for
/// footprints with exact masking terms, its bins (or smoothing lobes).
struct Bufs<'a> {
    images: Buf<'a, [f64; 2]>,
    acc: Buf<'a, (u32, f64)>,
    bins: Buf<'a, PatchBin>,
    lobes: Buf<'a, (f32, SlopeGaussian)>,
}

impl<'a> Bufs<'a> {
    fn new(scratch: Option<&'a GlintScratch>) -> Bufs<'a> {
        let mut b = Bufs {
            images: Lent::new(scratch.map(GlintScratch::home)),
            acc: Lent::new(scratch.map(GlintScratch::home)),
            bins: Lent::new(scratch.map(GlintScratch::home)),
            lobes: Lent::new(scratch.map(GlintScratch::home)),
        };
        b.images.clear();
        b.acc.clear();
        b.bins.clear();
        b.lobes.clear();
        b
    }
}

impl<'a> BinMapPatch<'a> {
    pub(super) fn new(
        map: &'a BinMap,
        footprint: &Footprint,
        alpha: Option<f32>,
        options: &PatchOptions,
        scratch: Option<&'a GlintScratch>,
    ) -> Self {
        let mut bufs = Bufs::new(scratch);
        let sub = map.params.subdivisions as f64;
        let (c, a, b) = footprint.parallelogram_texels(map.width, map.height);
        // Texel units → sub-texel units.
        let f = |v: Vec2| [v.x as f64 * sub, v.y as f64 * sub];
        let para = Parallelogram::new(f(c), f(a), f(b)).unwrap_or_else(|| {
            let c = if c.is_finite() { f(c) } else { [0.0, 0.0] };
            let w = MIN_WIDTH_TEXELS as f64 * sub;
            Parallelogram::new(c, [w, 0.0], [0.0, w]).unwrap_or_else(|| {
                Parallelogram::new([0.0, 0.0], [w, 0.0], [0.0, w]).expect("a square is valid")
            })
        });
        Self::images(
            &para,
            map.grid_w as f64,
            map.grid_h as f64,
            &mut bufs.images,
        );
        let center = Vec2::new(
            (para.center()[0] / sub) as f32,
            (para.center()[1] / sub) as f32,
        );
        let area_texels = para.area() / (sub * sub);
        let radius = 0.5 * (area_texels as f32).sqrt();
        let sigma = alpha.map(|a| a as f64 / std::f64::consts::SQRT_2);
        let mut moments = match para
            .scaled(1.0 / sub, 1.0 / sub)
            .and_then(|p| footprint_moments(&map.moments, map.width, map.height, &p))
        {
            Some(m) => m,
            None => map.moments.filtered(map.width, map.height, center, radius),
        };
        if let Some(s) = sigma {
            // Smoothing convolves the slope distribution with N(0, σ² I): the second moments grow
            // by σ².
            moments[2] += (s * s) as f32;
            moments[3] += (s * s) as f32;
        }
        let lobe = SlopeGaussian::from_moments(moments, map.params.sigma_min);
        let Bufs {
            images,
            mut acc,
            bins,
            lobes,
        } = bufs;
        let exact = map.exact_masking_for(area_texels, options).then(|| {
            ExactMasking::new(map, &para, images.as_slice(), sigma, &mut acc, bins, lobes)
        });
        BinMapPatch {
            map,
            para,
            images,
            lobe,
            exact,
            sigma,
            view_area: PreparedView::NONE,
            view_total: PreparedView::NONE,
        }
    }

    /// Prepares the patch for the view direction `wo` (shading frame): with exact masking terms,
    /// V(wo) and the visible sampler's normalisation (each a pass over the footprint's bins or
    /// smoothing lobes), computed here once and read by the queries at that wo
    /// (`view_visible_area`, `sample_visible`, `pdf_visible`); queries at any other view compute
    /// their own. Every value is the one the unprepared patch returns, bit for bit. Without exact
    /// terms there is nothing to prepare (V is the moment lobe's, O(1)). A second call replaces the
    /// first view. `Material::bsdf` prepares its glint patches for the shading point's wo.
    pub fn prepare_view(&mut self, wo: Vec3) {
        self.view_area = PreparedView::NONE;
        self.view_total = PreparedView::NONE;
        if let Some(e) = &self.exact
            && wo.z > 0.0
            && wo.is_finite()
        {
            let area = e.visible_area(&self.map.bins, wo) as f64;
            let total = self.visible_total_pass(e, wo);
            self.view_area = PreparedView::new(wo, area);
            self.view_total = PreparedView::new(wo, total);
        }
    }

    /// The translations (−p·W, −q·H) of every tile (p, q) that A's bounding box meets (W × H the
    /// sub-texel grid), into `out`.
    fn images(para: &Parallelogram, w: f64, h: f64, out: &mut Vec<[f64; 2]>) {
        let (lo, hi) = para.bounds();
        let (p0, p1) = ((lo[0] / w).floor() as i64, (hi[0] / w).floor() as i64);
        let (q0, q1) = ((lo[1] / h).floor() as i64, (hi[1] / h).floor() as i64);
        out.clear();
        for q in q0..=q1 {
            for p in p0..=p1 {
                out.push([-(p as f64) * w, -(q as f64) * h]);
            }
        }
    }

    /// The footprint's area |A| in texels² (after the footprint's clamps).
    pub fn area_texels(&self) -> f64 {
        let s = self.map.params.subdivisions as f64;
        self.para.area() / (s * s)
    }

    /// Number of periodic images of the map that the footprint meets (1 for a footprint inside the
    /// map).
    pub fn image_count(&self) -> usize {
        self.images.as_slice().len()
    }

    /// Scarf's bound of the visible area from the masking lobe's first two moments
    /// ([`SlopeGaussian::visible_area_bound`]): conservative, so the white furnace stays ≤ 1 whatever
    /// the footprint's slope distribution when the moments are the footprint's (they are, but for
    /// the boundary cells of the moment chain: src/glint/binmap/footprint_moments.rs).
    pub fn moment_bound_visible_area(&self, w: Vec3) -> f32 {
        self.lobe.visible_area_bound(w)
    }

    /// Whether the masking terms are computed from the footprint's bins (|A| ≤
    /// `exact_masking_texels`) rather than from the masking lobe.
    pub fn has_exact_masking(&self) -> bool {
        self.exact.is_some()
    }

    /// The form of the patch: exact masking over the footprint's bin list (its bins, or smoothing
    /// lobes, listed: work growing with the footprint) or the moment lobe's masking.
    pub fn form(&self) -> crate::glint::PatchForm {
        match &self.exact {
            Some(e) => crate::glint::PatchForm::BinList {
                bins: e.bins.as_slice().len() + e.lobes.as_slice().len(),
            },
            None => crate::glint::PatchForm::MomentMasking,
        }
    }

    /// The patch as weighted slope Gaussians, for its albedo estimate (src/glint/kernels/albedo.rs):
    /// with exact terms each bin of the footprint as a lobe of its mass at the slope of its mean
    /// direction, as wide as the bin (σ = its radius r_j / 2), or the smoothed patch's lobes;
    /// without, the masking lobe.
    pub(crate) fn albedo_lobes(&self) -> impl Iterator<Item = (f32, SlopeGaussian)> + Clone + '_ {
        let (bins, lobes, moment) = match &self.exact {
            Some(e) if self.sigma.is_some() => (None, Some(&e.lobes[..]), None),
            Some(e) => (Some(&e.bins[..]), None, None),
            None => (None, None, Some((1.0, self.lobe))),
        };
        let bin_lobe = |b: &super::masking::PatchBin| {
            let m = b.facet.mean;
            let (sx, sy) = (-m.x / m.z, -m.y / m.z);
            let v = 0.25 * b.facet.radius * b.facet.radius / (m.z * m.z).max(1e-6);
            let g = SlopeGaussian::from_moments(
                [sx, sy, sx * sx + v, sy * sy + v, sx * sy],
                crate::ndf::SIGMA_MIN_FLOOR,
            );
            (b.mass as f32, g)
        };
        bins.into_iter()
            .flat_map(move |b| b.iter().map(bin_lobe))
            .chain(lobes.into_iter().flat_map(|l| l.iter().copied()))
            .chain(moment)
    }

    /// The masking lobe (the footprint's filtered-moment Beckmann lobe).
    pub fn masking_lobe(&self) -> &SlopeGaussian {
        &self.lobe
    }

    /// The smoothing lobes' roughness α, `None` for the bin-resolution patch.
    pub fn smoothing_alpha(&self) -> Option<f32> {
        self.sigma.map(|s| (s * std::f64::consts::SQRT_2) as f32)
    }

    /// Σ_k I_{H_j}(t_k) |A ∩ T_k| in sub-texels² (texels² × s²): the overlap of A with the
    /// sub-texels of bin j, summed over the periodic images, with the traversal statistics. 0 for an
    /// empty or out-of-range bin.
    pub fn bin_overlap_with_stats(&self, bin: usize) -> (f64, QueryStats) {
        let mut stats = QueryStats::default();
        let Some(e) = self.map.table.get(bin) else {
            return (0.0, stats);
        };
        let view = self.map.tree_view();
        let mut sum = 0.0;
        for &d in self.images.as_slice() {
            let p = self.para.translated(d);
            sum += view.area(&p, e.start as usize, e.end as usize, e.root, &mut stats);
        }
        (sum, stats)
    }

    /// The exact masses ∫_{R_r} D cos θ dω of the bin-resolution D over every bin R_r of another
    /// equal-area grid `grid` (e.g. a ground truth's bins, [`crate::glint::BinnedPndf`]), for
    /// comparing the piecewise-constant D with a histogram on bins that do not align with the map's.
    /// `None` for a smoothed patch (its D is not constant per bin; integrate it numerically).
    ///
    /// D is constant on each of the map's bins H_j, so ∫_{R_r ∩ H_j} D cos θ dω =
    /// mass_j C(R_r ∩ H_j) / C(H_j) with C(X) = ∫_X cos θ dω. Both bin grids are rectangles of the
    /// same unit square under the same equal-area map (solid angle = 2π × area), so R_r ∩ H_j is the
    /// image of an axis-aligned rectangle and C of it is 2π × its area × (1 − the mean of
    /// max(a², b²) over it), (a, b) = 2u − 1, integrated exactly as in
    /// [`HemisphereBins::mean_cos`]. Σ_r of the result = Σ_j mass_j = 1 (up to rounding). A midpoint
    /// rule per reference bin instead misplaces the mass of every map bin that straddles a reference
    /// bin's edge by up to the fraction of its sample points on the wrong side (docs/binmap.md,
    /// "Measuring against a ground truth").
    ///
    /// Cost: one mass query per map bin (B tree queries) plus ≤ (⌈n_r/n⌉ + 1)² overlaps per
    /// non-empty bin.
    pub fn masses_on(&self, grid: &HemisphereBins) -> Option<Vec<f64>> {
        if self.sigma.is_some() {
            return None;
        }
        let bins = &self.map.bins;
        let (n, nr) = (bins.n(), grid.n());
        let mut out = vec![0.0f64; grid.len()];
        for bin in 0..bins.len() {
            let mass = self.bin_mass(bin);
            if mass <= 0.0 {
                continue;
            }
            let (i, j) = bins.cell(bin);
            let (x0, x1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
            let (y0, y1) = (j as f64 / n as f64, (j + 1) as f64 / n as f64);
            let whole = cos_weighted_area(x0, x1, y0, y1);
            if whole <= 0.0 {
                continue;
            }
            let span = |lo: f64, hi: f64| {
                let a = ((lo * nr as f64).floor() as usize).min(nr - 1);
                let b = ((hi * nr as f64).ceil() as usize).clamp(a + 1, nr);
                a..b
            };
            for rj in span(y0, y1) {
                let (ry0, ry1) = (rj as f64 / nr as f64, (rj + 1) as f64 / nr as f64);
                let (cy0, cy1) = (y0.max(ry0), y1.min(ry1));
                if cy1 <= cy0 {
                    continue;
                }
                for ri in span(x0, x1) {
                    let (rx0, rx1) = (ri as f64 / nr as f64, (ri + 1) as f64 / nr as f64);
                    let (cx0, cx1) = (x0.max(rx0), x1.min(rx1));
                    if cx1 <= cx0 {
                        continue;
                    }
                    out[rj * nr + ri] += mass * cos_weighted_area(cx0, cx1, cy0, cy1) / whole;
                }
            }
        }
        Some(out)
    }

    /// mass_j = Σ_k I_{H_j}(t_k) |A ∩ T_k| / |A| = ∫_{H_j} D cos θ dω for the unsmoothed patch
    /// (\[Atanasov2020\] §2, times |H|). Σ_j mass_j = 1. Read from the footprint's listed bins when
    /// the patch has exact masking terms (they hold the same sums), otherwise one forest query (D
    /// and the sampler's density at one direction share it: `MicrofacetBrdf` hands the density the
    /// D it evaluated, [`Ndf::pdf_normal_given_d`](crate::ndf::Ndf::pdf_normal_given_d)).
    pub fn bin_mass(&self, bin: usize) -> f64 {
        match self.exact.as_ref().and_then(|e| e.bin_mass(bin)) {
            Some(mass) => mass,
            None => self.forest_mass(bin),
        }
    }

    /// mass_j by the bin's forest query.
    fn forest_mass(&self, bin: usize) -> f64 {
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

    /// The smoothed D(h) = Σ_j mass_j D_j(h) in f64 (see the type's docs), for a unit upper h: over
    /// the footprint's own lobes when the patch lists them and they are fewer than the window's bins
    /// (small footprints: at most s²|A| lobes against (2⌈r n⌉ + 3)² window bins, each a forest
    /// query), otherwise over the window. Both sum the same terms, those of the non-empty bins whose
    /// centre slope is within r of h's (the lobes carry f32 masses: 6·10⁻⁸ relative).
    fn smoothed_d(&self, h: Vec3, sigma: f64) -> f64 {
        let r = (-2.0 * SMOOTH_TAIL.ln()).sqrt() * sigma;
        let window = (2 * ((r * self.map.bins.n() as f64).ceil() as usize + 1) + 1).pow(2);
        match self
            .exact
            .as_ref()
            .filter(|e| e.bins.as_slice().is_empty())
            .map(|e| e.lobes.as_slice())
            .filter(|l| !l.is_empty() && l.len() < window)
        {
            Some(lobes) => Self::smoothed_d_lobes(lobes, h, sigma),
            None => self.smoothed_d_window(h, sigma),
        }
    }

    /// The smoothed D(h) = Σ_j mass_j D_j(h) over the given (mass_j, D_j) lobes within r.
    fn smoothed_d_lobes(lobes: &[(f32, SlopeGaussian)], h: Vec3, sigma: f64) -> f64 {
        let Some(k) = SmoothingKernel::at(h, sigma) else {
            return 0.0;
        };
        let (sx, sy, r, inv2s2, norm) = (k.sx, k.sy, k.r, k.inv2s2, k.norm);
        let mut sum = 0.0;
        for (mass, lobe) in lobes {
            let c = lobe.mean();
            let (dx, dy) = (sx - c.x as f64, sy - c.y as f64);
            let q = dx * dx + dy * dy;
            if q <= r * r {
                sum += *mass as f64 * norm * (-q * inv2s2).exp();
            }
        }
        sum / (h.z as f64).powi(4)
    }

    /// The smoothed D(h) over the window of bins around h, each bin's mass through the forest.
    fn smoothed_d_window(&self, h: Vec3, sigma: f64) -> f64 {
        let Some(k) = SmoothingKernel::at(h, sigma) else {
            return 0.0;
        };
        let (sx, sy, r, inv2s2, norm) = (k.sx, k.sy, k.r, k.inv2s2, k.norm);
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

    /// D(m) in f64, 0 for invalid or below-horizon m.
    pub(super) fn d_f64(&self, m: Vec3) -> f64 {
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

/// ∫ cos θ dω over the equal-area image of the square-cell rectangle [x0, x1] × [y0, y1] ⊂ [0, 1]²,
/// divided by 2π: its area × (1 − mean of max(a², b²)), (a, b) = 2u − 1 (z = 1 − max(a², b²) under
/// the equal-area map; exact up to rounding, [`crate::warp::equal_area_mean_cos`]).
fn cos_weighted_area(x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let area = (x1 - x0) * (y1 - y0);
    if area <= 0.0 {
        return 0.0;
    }
    area * crate::warp::equal_area_mean_cos(x0, x1, y0, y1)
}

/// The smoothing Gaussian of the smoothed D at half-vector h: h's slope (sx, sy), the cut-off radius
/// r (where the kernel falls to `SMOOTH_TAIL`), 1/(2σ²) and the normaliser 1/(2πσ²).
struct SmoothingKernel {
    sx: f64,
    sy: f64,
    r: f64,
    inv2s2: f64,
    norm: f64,
}

impl SmoothingKernel {
    /// None for h at or below the horizon (no slope).
    fn at(h: Vec3, sigma: f64) -> Option<Self> {
        let s = crate::frame::normal_to_slope(h)?;
        let inv2s2 = 0.5 / (sigma * sigma);
        Some(SmoothingKernel {
            sx: s.x as f64,
            sy: s.y as f64,
            r: (-2.0 * SMOOTH_TAIL.ln()).sqrt() * sigma,
            inv2s2,
            norm: inv2s2 / std::f64::consts::PI,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glint::GlintNdf;
    use crate::ndf::Ndf;

    /// The smoothed D over the footprint's listed lobes against the window of bins with forest
    /// masses, at half vectors drawn from the patch: the same terms, so they agree to the f32
    /// rounding of the lobes' masses (6·10⁻⁸ relative per term; 10⁻⁶ relative allowed) plus 10⁻⁹.
    #[test]
    fn smoothed_d_over_lobes_matches_the_window() {
        let map = crate::glint::bumpy(64, 64, 0.25, 4.0, 3).unwrap();
        let bm = BinMap::build(&map, super::super::BinMapParams::default()).unwrap();
        for (area, alpha) in [(16.0f32, 0.05f32), (64.0, 0.1), (1024.0, 0.02)] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.7), area, 64, 64);
            let patch = bm.patch_with(
                &fp,
                &super::super::PatchOptions {
                    smoothing_alpha: alpha,
                    ..Default::default()
                },
                None,
            );
            let e = patch.exact.as_ref().unwrap();
            assert!(e.bins.as_slice().is_empty() && !e.lobes.as_slice().is_empty());
            let sigma = patch.sigma.unwrap();
            for k in 0..300 {
                let u = Vec2::new(
                    ((k as f32) * 0.618034).fract(),
                    ((k as f32) * 0.414214).fract(),
                );
                let h = patch.sample_normal(u);
                let a = BinMapPatch::smoothed_d_lobes(e.lobes.as_slice(), h, sigma);
                let b = patch.smoothed_d_window(h, sigma);
                assert!(
                    (a - b).abs() <= 1e-6 * b.abs() + 1e-9,
                    "area {area} α {alpha} h {h}: lobes {a} window {b}"
                );
            }
        }
    }
}
