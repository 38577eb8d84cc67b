//! The patch of a footprint, [`ProceduralPatch`]: the lobes of the one or two lattice levels the
//! footprint reads, weighted by its kernel, blended into the limit lobe as the footprint grows;
//! every term of the [`Ndf`](crate::ndf::Ndf) exact over those lobes (a Beckmann surface's in a
//! shared-shape set held by the patch, src/glint/kernels/shared_lobes.rs; a GGX surface's in a lobe
//! set lent by the scratch, src/glint/kernels/lobe_set.rs).

use super::ggx;
use super::lattice::{
    BLEND_BAND, CELL_SIGMAS, Candidates, Kernel, Level, gather_level, lobe_widths,
};
use super::limit::{GgxBlend, LimitNdf};
use super::params::{PatchOptions, ProceduralParams};
use crate::glint::kernels::lobe_set::{Few, LobeSet, box_half_widths};
use crate::glint::kernels::shared_lobes::SharedLobes;
use crate::glint::scratch::Lent;
use crate::glint::{Footprint, GlintScratch};
use crate::ndf::{Beckmann, Ggx, SlopeGaussian, forward_ndf};
use glam::{Vec2, Vec3};

/// The P-NDF of one footprint of a [`ProceduralGlints`](super::ProceduralGlints) surface: an
/// [`Ndf`](crate::ndf::Ndf) with D_P(m) = (1 − b) Σ_i w_i D_i(m) + b D_lim(m).
///
/// - The lobes D_i are those of the lattice level whose cells are 1.5-3 geometric kernel standard
///   deviations (λ1 λ2)^¼ wide (the finer level l), weighted by a tent one cell wide on each side
///   around the footprint's centre (about four lobes), normalised over the level; in the last
///   quarter of each octave of footprint sizes they are blended with the next coarser level's,
///   weighted (1 − t) and t (a brilinear filter over levels, so that the P-NDF changes
///   continuously with the footprint) (src/glint/procedural/lattice.rs).
/// - All lobes share one width β: each stands for n / K facets, n = density · 4π √det Σ those the
///   footprint holds and K = (Σ w)² / Σ w² the lobes the kernel effectively sees, so
///   1/β² = 1/σ² + min(1, K/n) (1/σ_f² − 1/σ²) per axis and the patch is as far from the limit, in
///   expected L2, as n facets of roughness σ_f are; its means are z τ with τ² = σ² − β².
/// - b blends in the limit lobe D_lim (the Beckmann NDF of the surface's α) as that expected
///   relative L2 distance, ρ = √((σx σy / (βx βy) − 1) / K), falls from 2 · `tolerance` to
///   `tolerance`: b = 1 (the limit lobe alone, one lobe) below `tolerance`.
/// - Masking, densities and samplers are exact over the patch's lobes: V(w) = Σ w_i V_i(w), the
///   signed projected area from the mean slope, `sample_visible` picks a lobe ∝ w_i V_i(wo) then its
///   visible normal (density Σ w_i ⟨wo,m⟩⁺ D_i / V(wo)), as every glint patch of the crate.
///
/// Every lobe has mean NDF D_lim (β² + τ² = σ², with β, τ depending on the footprint only), and the
/// kernel weights do not depend on the lobes' slopes, so the mean of D_P over the random field is
/// D_lim at every footprint size.
///
/// For a surface of the GGX limit (src/glint/procedural/ggx.rs) each lobe has its own variance
/// scale v_i and width (σ_i² = v_i α²), D_lim is the crate's [`Ggx`] held beside the lobes (not a
/// slope Gaussian: src/glint/procedural/limit.rs), and b also holds the share of GGX that brings
/// the patch to its facets' expected distance; ρ is then that facets' part.
#[derive(Clone, Debug)]
pub struct ProceduralPatch<'a> {
    body: Body<'a>,
    level: f32,
    limit_weight: f32,
    distance: f32,
}

/// What a patch holds: slope Gaussians (the facet lobes, with a Beckmann surface's limit lobe among
/// them), GGX alone, or facet lobes blended with GGX.
#[derive(Clone, Debug)]
// The inline lobes are the point: boxing them would allocate per shading point, and the patch is
// no larger than a mixture patch (asserted below), the largest `GlintPatch`.
#[allow(clippy::large_enum_variant)]
enum Body<'a> {
    /// A Beckmann surface's facet lobes (one shape, held inline), closed by its limit lobe in the
    /// hand-over.
    Shared(SharedLobes),
    /// A GGX surface's facet lobes (a lobe set lent by the scratch), or one lobe.
    Lobes(Few<'a>),
    /// A Beckmann surface's limit alone: the analytic NDF (the same function as the limit's
    /// centred slope Gaussian, with its cheaper closed forms and sampler) beside that lobe.
    Beckmann(Beckmann, SlopeGaussian),
    Ggx(Ggx),
    Blend(GgxBlend<'a>),
}

// Every gathered lobe fits a shared-shape set.
const _: () = assert!(Candidates::CAPACITY <= SharedLobes::CAPACITY);
// A patch holding its lobes inline is no larger than a mixture patch, so that `GlintPatch` (and
// every glint material's BSDF, moved a few times per shading point) does not grow with it.
const _: () = assert!(
    core::mem::size_of::<ProceduralPatch<'static>>()
        <= core::mem::size_of::<crate::glint::mixture::MixturePatch<'static>>()
);

/// Binds the patch's NDF to `$n` (for [`forward_ndf`]).
macro_rules! to_body {
    ($s:ident, $n:ident => $e:expr) => {
        match &$s.body {
            Body::Shared($n) => $e,
            Body::Lobes($n) => $e,
            Body::Beckmann($n, _) => $e,
            Body::Ggx($n) => $e,
            Body::Blend($n) => $e,
        }
    };
}

forward_ndf!(['a] ProceduralPatch<'a>, to_body);

impl ProceduralPatch<'_> {
    /// The patch that is the limit NDF alone, at continuous level `level` and expected distance
    /// `distance`; a Beckmann limit of roughness `alpha` is served by the analytic [`Beckmann`]
    /// NDF (the lobe itself where α is out of its range, which validation excludes).
    fn limit_alone(limit: LimitNdf, alpha: Vec2, level: f64, distance: f64) -> Self {
        ProceduralPatch {
            body: match limit {
                LimitNdf::Beckmann(g) => match Beckmann::new(alpha.x, alpha.y) {
                    Ok(b) => Body::Beckmann(b, g),
                    Err(_) => Body::Lobes(Few::One(g)),
                },
                LimitNdf::Ggx(g) => Body::Ggx(g),
            },
            level: level as f32,
            limit_weight: 1.0,
            distance: distance as f32,
        }
    }

    /// Prepares the patch for the view direction `wo` (shading frame): the exact V(wo) of its
    /// lobes that the queries at that wo share (`view_visible_area`, the visible densities, the
    /// visible sampler's pick between GGX and the lobes), computed here once, an O(lobes) pass.
    /// Queries at `wo` (the same bits) then read it; queries at any other view compute their own.
    /// Every value is the one the unprepared patch returns, bit for bit. A second call replaces the
    /// first view. `Material::bsdf` prepares its glint patches for the shading point's wo.
    pub fn prepare_view(&mut self, wo: Vec3) {
        match &mut self.body {
            Body::Shared(set) => set.prepare_view(wo),
            Body::Lobes(few) => few.prepare_view(wo),
            Body::Beckmann(..) | Body::Ggx(_) => {}
            Body::Blend(blend) => blend.prepare_view(wo),
        }
    }

    /// The number of lobes the patch holds (the limit NDF included, as one lobe): at most a few
    /// tens, whatever the footprint.
    pub fn lobe_count(&self) -> usize {
        let count = |few: &Few<'_>| match few {
            Few::None => 0,
            Few::One(_) => 1,
            Few::Set(s) => s.len(),
        };
        match &self.body {
            Body::Shared(set) => set.len(),
            Body::Lobes(few) => count(few),
            Body::Beckmann(..) | Body::Ggx(_) => 1,
            Body::Blend(blend) => count(blend.lobes()) + 1,
        }
    }

    /// The form of the patch: its facet lobes (the limit lobe among them where it is blended in)
    /// or the limit NDF alone; a few tens of lobes at most, whatever the footprint.
    pub fn form(&self) -> crate::glint::PatchForm {
        if self.limit_weight >= 1.0 {
            crate::glint::PatchForm::Limit
        } else {
            crate::glint::PatchForm::Facets {
                lobes: self.lobe_count(),
            }
        }
    }

    /// The continuous lattice level the footprint reads (0: one facet per cell; the patch holds the
    /// levels ⌊level⌋ and ⌊level⌋ + 1).
    pub fn level(&self) -> f32 {
        self.level
    }

    /// The weight b of the limit NDF in the patch (0: facets only; 1: the limit NDF alone).
    pub fn limit_weight(&self) -> f32 {
        self.limit_weight
    }

    /// The parts of the patch for its albedo estimate (src/glint/kernels/albedo.rs): its slope
    /// Gaussians with their weights in D_P, and the GGX part as (weight, NDF), if any.
    pub(crate) fn albedo_parts(
        &self,
    ) -> (
        impl Iterator<Item = (f32, SlopeGaussian)> + Clone + '_,
        Option<(f32, Ggx)>,
    ) {
        let (few, shared, alone, scale, ggx) = match &self.body {
            Body::Shared(s) => (None, Some(s), None, 1.0, None),
            Body::Lobes(f) => (Some(f), None, None, 1.0, None),
            Body::Beckmann(_, g) => (None, None, Some((1.0, *g)), 1.0, None),
            Body::Ggx(g) => (None, None, None, 0.0, Some((1.0, *g))),
            Body::Blend(b) => {
                let (lobes, weight, ggx) = b.parts();
                (Some(lobes), None, None, 1.0 - weight, Some((weight, ggx)))
            }
        };
        let lobes = few
            .into_iter()
            .flat_map(|f| f.iter_lobes())
            .chain(shared.into_iter().flat_map(|s| s.iter_lobes()))
            .map(move |(w, g)| (w * scale, g))
            .chain(alone);
        (lobes, ggx)
    }

    /// The expected relative L2 distance ρ of a patch of this footprint to the limit NDF
    /// (what [`PatchOptions::tolerance`] is compared with; for the GGX limit, the part of it that
    /// the footprint's facets carry, src/glint/procedural/ggx.rs).
    pub fn expected_distance(&self) -> f32 {
        self.distance
    }
}

/// Builds the patch of `footprint` on the surface of parameters `p`, levels `levels` and limit
/// NDF `limit` (the model's `patch_with`).
pub(super) fn make_patch<'a>(
    p: &ProceduralParams,
    levels: &[Level],
    limit: LimitNdf,
    footprint: &Footprint,
    options: &PatchOptions,
    scratch: Option<&'a GlintScratch>,
) -> ProceduralPatch<'a> {
    let [width, height] = p.resolution;
    let (c, cov) = footprint.gaussian_texels(width, height);
    let s0 = levels[0].spacing[0].max(levels[0].spacing[1]);
    let kernel = Kernel::new(
        [c.x as f64, c.y as f64],
        [
            cov.x_axis.x as f64,
            cov.x_axis.y as f64,
            cov.y_axis.y as f64,
        ],
        s0 * s0 / (CELL_SIGMAS * CELL_SIGMAS),
        (width.min(height) as f64).powi(2),
    );
    // The facets the footprint holds, n = density · 4π √det Σ (the effective count of a Gaussian
    // kernel), and the distance to the limit of n facets: ρ² = (σx σy / σ_f² − 1) / n for
    // Beckmann, its GGX form (src/glint/procedural/ggx.rs) for GGX.
    let n = p.density as f64
        * 4.0
        * std::f64::consts::PI
        * (kernel.lambda[0] * kernel.lambda[1]).sqrt();
    let sigma = [p.alpha.x as f64, p.alpha.y as f64].map(|a| a / std::f64::consts::SQRT_2);
    let sigma_f = p.facet_alpha as f64 / std::f64::consts::SQRT_2;
    let ratio = sigma[0] * sigma[1] / (sigma_f * sigma_f);
    let tol = options.clamped_tolerance();
    let footprint_distance = match limit {
        LimitNdf::Beckmann(_) => ((ratio - 1.0).max(0.0) / n).sqrt(),
        LimitNdf::Ggx(_) => ggx::footprint_distance(sigma, sigma_f, n),
    };
    // The finer level: cells of CELL_SIGMAS/2 to CELL_SIGMAS geometric standard deviations
    // (x = log2(CELL_SIGMAS (λ1 λ2)^¼ / s0) ≥ 0: the kernel's floor keeps both λ ≥ (s0/3)²).
    let x = (CELL_SIGMAS * kernel.geometric_sd() / s0).log2().max(0.0);
    if footprint_distance <= tol {
        // The patch's own distance is at most this one (exactly so for isotropic α): the
        // limit alone.
        return ProceduralPatch::limit_alone(limit, p.alpha, x, footprint_distance);
    }
    let top = levels.len() - 1;
    let (fine, t) = if x >= top as f64 {
        (top, 0.0)
    } else {
        // The coarser level's weight: 0 over the first 1 − BLEND_BAND of the octave, then rising
        // linearly to 1 at its end (where the coarser level becomes the finer one).
        let f = x.floor();
        let t = ((x - f - (1.0 - BLEND_BAND)) / BLEND_BAND).clamp(0.0, 1.0);
        (f as usize, t as f32)
    };
    let scales = matches!(limit, LimitNdf::Ggx(_));
    let mut cand = Candidates::new();
    if t < 1.0 {
        gather_level(levels, fine, p.seed, &kernel, 1.0 - t, scales, &mut cand);
    }
    if t > 0.0 {
        gather_level(levels, fine + 1, p.seed, &kernel, t, scales, &mut cand);
    }
    let weights = &cand.w[..cand.len];
    let sum: f64 = weights.iter().map(|&w| w as f64).sum();
    let sum2: f64 = weights.iter().map(|&w| (w as f64) * (w as f64)).sum();
    // The kernel's effective lobe count K = (Σ w)² / Σ w²; each lobe stands for n / K facets.
    let k = if sum2 > 0.0 { sum * sum / sum2 } else { 1.0 };
    let widths = Widths {
        sigma,
        sigma_f,
        r: k / n,
        k,
        tol,
        level: x,
    };
    match limit {
        LimitNdf::Beckmann(lobe) => beckmann_patch(&cand, sum, &widths, p.alpha, lobe),
        LimitNdf::Ggx(g) => ggx_patch(&cand, sum, &widths, p.alpha, g, scratch),
    }
}

/// What sets a patch's lobe widths and its limit weight: Beckmann deviations σ = α/√2, facet
/// deviation σ_f, r = K/n (clamped to 1 where used), the kernel's effective lobe count K, the
/// clamped tolerance and the continuous level.
struct Widths {
    sigma: [f64; 2],
    sigma_f: f64,
    r: f64,
    k: f64,
    tol: f64,
    level: f64,
}

impl Widths {
    /// The limit weight b of a patch of expected distance `distance`: 0 while ρ ≥ 2 tol, 1 below
    /// tol, linear in between.
    fn limit_weight(&self, distance: f64) -> f32 {
        ((2.0 * self.tol - distance) / self.tol).clamp(0.0, 1.0) as f32
    }
}

/// The patch of a Beckmann surface from its gathered lobes `cand` (weights summing to `sum`):
/// one shared width, held inline, the limit lobe closing the set where it is blended in.
fn beckmann_patch<'a>(
    cand: &Candidates,
    sum: f64,
    wd: &Widths,
    alpha: Vec2,
    limit: SlopeGaussian,
) -> ProceduralPatch<'a> {
    let (sigma, x) = (wd.sigma, wd.level);
    let (beta2, tau2) = lobe_widths(sigma, wd.sigma_f, wd.r);
    // The diagonal covariance's Cholesky factor directly.
    let [lx, ly] = beta2.map(|b| b.sqrt() as f32);
    let shape = SlopeGaussian::from_mean_cholesky(Vec2::ZERO, lx, 0.0, ly);
    let (Some(shape), true) = (shape, cand.len > 0) else {
        return ProceduralPatch::limit_alone(LimitNdf::Beckmann(limit), alpha, x, 0.0);
    };
    // The patch's expected distance: ρ² = Σ (w_i/Σw)² (σx σy / (βx βy) − 1).
    let distance =
        ((sigma[0] * sigma[1] / (beta2[0] * beta2[1]).sqrt() - 1.0).max(0.0) / wd.k).sqrt();
    let b = wd.limit_weight(distance);
    if b >= 1.0 {
        return ProceduralPatch::limit_alone(LimitNdf::Beckmann(limit), alpha, x, distance);
    }
    let tau = tau2.map(|v| v.sqrt() as f32);
    // Slope boxes holding 1 − 10⁻¹² of each lobe (√2 × the half-widths of the shared 10⁻⁶ tail):
    // the facet lobes are narrow and many, and a sampler's draws beyond a box (where D is 0) stay a
    // 10⁻¹² event per draw.
    let half = box_half_widths(&shape) * std::f32::consts::SQRT_2;
    // The facet lobes (one shape, held inline), closed by the limit lobe where it is blended in.
    let mut set = SharedLobes::new(shape, half);
    let scale = (1.0 - b) / sum as f32;
    for (w, z) in cand.w[..cand.len].iter().zip(&cand.z[..cand.len]) {
        set.push(w * scale, Vec2::new(tau[0] * z[0], tau[1] * z[1]));
    }
    if b > 0.0 {
        set.push_other(b, limit);
    }
    set.normalise();
    if set.len() == 0 {
        return ProceduralPatch::limit_alone(LimitNdf::Beckmann(limit), alpha, x, distance);
    }
    ProceduralPatch {
        body: Body::Shared(set),
        level: x as f32,
        limit_weight: b,
        distance: distance as f32,
    }
}

/// The patch of a GGX surface from its gathered lobes `cand` (weights summing to `sum`): each lobe
/// its own width from its variance scale, blended with GGX so that the patch is as far from GGX as
/// its footprint's facets are, and handed over to GGX by the tolerance
/// (src/glint/procedural/ggx.rs).
fn ggx_patch<'a>(
    cand: &Candidates,
    sum: f64,
    wd: &Widths,
    alpha: Vec2,
    limit: Ggx,
    scratch: Option<&'a GlintScratch>,
) -> ProceduralPatch<'a> {
    let x = wd.level;
    let r = wd.r.min(1.0);
    let distance = ggx::facet_distance(wd.sigma, wd.sigma_f, r, wd.k);
    let b = ggx::limit_weight(distance, r, wd.k, wd.limit_weight(distance));
    if b >= 1.0 || cand.len == 0 {
        return ProceduralPatch::limit_alone(LimitNdf::Ggx(limit), alpha, x, distance);
    }
    let alpha64 = [alpha.x as f64, alpha.y as f64];
    let mut set = Lent::<LobeSet>::new(scratch.map(|s| s.home()));
    set.clear();
    let scale = 1.0 / sum as f32;
    let max_var = (crate::glint::MAX_SLOPE as f64).powi(2);
    for i in 0..cand.len {
        let v = ggx::variance_scale(cand.u[i]);
        let (beta2, tau2) = ggx::scaled_lobe_widths(alpha64, v, wd.sigma_f, r);
        let z = cand.z[i];
        let mean = Vec2::new(
            (tau2[0].sqrt() * z[0] as f64) as f32,
            (tau2[1].sqrt() * z[1] as f64) as f32,
        );
        // The diagonal covariance's Cholesky factor directly (a lobe wider than `MAX_SLOPE`, which
        // `SlopeGaussian::new` refuses, is left out as it would be).
        let lobe = (beta2[0] <= max_var && beta2[1] <= max_var)
            .then(|| {
                let [lx, ly] = beta2.map(|b| b.sqrt() as f32);
                SlopeGaussian::from_mean_cholesky(mean, lx, 0.0, ly)
            })
            .flatten();
        if let Some(g) = lobe {
            // Slope boxes of 1 − 10⁻¹², as the Beckmann surface's facet lobes.
            let half = box_half_widths(&g) * std::f32::consts::SQRT_2;
            set.push_with_half_widths(cand.w[i] * scale, g, half);
        }
    }
    set.normalise();
    if set.len() == 0 {
        return ProceduralPatch::limit_alone(LimitNdf::Ggx(limit), alpha, x, distance);
    }
    let body = if b > 0.0 {
        Body::Blend(GgxBlend::new(Few::Set(set), b, limit))
    } else {
        Body::Lobes(Few::Set(set))
    };
    ProceduralPatch {
        body,
        level: x as f32,
        limit_weight: b,
        distance: distance as f32,
    }
}
