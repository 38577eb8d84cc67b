//! The "table" mode shared by `benches/ndf.rs` and `benches/fresnel.rs`: the inputs and the timing
//! loop of the C++ comparison harness (`benches/cpp/analytic.cpp`), written the same way on both
//! sides so that the two columns of the table in docs/results.md time the same thing.
//!
//! Inputs come from SplitMix64 (identical on both sides; each side prints a hash of its inputs so
//! that the identity can be checked). A batch is 1024 independent calls, each input passed through
//! a register-only optimisation barrier on each component ([`opaque`]) and each result stored; the
//! figure is the wall time of one batch / 1024, and a row reports the minimum and the median over
//! `ROUNDS × BATCHES` batches (after 200 warm-up batches).
//!
//! Batch k takes the k-th (mod `POOL`) block of 1024 inputs from a pool of `POOL × 1024`
//! (`BRDF_TABLE_POOL`, default 16): a renderer's directions never repeat, but a batch that repeats
//! the same 1024 inputs lets the branch predictor learn the outcome of every data-dependent branch
//! (pbrt-v4's dielectric Fresnel, which branches on the side of the interface, ran at 3.9 ns per
//! call on one repeated block and 9.1 ns on 16 blocks; branch-free code is unaffected). `POOL = 1`
//! gives the measure of the earlier tables.

#![allow(dead_code)] // each bench uses part of it

use glam::{Vec2, Vec3};
use std::time::Instant;

pub const N: usize = 1024;

/// Blocks of N inputs in the pool (`BRDF_TABLE_POOL`, default 16; see the module comment).
pub fn pool() -> usize {
    std::env::var("BRDF_TABLE_POOL")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&p: &usize| p > 0)
        .unwrap_or(16)
}

pub struct SplitMix(pub u64);

impl SplitMix {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn f(&mut self) -> f32 {
        (self.next() >> 40) as f32 * (1.0 / 16_777_216.0)
    }
}

pub struct Inputs {
    /// Cosine-distributed directions (a renderer's wo).
    pub w: Vec<Vec3>,
    /// normalize(α w_x, α w_y, w_z): normals inside the lobe, visible from the paired w.
    pub m: Vec<Vec3>,
    pub u: Vec<Vec2>,
    /// Uniform in [−1, 1) (dielectric: both sides of the interface).
    pub cos_signed: Vec<f32>,
    /// Uniform in [0, 1) (conductor).
    pub cos_unit: Vec<f32>,
}

/// `pool() × N` inputs of each kind, in the C++ harness's order.
pub fn inputs(alpha: f32) -> Inputs {
    let n = pool() * N;
    let mut rng = SplitMix(1);
    let w: Vec<Vec3> = (0..n)
        .map(|_| {
            let (a, b) = (rng.f(), rng.f());
            let (r, phi) = (a.sqrt(), 6.283_185_5f32 * b);
            Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - a).max(1e-6).sqrt())
        })
        .collect();
    let m = w
        .iter()
        .map(|v| {
            let s = Vec3::new(alpha * v.x, alpha * v.y, v.z);
            s * (1.0 / s.dot(s).sqrt())
        })
        .collect();
    let u = (0..n)
        .map(|_| {
            let a = rng.f();
            Vec2::new(a, rng.f())
        })
        .collect();
    let cos_signed = (0..n).map(|_| 2.0 * rng.f() - 1.0).collect();
    let cos_unit = (0..n).map(|_| rng.f()).collect();
    Inputs {
        w,
        m,
        u,
        cos_signed,
        cos_unit,
    }
}

/// FNV-1a over the bits of every input, in the C++ harness's order.
pub fn hash(inp: &Inputs) -> u64 {
    let mut h = 1_469_598_103_934_665_603u64;
    let mut mix = |v: f32| h = (h ^ v.to_bits() as u64).wrapping_mul(1_099_511_628_211);
    for i in 0..inp.w.len() {
        let (w, m, u) = (inp.w[i], inp.m[i], inp.u[i]);
        for v in [w.x, w.y, w.z, m.x, m.y, m.z, u.x, u.y] {
            mix(v);
        }
        mix(inp.cos_signed[i]);
        mix(inp.cos_unit[i]);
    }
    h
}

/// An optimisation barrier on one `f32` that costs nothing: an empty `asm!` that takes and returns
/// the value in an SSE register (no memory clobber, unlike `black_box`, whose store/reload per call
/// and whose clobber of all memory change the code under test, and differently in LLVM and GCC).
/// It stops the compiler from vectorising across calls or hoisting work out of the loop. The C++
/// harness uses the same asm (`asm volatile("" : "+x"(v))`). Elsewhere than x86-64: `black_box`.
#[inline(always)]
pub fn opaque(x: f32) -> f32 {
    #[cfg(target_arch = "x86_64")]
    {
        let mut x = x;
        // SAFETY: an empty asm block; it reads and writes only the register holding x.
        unsafe {
            std::arch::asm!("/* {0} */", inout(xmm_reg) x, options(nomem, nostack, preserves_flags));
        }
        x
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        std::hint::black_box(x)
    }
}

/// [`opaque`] on each component of a `Vec3`.
#[inline(always)]
pub fn bb3(v: Vec3) -> Vec3 {
    Vec3::new(opaque(v.x), opaque(v.y), opaque(v.z))
}

/// [`opaque`] on each component of a `Vec2`.
#[inline(always)]
pub fn bb2(v: Vec2) -> Vec2 {
    Vec2::new(opaque(v.x), opaque(v.y))
}

/// Rounds and batches per row: `BRDF_TABLE_ROUNDS`, `BRDF_TABLE_BATCHES` (default 5 × 1000).
pub fn settings() -> (usize, usize) {
    let get = |k: &str, d: usize| {
        std::env::var(k)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(d)
    };
    (get("BRDF_TABLE_ROUNDS", 5), get("BRDF_TABLE_BATCHES", 1000))
}

/// Times `batch` (one batch of N calls on the inputs `[k, k + N)`, k = N × (batch index mod
/// `pool()`)) and prints `name variant alpha min median` in ns per call.
pub fn time_it(name: &str, alpha: f32, mut batch: impl FnMut(std::ops::Range<usize>)) {
    let (rounds, batches) = settings();
    let pool = pool();
    let block = |b: usize| (b % pool) * N..(b % pool) * N + N;
    for b in 0..200 {
        batch(block(b));
    }
    let mut ns = Vec::with_capacity(rounds * batches);
    for b in 0..rounds * batches {
        let r = block(b);
        let t0 = Instant::now();
        batch(r);
        ns.push(t0.elapsed().as_nanos() as f64 / N as f64);
    }
    ns.sort_by(f64::total_cmp);
    println!(
        "{name:<24} {:<8} {alpha:5.3} {:8.2} {:8.2}",
        "crate",
        ns[0],
        ns[ns.len() / 2]
    );
}
