//! Do the headline figures the docs state still hold? The Beckmann mixture's bytes per texel, full and
//! compact storage, measured by `memory()` at the documented map size and compared with the table
//! of docs/results.md ("Memory per model") and with the copies of the full-storage figure in the
//! README, the crate docs (src/lib.rs) and the results' summary. (The "which model" guide's drift
//! check is `python3 tools/orb_which.py --check`, in CI.)

use brdf::glint::mixture::{LobeStorage, MixtureParams};
use brdf::glint::{self, BeckmannMixture};

/// A file of the repository as text.
fn read(path: &str) -> String {
    let full = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("{full}: {e}"))
}

/// A file's prose as one line: each line without its `//!` marker and indentation, joined by one
/// space (so that a phrase wrapped across lines is still found).
fn prose(path: &str) -> String {
    read(path)
        .lines()
        .map(|l| l.trim_start().trim_start_matches("//!").trim())
        .collect::<Vec<_>>()
        .join(" ")
}

/// The bold figure of the "Memory per model" row that starts with `row`.
fn memory_table_figure(results: &str, row: &str) -> f64 {
    let section = results
        .split("\n## Memory per model\n")
        .nth(1)
        .expect("docs/results.md has a \"Memory per model\" section");
    let line = section
        .lines()
        .find(|l| l.starts_with(row))
        .unwrap_or_else(|| panic!("no row {row:?} in \"Memory per model\""));
    let bold = line
        .split("**")
        .nth(1)
        .unwrap_or_else(|| panic!("no bold figure in {line:?}"));
    bold.parse()
        .unwrap_or_else(|_| panic!("{bold:?} is not a number"))
}

/// Bytes per texel of a default mixture of `storage` on the bumpy map at `n`².
fn bytes_per_texel(n: usize, storage: LobeStorage) -> f64 {
    let map = glint::bumpy(n, n, 0.25, 4.0, 1).unwrap();
    let params = MixtureParams {
        storage,
        ..MixtureParams::default()
    };
    let m = BeckmannMixture::build(&map, params).unwrap().memory();
    m.total() as f64 / (n * n) as f64
}

/// The table gives one decimal; the measured figure must round to it (the byte counts are exact, so
/// the only tolerance is the rounding). 512² is a size the docs state the figures at (512²-2048²:
/// the bytes per lobe do not depend on the size when the lobe grid halves down to 1 × 1).
#[test]
fn mixture_bytes_per_texel_match_the_docs() {
    let results = read("docs/results.md");
    let full = bytes_per_texel(512, LobeStorage::Full);
    let compact = bytes_per_texel(512, LobeStorage::Compact);
    println!("512²: full {full:.2} B/texel, compact {compact:.2} B/texel");
    for (row, measured) in [
        ("| Beckmann mixture, `LobeStorage::Full` (default) |", full),
        ("| Beckmann mixture, `LobeStorage::Compact` |", compact),
    ] {
        let stated = memory_table_figure(&results, row);
        assert!(
            (measured - stated).abs() <= 0.05 + 1e-9,
            "docs/results.md {row}: states {stated}, memory() gives {measured:.3}"
        );
    }
    // The copies of the headline figure, as each file words it.
    let copies = [
        ("README.md", format!("instead of ~{full:.0}")),
        ("src/lib.rs", format!("the mixture holds {full:.0} B/texel")),
        (
            "src/lib.rs",
            format!("{compact:.1} B/texel with `LobeStorage::Compact`"),
        ),
        (
            "docs/results.md",
            format!("mixture {full:.1} B ({compact:.1} B compact)"),
        ),
        ("docs/mixture.md", format!("{full:.1} B per lobe in all")),
    ];
    for (file, phrase) in copies {
        assert!(
            prose(file).contains(&phrase),
            "{file} no longer says {phrase:?} (memory() at 512² gives {full:.2} / {compact:.2} B/texel)"
        );
    }
}

/// The crate docs' guide states the mixture's default choices in words; they are the `DEFAULT_*`
/// constants.
#[test]
fn crate_guide_states_the_mixture_defaults() {
    use brdf::glint::mixture::{
        DEFAULT_CUT_AREA, DEFAULT_CUT_NODES, DEFAULT_FILTERED_AREA, DEFAULT_FILTERED_TOLERANCE,
        DEFAULT_LOD_TOLERANCE, DEFAULT_MASKING, DEFAULT_SUB_TEXEL_AREA, MaskingMode,
    };
    assert_eq!(DEFAULT_MASKING, MaskingMode::Exact);
    // Written with a thousands separator, as the docs write counts of texels.
    let thousands = |area: f32| {
        let area = area as u32;
        if area >= 1000 {
            format!("{},{:03}", area / 1000, area % 1000)
        } else {
            area.to_string()
        }
    };
    let area = thousands(DEFAULT_FILTERED_AREA);
    let phrases = [
        "exact masking by default".to_string(),
        format!("a sub-texel lobe below {DEFAULT_SUB_TEXEL_AREA} texels"),
        format!("a TV budget of {DEFAULT_LOD_TOLERANCE}"),
        format!("from {area} texels"),
        format!("within {DEFAULT_FILTERED_TOLERANCE} TV of the full mixture"),
        format!(
            "from {} texels a cut of at most {DEFAULT_CUT_NODES}",
            thousands(DEFAULT_CUT_AREA)
        ),
    ];
    let lib = prose("src/lib.rs");
    for phrase in phrases {
        assert!(
            lib.contains(&phrase),
            "src/lib.rs no longer says {phrase:?}"
        );
    }
}
