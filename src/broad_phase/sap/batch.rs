//! The batched halves of a commit: removing bodies (one pass over the pair list, one
//! compaction per axis) and inserting bodies (one sort and one merge per axis, then one sweep
//! to find the new pairs), instead of one O(n) array shift per body.

use super::super::endpoints::FreshEndpoint;
use super::super::pair_tracking::{PairTracking, TrackingContext};
use super::super::positions::{
    MAX_FLAG, both_static, cross_overlap, cross_slots, owner_id, owner_word,
};
use super::{INSERT, IncrementalSap, OpenInterval, REMOVE, STORED};
use crate::broad_phase::BodyKind;

impl<T: PairTracking> IncrementalSap<T> {
    /// Takes the bodies removed since the last commit out of the pair list, the tracking
    /// state and the endpoint arrays.
    pub(super) fn apply_removals(&mut self) {
        let mut gone = std::mem::take(&mut self.scratch.ids);
        gone.clear();
        for &id in &self.to_remove {
            let body = &mut self.bodies[id as usize];
            if body.state & REMOVE != 0 {
                body.state &= !(REMOVE | STORED);
                gone.push(id);
                self.scratch.marks.set(id);
            }
        }
        if !gone.is_empty() {
            let marks = &self.scratch.marks;
            self.pairs
                .retain(|pair| !marks.get(pair.a) && !marks.get(pair.b));
            self.tracker.forget(marks);
            for (axis, endpoints) in self.axes.iter_mut().enumerate() {
                endpoints.remove_marked(axis, marks, &mut self.slots);
            }
            for &id in &gone {
                self.scratch.marks.clear(id);
            }
        }
        self.scratch.ids = gone;
    }

    /// Merges the bodies inserted since the last commit into the endpoint arrays and lists
    /// their pairs.
    pub(super) fn apply_inserts(&mut self) {
        let mut fresh = std::mem::take(&mut self.scratch.ids);
        fresh.clear();
        for &id in &self.to_insert {
            let body = &mut self.bodies[id as usize];
            // The flag also removes repeats: an id inserted, removed, inserted again.
            if body.state & INSERT != 0 {
                body.state = (body.state & !INSERT) | STORED;
                fresh.push(id);
                self.scratch.marks.set(id);
            }
        }
        if !fresh.is_empty() {
            self.merge_fresh_endpoints(&fresh);
            for &axis in T::BULK_AXES {
                self.sweep_for_fresh_pairs(axis);
            }
            for &id in &fresh {
                self.scratch.marks.clear(id);
            }
        }
        self.scratch.ids = fresh;
    }

    /// Sorts the new bodies' endpoints once per axis and merges them in.
    fn merge_fresh_endpoints(&mut self, fresh: &[u32]) {
        let buffer = &mut self.scratch.fresh_endpoints;
        for (axis, endpoints) in self.axes.iter_mut().enumerate() {
            buffer.clear();
            for &id in fresh {
                let body = &self.bodies[id as usize];
                let is_static = body.kind == BodyKind::Static;
                buffer.push(FreshEndpoint::new(
                    body.aabb.min[axis],
                    owner_word(id, is_static, false),
                ));
                buffer.push(FreshEndpoint::new(
                    body.aabb.max[axis],
                    owner_word(id, is_static, true),
                ));
            }
            buffer.sort_unstable_by_key(FreshEndpoint::key);
            endpoints.merge_sorted(axis, buffer, &mut self.slots);
        }
    }

    /// One sweep along `axis`: every pair with at least one new body whose projections
    /// overlap on it goes to the tracking, with whether it overlaps on the other axes too.
    /// Open intervals are kept in two lists, new and old, so that old–old pairs cost nothing;
    /// each entry carries its body's endpoint positions on the other axes, so the cross-axis
    /// test reads the list sequentially.
    fn sweep_for_fresh_pairs(&mut self, axis: usize) {
        let Self {
            axes,
            slots,
            pairs,
            tracker,
            stats,
            scratch,
            ..
        } = self;
        let marks = &scratch.marks;
        let active_at = &mut scratch.active_at;
        if active_at.len() < slots.len() {
            active_at.resize(slots.len(), 0);
        }
        let (active_fresh, active_old) = (&mut scratch.active_fresh, &mut scratch.active_old);
        active_fresh.clear();
        active_old.clear();
        let mut candidates = 0;
        for &owner in axes[axis].owners() {
            let id = owner_id(owner);
            let is_fresh = marks.get(id);
            if owner & MAX_FLAG == 0 {
                let entry = OpenInterval {
                    owner,
                    cross: cross_slots(&slots[id as usize], axis),
                };
                let old_partners = if is_fresh { &active_old[..] } else { &[] };
                for list in [&active_fresh[..], old_partners] {
                    candidates += list.len() as u64;
                    for other in list {
                        let on_other_axes = cross_overlap(&entry.cross, &other.cross);
                        let wanted = on_other_axes || !T::SWEEP_FILTERS_CROSS_AXES;
                        if wanted && !both_static(owner, other.owner) {
                            let ctx = TrackingContext { slots, pairs };
                            tracker.fresh_overlap(
                                ctx,
                                axis,
                                id,
                                owner_id(other.owner),
                                on_other_axes,
                            );
                        }
                    }
                }
                let list = if is_fresh {
                    &mut *active_fresh
                } else {
                    &mut *active_old
                };
                active_at[id as usize] = list.len() as u32;
                list.push(entry);
            } else {
                let list = if is_fresh {
                    &mut *active_fresh
                } else {
                    &mut *active_old
                };
                let at = active_at[id as usize] as usize;
                list.swap_remove(at);
                if let Some(moved) = list.get(at) {
                    active_at[owner_id(moved.owner) as usize] = at as u32;
                }
            }
        }
        stats.pair_tests += candidates;
    }
}
