//! The two compiled copies of the per-query loops over lobe blocks: the crate's baseline target and,
//! on x86 CPUs that have it, AVX2 without FMA (bit-identical results). The copy is chosen once per
//! process ([`Simd::detected`]), held by each patch and applied once per query ([`dispatch`]),
//! above the loop over blocks.

/// Which compiled copy of the per-query block loops a patch runs: the crate's baseline target
/// (SSE2 on x86-64: 4 `f32` lanes per register; whatever the target has elsewhere) or, on x86 CPUs
/// that have it, AVX2 (8 `f32` lanes). The AVX2 copy is the same source compiled with
/// `#[target_feature(enable = "avx2")]` and **without FMA**: Rust never contracts `a * b + c` into a
/// fused multiply-add by itself, every operation stays an IEEE `f32`/`f64` operation in the same
/// order, so the two copies return bit-identical results (tested in
/// src/glint/mixture/dispatch_tests.rs). Enabling FMA would let the kernels use `mul_add` (one
/// rounding instead of two), which changes bits.
///
/// A value that says AVX2 exists only once `is_x86_feature_detected!("avx2")` returned true (the
/// field is private to this module): that is what makes the `unsafe` call in [`dispatch`] sound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Simd {
    avx2: bool,
}

impl Simd {
    /// The baseline copy (always available).
    pub const BASELINE: Simd = Simd { avx2: false };

    /// The best copy this CPU runs, detected once per process and cached: AVX2 where the CPU has it,
    /// unless the environment variable `BRDF_SIMD` is `baseline` when first asked (for comparisons
    /// and for ruling the dispatch out when chasing a bug); the baseline elsewhere.
    #[inline]
    pub fn detected() -> Simd {
        use std::sync::atomic::{AtomicU8, Ordering};
        // 0: not yet detected; 1: baseline; 2: AVX2.
        static CACHE: AtomicU8 = AtomicU8::new(0);
        match CACHE.load(Ordering::Relaxed) {
            1 => Simd::BASELINE,
            2 => Simd { avx2: true },
            _ => {
                let forced = std::env::var_os("BRDF_SIMD").is_some_and(|v| v == "baseline");
                let simd = if forced {
                    Simd::BASELINE
                } else {
                    Simd {
                        avx2: avx2_detected(),
                    }
                };
                CACHE.store(if simd.avx2 { 2 } else { 1 }, Ordering::Relaxed);
                simd
            }
        }
    }

    /// The copy's name: `"avx2"` or `"baseline"`.
    #[cfg(test)]
    pub fn name(self) -> &'static str {
        if self.avx2 { "avx2" } else { "baseline" }
    }
}

/// Whether the CPU runs AVX2 (never on other architectures).
fn avx2_detected() -> bool {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        false
    }
}

/// Marker of the instruction set a [`BlockPass`] is instantiated for. The type parameter only makes
/// the compiler emit one copy of the pass (and of the closures inside it) per instruction set, so
/// that the AVX2 copy, inlined whole into its `#[target_feature]` wrapper, shares no code with the
/// baseline copy.
pub(super) trait Isa {}
/// The baseline instruction set.
pub(super) enum BaselineIsa {}
/// AVX2 (without FMA).
#[cfg_attr(
    not(any(target_arch = "x86", target_arch = "x86_64")),
    allow(dead_code)
)]
pub(super) enum Avx2Isa {}
impl Isa for BaselineIsa {}
impl Isa for Avx2Isa {}

/// One per-query loop over lobe blocks (the walk and the lane kernels), written once and compiled
/// per instruction set. `run` must be `#[inline(always)]` and call only `#[inline]`/`#[inline(always)]`
/// code in its hot loop: a function compiled without AVX2 does not inline into one with it the
/// other way round, but the baseline-compiled walk would otherwise be called from the AVX2 copy.
pub(super) trait BlockPass {
    type Out;
    fn run<I: Isa>(self) -> Self::Out;
}

/// Runs `pass` in the copy `simd` selects. The choice sits above the loop over blocks (one branch per
/// query, not per block): a `#[target_feature]` function is not inlined into a caller without the
/// feature, so a kernel dispatched per block would cost a call per block.
#[inline(always)]
pub(super) fn dispatch<P: BlockPass>(simd: Simd, pass: P) -> P::Out {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    if simd.avx2 {
        // SAFETY: `simd.avx2` is true only in a `Simd` made by `Simd::detected`, after
        // `is_x86_feature_detected!("avx2")` returned true on this CPU (the field is private).
        return unsafe { run_avx2(pass) };
    }
    let _ = simd;
    pass.run::<BaselineIsa>()
}

/// `pass` compiled with AVX2 enabled (no FMA: bit-identical to the baseline, see [`Simd`]).
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
#[target_feature(enable = "avx2")]
fn run_avx2<P: BlockPass>(pass: P) -> P::Out {
    pass.run::<Avx2Isa>()
}
