//! The slides' `potential_collision` list: the pairs overlapping on every axis, with O(1) add
//! and remove, never rebuilt from scratch.
//!
//! The slides keep, in each cell of the n×n pair table, an iterator into the list; here the
//! table is sparse (a hash map holds only the listed pairs, pair → position in a dense `Vec`),
//! and removal is a swap-remove that fixes the position of the element moved into the hole.
//! Every add and remove is also logged, so that the step boundary can report the *net*
//! changes: a pair added and removed within one step cancels out.

use super::{Pair, clear_buffer};
use crate::pair_hash::{PairMap, hash_map_bytes};
use std::mem::size_of;

/// The current pair set and this step's change log.
#[derive(Debug, Default)]
pub struct PairSet {
    /// The pairs, dense, in an order that depends only on the history of adds and removes.
    pairs: Vec<Pair>,
    /// Pair key → position in `pairs`.
    position: PairMap<u32>,
    /// This step's events: `key << 1 | 1` for an add, `key << 1` for a remove.
    log: Vec<u64>,
    /// Net additions of the last finished step, sorted.
    added: Vec<Pair>,
    /// Net removals of the last finished step, sorted.
    removed: Vec<Pair>,
}

impl PairSet {
    /// The listed pairs.
    pub fn as_slice(&self) -> &[Pair] {
        &self.pairs
    }

    /// Net additions of the last finished step, sorted.
    pub fn added(&self) -> &[Pair] {
        &self.added
    }

    /// Net removals of the last finished step, sorted.
    pub fn removed(&self) -> &[Pair] {
        &self.removed
    }

    /// Whether the pair is listed.
    pub fn contains(&self, pair: Pair) -> bool {
        self.position.contains_key(&pair.key())
    }

    /// Lists the pair unless it is listed already; true when it was added.
    #[inline]
    pub fn add(&mut self, pair: Pair) -> bool {
        let key = pair.key();
        let next = self.pairs.len() as u32;
        match self.position.entry(key) {
            std::collections::hash_map::Entry::Occupied(_) => false,
            std::collections::hash_map::Entry::Vacant(slot) => {
                slot.insert(next);
                self.pairs.push(pair);
                self.log.push(key << 1 | 1);
                true
            }
        }
    }

    /// Unlists the pair if it is listed; true when it was removed.
    #[inline]
    pub fn remove(&mut self, pair: Pair) -> bool {
        let key = pair.key();
        let Some(at) = self.position.remove(&key) else {
            return false;
        };
        self.take_out(at as usize, key);
        true
    }

    /// Unlists every pair for which `keep` is false, in one pass.
    pub fn retain(&mut self, mut keep: impl FnMut(Pair) -> bool) {
        // Backwards, so that the element a swap-remove brings into the hole was already seen.
        for at in (0..self.pairs.len()).rev() {
            let pair = self.pairs[at];
            if !keep(pair) {
                let key = pair.key();
                self.position.remove(&key);
                self.take_out(at, key);
            }
        }
    }

    /// Swap-removes position `at` (whose map entry is already gone) and logs the removal.
    fn take_out(&mut self, at: usize, key: u64) {
        self.pairs.swap_remove(at);
        if let Some(moved) = self.pairs.get(at) {
            // The former last element now lives at `at`; it is listed, so its entry exists.
            if let Some(slot) = self.position.get_mut(&moved.key()) {
                *slot = at as u32;
            }
        }
        self.log.push(key << 1);
    }

    /// Ends a step: turns the log into sorted net additions and removals, clears the log.
    pub fn finish_step(&mut self) {
        clear_buffer(&mut self.added);
        clear_buffer(&mut self.removed);
        self.log.sort_unstable();
        // Events of one pair alternate add/remove, so adds − removes is −1, 0 or +1: the net
        // change from the previous step boundary.
        for events in self.log.chunk_by(|x, y| x >> 1 == y >> 1) {
            let adds = events.iter().filter(|e| *e & 1 == 1).count();
            let pair = Pair::from_key(events[0] >> 1);
            match (2 * adds).cmp(&events.len()) {
                std::cmp::Ordering::Greater => self.added.push(pair),
                std::cmp::Ordering::Less => self.removed.push(pair),
                std::cmp::Ordering::Equal => {}
            }
        }
        clear_buffer(&mut self.log);
    }

    /// Heap bytes held.
    pub fn memory_bytes(&self) -> usize {
        (self.pairs.capacity() + self.added.capacity() + self.removed.capacity())
            * size_of::<Pair>()
            + self.log.capacity() * size_of::<u64>()
            + hash_map_bytes(&self.position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(a: u32, b: u32) -> Pair {
        Pair::ordered(a, b)
    }

    fn check_positions(set: &PairSet) {
        assert_eq!(set.position.len(), set.pairs.len());
        for (at, pair) in set.pairs.iter().enumerate() {
            assert_eq!(set.position[&pair.key()] as usize, at);
        }
    }

    #[test]
    fn add_and_remove_keep_positions_and_refuse_repeats() {
        let mut set = PairSet::default();
        assert!(set.add(p(1, 2)) && set.add(p(3, 4)) && set.add(p(0, 9)));
        assert!(!set.add(p(2, 1)));
        assert!(set.remove(p(1, 2)));
        assert!(!set.remove(p(1, 2)));
        check_positions(&set);
        set.retain(|pair| pair.a != 3);
        check_positions(&set);
        assert_eq!(set.as_slice(), &[p(0, 9)]);
    }

    #[test]
    fn net_changes_cancel_within_a_step() {
        let mut set = PairSet::default();
        set.add(p(1, 2));
        set.add(p(5, 6));
        set.finish_step();
        assert_eq!(set.added(), &[p(1, 2), p(5, 6)]);
        set.remove(p(1, 2));
        set.add(p(1, 2));
        set.add(p(3, 4));
        set.remove(p(3, 4));
        set.remove(p(5, 6));
        set.add(p(0, 7));
        set.finish_step();
        assert_eq!(set.added(), &[p(0, 7)]);
        assert_eq!(set.removed(), &[p(5, 6)]);
    }
}
