//! Forged files, with valid checksums but contents no build writes (docs/format.md): inconsistent bin
//! maps, compact and full mixtures are each an `InvalidFile` naming what is wrong, and every re-sealed
//! byte change of a compact file loads to a total model or is refused (procedural glints:
//! `store_forged_procedural`). The patch options that format version 3 stored, whatever their
//! values, are read and ignored.
//!
//! The checksum used to forge the files is written from the format's documentation
//! (`support::format`), independently of the crate's code.

use crate::support;

use brdf::glint::binmap::BinMapParams;
use brdf::glint::{BinMap, Footprint, GlintNdf};
use brdf::ndf::Ndf;
use brdf::{Error, Vec2};
use support::format::reseal;
use support::store::{
    at, dirs, load_mixture, map, mixture_as_version_3, position_normal_as_version_3, saved,
    small_compact_file, small_mixture_file,
};

/// Offsets in a bin-map file: width 24, height 32, bins 40, leaf 48, sub-texels 56, lookup 64, σ 68,
/// 𝓑⁻¹ count 72, 𝓑⁻¹ 80.. (one u32 per sub-texel), then offsets (count, data), roots, forest,
/// moments. (𝓑 is not stored: the loader derives it from 𝓑⁻¹ and the offsets.)
#[test]
fn inconsistent_bin_maps_are_errors() {
    let n = 16;
    let params = BinMapParams {
        bins_per_axis: 5,
        leaf_size: 2,
        ..BinMapParams::default()
    };
    let built = BinMap::build(&map(n), params).unwrap();
    let file = saved(|w| built.save(w));
    let sub = built.subdivisions();
    assert_eq!(
        sub, 2,
        "the default sub-texel resolution the layout assumes"
    );
    let texels = (n * sub) * (n * sub);
    // Format versions 3 and 4: offsets, roots, forest, then 𝓑⁻¹ and 𝓑 (as u16: 25 bins).
    let layout = |file: &[u8]| {
        let offsets_at = 80;
        let roots_at = offsets_at + 4 * 26 + 8;
        let forest_at = roots_at + 4 * 25 + 8;
        let forest_len =
            u64::from_le_bytes(file[forest_at - 8..forest_at].try_into().unwrap()) as usize;
        let inverse_at = forest_at + 4 * forest_len + 8;
        let bin_map_at = inverse_at + 4 * texels + 8;
        (
            offsets_at, roots_at, forest_at, forest_len, inverse_at, bin_map_at,
        )
    };
    let (offsets_at, roots_at, forest_at, forest_len, inverse_at, bin_map_at) = layout(&file);
    assert_eq!(forest_len, built.forest().len(), "layout of the test");
    let u32_at = |f: &[u8], at: usize| u32::from_le_bytes(f[at..at + 4].try_into().unwrap());
    let with = |at: usize, v: u32| {
        let mut f = file.clone();
        f[at..at + 4].copy_from_slice(&v.to_le_bytes());
        reseal(f)
    };
    let with_u16 = |at: usize, v: u16| {
        let mut f = file.clone();
        f[at..at + 2].copy_from_slice(&v.to_le_bytes());
        reseal(f)
    };
    let swap = |a: usize, b: usize| {
        let mut f = file.clone();
        for k in 0..4 {
            f.swap(a + k, b + k);
        }
        reseal(f)
    };
    // Two texels of the same bin list swapped: still a permutation with the right bins, but the
    // forest's split no longer holds (the first tree's root splits x at 8: find a left and a right
    // texel of its list).
    let root_bin = (0..25)
        .find(|&b| built.bin_range(b).is_some_and(|r| r.2.is_some()))
        .unwrap();
    let (s, e, _) = built.bin_range(root_bin).unwrap();
    let mid = built.forest()[0] as usize;
    assert!(s < mid && mid < e);
    // A sub-texel given another bin by 𝓑 than the list that holds it.
    let pair_bin = (0..25).find(|&b| b != root_bin).unwrap();
    let k0 = built.texels_of_bin(root_bin)[0] as usize;
    let disagree =
        format!("is in the list of bin {root_bin} but the bin map gives it bin Some({pair_bin})");
    let not_a_bin = format!("bin map[{k0}] = 25 is not a bin");
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "sub-texel beyond the grid",
            with(inverse_at, texels as u32),
            "outside its leaf's region",
        ),
        (
            "bin map disagreeing with the lists",
            with_u16(bin_map_at + 2 * k0, pair_bin as u16),
            &disagree,
        ),
        (
            "bin map value beyond the bins",
            with_u16(bin_map_at + 2 * k0, 25),
            &not_a_bin,
        ),
        (
            "offsets decreasing",
            with(offsets_at + 4, texels as u32 + 5),
            "must not decrease",
        ),
        (
            "offsets not ending at the sub-texel count",
            with(offsets_at + 4 * 25, texels as u32 - 1),
            "offsets run from",
        ),
        (
            "inverse not a permutation",
            with(inverse_at + 4, u32_at(&file, inverse_at)),
            "inverse",
        ),
        (
            "texel on the wrong side",
            swap(inverse_at + 4 * s, inverse_at + 4 * (e - 1)),
            "wrong side",
        ),
        (
            "root not at the layout's place",
            with(roots_at + 4 * root_bin, 2),
            "roots",
        ),
        (
            "mid outside the range",
            with(forest_at, (e + 1) as u32),
            "outside",
        ),
        ("right link broken", with(forest_at + 4, 0), "right child"),
    ];
    for (name, f, needle) in cases {
        let e = BinMap::load(&mut f.as_slice()).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains(needle),
            "{name}: {e}"
        );
    }
    // A sub-texel repeated (in place of another) within a list too short for a tree: its region is
    // the whole map and 𝓑 is untouched, so only the fingerprint of 𝓑 against 𝓑⁻¹ sees it.
    let params = BinMapParams {
        leaf_size: 64,
        ..params
    };
    let built = BinMap::build(&map(n), params).unwrap();
    let mut f = saved(|w| built.save(w));
    let inverse_at = layout(&f).4;
    let b = (0..25)
        .find(|&b| {
            built
                .bin_range(b)
                .is_some_and(|r| r.2.is_none() && r.1 - r.0 >= 2)
        })
        .unwrap();
    let (s, _, _) = built.bin_range(b).unwrap();
    let first = u32_at(&f, inverse_at + 4 * s);
    f[inverse_at + 4 * (s + 1)..inverse_at + 4 * (s + 2)].copy_from_slice(&first.to_le_bytes());
    let e = BinMap::load(&mut reseal(f).as_slice()).unwrap_err();
    assert!(
        e.to_string().contains(&format!(
            "inverse[{}] = {first} is out of range or repeated",
            s + 1
        )),
        "{e}"
    );
}

/// Offsets in the compact mixture file of a 6² map (docs/format.md, kind 5; lobe grid 6², levels of
/// detail 6² and 3²; format versions 5 and 6): the parameters as kind 2 up to 72, level count 72; level 0:
/// frame count 80, 4 frames 88..152, block count 152, 4 blocks 160..800, error count 800 (0); level
/// 1: frame count 808, 1 frame 816..832, block count 832, 1 block 840..1000, error count 1000, 9
/// codes 1008..1017.
mod compact_at {
    pub const LEVELS: usize = 72;
    pub const FRAME0: usize = 88;
    pub const BLOCK0: usize = 160;
    pub const ERROR_COUNT1: usize = 1000;
    pub const END: usize = 1017;
}

/// Compact files whose checksums are valid but whose contents no build writes: each an
/// `InvalidFile` naming what is wrong (before any model is made).
#[test]
fn inconsistent_compact_contents_are_errors() {
    let file = small_compact_file();
    assert_eq!(
        file.len(),
        compact_at::END + 8,
        "the layout the offsets assume"
    );
    let f32_at = |f: &[u8], at: usize| f32::from_le_bytes(f[at..at + 4].try_into().unwrap());
    let with = |at: usize, bytes: &[u8]| {
        let mut f = file.clone();
        f[at..at + bytes.len()].copy_from_slice(bytes);
        reseal(f)
    };
    let (lo, hi) = (
        f32_at(&file, compact_at::FRAME0),
        f32_at(&file, compact_at::FRAME0 + 8),
    );
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "level count",
            with(compact_at::LEVELS, &3u64.to_le_bytes()),
            "levels = 3",
        ),
        (
            "error count",
            with(compact_at::ERROR_COUNT1, &8u64.to_le_bytes()),
            "errors holds 8",
        ),
        // J₁₁ of lane 0 (words 32.. of the block) = +0 or +∞ in binary16.
        (
            "J zero",
            with(compact_at::BLOCK0 + 64, &0u16.to_le_bytes()),
            "J =",
        ),
        (
            "J infinite",
            with(compact_at::BLOCK0 + 64, &0x7C00u16.to_le_bytes()),
            "J =",
        ),
        (
            "frame reversed",
            with(compact_at::FRAME0, &(hi + 1.0).to_le_bytes()),
            "lo > hi",
        ),
        (
            "frame shrunk",
            with(compact_at::FRAME0, &(0.5 * (lo + hi)).to_le_bytes()),
            "outside its block's box",
        ),
        (
            "frame huge",
            with(compact_at::FRAME0, &(-1e30f32).to_le_bytes()),
            "frames",
        ),
    ];
    for (name, f, needle) in cases {
        let e = load_mixture(&f).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains(needle),
            "{name}: {e}"
        );
    }
}

/// Every single-byte change of a small compact file, re-sealed (so the checksum passes): the loader
/// returns an error or a mixture whose queries are total (finite, non-negative `d` and pdfs, unit
/// upper-hemisphere samples) — never a panic. A changed mean code or binary16 J that stays valid is a
/// legitimate different model; everything else must be refused.
#[test]
fn resealed_compact_byte_changes_load_to_total_models_or_errors() {
    let file = small_compact_file();
    let (mut ok, mut refused) = (0, 0);
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 9.0, 6, 6);
    for k in 24..file.len() - 8 {
        let mut f = file.clone();
        f[k] ^= 0x5A;
        let Ok(mix) = load_mixture(&reseal(f)) else {
            refused += 1;
            continue;
        };
        ok += 1;
        let p = mix.patch(&fp);
        for w in dirs() {
            let d = p.d(w);
            assert!(d.is_finite() && d >= 0.0, "byte {k}: d({w}) = {d}");
            let l = p.lambda(w);
            assert!(l.is_finite() && l >= 0.0, "byte {k}: lambda({w}) = {l}");
            let m = p.sample_visible(w, Vec2::new(0.3, 0.8));
            assert!(
                m.is_finite() && (m.length() - 1.0).abs() < 1e-3 && m.z >= 0.0,
                "byte {k}: sample {m}"
            );
            let q = p.pdf_visible(w, m);
            assert!(q.is_finite() && q >= 0.0, "byte {k}: pdf {q}");
        }
    }
    println!("{ok} changed files loaded (all total), {refused} refused");
    assert!(ok > 0 && refused > 0);
}

#[test]
fn inconsistent_contents_with_valid_checksums_are_errors() {
    let file = small_mixture_file();
    let set =
        |f: &mut Vec<u8>, at: usize, bytes: &[u8]| f[at..at + bytes.len()].copy_from_slice(bytes);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "lobe count off by one",
            {
                let mut f = file.clone();
                set(&mut f, at::LOBE_COUNT, &35u64.to_le_bytes());
                f
            },
            "lobes",
        ),
        (
            "width changes the grid",
            {
                let mut f = file.clone();
                set(&mut f, at::WIDTH, &7u64.to_le_bytes());
                f
            },
            "lobes",
        ),
        (
            "zero width",
            {
                let mut f = file.clone();
                set(&mut f, at::WIDTH, &0u64.to_le_bytes());
                f
            },
            "map size",
        ),
        (
            "spacing below MIN_SPACING",
            {
                let mut f = file.clone();
                set(&mut f, at::SPACING, &0.01f32.to_le_bytes());
                f
            },
            "spacing",
        ),
        (
            "unknown seed kernel",
            {
                let mut f = file.clone();
                set(&mut f, at::SEED, &2u32.to_le_bytes());
                f
            },
            "seed kernel",
        ),
        (
            "NaN moment",
            {
                let mut f = file.clone();
                set(&mut f, at::LOBES + 8, &f32::NAN.to_le_bytes());
                f
            },
            "lobes[0][2]",
        ),
        (
            "negative second moment",
            {
                let mut f = file.clone();
                set(&mut f, at::LOBES + 20 * 3 + 12, &(-1.0f32).to_le_bytes());
                f
            },
            "lobes[3][3]",
        ),
        (
            "huge mean",
            {
                let mut f = file.clone();
                set(&mut f, at::LOBES, &1e30f32.to_le_bytes());
                f
            },
            "lobes[0][0]",
        ),
        // Version 3: one level of merge errors (6² lobes → 3² nodes) after the 36 lobes.
        (
            "level count",
            {
                let mut f = file.clone();
                set(&mut f, at::LEVELS, &2u64.to_le_bytes());
                f
            },
            "levels = 2 but the lobe grid 6×6 has 1",
        ),
        (
            "merge error above 1",
            {
                let mut f = file.clone();
                set(&mut f, at::ERRORS + 12 * 4 + 8, &1.5f32.to_le_bytes());
                f
            },
            "merge errors[4][2]",
        ),
        (
            "NaN merge error",
            {
                let mut f = file.clone();
                set(&mut f, at::ERRORS, &f32::NAN.to_le_bytes());
                f
            },
            "merge errors[0][0]",
        ),
        (
            "negative merge error",
            {
                let mut f = file.clone();
                set(&mut f, at::ERRORS + 12 * 8 + 4, &(-1e-3f32).to_le_bytes());
                f
            },
            "merge errors[8][1]",
        ),
    ];
    for (name, f, needle) in cases {
        let e = load_mixture(&reseal(f)).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains(needle),
            "{name}: {e}"
        );
    }
    // The payload length declaring more than the fields hold.
    let mut f = file.clone();
    let declared = u64::from_le_bytes(f[16..24].try_into().unwrap());
    f[16..24].copy_from_slice(&(declared + 8).to_le_bytes());
    let n = f.len() - 8;
    f.splice(n..n, [0u8; 8]);
    let e = load_mixture(&reseal(f)).unwrap_err();
    assert!(
        matches!(e, Error::InvalidFile { .. }) && e.to_string().contains("payload"),
        "{e}"
    );
}

/// Format version 3 stored patch options (the mixture's masking mode and cost cap, the
/// position-normal map's footprint cap). Options are per query, so a version-3 file loads whatever
/// those fields hold (values no build wrote included) and answers exactly as the version-4 file:
/// its default patch is the default patch, bit for bit.
#[test]
fn version_3_option_fields_are_read_and_ignored() {
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 9.0, 6, 6);
    let answers = |p: &dyn Ndf| -> Vec<u32> {
        dirs()
            .iter()
            .flat_map(|&w| [p.d(w), p.lambda(w), p.projected_area(w)])
            .map(f32::to_bits)
            .collect()
    };
    for file in [small_mixture_file(), small_compact_file()] {
        let now = load_mixture(&file).unwrap();
        for (masking, lod_lobes) in [(1u32, 0.0f32), (7, f32::NAN), (0, -1.0)] {
            let forged = mixture_as_version_3(&file, masking, lod_lobes);
            let old =
                load_mixture(&forged).unwrap_or_else(|e| panic!("{masking} {lod_lobes}: {e}"));
            assert_eq!(
                answers(&old.patch(&fp)),
                answers(&now.patch(&fp)),
                "masking {masking}, lod_lobes {lod_lobes}"
            );
        }
    }
    let pn = brdf::glint::PositionNormalMap::build(&map(6), Default::default()).unwrap();
    let file = saved(|w| pn.save(w));
    for cap in [1.0f32, 0.0, f32::NAN] {
        let forged = position_normal_as_version_3(&file, cap);
        let old = brdf::glint::PositionNormalMap::load(&mut forged.as_slice()).unwrap();
        assert_eq!(
            answers(&old.patch(&fp)),
            answers(&pn.patch(&fp)),
            "max_query_texels {cap}"
        );
    }
}

/// A stored filtered mixture that no build writes, with a valid checksum, is refused with what is
/// wrong: a node whose weights do not sum to 1, a level count (2⁶⁴ − 1 included) or an error count
/// that does not match the chain, an error that is not a total variation (docs/format.md, "The filtered mixture
/// in a file").
#[test]
fn inconsistent_filtered_mixtures_are_errors() {
    use brdf::glint::PositionNormalMap;
    let pn = PositionNormalMap::build(&map(8), Default::default()).unwrap();
    let file = saved(|w| pn.save(w));
    let load = |f: Vec<u8>| PositionNormalMap::load(&mut reseal(f).as_slice()).unwrap_err();
    let word = |f: &[u8], at: usize| u64::from_le_bytes(f[at..at + 8].try_into().unwrap());
    // Header 24, size and rate 24, three f32, the element count and 64 elements of 24 bytes; then
    // the level count, level 1's node count and its first node (weight first).
    let chain = 24 + 24 + 12 + 8 + 64 * 24;
    assert_eq!(
        word(&file, chain),
        3,
        "levels 4², 2², 1² above the 8² elements"
    );
    let node = chain + 16;
    let mut f = file.clone();
    let w = f32::from_le_bytes(f[node..node + 4].try_into().unwrap());
    f[node..node + 4].copy_from_slice(&(0.5 * w).to_le_bytes());
    let e = load(f);
    assert!(e.to_string().contains("weights sum to"), "{e}");
    // One level fewer than the grid has.
    let mut f = file.clone();
    f[chain..chain + 8].copy_from_slice(&2u64.to_le_bytes());
    let e = load(f);
    assert!(e.to_string().contains("filtered-mixture levels = 2"), "{e}");
    // A level count of 2⁶⁴ − 1 (found by fuzzing: `n + 1` overflowed, a panic in debug builds).
    let mut f = file.clone();
    f[chain..chain + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    let e = load(f);
    assert!(e.to_string().contains("filtered-mixture levels ="), "{e}");
    // The errors end the payload: their count (one per level of the chain, 4 here) and values.
    let count = file.len() - 8 - 4 * 4 - 8;
    assert_eq!(word(&file, count), 4);
    let mut f = file.clone();
    let last = file.len() - 8 - 4;
    f[last..last + 4].copy_from_slice(&1.5f32.to_le_bytes());
    let e = load(f);
    assert!(e.to_string().contains("not a total variation"), "{e}");
    // Three errors for a chain of four levels.
    let mut f = file[..count].to_vec();
    f.extend_from_slice(&3u64.to_le_bytes());
    f.extend_from_slice(&file[count + 8..count + 8 + 12]);
    f.extend_from_slice(&[0u8; 8]);
    let payload = word(&f, 16) - 4;
    f[16..24].copy_from_slice(&payload.to_le_bytes());
    let e = load(f);
    assert!(e.to_string().contains("3 filtered-mixture errors"), "{e}");
}
