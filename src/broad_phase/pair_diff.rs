//! Sorted pair lists: the changes between two (for the broad phases that recompute pairs each
//! commit, or a region of [`super::RegionSweep`]: keep the previous sorted list and diff it
//! against the new one in one merge pass), and the merge of two.

use super::Pair;
use std::cmp::Ordering;
use std::mem::size_of;

/// The current sorted pair list, the next one being built, and their difference.
#[derive(Debug, Default)]
pub struct PairHistory {
    current: Vec<Pair>,
    next: Vec<Pair>,
    added: Vec<Pair>,
    removed: Vec<Pair>,
}

impl PairHistory {
    /// The buffer to fill with this commit's pairs (cleared, any order).
    pub fn begin(&mut self) -> &mut Vec<Pair> {
        self.next.clear();
        &mut self.next
    }

    /// Sorts the filled buffer, makes it current and diffs it against the previous list.
    pub fn finish(&mut self) {
        self.next.sort_unstable();
        self.added.clear();
        self.removed.clear();
        diff_sorted(
            &self.current,
            &self.next,
            &mut self.added,
            &mut self.removed,
        );
        std::mem::swap(&mut self.current, &mut self.next);
    }

    /// A commit that found the same pairs as the one before (nothing moved): no changes.
    pub fn keep(&mut self) {
        self.added.clear();
        self.removed.clear();
    }

    /// The pairs of the last commit, sorted.
    pub fn current(&self) -> &[Pair] {
        &self.current
    }

    /// Pairs in the last commit and not the one before, sorted.
    pub fn added(&self) -> &[Pair] {
        &self.added
    }

    /// Pairs in the commit before the last and not the last, sorted.
    pub fn removed(&self) -> &[Pair] {
        &self.removed
    }

    /// Heap bytes held.
    pub fn memory_bytes(&self) -> usize {
        (self.current.capacity()
            + self.next.capacity()
            + self.added.capacity()
            + self.removed.capacity())
            * size_of::<Pair>()
    }
}

/// Appends `new \ old` to `added` and `old \ new` to `removed` (both inputs sorted, no repeats).
pub fn diff_sorted(old: &[Pair], new: &[Pair], added: &mut Vec<Pair>, removed: &mut Vec<Pair>) {
    diff_sorted_by_key(old, new, |p| *p, |p| *p, added, removed);
}

/// [`diff_sorted`] for lists of different items sorted by a common key (no key repeated in a
/// list): appends the items of `new` whose key is not in `old` to `added`, and those of `old`
/// whose key is not in `new` to `removed`, each in its list's order. One merge pass, where a
/// binary search of one list for each item of the other would take a cache miss per step of
/// the search (the collision messages compare thousands of touching pairs each substep).
pub fn diff_sorted_by_key<A: Copy, B: Copy, K: Ord>(
    old: &[A],
    new: &[B],
    old_key: impl Fn(&A) -> K,
    new_key: impl Fn(&B) -> K,
    added: &mut Vec<B>,
    removed: &mut Vec<A>,
) {
    let (mut i, mut j) = (0, 0);
    while i < old.len() && j < new.len() {
        match old_key(&old[i]).cmp(&new_key(&new[j])) {
            Ordering::Less => {
                removed.push(old[i]);
                i += 1;
            }
            Ordering::Greater => {
                added.push(new[j]);
                j += 1;
            }
            Ordering::Equal => {
                i += 1;
                j += 1;
            }
        }
    }
    removed.extend_from_slice(&old[i..]);
    added.extend_from_slice(&new[j..]);
}

/// Two sorted lists without common items merged into `out`.
pub fn merge_sorted(a: &[Pair], b: &[Pair], out: &mut Vec<Pair>) {
    out.clear();
    out.reserve(a.len() + b.len());
    if b.len() * 8 < a.len() {
        merge_few(a, b, out);
        return;
    }
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i] < b[j] {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
}

/// [`merge_sorted`] for a `b` much shorter than `a`: each pair of `b` finds its place in what
/// is left of `a` by binary search, and the run of `a` before it is copied whole. The regions
/// merge a few new pairs into many kept ones, where a pair-by-pair merge spent a compare and a
/// branch on every kept pair.
fn merge_few(a: &[Pair], b: &[Pair], out: &mut Vec<Pair>) {
    let mut rest = a;
    for &p in b {
        let before = rest.partition_point(|q| *q < p);
        out.extend_from_slice(&rest[..before]);
        out.push(p);
        rest = &rest[before..];
    }
    out.extend_from_slice(rest);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diff_finds_both_sides() {
        let p = |a, b| Pair { a, b };
        let (mut added, mut removed) = (Vec::new(), Vec::new());
        diff_sorted(
            &[p(0, 1), p(0, 3), p(2, 5)],
            &[p(0, 2), p(0, 3), p(4, 5)],
            &mut added,
            &mut removed,
        );
        assert_eq!(added, [p(0, 2), p(4, 5)]);
        assert_eq!(removed, [p(0, 1), p(2, 5)]);
    }

    #[test]
    fn keyed_diff_keeps_each_side_s_items_and_matches_binary_searches_on_random_lists() {
        let mut rng = crate::test_rng::TestRng::new(11);
        let mut next = || rng.below(300);
        for _ in 0..50 {
            let mut old: Vec<u32> = (0..next() % 120).map(|_| next()).collect();
            // The new list carries a payload beside its key, as the collision messages do.
            let mut new: Vec<(u32, u32)> = (0..next() % 120).map(|_| (next(), next())).collect();
            old.sort_unstable();
            old.dedup();
            new.sort_unstable_by_key(|t| t.0);
            new.dedup_by_key(|t| t.0);
            let (mut added, mut removed) = (Vec::new(), Vec::new());
            diff_sorted_by_key(&old, &new, |k| *k, |t| t.0, &mut added, &mut removed);
            let gone: Vec<u32> = (old.iter().copied())
                .filter(|k| new.binary_search_by_key(k, |t| t.0).is_err())
                .collect();
            let came: Vec<(u32, u32)> = (new.iter().copied())
                .filter(|t| old.binary_search(&t.0).is_err())
                .collect();
            assert_eq!(removed, gone);
            assert_eq!(added, came);
        }
    }

    #[test]
    fn merging_gives_the_sorted_union_whether_one_side_is_short_or_not() {
        let mut seed = 7u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 40) as u32 % 500
        };
        for (na, nb) in [
            (0, 0),
            (40, 0),
            (0, 40),
            (200, 3),
            (200, 30),
            (50, 50),
            (3, 200),
        ] {
            let mut all: Vec<Pair> = (0..na + nb)
                .map(|_| Pair::ordered(next(), next() + 500))
                .collect();
            all.sort_unstable();
            all.dedup();
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for p in &all {
                // Spread at random, so that `b`'s pairs fall between `a`'s.
                if (next() as usize) % (na + nb) < nb {
                    b.push(*p)
                } else {
                    a.push(*p)
                }
            }
            let mut out = Vec::new();
            merge_sorted(&a, &b, &mut out);
            assert_eq!(out, all, "{na} + {nb}");
        }
    }
}
