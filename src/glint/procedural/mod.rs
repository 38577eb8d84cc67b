//! Procedural glints: a glint NDF without a normal map, in constant time per footprint.
//!
//! A [`ProceduralGlints`] surface is a stationary random field of facets defined by a seed and
//! a few numbers a user understands ([`ProceduralParams`]): the roughness α the glints
//! converge to, the facets' own roughness α_f (the size of one glint), their density per texel and
//! the resolution that footprints are measured in, and which NDF it converges to
//! ([`ProceduralLimit`]: Beckmann, or GGX as a Gaussian scale mixture,
//! src/glint/procedural/ggx.rs). Nothing is stored per texel: a stateless hash
//! places one lobe per cell of a multiscale lattice (src/glint/procedural/lattice.rs), and a
//! footprint reads the one or two levels whose cells match its size.
//!
//! - [`ProceduralGlints::new`] validates the parameters and tabulates the levels (a few dozen
//!   numbers).
//! - [`GlintNdf::patch_with`] turns a [`Footprint`] into a [`ProceduralPatch`] of about 4-6
//!   lobes per level read (a tent one cell wide around the footprint's centre; at most 33 lobes),
//!   blending into the limit NDF as the footprint grows: bounded work at every footprint size.
//! - The mean of the P-NDF over positions is the limit NDF at every footprint size; the patch's
//!   distance to it falls as 1/√(facets seen) (docs/procedural.md, with the method, its parameters,
//!   its limits and its measurements).
//!
//! The lattice of lobes with widths that grow with the level follows the multiscale facet process
//! of Kemppinen et al. 2025 and the count-based levels of Deliot and Belcour 2023 in spirit; the
//! construction (lobe widths matched in L2, the exact mean) is the crate's own (docs/procedural.md).

mod ggx;
mod lattice;
mod limit;
mod params;
mod patch;
mod store;

pub use limit::LimitNdf;
pub use params::{
    DEFAULT_TOLERANCE, MAX_ALPHA, MAX_CELLS_PER_SIDE, MAX_RESOLUTION, MIN_ALPHA, MIN_FACET_ALPHA,
    PatchOptions, ProceduralLimit, ProceduralParams,
};
pub use patch::ProceduralPatch;

use crate::error::Result;
use crate::glint::{Footprint, GlintNdf, GlintScratch};
use crate::ndf::{Ggx, SlopeGaussian};
use lattice::Level;

/// A procedural glint surface (module docs): its parameters and its tabulated lattice levels.
///
/// # Example
/// ```
/// use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
/// use brdf::glint::{Footprint, GlintNdf};
/// use brdf::ndf::Ndf;
/// use brdf::{Vec2, Vec3};
///
/// let glints = ProceduralGlints::new(ProceduralParams { seed: 7, ..Default::default() })?;
/// let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.7), 16.0, 1024, 1024);
/// let patch = glints.patch(&fp);
/// assert!(patch.d(Vec3::Z).is_finite());
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct ProceduralGlints {
    params: ProceduralParams,
    levels: Vec<Level>,
    limit: LimitNdf,
}

impl PartialEq for ProceduralGlints {
    fn eq(&self, other: &Self) -> bool {
        self.params == other.params
    }
}

impl ProceduralGlints {
    /// A surface of the given parameters.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the first parameter out of range
    /// ([`ProceduralParams::validate`]).
    pub fn new(params: ProceduralParams) -> Result<Self> {
        params.validate()?;
        let levels = lattice::levels(&params);
        let (ax, ay) = (params.alpha.x, params.alpha.y);
        let limit = match params.limit {
            ProceduralLimit::Beckmann => LimitNdf::Beckmann(SlopeGaussian::beckmann(ax, ay)?),
            ProceduralLimit::Ggx => LimitNdf::Ggx(Ggx::new(ax, ay)?),
        };
        Ok(ProceduralGlints {
            params,
            levels,
            limit,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &ProceduralParams {
        &self.params
    }

    /// The limit NDF ([`ProceduralParams::limit`]): the centred anisotropic Beckmann lobe or the
    /// GGX NDF of roughness `alpha`, the mean of every patch over positions and the patch of every
    /// large footprint.
    pub fn limit(&self) -> LimitNdf {
        self.limit
    }

    /// The grid footprints are measured in, (width, height) = `resolution` texels per uv period
    /// (the procedural model's "map size").
    pub fn map_size(&self) -> (usize, usize) {
        (self.params.resolution[0], self.params.resolution[1])
    }

    /// The number of lattice levels (level 0 holds one facet per cell; the last one cell per uv
    /// side).
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }
}

impl GlintNdf for ProceduralGlints {
    type Patch<'a> = ProceduralPatch<'a>;
    type Options = PatchOptions;

    fn patch_with<'a>(
        &'a self,
        footprint: &Footprint,
        options: &PatchOptions,
        scratch: Option<&'a GlintScratch>,
    ) -> ProceduralPatch<'a> {
        patch::make_patch(
            &self.params,
            &self.levels,
            self.limit,
            footprint,
            options,
            scratch,
        )
    }
}
