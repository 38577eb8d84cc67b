//! Parameters and per-query options of the procedural glint model: [`ProceduralParams`] (what
//! defines the surface, validated) and [`PatchOptions`] (what a query chooses), with their
//! documented `DEFAULT_*` values.

use crate::error::{Error, Result, positive};
use glam::Vec2;

/// Smallest accepted limit roughness α (either axis): 10⁻³.
pub const MIN_ALPHA: f32 = 1.0e-3;

/// Largest accepted limit roughness α (either axis): 2.
pub const MAX_ALPHA: f32 = 2.0;

/// Smallest accepted facet roughness α_f: 10⁻⁴.
pub const MIN_FACET_ALPHA: f32 = 1.0e-4;

/// Largest number of level-0 cells per uv side: 2²⁴ (the lattice indices the hash reads).
pub const MAX_CELLS_PER_SIDE: usize = 1 << 24;

/// Largest accepted `resolution`: 2²⁰ texels per uv side.
pub const MAX_RESOLUTION: usize = 1 << 20;

/// Default tolerance ([`PatchOptions::tolerance`]): 0.05, the expected relative L2 distance of a
/// footprint's P-NDF to the limit NDF below which the patch is the limit lobe alone.
pub const DEFAULT_TOLERANCE: f32 = 0.05;

/// The NDF a procedural glint surface converges to (its mean over positions at every footprint, and
/// its patch at large footprints): [`ProceduralParams::limit`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ProceduralLimit {
    /// The anisotropic Beckmann NDF of roughness α (slope deviations σ = α/√2 per axis): every
    /// lobe's mean is drawn with one shared spread (docs/procedural.md).
    #[default]
    Beckmann,
    /// The anisotropic GGX NDF of roughness α, as a Gaussian scale mixture: each lattice cell draws
    /// its own variance scale v (docs/procedural.md, "The GGX limit").
    Ggx,
}

/// What defines a procedural glint surface (validated by
/// [`ProceduralGlints::new`](super::ProceduralGlints::new)). `Default` gives the documented
/// associated `DEFAULT_*` values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProceduralParams {
    /// Roughness (αx, αy) of the anisotropic NDF the glints converge to (each in
    /// [[`MIN_ALPHA`], [`MAX_ALPHA`]]): the mean of the P-NDF over positions at every footprint,
    /// and its limit for large footprints.
    pub alpha: Vec2,
    /// Which NDF of roughness `alpha` the glints converge to: Beckmann (the default) or GGX.
    pub limit: ProceduralLimit,
    /// The facets' own Beckmann roughness α_f (isotropic; in [[`MIN_FACET_ALPHA`], min(αx, αy))):
    /// the angular size of one glint.
    pub facet_alpha: f32,
    /// Facets per texel (> 0): with `resolution`, resolution² · density facets per unit square of
    /// uv. The density of glints at a given footprint; a continuous parameter (glints move and
    /// merge smoothly as it changes).
    pub density: f32,
    /// Texels per unit of uv along u and along v, [width, height] (each in
    /// [1, [`MAX_RESOLUTION`]]): the grid in which footprints are measured
    /// ([`Footprint::gaussian_texels`](crate::glint::Footprint)), the procedural model's "map
    /// size". Texels are square in the model: the facets are isotropic in texel units. The pattern
    /// repeats with period 1 in u and in v.
    pub resolution: [usize; 2],
    /// The seed of the pattern: two seeds give two independent surfaces of the same statistics.
    pub seed: u64,
}

impl ProceduralParams {
    /// Default limit roughness: α = 0.3 on both axes.
    pub const DEFAULT_ALPHA: f32 = 0.3;
    /// Default facet roughness: α_f = 0.02, a glint about 1° wide.
    pub const DEFAULT_FACET_ALPHA: f32 = 0.02;
    /// Default density: one facet per texel.
    pub const DEFAULT_DENSITY: f32 = 1.0;
    /// Default resolution: 1024 texels per uv side (the crate's usual map size).
    pub const DEFAULT_RESOLUTION: [usize; 2] = [1024, 1024];

    /// Checks every parameter (the rules on the fields).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of its range.
    pub fn validate(&self) -> Result<()> {
        for (name, a) in [("alpha.x", self.alpha.x), ("alpha.y", self.alpha.y)] {
            if !(a.is_finite() && (MIN_ALPHA..=MAX_ALPHA).contains(&a)) {
                return Err(Error::InvalidParameter {
                    name,
                    value: a as f64,
                    reason: "the limit roughness must be finite, in [1e-3, 2]",
                });
            }
        }
        let fa = self.facet_alpha;
        if !(fa.is_finite() && fa >= MIN_FACET_ALPHA && fa < self.alpha.min_element()) {
            return Err(Error::InvalidParameter {
                name: "facet_alpha",
                value: fa as f64,
                reason: "the facet roughness must be finite, at least 1e-4 and below min(alpha)",
            });
        }
        positive("density", self.density)?;
        for (name, r) in [
            ("resolution[0]", self.resolution[0]),
            ("resolution[1]", self.resolution[1]),
        ] {
            if !(1..=MAX_RESOLUTION).contains(&r) {
                return Err(Error::InvalidParameter {
                    name,
                    value: r as f64,
                    reason: "texels per uv side must be in [1, 2^20]",
                });
            }
            let cells = r as f64 * (self.density as f64).sqrt();
            if !(cells >= 0.5 && cells < MAX_CELLS_PER_SIDE as f64) {
                return Err(Error::InvalidParameter {
                    name: "density",
                    value: self.density as f64,
                    reason: "resolution * sqrt(density) (facets per uv side) must be in [0.5, 2^24)",
                });
            }
        }
        Ok(())
    }
}

impl Default for ProceduralParams {
    fn default() -> Self {
        ProceduralParams {
            alpha: Vec2::splat(Self::DEFAULT_ALPHA),
            limit: ProceduralLimit::Beckmann,
            facet_alpha: Self::DEFAULT_FACET_ALPHA,
            density: Self::DEFAULT_DENSITY,
            resolution: Self::DEFAULT_RESOLUTION,
            seed: 0,
        }
    }
}

/// Per-query options of a [`ProceduralGlints`](super::ProceduralGlints) patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchOptions {
    /// The footprint's expected relative L2 distance to the limit NDF, ρ, below which the patch is
    /// the limit lobe alone; between `tolerance` and 2 · `tolerance` the patch blends the facet
    /// lobes into the limit lobe (docs/procedural.md). Values outside [10⁻⁴, 1] (NaN included)
    /// are clamped to that range (NaN to the default).
    pub tolerance: f32,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            tolerance: DEFAULT_TOLERANCE,
        }
    }
}

impl PatchOptions {
    /// The tolerance as a query uses it (clamped, NaN → the default).
    pub(crate) fn clamped_tolerance(&self) -> f64 {
        if self.tolerance.is_nan() {
            DEFAULT_TOLERANCE as f64
        } else {
            self.tolerance.clamp(1.0e-4, 1.0) as f64
        }
    }
}
