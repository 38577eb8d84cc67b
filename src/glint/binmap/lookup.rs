//! Bin → (texel range of the inverse bin map, kd-tree root): a dense offset table or a sparse
//! open-addressing hash table of the non-empty bins.
//!
//! # Reference
//! \[Atanasov2020\] §2.3 (a hash map from bin index to its texel list, non-empty bins being sparse).

use super::forest::NO_TREE;

/// How a [`BinMap`](super::BinMap) finds a bin's texel list.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum BinLookup {
    /// B + 1 `u32` offsets (prefix sums of the bin counts) and B `u32` tree roots: one indexed load
    /// per lookup, 8 bytes per bin whether empty or not.
    #[default]
    Dense,
    /// An open-addressing hash table (linear probing, multiplicative hash, load ≤ ½) holding only the
    /// non-empty bins: 16 bytes per slot, 2–4 slots per non-empty bin, as in the talk.
    Hash,
}

/// One entry: the bin's range [start, end) in the inverse map and its tree root.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Entry {
    pub(crate) start: u32,
    pub(crate) end: u32,
    pub(crate) root: u32,
}

const EMPTY_KEY: u32 = u32::MAX;

/// The lookup structure.
#[derive(Clone, Debug)]
pub(crate) enum Table {
    Dense {
        offsets: Vec<u32>,
        roots: Vec<u32>,
    },
    Hash {
        /// (key, start, end, root) per slot; capacity a power of two.
        slots: Vec<[u32; 4]>,
        shift: u32,
    },
}

/// Fibonacci hashing: the top bits of key × 2⁶⁴/φ.
#[inline]
fn slot_of(key: u32, shift: u32) -> usize {
    ((key as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> shift) as usize
}

impl Table {
    /// Builds the table from the prefix-sum offsets (B + 1 entries) and the tree roots (B entries).
    pub(crate) fn new(kind: BinLookup, offsets: Vec<u32>, roots: Vec<u32>) -> Table {
        match kind {
            BinLookup::Dense => Table::Dense { offsets, roots },
            BinLookup::Hash => {
                let nonempty = offsets.windows(2).filter(|w| w[1] > w[0]).count();
                let capacity = (2 * nonempty).max(2).next_power_of_two();
                let shift = 64 - capacity.trailing_zeros();
                let mut slots = vec![[EMPTY_KEY, 0, 0, NO_TREE]; capacity];
                for (bin, w) in offsets.windows(2).enumerate() {
                    if w[1] == w[0] {
                        continue;
                    }
                    let mut s = slot_of(bin as u32, shift);
                    while slots[s][0] != EMPTY_KEY {
                        s = (s + 1) & (capacity - 1);
                    }
                    slots[s] = [bin as u32, w[0], w[1], roots[bin]];
                }
                Table::Hash { slots, shift }
            }
        }
    }

    /// The entry of `bin`, `None` for an empty or out-of-range bin.
    #[inline]
    pub(crate) fn get(&self, bin: usize) -> Option<Entry> {
        match self {
            Table::Dense { offsets, roots } => {
                let (start, end) = (*offsets.get(bin)?, *offsets.get(bin + 1)?);
                (end > start).then(|| Entry {
                    start,
                    end,
                    root: roots[bin],
                })
            }
            Table::Hash { slots, shift } => {
                let key = u32::try_from(bin).ok().filter(|&k| k != EMPTY_KEY)?;
                let mask = slots.len() - 1;
                let mut s = slot_of(key, *shift);
                loop {
                    let e = slots[s];
                    if e[0] == key {
                        return Some(Entry {
                            start: e[1],
                            end: e[2],
                            root: e[3],
                        });
                    }
                    if e[0] == EMPTY_KEY {
                        return None;
                    }
                    s = (s + 1) & mask;
                }
            }
        }
    }

    /// Bytes held.
    pub(crate) fn bytes(&self) -> usize {
        match self {
            Table::Dense { offsets, roots } => 4 * (offsets.len() + roots.len()),
            Table::Hash { slots, .. } => 16 * slots.len(),
        }
    }
}
