//! Saving and loading a built [`BinMap`] (format: docs/format.md, kind 4, format version 3).
//!
//! Stored: the map size, the build parameters (sub-texel resolution s included), the prefix-sum
//! offsets of the bins' lists (B + 1) and their tree roots (B), the packed forest, the inverse bin
//! map 𝓑⁻¹ in the forest's order (u32 per sub-texel of the (s·width) × (s·height) grid), the bin map
//! 𝓑 itself (u16 per sub-texel, u32 above 2¹⁶ bins), the bins' slope-moment chain of the masking
//! lobe and its measured errors (a chain stored from level 2 holds the map's own slopes: it is
//! rebuilt from 𝓑 and the errors are measured again). Rebuilt on load (cheap, by the build's own
//! routines): the per-bin tables (centre slopes, masking facets) and the lookup (dense or hash)
//! from the offsets and roots.
//!
//! The inverse map and the forest are stored rather than rebuilt because sorting the texels into the
//! trees is most of the build; 𝓑 is stored because deriving it from 𝓑⁻¹ writes one sub-texel at a
//! random place per list entry (most of a format-2 load). The loader validates everything before
//! use, with sequential reads only:
//! - the forest is exactly the pre-order layout the builder writes (each internal node where the
//!   previous one ends, right-child links consistent, a list gets a tree exactly when it is longer
//!   than the leaf size), and every leaf's texels lie in the leaf's region (regions nest, so every
//!   internal node's two ranges then hold exactly the texels on each side of its split, the
//!   builder's partition);
//! - 𝓑 and 𝓑⁻¹ describe the same assignment: the multiset of pairs (k, b) over the lists of 𝓑⁻¹
//!   equals the multiset of pairs (k, 𝓑(k)) over the sub-texels, compared by a randomised
//!   fingerprint ([`crate::glint::io::multiset`]). The right side holds every sub-texel once, so equal
//!   multisets make 𝓑⁻¹ a permutation of the sub-texels that lists each one in the bin 𝓑 gives it.
//!   A file whose 𝓑 and 𝓑⁻¹ disagree passes with probability at most n / (2⁶¹ − 1) for n
//!   sub-texels (below 2⁻³⁷ at 2048², s = 2) over the loader's random draw; a disagreement found is
//!   then located exactly, to name it in the error.
//!
//! A file that passes is a bin map the builder could have produced.
//!
//! The load overlaps its checks with its reads: the reads stay on the calling thread (a
//! `std::io::Read` need not be `Send`) while the per-bin tables, as soon as the offsets are read, and
//! the forest walk, as soon as 𝓑⁻¹ is, run on rayon's pool ([`rayon::in_place_scope`]); 𝓑's
//! fingerprint is taken chunk by chunk as 𝓑 is read. Errors are still reported in the order of a
//! sequential load: the read and the checksum first, then the values.

use super::forest::NO_TREE;
use super::lookup::Table;
use super::{BinIndex, BinLookup, BinMap, BinMapParams, MASKING_FIRST_LEVEL, check_params};
use crate::Result;
use crate::glint::MAX_SLOPE;
use crate::glint::io::format::{self, Decoder, Kind, Stored, invalid};
use crate::glint::io::multiset;
use crate::glint::surface::{MomentLevel, MomentPyramid};
use rayon::prelude::*;
use std::io::{Read, Write};

/// The first level of a stored moment chain in the format's older layout, whose chain holds the
/// map's own texel slopes from 4 × 4-texel cells (rebuilt from 𝓑 on load).
const LEGACY_MOMENTS_FIRST: usize = 2;

impl BinMap {
    /// Writes the bin map in the crate's binary format (docs/format.md): size, parameters, 𝓑⁻¹, 𝓑,
    /// bin offsets and roots, forest and coarse moments, exactly (about 6 bytes per sub-texel plus 8
    /// per bin). Writes in 64 KiB blocks.
    ///
    /// # Errors
    /// [`crate::Error::Stream`] if the writer fails.
    pub fn save(&self, w: &mut impl Write) -> Result<()> {
        let p = &self.params;
        let nb = self.bins.len();
        // Offsets and roots of every bin, whatever the lookup (the hash table is rebuilt from them).
        let entries: Vec<(u32, u32)> = (0..nb)
            .map(|b| {
                self.table
                    .get(b)
                    .map_or((0, NO_TREE), |e| (e.end - e.start, e.root))
            })
            .collect();
        let mut offsets = Vec::with_capacity(nb + 1);
        offsets.push(0u32);
        for &(len, _) in &entries {
            offsets.push(offsets[offsets.len() - 1] + len);
        }
        let (first, levels) = self.moments.parts();
        format::save(w, Kind::BinMap, |e| {
            e.len(self.width)?;
            e.len(self.height)?;
            e.len(p.bins_per_axis)?;
            e.len(p.leaf_size)?;
            e.len(p.subdivisions)?;
            e.put(match p.lookup {
                BinLookup::Dense => 0u32,
                BinLookup::Hash => 1u32,
            })?;
            e.put(p.sigma_min)?;
            // The small tables first, so that a load can check the forest while it reads 𝓑.
            e.array(offsets.iter().map(|&o| [o]))?;
            e.array(entries.iter().map(|&(_, root)| [root]))?;
            e.array(self.nodes.iter().map(|&v| [v]))?;
            e.array(self.inverse.iter().map(|&k| [k]))?;
            match &self.bin_map {
                BinIndex::U16(v) => e.array(v.iter().map(|&b| [b]))?,
                BinIndex::U32(v) => e.array(v.iter().map(|&b| [b]))?,
            }
            e.len(first)?;
            e.len(levels.len())?;
            for l in levels {
                e.len(l.width)?;
                e.len(l.height)?;
                e.array(l.data.iter().copied())?;
            }
            // The moment-lobe masking's measured errors (since version 6).
            e.array(self.moment_masking_errors().iter().map(|&v| [v]))
        })
    }

    /// Reads a bin map written by [`BinMap::save`]. Its patches (plain and smoothed) answer `d`,
    /// `lambda`, `projected_area`, `sample_visible` and `pdf_visible` bit-identically to the saved
    /// one's.
    ///
    /// # Errors
    /// [`crate::Error::BadMagic`] (foreign bytes), [`crate::Error::CorruptHeader`] (a damaged header,
    /// docs/format.md "Damaged or unsupported"), [`crate::Error::UnsupportedVersion`],
    /// [`crate::Error::WrongModelKind`], [`crate::Error::Truncated`],
    /// [`crate::Error::ChecksumMismatch`], [`crate::Error::Stream`]; [`crate::Error::InvalidFile`] for
    /// parameters the builder refuses, sizes that do not match the map or the bins, and any
    /// inconsistency of 𝓑, 𝓑⁻¹, the offsets, the forest or the moments (see the module docs).
    pub fn load(r: &mut impl Read) -> Result<Self> {
        let mut d = Decoder::open(r, Kind::BinMap)?;
        d.require_version(3)?;
        let width = d.len("width", i32::MAX as usize)?;
        let height = d.len("height", i32::MAX as usize)?;
        let params = BinMapParams {
            bins_per_axis: d.len("bins_per_axis", usize::MAX)?,
            leaf_size: d.len("leaf_size", usize::MAX)?,
            subdivisions: d.len("subdivisions", usize::MAX)?,
            lookup: match d.get::<u32>("lookup")? {
                0 => BinLookup::Dense,
                1 => BinLookup::Hash,
                v => return Err(invalid(format!("lookup {v} (0 or 1 expected)"))),
            },
            sigma_min: d.get("sigma_min")?,
        };
        let refused = |e: crate::Error| invalid(format!("stored bin map refused: {e}"));
        let bins = check_params(&params).map_err(refused)?;
        crate::glint::surface::texel_count(width, height, width.saturating_mul(height))
            .map_err(refused)?;
        let s = params.subdivisions;
        let (grid_w, grid_h) = (width * s, height * s);
        let texels = grid_w.saturating_mul(grid_h);
        if texels >= u32::MAX as usize {
            return Err(invalid(format!(
                "{texels} sub-texels: the bin map needs fewer than 2^32"
            )));
        }
        let nb = bins.len();
        let offsets = flat(d.array::<u32, 1>("offsets", nb + 1)?);
        let roots = flat(d.array::<u32, 1>("roots", nb)?);
        // Internal nodes hold at least 2 texels and those of one depth are disjoint, so a forest has
        // fewer than texels × (depth ≤ 64) nodes; the bound only limits the count before its check.
        let nodes = flat(d.array_up_to::<u32, 1>("forest", 128 * texels)?);
        // Checked now (the forest walk slices 𝓑⁻¹ by the offsets), reported after the checksum.
        let offsets_ok = check_offsets(&offsets, texels);
        let sizes = MomentPyramid::level_sizes(width, height);
        let first = MASKING_FIRST_LEVEL.min(sizes.len() - 1);
        let z = multiset::random_point();
        // The reads stay on this thread; the per-bin tables (from the offsets) and then the forest
        // walk with the lists' fingerprint (from 𝓑⁻¹) run on the thread pool meanwhile, and 𝓑's
        // fingerprint is taken chunk by chunk as 𝓑 is read.
        let (mut tables, mut forest) = (None, None);
        let read = rayon::in_place_scope(|outer| {
            outer.spawn(|_| tables = Some(super::facets::bin_tables(&bins, &offsets)));
            let inverse = flat(d.array::<u32, 1>("inverse", texels)?);
            let rest = rayon::in_place_scope(|inner| {
                if offsets_ok.is_ok() {
                    inner.spawn(|_| {
                        forest = Some(check_forest(
                            &inverse,
                            &offsets,
                            &roots,
                            &nodes,
                            [grid_w, grid_h],
                            params.leaf_size,
                            z,
                        ));
                    });
                }
                let mut assigned = Assignment::new(nb, z);
                // The builder's storage choice (u16 when every bin fits).
                let bin_map = if nb <= 1 << 16 {
                    BinIndex::U16(bytemuck::cast_vec(d.array_with::<u16, 1>(
                        "bin map",
                        texels,
                        |at, chunk| assigned.add(at, chunk.as_flattened()),
                    )?))
                } else {
                    BinIndex::U32(flat(d.array_with::<u32, 1>(
                        "bin map",
                        texels,
                        |at, chunk| assigned.add(at, chunk.as_flattened()),
                    )?))
                };
                let (stored_first, levels) = read_moments(&mut d, &sizes, first)?;
                // Format version 6 holds the moment-lobe masking's measured errors (at most one
                // per level of the map); older files get them measured, as a build does.
                let errors = if d.version() >= 6 {
                    Some(d.array_up_to::<f32, 1>("masking errors", sizes.len() + 1)?)
                } else {
                    None
                };
                d.finish()?;
                Ok((bin_map, stored_first, levels, errors, assigned.finish()))
            })?;
            Ok::<_, crate::Error>((inverse, rest))
        });
        let (inverse, (bin_map, stored_first, levels, errors, assigned)) = read?;
        // A chain stored from level 2 holds the map's own slopes (the format's older layout):
        // rebuilt from 𝓑 below, and the errors measured on it again.
        let legacy = stored_first != first;
        let errors: Option<Vec<f32>> = errors
            .filter(|_| !legacy)
            .map(|e| e.into_iter().map(|[v]| v).collect());
        // Relative G1 errors, capped at 1 when measured.
        if let Some(e) = errors.iter().flatten().find(|e| !(0.0..=1.0).contains(*e)) {
            return Err(invalid(format!(
                "moment masking error {e} is not in [0, 1]"
            )));
        }
        let m = 2.0 * MAX_SLOPE;
        for l in &levels {
            format::check_range(&l.data, "moments", |c| match c {
                0 | 1 => (-m, m),
                2 | 3 => (0.0, m * m),
                _ => (-m * m, m * m),
            })?;
        }
        offsets_ok?;
        let lists = forest.expect("the forest walk ran: the offsets are valid")?;
        if lists != assigned? {
            return Err(disagreement(&inverse, &offsets, &bin_map));
        }
        let super::facets::BinTables {
            facets,
            center_slope,
            corners,
        } = tables.expect("the tables task ran");
        let moments = if legacy {
            let pole = bins.bin_of(glam::Vec3::Z).unwrap_or(0);
            super::footprint_moments::chain(
                &bins,
                &|k| bin_map.get(k).unwrap_or(pole),
                width,
                height,
                s,
            )
        } else {
            MomentPyramid::from_parts(first, levels)
        };
        Ok(BinMap {
            width,
            height,
            bins,
            params,
            grid_w,
            grid_h,
            bin_map,
            inverse,
            nodes,
            table: Table::new(params.lookup, offsets, roots),
            center_slope,
            facets,
            corners,
            moments,
            moment_masking_error: Vec::new(),
        }
        .with_masking_errors(errors))
    }
}

impl Stored for BinMap {
    const KINDS: &'static [Kind] = &[Kind::BinMap];
    fn save_to(&self, mut w: &mut dyn Write) -> Result<()> {
        self.save(&mut w)
    }
    fn load_from(mut r: &mut dyn Read) -> Result<Self> {
        Self::load(&mut r)
    }
}

fn flat(v: Vec<[u32; 1]>) -> Vec<u32> {
    // Same size and alignment: the vector is reinterpreted in place, no copy.
    bytemuck::cast_vec(v)
}

/// The offsets are prefix sums: from 0 to the sub-texel count `n`, never decreasing.
fn check_offsets(offsets: &[u32], n: usize) -> Result<()> {
    let nb = offsets.len() - 1;
    if offsets[0] != 0 || offsets[nb] as usize != n {
        return Err(invalid(format!(
            "offsets run from {} to {} where the lists of {n} sub-texels need 0 to {n}",
            offsets[0], offsets[nb]
        )));
    }
    if let Some(b) = (0..nb).find(|&b| offsets[b + 1] < offsets[b]) {
        return Err(invalid(format!(
            "offsets[{}] = {} < offsets[{b}] = {}: the offsets must not decrease",
            b + 1,
            offsets[b + 1],
            offsets[b]
        )));
    }
    Ok(())
}

/// The pair (sub-texel k, bin b) as one element of GF(2⁶¹ − 1): k · B + b, below 2⁵⁶ for k < 2³²
/// and B ≤ 4096² bins (unique for b < B).
#[inline(always)]
fn pair(k: u32, b: usize, nb: usize) -> u64 {
    k as u64 * nb as u64 + b as u64
}

/// The masking lobe's moment chain: its first level and level count, then each level's size (which
/// must be the one in `sizes`, the map's whole chain) and its moments. The first level is `first`
/// or [`LEGACY_MOMENTS_FIRST`] (older files, whose chain the loader rebuilds); returns it with the
/// levels read.
fn read_moments(
    d: &mut Decoder<'_>,
    sizes: &[(usize, usize)],
    first: usize,
) -> Result<(usize, Vec<MomentLevel>)> {
    let stored_first = d.len("moments first level", usize::MAX)?;
    let legacy = LEGACY_MOMENTS_FIRST.min(sizes.len() - 1);
    if stored_first != first && stored_first != legacy {
        return Err(invalid(format!(
            "moment chain from level {stored_first}; the map keeps levels from {first}"
        )));
    }
    let sizes = &sizes[stored_first..];
    let level_count = d.len("moment levels", stored_first + sizes.len())?;
    if level_count != sizes.len() {
        return Err(invalid(format!(
            "moment chain from level {stored_first} with {level_count} levels; the map's has {}",
            sizes.len()
        )));
    }
    let mut levels = Vec::with_capacity(level_count);
    for &(w, h) in sizes {
        let (sw, sh) = (
            d.len("moment level width", w)?,
            d.len("moment level height", h)?,
        );
        if (sw, sh) != (w, h) {
            return Err(invalid(format!(
                "moment level of {sw}×{sh} texels where the map's chain has {w}×{h}"
            )));
        }
        let data = d.array::<f32, 5>("moments", w * h)?;
        levels.push(MomentLevel {
            width: w,
            height: h,
            data,
        });
    }
    Ok((stored_first, levels))
}

/// The fingerprint at `z` of the pairs (k, 𝓑(k)) over every sub-texel k, taken chunk by chunk as 𝓑
/// is read; the first 𝓑(k) that is not a bin (its pair would alias another sub-texel's) is kept
/// as the error.
struct Assignment {
    bins: usize,
    z: u64,
    print: u64,
    bad: Option<crate::Error>,
}

impl Assignment {
    fn new(bins: usize, z: u64) -> Assignment {
        Assignment {
            bins,
            z,
            print: 1,
            bad: None,
        }
    }

    /// The sub-texels `at`, `at` + 1, … with bins `chunk`.
    fn add<T: Copy + Into<u64>>(&mut self, at: usize, chunk: &[T]) {
        if self.bad.is_some() {
            return;
        }
        let nb = self.bins as u64;
        if let Some(t) = chunk.iter().position(|&b| b.into() >= nb) {
            self.bad = Some(invalid(format!(
                "bin map[{}] = {} is not a bin (there are {nb})",
                at + t,
                chunk[t].into()
            )));
            return;
        }
        let p = multiset::product(
            self.z,
            (at as u32..)
                .zip(chunk)
                .map(|(k, &b)| pair(k, b.into() as usize, self.bins)),
        );
        self.print = multiset::combine(self.print, p);
    }

    fn finish(self) -> Result<u64> {
        self.bad.map_or(Ok(self.print), Err)
    }
}

/// Names the first disagreement between 𝓑⁻¹ (its entries already known to be sub-texels) and 𝓑,
/// once their fingerprints differ: a sub-texel listed twice, or listed in a bin other than its 𝓑.
/// The slow path of corrupt files only (a random access per entry).
fn disagreement(inverse: &[u32], offsets: &[u32], bin_map: &BinIndex) -> crate::Error {
    let n = inverse.len();
    let mut seen = vec![0u64; n.div_ceil(64)];
    for b in 0..offsets.len() - 1 {
        let start = offsets[b] as usize;
        for (i, &k) in (start..).zip(&inverse[start..offsets[b + 1] as usize]) {
            let k = k as usize;
            let bit = 1u64 << (k % 64);
            match seen.get_mut(k / 64) {
                Some(word) if *word & bit == 0 => *word |= bit,
                _ => {
                    return invalid(format!(
                        "inverse[{i}] = {k} is out of range or repeated (not a permutation of the \
                         {n} sub-texels)"
                    ));
                }
            }
            let found = bin_map.get(k);
            if found != Some(b) {
                return invalid(format!(
                    "inverse[{i}] = {k} is in the list of bin {b} but the bin map gives it bin {found:?}"
                ));
            }
        }
    }
    invalid("the bin map and the inverse bin map disagree (multiset fingerprints differ)".into())
}

/// The forest is exactly the builder's layout (see forest.rs): bins in order, each list longer than
/// `leaf` has a tree at the current end of the array, nodes in pre-order (a left child that is internal
/// follows its parent, the stored right-child index is where the left subtree ends), mids within the
/// node's range, and every leaf's texels inside the leaf's region. Regions nest and the two children of
/// a node split its region at the builder's split, so this puts every internal node's left range on
/// one side of its split and its right range on the other: the builder's partition. Cost O(texels +
/// nodes) (one division per texel), no allocation.
///
/// Returns the fingerprint at `z` of the pairs (k, b) over every entry k of every bin b's list (each
/// list hashed right after its tree's walk, while it is in cache).
fn check_forest(
    inverse: &[u32],
    offsets: &[u32],
    roots: &[u32],
    nodes: &[u32],
    size: [usize; 2],
    leaf: usize,
    z: u64,
) -> Result<u64> {
    let f = Forest {
        inverse,
        nodes,
        width: Divisor::new(size[0] as u32),
        leaf,
    };
    // Each tree is walked from its stored root, bins in parallel; the layout (trees back to back in
    // bin order, from 0 to the end of the array) is then checked in order on the walks' ends.
    let ends: Vec<Result<(Option<usize>, u64)>> = (0..roots.len())
        .into_par_iter()
        .map(|b| {
            let (start, end) = (offsets[b] as usize, offsets[b + 1] as usize);
            let print = || {
                let list = &inverse[start..end];
                multiset::product(z, list.iter().map(|&k| pair(k, b, roots.len())))
            };
            if end - start <= leaf {
                return if roots[b] == NO_TREE {
                    f.node(
                        b,
                        start,
                        end,
                        [0, 0, size[0] as u32, size[1] as u32],
                        &mut 0,
                    )
                    .map(|()| (None, print()))
                } else {
                    Err(invalid(format!(
                        "roots[{b}] = {} where the forest layout needs {NO_TREE} (no tree)",
                        roots[b]
                    )))
                };
            }
            let mut cursor = roots[b] as usize;
            f.node(
                b,
                start,
                end,
                [0, 0, size[0] as u32, size[1] as u32],
                &mut cursor,
            )
            .map(|()| (Some(cursor), print()))
        })
        .collect();
    let mut cursor = 0usize;
    let mut print = 1;
    for (b, walked) in ends.into_iter().enumerate() {
        // The same first error as walking the trees one after the other: a misplaced root before
        // anything found inside its tree.
        let has_tree = offsets[b + 1] - offsets[b] > leaf as u32;
        if has_tree && roots[b] as usize != cursor {
            return Err(invalid(format!(
                "roots[{b}] = {} where the forest layout needs {cursor}",
                roots[b]
            )));
        }
        let (end, p) = walked?;
        if let Some(end) = end {
            cursor = end;
        }
        print = multiset::combine(print, p);
    }
    if cursor != nodes.len() {
        return Err(invalid(format!(
            "the forest holds {} values but its trees use {cursor}",
            nodes.len()
        )));
    }
    Ok(print)
}

struct Forest<'a> {
    inverse: &'a [u32],
    nodes: &'a [u32],
    width: Divisor,
    leaf: usize,
}

/// Division of u32 numerators by a fixed u32 divisor d ≥ 2 by one multiplication: with
/// M = ⌊(2⁶⁴ − 1)/d⌋ + 1, ⌊n/d⌋ is the high 64 bits of M·n for every n < 2³² (Lemire, Kaser and
/// Kurz 2019, "Faster remainder by direct computation", §3), the remainder n − d·⌊n/d⌋. d = 1 (a
/// one-sub-texel-wide grid, where M would wrap to 0) is answered directly.
#[derive(Clone, Copy)]
struct Divisor {
    d: u32,
    m: u64,
}

impl Divisor {
    fn new(d: u32) -> Divisor {
        let d = d.max(1);
        Divisor {
            d,
            m: (u64::MAX / d as u64).wrapping_add(1),
        }
    }

    /// (n mod d, ⌊n/d⌋).
    #[inline(always)]
    fn rem_div(self, n: u32) -> (u32, u32) {
        if self.d == 1 {
            return (0, n);
        }
        let q = ((self.m as u128 * n as u128) >> 64) as u32;
        (n - q * self.d, q)
    }
}

impl Forest<'_> {
    /// Checks the (sub)tree of the range [s, e) with region [x0, y0, x1, y1] whose first internal node
    /// must sit at `cursor`; advances `cursor` past it. Depth ≤ 2 + log₂ of the sides (regions halve).
    fn node(
        &self,
        b: usize,
        s: usize,
        e: usize,
        region: [u32; 4],
        cursor: &mut usize,
    ) -> Result<()> {
        let [x0, y0, x1, y1] = region;
        if e - s <= self.leaf {
            let w = self.width;
            let outside = |k: u32| {
                let (x, y) = w.rem_div(k);
                x < x0 || x >= x1 || y < y0 || y >= y1
            };
            if let Some(i) = (s..e).find(|&i| outside(self.inverse[i])) {
                return Err(invalid(format!(
                    "forest of bin {b}: texel {} at inverse[{i}] lies outside its leaf's region \
                     {region:?} (on the wrong side of a split)",
                    self.inverse[i]
                )));
            }
            return Ok(());
        }
        let at = *cursor;
        if at + 2 > self.nodes.len() || (x1 - x0) as u64 * (y1 - y0) as u64 <= 1 {
            return Err(invalid(format!(
                "forest of bin {b}: the node at {at} is beyond the array or splits a region of one texel"
            )));
        }
        let mid = self.nodes[at] as usize;
        if !(s..=e).contains(&mid) {
            return Err(invalid(format!(
                "forest[{at}] = {mid} outside its node's range [{s}, {e}]"
            )));
        }
        let along_x = x1 - x0 >= y1 - y0;
        let split = if along_x {
            x0 + (x1 - x0) / 2
        } else {
            y0 + (y1 - y0) / 2
        };
        let (left, right) = if along_x {
            ([x0, y0, split, y1], [split, y0, x1, y1])
        } else {
            ([x0, y0, x1, split], [x0, split, x1, y1])
        };
        *cursor += 2;
        self.node(b, s, mid, left, cursor)?;
        if self.nodes[at + 1] as usize != *cursor {
            return Err(invalid(format!(
                "forest[{}] = {} links the right child where the left subtree ends, at {}",
                at + 1,
                self.nodes[at + 1],
                *cursor
            )));
        }
        self.node(b, mid, e, right, cursor)
    }
}

#[cfg(test)]
mod tests;
