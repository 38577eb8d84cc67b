//! The bin map's build parameters ([`BinMapParams`]) and per-query options ([`PatchOptions`]),
//! with their documented defaults.

use super::BinLookup;

/// Default bins per axis n: 255 (B = n² = 65 025 bins of 9.7·10⁻⁵ sr, about 0.56° across; 𝓑 still
/// fits `u16`). Chosen with [`DEFAULT_SUBDIVISIONS`] from accuracy against memory on the procedural
/// maps (docs/results.md, "Inverse bin map (Atanasov 2020)"): against the talk's car-paint setting 127² it
/// lowers the TV distance to the ground truth at ≥ 256 texels on brushed, scratched and flakes
/// (1.3-2.3×) and raises it 1.2× on the smooth bumpy map, for 0.5 B/texel more at 2048² (the
/// per-bin tables: 3.4 MB per map whatever its size). 127 remains the talk's setting.
pub const DEFAULT_BINS_PER_AXIS: usize = 255;

/// Default maximum leaf size L of the kd-trees: lists of at most L texels are scanned linearly, and
/// only longer lists get a tree (16, as in the talk).
pub const DEFAULT_LEAF_SIZE: usize = 16;

/// Default floor σ_ε of the masking lobe's slope standard deviation (see [`BinMapParams::sigma_min`]).
pub const DEFAULT_MASKING_SIGMA_MIN: f32 = crate::ndf::DEFAULT_SIGMA_MIN;

/// Default sub-texel resolution s: each texel is binned as s × s sub-texels of the interpolated
/// surface (normals at n-rooks points, see [`BinMap::build`](super::BinMap::build)). 2 was chosen with
/// [`DEFAULT_BINS_PER_AXIS`] from accuracy against memory on the procedural maps (docs/results.md,
/// "Inverse bin map (Atanasov 2020)" and "Memory per model"): with 255² bins, at ≥ 256 texels,
/// the TV distance to the ground truth is 2.1-4.2× below the talk's map (s = 1, 127²) on bumpy,
/// brushed and scratched for 2.8× its memory (29.2 B/texel at 2048²); s = 3 costs 62.9 B/texel,
/// over the 42 B/texel budget whatever the integer widths (docs/binmap.md).
pub const DEFAULT_SUBDIVISIONS: usize = 2;

/// Largest accepted sub-texel resolution s (s² sub-texels per texel).
pub const MAX_SUBDIVISIONS: usize = 16;

/// Default lookup: measured faster than the hash table at 2048² (docs/results.md).
pub const DEFAULT_LOOKUP: BinLookup = BinLookup::Dense;

/// The finest level of the bins' slope-moment mip chain kept for the masking lobe: level 1 (2 × 2
/// texels per moment texel), 20 B / 4 texels ≈ 6.7 B per texel for the whole chain. With level 2
/// (4 × 4 texels) the boundary cells of a footprint mixed in enough slopes from outside it for the
/// furnace to reach 1.0143 ± 0.0016 (src/glint/binmap/footprint_moments.rs).
pub const MASKING_FIRST_LEVEL: usize = 1;

/// Default [`PatchOptions::exact_masking_texels`]: 4096 texels, the cost cap of the exact masking
/// pass. Below it a footprint's masking is the exact Smith terms of its own bins unless the map's
/// measured error of the O(1) moment lobe is within [`PatchOptions::moment_masking_tolerance`];
/// that lobe loses up to 6 % of the albedo at θo = 45°, 12 % at 70° and 18 % at 85° on some
/// procedural maps (bumpy, flakes) and 0.2 % / 1.5 % / 9 % on others (scratched), hence a
/// per-map choice (docs/results.md, "Inverse bin map: the masking level of detail").
pub const DEFAULT_EXACT_MASKING_TEXELS: f32 = 4096.0;

/// Smallest footprint (texels²) that takes the moment lobe's masking whatever
/// [`PatchOptions::exact_masking_texels`] says: 128. Below it the footprint's boundary cells of the
/// moment chain weigh too much for its moments to be the footprint's, so Scarf's bound need not
/// bound its visible area (with 4 × 4-texel cells of the map's own slopes the furnace reaches 1.41
/// at 85° and 1.10 at 45° on 64-texel footprints: docs/binmap.md); from 128 texels the furnace stays at most 1 + 3 standard
/// errors on the test maps (tests/it/binmap_masking_lod.rs).
pub const MIN_MOMENT_MASKING_TEXELS: f32 = 128.0;

/// Default [`PatchOptions::moment_masking_tolerance`]: 0.02, a 2 % mean error of G1 at 45° and
/// 70°. On the procedural maps it serves the moment lobe on scratched (measured 0.003-0.004) and
/// brushed (0.009-0.010), where its albedo stays within 0.3 % at 45° and 2.3 % at 70° of the exact
/// terms', and not on bumpy (0.044-0.046) or flakes (0.024-0.028), which lose up to 12 % and 9 %
/// (docs/results.md, "Inverse bin map: the masking level of detail").
pub const DEFAULT_MOMENT_MASKING_TOLERANCE: f32 = 0.02;

/// Build parameters of a [`BinMap`](super::BinMap). `Default` gives the documented `DEFAULT_*` values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BinMapParams {
    /// Bins per axis n, odd, 1 ≤ n ≤ [`HemisphereBins::MAX_N`](crate::glint::HemisphereBins::MAX_N): B = n² bins of 2π/n² sr each, the
    /// pole at the centre of the middle bin.
    pub bins_per_axis: usize,
    /// Maximum leaf size L (≥ 1).
    pub leaf_size: usize,
    /// Dense or hashed bin lookup.
    pub lookup: BinLookup,
    /// Floor σ_ε (> 0) of the slope standard deviation of the masking lobe (the footprint's
    /// filtered-moment Beckmann lobe, see [`BinMapPatch`](super::BinMapPatch)).
    pub sigma_min: f32,
    /// Sub-texel resolution s, 1 ≤ s ≤ [`MAX_SUBDIVISIONS`]: every texel is split into s × s
    /// sub-texels, each a flat facet carrying the interpolated surface's normal
    /// ([`NormalMap::normal_at_texel`](crate::glint::NormalMap::normal_at_texel)) at one point inside it, the s² points of a texel in an
    /// n-rooks pattern (s² distinct coordinates per axis; see [`BinMap::build`](super::BinMap::build)); the bin map, the inverse map and the forest work on the
    /// (s·width) × (s·height) sub-texel grid. s = 1 is the talk's one-normal-per-texel map. Memory
    /// of 𝓑, 𝓑⁻¹ and the forest grows as s².
    pub subdivisions: usize,
}

impl Default for BinMapParams {
    fn default() -> Self {
        BinMapParams {
            bins_per_axis: DEFAULT_BINS_PER_AXIS,
            leaf_size: DEFAULT_LEAF_SIZE,
            lookup: DEFAULT_LOOKUP,
            sigma_min: DEFAULT_MASKING_SIGMA_MIN,
            subdivisions: DEFAULT_SUBDIVISIONS,
        }
    }
}

/// Default [`PatchOptions::smoothing_alpha`]: 0, the one-bin angular resolution of
/// \[Atanasov2020\].
pub const DEFAULT_SMOOTHING_ALPHA: f32 = 0.0;

/// Per-query options of a bin-map patch (the [`GlintNdf::Options`](crate::glint::GlintNdf::Options) of [`BinMap`](super::BinMap)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchOptions {
    /// Beckmann roughness α of a lobe that spreads every bin's mass about the bin's centre
    /// direction (slope σ = α/√2): D(h) = Σ_j mass_j D_j(h) (see [`BinMapPatch`](super::BinMapPatch)). 0 keeps the
    /// one-bin resolution; a value that is not finite and > 0 means 0; α is clamped to
    /// [[`crate::ndf::MIN_ALPHA`], [`crate::ndf::MAX_ALPHA`]] = [10⁻⁴, 10⁴], the range of the
    /// analytic NDFs (options are per query, so they are clamped rather than refused; beyond 10⁴
    /// the lobes' variance leaves the slope range a `SlopeGaussian` holds and the window of bins a
    /// smoothed D sums over overflows).
    ///
    /// # Reference
    /// The smoothing follows the idea of the authors' later full paper (a Beckmann lobe per bin);
    /// \[Atanasov2020\] itself has one-bin angular resolution.
    pub smoothing_alpha: f32,
    /// Largest footprint (texels²) whose patch may compute its masking terms from its own bins: one
    /// O(s² |A|) pass over the footprint's sub-texels at patch construction, then O(bins in A) per
    /// direction, and the visible-normal sampler. Larger footprints, and those the
    /// `moment_masking_tolerance` serves, take the Smith terms of the footprint's filtered-moment
    /// lobe (O(1)) and the normal sampler. Values below
    /// [`MIN_MOMENT_MASKING_TEXELS`] (NaN included) act as it: smaller footprints always keep their
    /// own bins. `f32::INFINITY` gives every footprint its own bins. `Default` gives
    /// [`DEFAULT_EXACT_MASKING_TEXELS`]; docs/binmap.md gives the error and cost that chose it.
    pub exact_masking_texels: f32,
    /// Largest measured G1 error of the moment lobe's masking
    /// ([`BinMap::moment_masking_errors`](super::BinMap::moment_masking_errors), measured per map by
    /// the build) at which a footprint between [`MIN_MOMENT_MASKING_TEXELS`] and
    /// `exact_masking_texels` takes the moment lobe's masking instead of its own bins'
    /// ([`DEFAULT_MOMENT_MASKING_TOLERANCE`]); 0 or NaN never, `f32::INFINITY` always (from
    /// [`MIN_MOMENT_MASKING_TEXELS`]).
    pub moment_masking_tolerance: f32,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            smoothing_alpha: DEFAULT_SMOOTHING_ALPHA,
            exact_masking_texels: DEFAULT_EXACT_MASKING_TEXELS,
            moment_masking_tolerance: DEFAULT_MOMENT_MASKING_TOLERANCE,
        }
    }
}
