//! The bodies of [`super::RegionSweep`] too large for its cells (a ground slab, a level's
//! outer wall): kept out of the regions, so that one box does not join thousands of them, and
//! tested against the other bodies directly. They own every pair that involves one of them.
//!
//! Such bodies are expected to be few and to move rarely (nothing enforces it; the cells grow
//! when there are many). When none of them changed, a commit re-tests only the bodies that
//! changed against them; when one changed, every pair of a large body is found again from
//! scratch, a scan over every id up to the largest (`O((large + 1) × largest id)`: about
//! 0.2 ms a step per 100k ids for a ground slab that moves every step).

use super::region::BodyView;
use super::{BodyKind, Pair, ProxyId};
use crate::bounding::Aabb;
use std::mem::size_of;

/// What the large bodies need to know of every body (ids below [`BodyView::id_bound`]).
pub(super) trait LargeView: BodyView {
    /// The box, kind and whether the body is large, for a present id; `None` otherwise.
    fn body(&self, id: ProxyId) -> Option<(Aabb, BodyKind, bool)>;
    /// Whether the id changed in this commit.
    fn changed(&self, id: ProxyId) -> bool;
}

/// The large bodies and the pairs they own.
#[derive(Debug, Default)]
pub(super) struct LargeBodies {
    /// The large bodies as of the last commit, by id.
    ids: Vec<ProxyId>,
    /// Their pairs, sorted.
    owned: Vec<Pair>,
    /// This commit's pairs (scratch).
    found: Vec<Pair>,
    /// The last pairs of changed bodies (scratch).
    dropped: Vec<Pair>,
}

impl LargeBodies {
    /// Whether any pair or body is held (else a commit without a large change skips them).
    pub fn is_idle(&self) -> bool {
        self.ids.is_empty() && self.owned.is_empty()
    }

    /// The large bodies as of the last full refresh.
    pub fn count(&self) -> usize {
        self.ids.len()
    }

    /// Hands every owned pair to `removed` and forgets everything (the regions are laid out
    /// again).
    pub fn clear(&mut self, removed: &mut Vec<Pair>) {
        removed.append(&mut self.owned);
        self.ids.clear();
    }

    /// Finds this commit's pairs of the large bodies and appends the difference with the last
    /// ones; `full` when a large body changed (or a body became or stopped being large).
    /// Returns the box tests made.
    pub fn refresh(
        &mut self,
        view: &impl LargeView,
        changed: &[ProxyId],
        full: bool,
        (added, removed): (&mut Vec<Pair>, &mut Vec<Pair>),
    ) -> u64 {
        if !full {
            return self.find_changed(view, changed, (added, removed));
        }
        let tests = self.find_all(view);
        self.found.sort_unstable();
        super::pair_diff::diff_sorted(&self.owned, &self.found, added, removed);
        std::mem::swap(&mut self.owned, &mut self.found);
        tests
    }

    /// Every pair of a large body, from scratch.
    fn find_all(&mut self, view: &impl LargeView) -> u64 {
        self.ids.clear();
        self.ids.extend(
            (0..view.id_bound() as ProxyId)
                .filter(|&id| view.body(id).is_some_and(|(_, _, large)| large)),
        );
        self.found.clear();
        let mut tests = 0;
        for &l in &self.ids {
            let Some((big, big_kind, _)) = view.body(l) else {
                continue;
            };
            for other in 0..view.id_bound() as ProxyId {
                let Some((aabb, kind, large)) = view.body(other) else {
                    continue;
                };
                // A pair of two large bodies is found once, from its smaller id.
                if other == l || (large && other < l) {
                    continue;
                }
                tests += 1;
                if !BodyKind::both_static(big_kind, kind) && big.intersects(&aabb) {
                    self.found.push(Pair::ordered(l, other));
                }
            }
        }
        tests
    }

    /// The last pairs of unchanged bodies kept, and the changed bodies against the large
    /// ones. Only the changed bodies' pairs are sorted and diffed, the dropped against the new
    /// (no kept pair is among either: each has a changed body), then merged into the kept
    /// ones, which are sorted already (a ground slab owns about one pair a body, and sorting
    /// or diffing them all again cost every commit), as `Region::sweep_few` does.
    fn find_changed(
        &mut self,
        view: &impl LargeView,
        changed: &[ProxyId],
        (added, removed): (&mut Vec<Pair>, &mut Vec<Pair>),
    ) -> u64 {
        self.found.clear();
        self.dropped.clear();
        for &p in &self.owned {
            if view.changed(p.a) || view.changed(p.b) {
                self.dropped.push(p);
            } else {
                self.found.push(p);
            }
        }
        let kept = self.found.len();
        let mut tests = 0;
        for &id in changed {
            let Some((aabb, kind, false)) = view.body(id) else {
                continue;
            };
            for &l in &self.ids {
                let Some((big, big_kind, _)) = view.body(l) else {
                    continue;
                };
                tests += 1;
                if !BodyKind::both_static(big_kind, kind) && big.intersects(&aabb) {
                    self.found.push(Pair::ordered(l, id));
                }
            }
        }
        self.found[kept..].sort_unstable();
        let (old, new) = self.found.split_at(kept);
        super::pair_diff::diff_sorted(&self.dropped, new, added, removed);
        super::pair_diff::merge_sorted(old, new, &mut self.owned);
        tests
    }

    /// Heap bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.ids.capacity() * size_of::<ProxyId>()
            + (self.owned.capacity() + self.found.capacity() + self.dropped.capacity())
                * size_of::<Pair>()
    }
}
