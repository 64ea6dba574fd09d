//! A fixed, seedless hasher for the grid's lookup tables (cell coordinates and object ids).
//!
//! The standard `RandomState` is seeded per process, so anything derived from a map's iteration
//! order would change from run to run. The grid only ever *looks up* keys (outputs are sorted),
//! but a fixed hasher also makes its memory layout and timings reproducible, and it is cheaper:
//! a key is one or two machine words, which SipHash is far too slow for.
//!
//! Each written word is folded in with a multiply-rotate step (the FxHash scheme of the Rust
//! compiler), and [`Hasher::finish`] applies the MurmurHash3 64-bit finaliser (Appleby 2011) so
//! that the top bits, which `hashbrown` uses as its control tag, depend on every input bit.

use std::hash::{BuildHasher, Hasher};

/// Builds [`CellHasher`]s; every builder is the same (there is no seed).
#[derive(Clone, Copy, Debug, Default)]
pub struct CellHashBuilder;

impl BuildHasher for CellHashBuilder {
    type Hasher = CellHasher;

    fn build_hasher(&self) -> CellHasher {
        CellHasher { state: 0 }
    }
}

/// A multiply-rotate word hasher with an avalanche finaliser; see the module docs.
#[derive(Clone, Copy, Debug)]
pub struct CellHasher {
    state: u64,
}

/// The golden-ratio multiplier of FxHash: odd, with well-spread bits.
const FOLD_MULTIPLIER: u64 = 0x9E37_79B9_7F4A_7C15;

impl CellHasher {
    #[inline]
    fn fold(&mut self, word: u64) {
        self.state = (self.state.rotate_left(26) ^ word).wrapping_mul(FOLD_MULTIPLIER);
    }
}

impl Hasher for CellHasher {
    fn write(&mut self, bytes: &[u8]) {
        crate::pair_hash::for_each_word(bytes, |word| self.fold(word));
    }

    #[inline]
    fn write_u32(&mut self, n: u32) {
        self.fold(u64::from(n));
    }

    #[inline]
    fn write_i32(&mut self, n: i32) {
        self.fold(u64::from(n as u32));
    }

    #[inline]
    fn write_u64(&mut self, n: u64) {
        self.fold(n);
    }

    #[inline]
    fn finish(&self) -> u64 {
        murmur3_finalize(self.state)
    }
}

/// MurmurHash3's `fmix64`: every output bit depends on every input bit.
#[inline]
fn murmur3_finalize(mut h: u64) -> u64 {
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^ (h >> 33)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::Hash;

    fn hash_of(value: impl Hash) -> u64 {
        CellHashBuilder.hash_one(value)
    }

    #[test]
    fn the_same_key_hashes_the_same_in_every_builder() {
        assert_eq!(hash_of((3i32, -7i32, 11i32)), hash_of((3i32, -7i32, 11i32)));
        assert_eq!(
            CellHashBuilder.hash_one(42u32),
            CellHashBuilder.hash_one(42u32)
        );
    }

    #[test]
    fn neighbouring_cells_spread_over_the_top_bits() {
        // hashbrown takes its 7-bit control tag from the top of the hash: neighbouring cells
        // must not all share it, or every probe would compare keys.
        let mut tags = std::collections::BTreeSet::new();
        for x in -4i32..4 {
            for y in -4i32..4 {
                tags.insert(hash_of((x, y, 0i32)) >> 57);
            }
        }
        assert!(
            tags.len() > 32,
            "only {} distinct tags over 64 cells",
            tags.len()
        );
    }

    #[test]
    fn byte_writes_depend_on_every_chunk() {
        let mut a = CellHashBuilder.build_hasher();
        a.write(&[1, 2, 3, 4, 5, 6, 7, 8, 9]);
        let mut b = CellHashBuilder.build_hasher();
        b.write(&[1, 2, 3, 4, 5, 6, 7, 8, 10]);
        assert_ne!(a.finish(), b.finish());
    }
}
