//! A file that declares far more data than it holds costs at most about what it holds: the loaders
//! allocate as data arrive (64 KiB steps), never from the declared sizes.
//!
//! Its own test binary because it measures the heap with a counting global allocator (one test, so
//! no other thread allocates meanwhile).

use brdf::Error;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::{BeckmannMixture, NormalMap};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
            PEAK.fetch_max(now, Ordering::SeqCst);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        CURRENT.fetch_sub(layout.size(), Ordering::SeqCst);
    }
}

#[global_allocator]
static A: Counting = Counting;

/// The documented checksum (docs/format.md), shared with tests/it/store_*.rs.
#[path = "it/support/format.rs"]
mod format;
use format::reseal;

/// Peak heap growth (bytes) while running `f`.
fn peak_during<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = CURRENT.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    let out = f();
    (out, PEAK.load(Ordering::SeqCst) - base)
}

#[test]
fn lying_sizes_allocate_no_more_than_the_file_holds() {
    let map = NormalMap::from_slopes(4, 4, vec![brdf::Vec2::new(0.1, -0.2); 16]).unwrap();
    let params = MixtureParams {
        samples: 4,
        ..MixtureParams::default()
    };
    let mut file = Vec::new();
    BeckmannMixture::build(&map, params)
        .unwrap()
        .save(&mut file)
        .unwrap();
    // Format version 6 (docs/format.md: lobe count at 72, lobes at 80, as in version 5). Declare a 40000² map (1.6·10⁹
    // lobes, 32 GB) and a payload that claims it all; keep 1 MiB of
    // real lobe data (zeros are valid moments) so that the loader reads some before running out.
    file[24..32].copy_from_slice(&40000u64.to_le_bytes());
    file[32..40].copy_from_slice(&40000u64.to_le_bytes());
    file[72..80].copy_from_slice(&1_600_000_000u64.to_le_bytes());
    file[16..24].copy_from_slice(&(56 + 32_000_000_000u64).to_le_bytes());
    file.truncate(80);
    file.resize(80 + (1 << 20) + 8, 0);
    let file = reseal(file);
    let (r, peak) = peak_during(|| BeckmannMixture::load(&mut file.as_slice()));
    assert!(
        matches!(r, Err(Error::Truncated { what: "lobes" })),
        "{r:?}"
    );
    // At most what was read (1 MiB) plus one 64 KiB chunk, times 2 for Vec's doubling growth.
    assert!(
        peak <= 2 * ((1 << 20) + (1 << 16)) + 4096,
        "peak {peak} bytes"
    );

    // A compact mixture (model kind 5) declaring a 32768² map: its level 0 needs 8192² frames
    // (1 GiB) and then 8192² blocks (10 GiB); 1 MiB of frames is present.
    let params = MixtureParams {
        storage: brdf::glint::mixture::LobeStorage::Compact,
        ..params
    };
    let mut file = Vec::new();
    BeckmannMixture::build(&map, params)
        .unwrap()
        .save(&mut file)
        .unwrap();
    assert_eq!(&file[12..16], &5u32.to_le_bytes());
    file[24..32].copy_from_slice(&32768u64.to_le_bytes());
    file[32..40].copy_from_slice(&32768u64.to_le_bytes());
    // Levels 32768², 16384², …, 1²: 16.
    file[72..80].copy_from_slice(&16u64.to_le_bytes());
    file[80..88].copy_from_slice(&(8192u64 * 8192).to_le_bytes());
    file[16..24].copy_from_slice(&(64 + 12_000_000_000u64).to_le_bytes());
    file.truncate(88);
    file.resize(88 + (1 << 20) + 8, 0);
    let file = reseal(file);
    let (r, peak) = peak_during(|| BeckmannMixture::load(&mut file.as_slice()));
    assert!(
        matches!(r, Err(Error::Truncated { what: "frames" })),
        "{r:?}"
    );
    assert!(
        peak <= 2 * ((1 << 20) + (1 << 16)) + 4096,
        "peak {peak} bytes"
    );

    // A normal map header declaring 2^30 × 2 texels (16 GiB of slopes) with nothing behind it.
    let mut nm = Vec::new();
    map.save(&mut nm).unwrap();
    nm[24..32].copy_from_slice(&(1u64 << 30).to_le_bytes());
    nm[32..40].copy_from_slice(&2u64.to_le_bytes());
    nm[40..48].copy_from_slice(&(1u64 << 31).to_le_bytes());
    nm[16..24].copy_from_slice(&(24 + (1u64 << 34)).to_le_bytes());
    let (r, peak) = peak_during(|| NormalMap::load(&mut reseal(nm).as_slice()));
    assert!(matches!(r, Err(Error::Truncated { .. })), "{r:?}");
    assert!(peak <= 4 * (1 << 16) + 4096, "peak {peak} bytes");
}
