//! Small ids that stay with their keys from round to round. The query index keeps its tree
//! through a change of colliders only if a collider keeps its id ([`ColliderTree`]); an ECS
//! iterates its colliders in an order that moves when one is despawned (a table's swap-remove),
//! so ids by position would all change. These ids are dense (freed ids are reused, lowest
//! last freed first), so the tree can index by them.
//!
//! A round checks each key against the key at the same position last round, and looks up the
//! hash map only where they differ: a round without change costs one comparison a key.
//!
//! [`ColliderTree`]: super::ColliderTree

use std::collections::HashMap;
use std::hash::Hash;

/// Ids by key (see the [module](self)).
#[derive(Clone, Debug)]
pub struct StableIds<K> {
    /// The keys of the last round in order, and their ids.
    last: Vec<(K, u32)>,
    /// The keys of this round so far.
    current: Vec<(K, u32)>,
    /// Whether this round has differed from the last so far.
    changed: bool,
    id_of: HashMap<K, u32>,
    /// The key of each id, `None` while free.
    key_of: Vec<Option<K>>,
    /// The last changed round each id was given in.
    given_in: Vec<u64>,
    round: u64,
    free: Vec<u32>,
}

impl<K> Default for StableIds<K> {
    fn default() -> Self {
        Self {
            last: Vec::new(),
            current: Vec::new(),
            changed: false,
            id_of: HashMap::new(),
            key_of: Vec::new(),
            given_in: Vec::new(),
            round: 0,
            free: Vec::new(),
        }
    }
}

impl<K: Copy + Eq + Hash> StableIds<K> {
    /// Starts a round: the keys follow through [`Self::id`], then [`Self::finish`].
    pub fn begin(&mut self) {
        self.current.clear();
        self.changed = false;
    }

    /// The id of this round's next key: the id it had if it was given before and not freed
    /// since, else a free one. A key given twice in a round gets one id.
    #[inline]
    pub fn id(&mut self, key: K) -> u32 {
        let id = match self.last.get(self.current.len()) {
            Some(&(k, id)) if k == key => id,
            _ => {
                self.changed = true;
                self.id_of_new(key)
            }
        };
        self.current.push((key, id));
        id
    }

    /// The id of a key not found at its position of the last round.
    fn id_of_new(&mut self, key: K) -> u32 {
        if let Some(&id) = self.id_of.get(&key) {
            return id;
        }
        let id = self.free.pop().unwrap_or(self.key_of.len() as u32);
        if id as usize == self.key_of.len() {
            self.key_of.push(None);
            self.given_in.push(0);
        }
        self.key_of[id as usize] = Some(key);
        self.id_of.insert(key, id);
        id
    }

    /// Ends the round: the ids of keys not given in it are freed. A round that gave every
    /// key at its last position frees nothing and costs nothing more; one that did not marks
    /// the ids it gave and frees those of the last round's keys left unmarked.
    pub fn finish(&mut self) {
        if self.changed || self.current.len() != self.last.len() {
            self.round += 1;
            for &(_, id) in &self.current {
                self.given_in[id as usize] = self.round;
            }
            for &(key, id) in &self.last {
                if self.given_in[id as usize] != self.round && self.key_of[id as usize].is_some() {
                    self.key_of[id as usize] = None;
                    self.id_of.remove(&key);
                    self.free.push(id);
                }
            }
            // Lowest ids handed out first, so the ids stay dense.
            self.free.sort_unstable_by(|a, b| b.cmp(a));
        }
        std::mem::swap(&mut self.last, &mut self.current);
    }

    /// The key holding `id`, if any.
    pub fn key(&self, id: u32) -> Option<K> {
        self.key_of.get(id as usize).copied().flatten()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round(ids: &mut StableIds<u64>, keys: &[u64]) -> Vec<u32> {
        ids.begin();
        let given = keys.iter().map(|&k| ids.id(k)).collect();
        ids.finish();
        given
    }

    #[test]
    fn ids_follow_their_keys_through_swap_removes_and_freed_ids_are_reused_lowest_first() {
        let mut ids = StableIds::default();
        assert_eq!(round(&mut ids, &[10, 11, 12, 13]), [0, 1, 2, 3]);
        assert_eq!(round(&mut ids, &[10, 11, 12, 13]), [0, 1, 2, 3]);
        // 11 despawned: the last key moves into its place.
        assert_eq!(round(&mut ids, &[10, 13, 12]), [0, 3, 2]);
        assert_eq!(ids.key(1), None);
        assert_eq!(ids.key(3), Some(13));
        // Two new keys: the freed id 1 first, then a new one.
        assert_eq!(round(&mut ids, &[10, 13, 12, 20, 21]), [0, 3, 2, 1, 4]);
        assert_eq!(ids.key(1), Some(20));
        // All gone, then back: ids from 0 again.
        assert_eq!(round(&mut ids, &[]), Vec::<u32>::new());
        assert_eq!((0..6).filter_map(|i| ids.key(i)).count(), 0);
        assert_eq!(round(&mut ids, &[21, 10]), [0, 1]);
    }

    #[test]
    fn a_key_twice_in_a_round_gets_one_id_and_a_reordered_round_keeps_every_id() {
        let mut ids = StableIds::default();
        assert_eq!(round(&mut ids, &[5, 6, 5]), [0, 1, 0]);
        assert_eq!(round(&mut ids, &[6, 5]), [1, 0]);
        let keys: Vec<u64> = (0..300).collect();
        let first = round(&mut ids, &keys);
        let mut reversed = keys.clone();
        reversed.reverse();
        let again = round(&mut ids, &reversed);
        assert!(first.iter().rev().eq(again.iter()));
        assert!(again.iter().all(|&id| id < 300));
    }
}
