//! The moves half of a commit: the endpoints of every body updated since the last commit
//! travel to their new places, body by body (Bullet's per-body sorts) or by one insertion
//! sort over each whole axis (the slides' `InsertionSort_X`), and every swap is forwarded to
//! the pair tracking.

use super::super::endpoints::{SortCount, SwapListener};
use super::super::pair_set::PairSet;
use super::super::pair_tracking::{PairTracking, TrackingContext};
use super::super::positions::{EndpointSlots, Pass};
use super::{DIRTY, IncrementalSap};

/// Forwards endpoint-swap events to the pair tracking.
struct SwapToTracking<'a, T> {
    tracker: &'a mut T,
    pairs: &'a mut PairSet,
}

impl<T: PairTracking> SwapListener for SwapToTracking<'_, T> {
    #[inline(always)]
    fn endpoint_passed(&mut self, pass: Pass, slots: &[EndpointSlots]) {
        let ctx = TrackingContext {
            slots,
            pairs: self.pairs,
        };
        self.tracker.endpoint_passed(ctx, &pass);
    }
}

impl<T: PairTracking> IncrementalSap<T> {
    /// Moves the endpoints of the bodies updated since the last commit into place; returns
    /// false if it gave up past the swap budget (`IncrementalSap::set_max_swaps`), the axes
    /// then part sorted.
    pub(super) fn apply_updates(&mut self) -> bool {
        let mut moved = std::mem::take(&mut self.scratch.ids);
        moved.clear();
        for &id in &self.to_update {
            let body = &mut self.bodies[id as usize];
            if body.state & DIRTY != 0 {
                body.state &= !DIRTY;
                moved.push(id);
            }
        }
        let stored = self.axes[0].len() / 2;
        let whole_arrays = moved.len() as f32 >= self.full_sort_fraction(stored) * stored as f32;
        let Self {
            axes,
            slots,
            bodies,
            pairs,
            tracker,
            ..
        } = self;
        let mut listener = SwapToTracking { tracker, pairs };
        let mut count = SortCount::default();
        let budget = self.max_swaps;
        if whole_arrays && !moved.is_empty() {
            for (axis, endpoints) in axes.iter_mut().enumerate() {
                for &id in &moved {
                    let aabb = &bodies[id as usize].aabb;
                    endpoints.write_body(axis, id, (aabb.min[axis], aabb.max[axis]), slots);
                }
                let left = budget.saturating_sub(count.swaps);
                count += endpoints.insertion_sort_within(axis, left, slots, &mut listener);
                if count.swaps > budget {
                    break;
                }
            }
        } else {
            // Body by body, all axes at once: one read of the body's record.
            for &id in &moved {
                let aabb = bodies[id as usize].aabb;
                for (axis, endpoints) in axes.iter_mut().enumerate() {
                    let bounds = (aabb.min[axis], aabb.max[axis]);
                    count += endpoints.move_body(axis, id, bounds, slots, &mut listener);
                }
                if count.swaps > budget {
                    break;
                }
            }
        }
        self.stats.endpoint_swaps += count.swaps;
        self.stats.pair_tests += count.flips;
        self.scratch.ids = moved;
        count.swaps <= budget
    }
}
