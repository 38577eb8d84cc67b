//! A randomised multiset fingerprint: is one list of integers a rearrangement of another, checked with
//! sequential reads only.
//!
//! Two multisets {a_i} and {b_i} of integers below p = 2⁶¹ − 1 are compared through the polynomials
//! A(z) = Π (z − a_i) and B(z) = Π (z − b_i) over the field GF(p), evaluated at one point z drawn at
//! random. Equal multisets give equal products at every z. Different multisets make A − B a non-zero
//! polynomial of degree at most n (the element count), which has at most n roots, so the products
//! agree with probability at most n / p over the draw of z (the Schwartz–Zippel lemma; the classic
//! polynomial fingerprint for multiset equality). For 2³² elements that is below 2⁻²⁹, for the 1.7·10⁷
//! sub-texels of a 2048² bin map below 2⁻³⁷. The point is drawn afresh by every check from the
//! standard library's per-process random hashing keys, so a file cannot be crafted against it.
//!
//! Used by the bin map's loader to check that its stored 𝓑 and 𝓑⁻¹ describe the same assignment of
//! sub-texels to bins without a random access per sub-texel (src/glint/binmap/store.rs).

use std::hash::{BuildHasher, RandomState};

/// The Mersenne prime 2⁶¹ − 1.
pub(crate) const P: u64 = (1 << 61) - 1;

/// a · b mod p for a, b < p: the 122-bit product folded once at bit 61 (2⁶¹ ≡ 1 mod p).
#[inline(always)]
fn mul_mod(a: u64, b: u64) -> u64 {
    let t = a as u128 * b as u128;
    reduce((t as u64 & P) + (t >> 61) as u64)
}

/// x mod p for x < 2p.
#[inline(always)]
fn reduce(x: u64) -> u64 {
    if x >= P { x - P } else { x }
}

/// A point z of GF(p) drawn at random (from fresh [`RandomState`] keys, which the standard library
/// seeds from the operating system once per process and varies per call).
pub(crate) fn random_point() -> u64 {
    let h = RandomState::new().hash_one(0x6d75_6c74_6973_6574_u64);
    // The top 61 bits are uniform in [0, 2⁶¹); 2⁶¹ − 1 itself maps to 0 (a bias of 2⁻⁶¹).
    reduce(h >> 3)
}

/// Π (z − x) mod p over `xs` (every x < p, z < p), in eight interleaved products so that the
/// multiplier's latency is hidden (an iterator is taken eight items at a time).
pub(crate) fn product(z: u64, xs: impl IntoIterator<Item = u64>) -> u64 {
    let mut lanes = [1u64; 8];
    let mut it = xs.into_iter();
    loop {
        let mut batch = [0u64; 8];
        let mut n = 0;
        for slot in &mut batch {
            match it.next() {
                Some(x) => {
                    *slot = x;
                    n += 1;
                }
                None => break,
            }
        }
        if n == 8 {
            for (lane, &x) in lanes.iter_mut().zip(&batch) {
                *lane = mul_mod(*lane, term(z, x));
            }
        } else {
            for (lane, &x) in lanes.iter_mut().zip(&batch[..n]) {
                *lane = mul_mod(*lane, term(z, x));
            }
            break;
        }
    }
    lanes.into_iter().fold(1, mul_mod)
}

/// z − x mod p for x, z < p.
#[inline(always)]
fn term(z: u64, x: u64) -> u64 {
    debug_assert!(x < P && z < P);
    reduce(z + (P - x))
}

/// The product of two partial fingerprints (of two disjoint parts of one multiset).
#[inline]
pub(crate) fn combine(a: u64, b: u64) -> u64 {
    mul_mod(a, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mul_mod_matches_wide_arithmetic() {
        let vals = [
            0,
            1,
            2,
            12345,
            P - 1,
            P - 2,
            1 << 60,
            (1 << 61) - 3,
            0xdead_beef_1234,
        ];
        for &a in &vals {
            for &b in &vals {
                let want = ((a as u128 * b as u128) % P as u128) as u64;
                assert_eq!(mul_mod(a, b), want, "{a} · {b}");
            }
        }
    }

    #[test]
    fn equal_multisets_agree_in_any_order_and_split() {
        let z = random_point();
        let a: Vec<u64> = (0..1000u64).map(|k| k * 7919 % 1009).collect();
        let mut b = a.clone();
        b.reverse();
        b.swap(3, 700);
        assert_eq!(product(z, a.iter().copied()), product(z, b.iter().copied()));
        let (l, r) = b.split_at(333);
        assert_eq!(
            combine(product(z, l.iter().copied()), product(z, r.iter().copied())),
            product(z, a.iter().copied())
        );
    }

    #[test]
    fn a_changed_element_is_seen() {
        // A repeated element in place of another, and a sum-preserving change (x + 1, y − 1): both
        // must differ at a random point (failure probability ≤ 1000 / p per case).
        for _ in 0..20 {
            let z = random_point();
            let a: Vec<u64> = (0..1000).collect();
            let mut dup = a.clone();
            dup[10] = dup[11];
            let mut shifted = a.clone();
            shifted[10] += 1;
            shifted[500] -= 1;
            let pa = product(z, a.iter().copied());
            assert_ne!(pa, product(z, dup.iter().copied()));
            assert_ne!(pa, product(z, shifted.iter().copied()));
        }
    }

    #[test]
    fn points_vary_between_draws() {
        let draws: Vec<u64> = (0..8).map(|_| random_point()).collect();
        assert!(draws.iter().all(|&z| z < P));
        assert!(draws.windows(2).any(|w| w[0] != w[1]), "{draws:?}");
    }
}
