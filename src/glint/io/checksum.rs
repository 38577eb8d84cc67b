//! The file format's checksum (docs/format.md, "Checksum"), and the one of format version 1, which
//! a reader computes only to tell an intact version-1 file (unsupported) from a damaged header.

/// The file checksum: four interleaved 64-bit multiply-rotate lanes over little-endian 64-bit words.
///
/// Word k of the input (8 bytes, the last one zero-padded) goes to lane k mod 4; lane j starts at
/// 0xCBF2_9CE4_8422_2325 + j and takes a word w as h ← rotl₂₉((h ⊕ w) · 0x9E37_79B9_7F4A_7C15).
/// At the end h = lane 0, then for j = 1, 2, 3: h ← rotl₂₉((h ⊕ lane j) · 0x9E37_79B9_7F4A_7C15);
/// then h ← h ⊕ (byte count) and the SplitMix64 finaliser (h ⊕= h ≫ 30; h ·= 0xBF58_476D_1CE4_E5B9;
/// h ⊕= h ≫ 27; h ·= 0x94D0_49BB_1331_11EB; h ⊕= h ≫ 31). Every step is a bijection of its lane (or
/// of h) for fixed other inputs, so any change of one word changes the result; it detects
/// corruption, it is not a cryptographic signature. The four lanes are independent dependency
/// chains, so the hash runs at the multiplier's throughput (~0.2 cycle per byte) rather than its
/// latency (~0.7 for the single chain of format version 1).
#[derive(Clone, Debug)]
pub(crate) struct Checksum {
    lanes: [u64; 4],
    pending: [u8; 32],
    pending_len: usize,
    total: u64,
}

impl Checksum {
    const SEED: u64 = 0xCBF2_9CE4_8422_2325;
    const MUL: u64 = 0x9E37_79B9_7F4A_7C15;

    pub(crate) fn new() -> Checksum {
        Checksum {
            lanes: std::array::from_fn(|j| Self::SEED.wrapping_add(j as u64)),
            pending: [0; 32],
            pending_len: 0,
            total: 0,
        }
    }

    #[inline]
    fn mix(h: u64, w: u64) -> u64 {
        (h ^ w).wrapping_mul(Self::MUL).rotate_left(29)
    }

    /// One 32-byte block: words 0-3 into lanes 0-3.
    #[inline]
    fn block(&mut self, b: &[u8]) {
        for (j, lane) in self.lanes.iter_mut().enumerate() {
            let w = u64::from_le_bytes(b[8 * j..8 * j + 8].try_into().unwrap_or([0; 8]));
            *lane = Self::mix(*lane, w);
        }
    }

    pub(crate) fn update(&mut self, mut bytes: &[u8]) {
        self.total += bytes.len() as u64;
        if self.pending_len > 0 {
            let take = (32 - self.pending_len).min(bytes.len());
            self.pending[self.pending_len..self.pending_len + take].copy_from_slice(&bytes[..take]);
            self.pending_len += take;
            bytes = &bytes[take..];
            if self.pending_len < 32 {
                return;
            }
            let block = self.pending;
            self.block(&block);
            self.pending_len = 0;
        }
        let mut blocks = bytes.chunks_exact(32);
        for b in &mut blocks {
            self.block(b);
        }
        let rest = blocks.remainder();
        self.pending[..rest.len()].copy_from_slice(rest);
        self.pending_len = rest.len();
    }

    pub(crate) fn finish(mut self) -> u64 {
        // The last (< 32) bytes: whole and zero-padded words into lanes 0, 1, ... in order.
        let mut tail = [0u8; 32];
        tail[..self.pending_len].copy_from_slice(&self.pending[..self.pending_len]);
        for j in 0..self.pending_len.div_ceil(8) {
            let w = u64::from_le_bytes(tail[8 * j..8 * j + 8].try_into().unwrap_or([0; 8]));
            self.lanes[j] = Self::mix(self.lanes[j], w);
        }
        let mut h = self.lanes[0];
        for &lane in &self.lanes[1..] {
            h = Self::mix(h, lane);
        }
        splitmix_finish(h ^ self.total)
    }
}

/// The checksum of a byte string (what [`Checksum`] computes over a whole file but its last 8 bytes).
#[cfg(test)]
pub(crate) fn checksum(bytes: &[u8]) -> u64 {
    let mut c = Checksum::new();
    c.update(bytes);
    c.finish()
}

/// The checksum of format version 1: the same words, mix and finaliser as [`Checksum`], in one chain
/// (h starts at 0xCBF2_9CE4_8422_2325 and takes every word in order; then h ⊕= byte count and the
/// SplitMix64 finaliser). No file is written with it; a reader computes it only to confirm that a
/// file whose header says version 1 is one (docs/format.md, "Damaged or unsupported").
#[derive(Clone, Debug)]
pub(crate) struct ChecksumV1 {
    state: u64,
    pending: [u8; 8],
    pending_len: usize,
    total: u64,
}

impl ChecksumV1 {
    pub(crate) fn new() -> ChecksumV1 {
        ChecksumV1 {
            state: Checksum::SEED,
            pending: [0; 8],
            pending_len: 0,
            total: 0,
        }
    }

    pub(crate) fn update(&mut self, mut bytes: &[u8]) {
        self.total += bytes.len() as u64;
        if self.pending_len > 0 {
            let take = (8 - self.pending_len).min(bytes.len());
            self.pending[self.pending_len..self.pending_len + take].copy_from_slice(&bytes[..take]);
            self.pending_len += take;
            bytes = &bytes[take..];
            if self.pending_len < 8 {
                return;
            }
            self.state = Checksum::mix(self.state, u64::from_le_bytes(self.pending));
            self.pending_len = 0;
        }
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            let w = u64::from_le_bytes(w.try_into().unwrap_or([0; 8]));
            self.state = Checksum::mix(self.state, w);
        }
        let rest = words.remainder();
        self.pending[..rest.len()].copy_from_slice(rest);
        self.pending_len = rest.len();
    }

    pub(crate) fn finish(mut self) -> u64 {
        if self.pending_len > 0 {
            let mut last = [0u8; 8];
            last[..self.pending_len].copy_from_slice(&self.pending[..self.pending_len]);
            self.state = Checksum::mix(self.state, u64::from_le_bytes(last));
        }
        splitmix_finish(self.state ^ self.total)
    }
}

/// The SplitMix64 finaliser both checksums end with.
fn splitmix_finish(mut h: u64) -> u64 {
    h ^= h >> 30;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^ (h >> 31)
}

/// A running file checksum of either era (what [`crate::glint::io::header`] confirms a file with).
pub(crate) trait FileHash {
    fn update(&mut self, bytes: &[u8]);
    fn finish(self) -> u64;
}

impl FileHash for Checksum {
    fn update(&mut self, bytes: &[u8]) {
        Checksum::update(self, bytes);
    }
    fn finish(self) -> u64 {
        Checksum::finish(self)
    }
}

impl FileHash for ChecksumV1 {
    fn update(&mut self, bytes: &[u8]) {
        ChecksumV1::update(self, bytes);
    }
    fn finish(self) -> u64 {
        ChecksumV1::finish(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checksum_is_independent_of_chunking() {
        let data: Vec<u8> = (0..1000u32).map(|k| (k * 7 + 3) as u8).collect();
        let whole = checksum(&data);
        for split in [1, 3, 7, 8, 9, 31, 32, 33, 500, 999] {
            let mut c = Checksum::new();
            for part in data.chunks(split) {
                c.update(part);
            }
            assert_eq!(c.finish(), whole, "chunks of {split}");
        }
        // Any single flipped bit, and an appended zero byte, change it.
        for bit in [0usize, 7, 63, 64, 4000, 7999] {
            let mut d = data.clone();
            d[bit / 8] ^= 1 << (bit % 8);
            assert_ne!(checksum(&d), whole, "bit {bit}");
        }
        let mut d = data.clone();
        d.push(0);
        assert_ne!(checksum(&d), whole);
    }

    /// The reference value of the documented algorithm, computed by hand-written steps here: 9 bytes,
    /// i.e. word 0 ("BRDFGLNT") into lane 0 and word 1 (0x01, zero-padded) into lane 1.
    #[test]
    fn checksum_matches_the_documented_steps() {
        let bytes = b"BRDFGLNT\x01";
        let seed: u64 = 0xCBF2_9CE4_8422_2325;
        let mul: u64 = 0x9E37_79B9_7F4A_7C15;
        let mix = |h: u64, w: u64| (h ^ w).wrapping_mul(mul).rotate_left(29);
        let lanes = [
            mix(seed, u64::from_le_bytes(*b"BRDFGLNT")),
            mix(seed + 1, 1),
            seed + 2,
            seed + 3,
        ];
        let mut h = lanes[0];
        for lane in &lanes[1..] {
            h = mix(h, *lane);
        }
        h ^= 9;
        h ^= h >> 30;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 27;
        h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
        h ^= h >> 31;
        assert_eq!(checksum(bytes), h);
    }

    /// Format version 1's checksum from its documented steps: one chain over the words
    /// "BRDFGLNT" and 0x01 (zero-padded), then the length and the finaliser.
    #[test]
    fn version_1_checksum_matches_the_documented_steps() {
        let bytes = b"BRDFGLNT\x01";
        let mix = |h: u64, w: u64| (h ^ w).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(29);
        let mut h = mix(0xCBF2_9CE4_8422_2325, u64::from_le_bytes(*b"BRDFGLNT"));
        h = mix(h, 1);
        h ^= 9;
        h ^= h >> 30;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 27;
        h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
        h ^= h >> 31;
        for split in [1, 3, 9] {
            let mut c = ChecksumV1::new();
            for part in bytes.chunks(split) {
                c.update(part);
            }
            assert_eq!(c.finish(), h, "chunks of {split}");
        }
    }
}
