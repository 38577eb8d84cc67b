//! [`ViewMemo`]: the exact visible area V_P(wo) of the last view a patch was asked about, kept so
//! that the queries a renderer makes at one shading point and one wo (`eval` and `pdf` at a few
//! wi, `sample`) pay the pass over the patch's lobes once instead of once per query.
//!
//! The same memo keyed by any three `u32` ([`ViewMemo::get_or_key`]) keeps another per-patch
//! value that consecutive queries share (the bin map's last bin mass).
//!
//! Patches are shared between threads (the truth integrators run them under rayon), so the memo is
//! `Send + Sync` without a lock: a sequence lock over atomics. A reader that races a writer sees a
//! changed sequence number and computes V itself; a writer that finds another writer at work skips
//! its store. Either way every caller gets the value its own pass would give, bit for bit.

use glam::Vec3;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering, fence};

/// One memoised f64 keyed by the bits of a direction (0 in the sequence: empty; odd: a store in
/// progress).
#[derive(Debug, Default)]
pub(crate) struct ViewMemo {
    seq: AtomicU32,
    key: [AtomicU32; 3],
    value: AtomicU64,
}

impl Clone for ViewMemo {
    /// An empty memo: a copy of a patch computes its own views.
    fn clone(&self) -> Self {
        ViewMemo::default()
    }
}

/// The key of a direction: its three components' bits (a deterministic pass gives one value per
/// key).
fn key_of(w: Vec3) -> [u32; 3] {
    [w.x.to_bits(), w.y.to_bits(), w.z.to_bits()]
}

impl ViewMemo {
    /// The value kept for `w` if it is the last one stored, else `compute()`, stored for `w`.
    #[inline]
    pub(crate) fn get_or(&self, w: Vec3, compute: impl FnOnce() -> f64) -> f64 {
        self.get_or_key(key_of(w), compute)
    }

    /// The value kept for `key` if it is the last one stored, else `compute()`, stored for `key`.
    #[inline]
    pub(crate) fn get_or_key(&self, key: [u32; 3], compute: impl FnOnce() -> f64) -> f64 {
        if let Some(v) = self.get(key) {
            return v;
        }
        let v = compute();
        self.put(key, v);
        v
    }

    #[inline]
    fn get(&self, key: [u32; 3]) -> Option<f64> {
        let s1 = self.seq.load(Ordering::Acquire);
        if s1 == 0 || s1 & 1 == 1 {
            return None;
        }
        let k = [0, 1, 2].map(|i| self.key[i].load(Ordering::Relaxed));
        let v = self.value.load(Ordering::Relaxed);
        fence(Ordering::Acquire);
        let s2 = self.seq.load(Ordering::Relaxed);
        (s1 == s2 && k == key).then_some(f64::from_bits(v))
    }

    #[inline]
    fn put(&self, key: [u32; 3], v: f64) {
        let s = self.seq.load(Ordering::Relaxed);
        if s & 1 == 1
            || self
                .seq
                .compare_exchange(s, s.wrapping_add(1), Ordering::Acquire, Ordering::Relaxed)
                .is_err()
        {
            return;
        }
        fence(Ordering::Release);
        for (a, k) in self.key.iter().zip(key) {
            a.store(k, Ordering::Relaxed);
        }
        self.value.store(v.to_bits(), Ordering::Relaxed);
        // Skip 0 (empty) when the counter wraps.
        let next = s.wrapping_add(2);
        self.seq
            .store(if next == 0 { 2 } else { next }, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_last_view_only() {
        let m = ViewMemo::default();
        let (a, b) = (Vec3::new(0.1, 0.2, 0.9), Vec3::new(0.3, 0.0, 0.8));
        let mut calls = 0;
        let mut f = |x: f64| {
            calls += 1;
            x
        };
        assert_eq!(m.get_or(a, || f(1.0)), 1.0);
        assert_eq!(m.get_or(a, || f(9.0)), 1.0);
        assert_eq!(m.get_or(b, || f(2.0)), 2.0);
        assert_eq!(m.get_or(a, || f(3.0)), 3.0);
        // −0.0 and 0.0 are different keys.
        let c = Vec3::new(-0.0, 0.0, 1.0);
        assert_eq!(m.get_or(c, || f(4.0)), 4.0);
        assert_eq!(m.get_or(Vec3::Z, || f(5.0)), 5.0);
        assert_eq!(calls, 5);
        assert_eq!(m.clone().get_or(Vec3::Z, || 6.0), 6.0);
    }

    #[test]
    fn threads_always_read_their_own_value() {
        // Each thread's value is a function of its key: any torn or stale read would show.
        let m = ViewMemo::default();
        std::thread::scope(|s| {
            for t in 0..4u32 {
                let m = &m;
                s.spawn(move || {
                    for i in 0..20_000u32 {
                        let x = ((t * 7 + i % 5) as f32) * 0.01;
                        let w = Vec3::new(x, 1.0 - x, 0.5);
                        let want = x as f64 * 3.0 + 1.0;
                        assert_eq!(m.get_or(w, || want), want);
                    }
                });
            }
        });
    }
}
