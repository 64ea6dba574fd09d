//! The list of object slots in one grid cell, stored inline for the common small case.
//!
//! A query reads a cell's list right after finding the cell in the hash table. A `Vec` would
//! put the entries behind a pointer, one more cache miss per visited cell; with the automatic
//! cell size a cell holds only a few objects, so the first [`INLINE_SLOTS`] entries live inside
//! the table entry itself (which stays the size a bare `Vec` entry would have had, 64 bytes
//! with its key) and only crowded cells spill the rest to the heap.

/// Entries kept inline: a length and 5 slots fill the 24 bytes beside the overflow `Vec`.
pub(super) const INLINE_SLOTS: usize = 5;

/// An unordered list of slots: `inline[..min(len, INLINE_SLOTS)]` then `overflow`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(super) struct CellList {
    len: u32,
    inline: [u32; INLINE_SLOTS],
    overflow: Vec<u32>,
}

impl CellList {
    /// Number of slots listed.
    #[inline]
    pub(super) fn len(&self) -> usize {
        self.len as usize
    }

    /// True when the list holds no slot.
    pub(super) fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The slots, in storage order: the inline part, then the overflow.
    #[inline]
    pub(super) fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        let inline = self.len().min(INLINE_SLOTS);
        self.inline[..inline].iter().chain(&self.overflow).copied()
    }

    /// Appends `slot`.
    pub(super) fn push(&mut self, slot: u32) {
        let len = self.len();
        if len < INLINE_SLOTS {
            self.inline[len] = slot;
        } else {
            self.overflow.push(slot);
        }
        // A cell lists each object at most once, and objects are counted in `u32`.
        self.len += 1;
    }

    /// Removes one occurrence of `slot` (moving the last entry into its place); returns
    /// whether it was there. Linear in the list's length.
    pub(super) fn remove(&mut self, slot: u32) -> bool {
        let Some(index) = self.iter().position(|s| s == slot) else {
            return false;
        };
        let last = match self.overflow.pop() {
            Some(last) => last,
            None => self.inline[self.len() - 1],
        };
        if index < INLINE_SLOTS {
            self.inline[index] = last;
        } else if index - INLINE_SLOTS < self.overflow.len() {
            self.overflow[index - INLINE_SLOTS] = last;
        }
        self.len -= 1;
        if self.overflow.is_empty() {
            // Give back the heap block of a cell that was crowded once.
            self.overflow = Vec::new();
        }
        true
    }

    /// Heap bytes held (the inline part is counted with the table entry).
    pub(super) fn heap_bytes(&self) -> usize {
        self.overflow.capacity() * size_of::<u32>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    fn sorted(list: &CellList) -> Vec<u32> {
        let mut v: Vec<u32> = list.iter().collect();
        v.sort_unstable();
        v
    }

    #[test]
    fn the_table_entry_stays_one_cache_line() {
        assert_eq!(size_of::<(glam::IVec3, CellList)>(), 64);
    }

    #[test]
    fn pushes_and_removals_across_the_inline_boundary_match_a_set() {
        // Remove from the front, the middle, the inline part and the overflow, in turns.
        for count in 0..12u32 {
            for first_removed in 0..count.max(1) {
                let mut list = CellList::default();
                let mut model = BTreeSet::new();
                for slot in 0..count {
                    list.push(slot * 10);
                    model.insert(slot * 10);
                }
                // Visit every slot once, starting anywhere, in a scrambled order (13 is coprime
                // with every `count + 1` up to 12), plus one absent slot.
                for step in 0..=count {
                    let slot = (first_removed + 13 * step) % (count + 1) * 10;
                    assert_eq!(list.remove(slot), model.remove(&slot), "slot {slot}");
                    assert_eq!(list.len(), model.len());
                    assert_eq!(sorted(&list), model.iter().copied().collect::<Vec<_>>());
                }
                assert!(list.is_empty());
                assert_eq!(list.heap_bytes(), 0);
            }
        }
    }

    #[test]
    fn removing_an_absent_slot_changes_nothing() {
        let mut list = CellList::default();
        list.push(4);
        assert!(!list.remove(5));
        assert_eq!(sorted(&list), vec![4]);
    }
}
