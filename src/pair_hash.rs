//! A fixed, fast hasher for pair keys, and the memory estimate of a hash table.
//!
//! Pair maps are hit on every endpoint swap that changes an overlap, and the narrow phase's
//! manifold cache on every costly pair of every step, so the hash must be a few instructions;
//! the keys are never adversarial, so SipHash's protection buys nothing. The hash is a folded
//! multiply (the full 128-bit product of the key and an odd constant, high half xor
//! low half: every key bit reaches both ends of the result, which the table's bucket index and
//! tag use). It is fixed, so the same calls build the same table; its iteration order still
//! never reaches an output.

use std::collections::HashMap;
use std::hash::{BuildHasher, Hasher};
use std::mem::size_of;

/// Builds [`PairHasher`]s (no per-table random state).
#[derive(Clone, Copy, Debug, Default)]
pub struct PairHashBuilder;

impl BuildHasher for PairHashBuilder {
    type Hasher = PairHasher;

    #[inline]
    fn build_hasher(&self) -> PairHasher {
        PairHasher(0)
    }
}

/// The folded-multiply hasher; meant for `u64` keys (a tuple of them folds each in turn).
#[derive(Clone, Copy, Debug)]
pub struct PairHasher(u64);

/// An odd constant with well-spread bits (2^64 / golden ratio).
const MULTIPLIER: u64 = 0x9E37_79B9_7F4A_7C15;

#[inline]
fn folded_multiply(x: u64) -> u64 {
    let product = u128::from(x) * u128::from(MULTIPLIER);
    // The truncation keeps the low half; the shift brings down the high half.
    (product as u64) ^ ((product >> 64) as u64)
}

impl Hasher for PairHasher {
    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.0 = folded_multiply(self.0 ^ x);
    }

    fn write(&mut self, bytes: &[u8]) {
        // Not used by u64 keys; kept correct for any other key type.
        for_each_word(bytes, |word| self.write_u64(word));
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// Feeds `bytes` to `fold` as little-endian 64-bit words, the last one zero-padded: how a
/// word hasher takes keys that are not words.
pub(crate) fn for_each_word(bytes: &[u8], mut fold: impl FnMut(u64)) {
    for chunk in bytes.chunks(8) {
        let mut word = [0u8; 8];
        word[..chunk.len()].copy_from_slice(chunk);
        fold(u64::from_le_bytes(word));
    }
}

/// A hash map keyed by pair keys.
pub type PairMap<V> = HashMap<u64, V, PairHashBuilder>;

/// Heap bytes of a hash table, estimated from its capacity: the standard table keeps
/// `capacity * 8 / 7` buckets (a power of two), each holding one entry and one control byte.
pub fn hash_map_bytes<K, V>(map: &HashMap<K, V, PairHashBuilder>) -> usize {
    let capacity = map.capacity();
    if capacity == 0 {
        return 0;
    }
    let buckets = if capacity < 8 {
        capacity + 1
    } else {
        capacity / 7 * 8
    };
    buckets.next_power_of_two() * (size_of::<(K, V)>() + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbouring_keys_spread_over_low_and_high_bits() {
        let hashes: Vec<u64> = (0..1024u64).map(folded_multiply).collect();
        let low_buckets: std::collections::BTreeSet<u64> =
            hashes.iter().map(|h| h & 1023).collect();
        let tags: std::collections::BTreeSet<u64> = hashes.iter().map(|h| h >> 57).collect();
        assert!(
            low_buckets.len() > 600,
            "{} distinct low buckets",
            low_buckets.len()
        );
        assert!(tags.len() > 100, "{} distinct tags", tags.len());
    }

    #[test]
    fn tuple_keys_spread_and_their_order_matters() {
        // The manifold cache's keys: two collider ids, folded in turn.
        let hash = |a: u64, b: u64| PairHashBuilder.hash_one((a, b));
        let low_buckets: std::collections::BTreeSet<u64> = (0..32u64)
            .flat_map(|a| (0..32u64).map(move |b| hash(a, b) & 1023))
            .collect();
        // A random hash fills about 647 of the 1,024 buckets; one blind to either half, 32.
        assert!(
            low_buckets.len() > 550,
            "{} distinct low buckets",
            low_buckets.len()
        );
        assert!((1..32u64).all(|a| hash(a, 0) != hash(0, a)));
    }

    #[test]
    fn memory_estimate_grows_with_the_table() {
        let mut map: PairMap<u32> = PairMap::default();
        assert_eq!(hash_map_bytes(&map), 0);
        map.extend((0..1000u64).map(|k| (k, 0)));
        let bytes = hash_map_bytes(&map);
        assert!((1000 * 13..=4096 * 17).contains(&bytes), "{bytes}");
    }
}
