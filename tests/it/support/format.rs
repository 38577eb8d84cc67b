//! The file format's checksum and a re-sealing helper, written from docs/format.md (format version
//! 2), independently of the crate's code: tests that forge files with valid checksums use it, and a
//! mismatch with the crate would fail them.

/// The documented checksum: four lanes, word k (8 bytes, the last zero-padded) into lane k mod 4.
pub fn doc_checksum(bytes: &[u8]) -> u64 {
    const MUL: u64 = 0x9E37_79B9_7F4A_7C15;
    let mix = |h: u64, w: u64| (h ^ w).wrapping_mul(MUL).rotate_left(29);
    let mut lanes = [0u64; 4];
    for (j, lane) in lanes.iter_mut().enumerate() {
        *lane = 0xCBF2_9CE4_8422_2325u64 + j as u64;
    }
    for (k, chunk) in bytes.chunks(8).enumerate() {
        let mut w = [0u8; 8];
        w[..chunk.len()].copy_from_slice(chunk);
        lanes[k % 4] = mix(lanes[k % 4], u64::from_le_bytes(w));
    }
    let mut h = lanes[0];
    for lane in &lanes[1..] {
        h = mix(h, *lane);
    }
    h ^= bytes.len() as u64;
    h ^= h >> 30;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^ (h >> 31)
}

/// Replaces the last 8 bytes of a file by the checksum of the others.
pub fn reseal(mut file: Vec<u8>) -> Vec<u8> {
    let n = file.len() - 8;
    let sum = doc_checksum(&file[..n]);
    file[n..].copy_from_slice(&sum.to_le_bytes());
    file
}

/// The checksum of format version 1, from that version's docs/format.md: one chain over the 8-byte
/// words (the last zero-padded), then the length and the same finaliser.
#[allow(dead_code)] // not every test binary that includes this file uses it
pub fn doc_checksum_v1(bytes: &[u8]) -> u64 {
    const MUL: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut h = 0xCBF2_9CE4_8422_2325u64;
    for chunk in bytes.chunks(8) {
        let mut w = [0u8; 8];
        w[..chunk.len()].copy_from_slice(chunk);
        h = (h ^ u64::from_le_bytes(w))
            .wrapping_mul(MUL)
            .rotate_left(29);
    }
    h ^= bytes.len() as u64;
    h ^= h >> 30;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^ (h >> 31)
}

/// Replaces the last 8 bytes of a file by the version-1 checksum of the others.
#[allow(dead_code)] // not every test binary that includes this file uses it
pub fn reseal_v1(mut file: Vec<u8>) -> Vec<u8> {
    let n = file.len() - 8;
    let sum = doc_checksum_v1(&file[..n]);
    file[n..].copy_from_slice(&sum.to_le_bytes());
    file
}
