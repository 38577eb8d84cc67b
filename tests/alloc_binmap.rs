//! No heap allocation per shading point for the bin map (issue 13, item 5): after one warm-up call,
//! `BinMap::patch_in` (and `patch_smoothed_in`) with a reused `BinMapScratch`, and every `Ndf`
//! method of the patch, allocate nothing.
//!
//! A counting global allocator (this file is its own test binary, so it disturbs no other test)
//! counts the allocations made by the current thread only (a `const` thread-local, which itself
//! never allocates), so the test harness's other threads do not interfere.

use brdf::glint::{BinMap, BinMapParams, BinMapScratch, Footprint, bumpy};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

/// Every per-shading-point call on a patch; returns a sum so nothing is optimised away (not
/// necessarily finite: Λ is `f32::MAX` for a patch leaning away from wo).
fn shade(patch: &impl Ndf) -> f32 {
    let mut acc = 0.0;
    for k in 0..16 {
        let u = Vec2::new((k as f32 + 0.5) / 16.0, ((k * 7) % 16) as f32 / 16.0 + 0.01);
        let t = (k as f32 / 16.0) * 1.55;
        let wo = Vec3::new(t.sin() * 0.8, t.sin() * 0.6, t.cos()).normalize();
        let h = patch.sample_visible(wo, u);
        let m = patch.sample_normal(u);
        acc += patch.d(h) + patch.d(m);
        acc += patch.lambda(wo) + patch.projected_area(wo) + patch.visible_area(wo);
        acc += patch.pdf_visible(wo, h) + patch.pdf_normal(m);
        acc += patch.g2_height_correlated(wo, h, h);
    }
    acc
}

#[test]
fn patch_in_and_its_ndf_calls_allocate_nothing_after_warm_up() {
    let map = bumpy(128, 128, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let mut scratch = BinMapScratch::default();
    // Footprints from sub-texel to above the exact-masking limit (4096 texels), one crossing the
    // border (several periodic images).
    let footprints: Vec<Footprint> = [
        (Vec2::new(0.4, 0.6), 0.5),
        (Vec2::new(0.4, 0.6), 64.0),
        (Vec2::new(0.99, 0.01), 1000.0),
        (Vec2::new(0.5, 0.5), 3000.0),
        (Vec2::new(0.5, 0.5), 8192.0),
    ]
    .iter()
    .map(|&(c, a)| Footprint::isotropic_texels(c, a, 128, 128))
    .collect();
    // Warm-up: one call per footprint grows the scratch to the largest.
    let mut sink = 0.0;
    for fp in &footprints {
        sink += shade(&bm.patch_in(fp, &mut scratch));
        sink += shade(&bm.patch_smoothed_in(fp, 0.05, &mut scratch));
    }
    let before = allocations();
    for fp in &footprints {
        sink += shade(&bm.patch_in(fp, &mut scratch));
        sink += shade(&bm.patch_smoothed_in(fp, 0.05, &mut scratch));
    }
    let after = allocations();
    std::hint::black_box(sink);
    assert_eq!(after - before, 0, "allocations after warm-up");
    // The counter works: the allocating path is seen.
    let before = allocations();
    sink += shade(&bm.patch(&footprints[1]));
    assert!(
        allocations() > before,
        "the counter missed patch()'s allocations"
    );
    std::hint::black_box(sink);
}

#[test]
fn patch_in_equals_patch() {
    let map = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let mut scratch = BinMapScratch::default();
    for area in [1.0f32, 100.0, 5000.0] {
        let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.7), area, 64, 64);
        let owned = bm.patch(&fp);
        let borrowed = bm.patch_in(&fp, &mut scratch);
        for k in 0..64 {
            let u = Vec2::new((k as f32 + 0.5) / 64.0, 0.37);
            let wo = Vec3::new(0.5, -0.3, 0.2 + k as f32 / 64.0).normalize();
            let h = owned.sample_visible(wo, u);
            assert_eq!(h, borrowed.sample_visible(wo, u));
            assert_eq!(owned.d(h), borrowed.d(h));
            assert_eq!(owned.visible_area(wo), borrowed.visible_area(wo));
            assert_eq!(owned.pdf_visible(wo, h), borrowed.pdf_visible(wo, h));
        }
    }
}
