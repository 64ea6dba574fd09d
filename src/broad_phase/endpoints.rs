//! The per-axis sorted endpoint arrays of sweep and prune, and the insertion-sort moves that
//! keep them sorted while reporting every pass to a [`SwapListener`].
//!
//! One array per axis holds the two endpoints of every body's projection, struct-of-arrays:
//! the values and the owner words ([`super::positions`]). The order is
//! `(value, min before max)`, so touching intervals overlap, as in [`Aabb::intersects`]
//! (values compare as floats, so `-0.0` and `0.0` are equal there too). Each body records the
//! positions of its six endpoints, rewritten on every move.
//!
//! [`Aabb::intersects`]: crate::bounding::Aabb::intersects

use super::id_marks::IdMarks;
use super::positions::{EndpointSlots, MAX_FLAG, Pass, cross_slots, owner_id, slot_index};
use super::{ProxyId, float_order_key};

/// The sort order: `(value, min before max)`; true when endpoint 1 strictly precedes 2.
#[inline]
fn precedes(v1: f32, o1: u32, v2: f32, o2: u32) -> bool {
    v1 < v2 || (v1 == v2 && (o1 & MAX_FLAG) < (o2 & MAX_FLAG))
}

/// An endpoint about to be merged into an axis, with its sort key.
#[derive(Clone, Copy, Debug)]
pub struct FreshEndpoint {
    /// The array order `(value, min before max)`, then the id so that equal endpoints sort
    /// the same way every time; an integer key sorts several times faster than a float
    /// comparator. `-0.0` becomes `0.0` first, since the array holds them equal.
    key: u64,
    value: f32,
    owner: u32,
}

impl FreshEndpoint {
    /// The endpoint of `owner` at `value`.
    #[inline]
    pub fn new(value: f32, owner: u32) -> Self {
        let key = u64::from(float_order_key(value + 0.0)) << 32
            | u64::from(owner & MAX_FLAG) << 31
            | u64::from(owner >> 2);
        Self { key, value, owner }
    }

    /// The sort key.
    #[inline]
    pub fn key(&self) -> u64 {
        self.key
    }
}

/// Receives every endpoint pass of a sort. `slots` are current except the travelling
/// endpoint's own slot on the axis being sorted.
pub trait SwapListener {
    /// `pass.moving` just passed `pass.passed`.
    fn endpoint_passed(&mut self, pass: Pass, slots: &[EndpointSlots]);
}

/// Work done by a sort.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SortCount {
    /// Adjacent transpositions.
    pub swaps: u64,
    /// Transpositions that flipped an overlap ([`Pass::flips_overlap`]).
    pub flips: u64,
}

impl std::ops::AddAssign for SortCount {
    fn add_assign(&mut self, other: Self) {
        self.swaps += other.swaps;
        self.flips += other.flips;
    }
}

/// One axis's sorted endpoints (struct of arrays).
#[derive(Debug, Default)]
pub struct AxisEndpoints {
    values: Vec<f32>,
    owners: Vec<u32>,
}

impl AxisEndpoints {
    /// Number of endpoints (twice the number of stored bodies).
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Owner words in array order.
    pub fn owners(&self) -> &[u32] {
        &self.owners
    }

    /// The value at a position.
    pub fn value_at(&self, at: usize) -> f32 {
        self.values[at]
    }

    /// Heap bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.values.capacity() * size_of::<f32>() + self.owners.capacity() * size_of::<u32>()
    }

    /// Moves the endpoint at `start` towards the front until the order holds.
    fn sift_down<const AXIS: usize>(
        &mut self,
        start: usize,
        slots: &mut [EndpointSlots],
        listener: &mut impl SwapListener,
    ) -> SortCount {
        let (value, owner) = (self.values[start], self.owners[start]);
        let moving_cross = cross_slots(&slots[owner_id(owner) as usize], AXIS);
        let mut flips = 0;
        let mut at = start;
        while at > 0 {
            let (prev_value, prev_owner) = (self.values[at - 1], self.owners[at - 1]);
            if !precedes(value, owner, prev_value, prev_owner) {
                break;
            }
            self.values[at] = prev_value;
            self.owners[at] = prev_owner;
            slots[owner_id(prev_owner) as usize][slot_index(AXIS, prev_owner)] = at as u32;
            let pass = Pass {
                axis: AXIS,
                moving: owner,
                passed: prev_owner,
                moving_down: true,
                moving_cross,
            };
            flips += u64::from(pass.flips_overlap_bit());
            listener.endpoint_passed(pass, slots);
            at -= 1;
        }
        self.place(AXIS, at, value, owner, slots);
        SortCount {
            swaps: (start - at) as u64,
            flips,
        }
    }

    /// Moves the endpoint at `start` towards the back until the order holds.
    fn sift_up<const AXIS: usize>(
        &mut self,
        start: usize,
        slots: &mut [EndpointSlots],
        listener: &mut impl SwapListener,
    ) -> SortCount {
        let (value, owner) = (self.values[start], self.owners[start]);
        let moving_cross = cross_slots(&slots[owner_id(owner) as usize], AXIS);
        let last = self.values.len() - 1;
        let mut flips = 0;
        let mut at = start;
        while at < last {
            let (next_value, next_owner) = (self.values[at + 1], self.owners[at + 1]);
            if !precedes(next_value, next_owner, value, owner) {
                break;
            }
            self.values[at] = next_value;
            self.owners[at] = next_owner;
            slots[owner_id(next_owner) as usize][slot_index(AXIS, next_owner)] = at as u32;
            let pass = Pass {
                axis: AXIS,
                moving: owner,
                passed: next_owner,
                moving_down: false,
                moving_cross,
            };
            flips += u64::from(pass.flips_overlap_bit());
            listener.endpoint_passed(pass, slots);
            at += 1;
        }
        self.place(AXIS, at, value, owner, slots);
        SortCount {
            swaps: (at - start) as u64,
            flips,
        }
    }

    /// Writes an endpoint at its final position and records it in its body's slots.
    #[inline]
    fn place(
        &mut self,
        axis: usize,
        at: usize,
        value: f32,
        owner: u32,
        slots: &mut [EndpointSlots],
    ) {
        self.values[at] = value;
        self.owners[at] = owner;
        slots[owner_id(owner) as usize][slot_index(axis, owner)] = at as u32;
    }

    /// Gives one body new bounds on this axis and restores the order by moving its two
    /// endpoints only (Bullet's sortMinDown / sortMaxUp / sortMinUp / sortMaxDown order, which
    /// never lets a min run into its own max before that max has moved out of the way).
    pub fn move_body(
        &mut self,
        axis: usize,
        id: ProxyId,
        bounds: (f32, f32),
        slots: &mut [EndpointSlots],
        listener: &mut impl SwapListener,
    ) -> SortCount {
        // One copy per axis, so that every position computation is a constant.
        match axis {
            0 => self.move_body_on::<0>(id, bounds, slots, listener),
            1 => self.move_body_on::<1>(id, bounds, slots, listener),
            _ => self.move_body_on::<2>(id, bounds, slots, listener),
        }
    }

    fn move_body_on<const AXIS: usize>(
        &mut self,
        id: ProxyId,
        (new_min, new_max): (f32, f32),
        slots: &mut [EndpointSlots],
        listener: &mut impl SwapListener,
    ) -> SortCount {
        let body = id as usize;
        let (min_slot, max_slot) = (2 * AXIS, 2 * AXIS + 1);
        let (min_at, max_at) = (
            slots[body][min_slot] as usize,
            slots[body][max_slot] as usize,
        );
        let (old_min, old_max) = (self.values[min_at], self.values[max_at]);
        self.values[min_at] = new_min;
        self.values[max_at] = new_max;
        let mut count = SortCount::default();
        if new_min < old_min {
            count += self.sift_down::<AXIS>(min_at, slots, listener);
        }
        if new_max > old_max {
            count += self.sift_up::<AXIS>(slots[body][max_slot] as usize, slots, listener);
        }
        if new_min > old_min {
            count += self.sift_up::<AXIS>(slots[body][min_slot] as usize, slots, listener);
        }
        if new_max < old_max {
            count += self.sift_down::<AXIS>(slots[body][max_slot] as usize, slots, listener);
        }
        count
    }

    /// Overwrites the values of a body's endpoints in place, leaving the order to a later
    /// [`AxisEndpoints::insertion_sort_within`].
    pub fn write_body(
        &mut self,
        axis: usize,
        id: ProxyId,
        (min, max): (f32, f32),
        slots: &[EndpointSlots],
    ) {
        let body = &slots[id as usize];
        self.values[body[2 * axis] as usize] = min;
        self.values[body[2 * axis + 1] as usize] = max;
    }

    /// The slides' `InsertionSort_X` over the whole array (after many bodies were written),
    /// giving up once it has made more than `max_swaps` swaps: the array is then part sorted
    /// (every swap made was reported to `listener`).
    pub fn insertion_sort_within(
        &mut self,
        axis: usize,
        max_swaps: u64,
        slots: &mut [EndpointSlots],
        listener: &mut impl SwapListener,
    ) -> SortCount {
        match axis {
            0 => self.insertion_sort_on::<0>(max_swaps, slots, listener),
            1 => self.insertion_sort_on::<1>(max_swaps, slots, listener),
            _ => self.insertion_sort_on::<2>(max_swaps, slots, listener),
        }
    }

    fn insertion_sort_on<const AXIS: usize>(
        &mut self,
        max_swaps: u64,
        slots: &mut [EndpointSlots],
        listener: &mut impl SwapListener,
    ) -> SortCount {
        let mut count = SortCount::default();
        for at in 1..self.values.len() {
            let (value, owner) = (self.values[at], self.owners[at]);
            if precedes(value, owner, self.values[at - 1], self.owners[at - 1]) {
                count += self.sift_down::<AXIS>(at, slots, listener);
                if count.swaps > max_swaps {
                    break;
                }
            }
        }
        count
    }

    /// Merges endpoints sorted by [`FreshEndpoint::key`] into the array in one backwards pass (only
    /// the endpoints after the first insertion point move).
    pub fn merge_sorted(
        &mut self,
        axis: usize,
        fresh: &[FreshEndpoint],
        slots: &mut [EndpointSlots],
    ) {
        let mut read = self.values.len();
        let mut write = read + fresh.len();
        self.values.resize(write, 0.0);
        self.owners.resize(write, 0);
        for &FreshEndpoint { value, owner, .. } in fresh.iter().rev() {
            while read > 0 && precedes(value, owner, self.values[read - 1], self.owners[read - 1]) {
                read -= 1;
                write -= 1;
                let (old_value, old_owner) = (self.values[read], self.owners[read]);
                self.place(axis, write, old_value, old_owner, slots);
            }
            write -= 1;
            self.place(axis, write, value, owner, slots);
        }
    }

    /// Drops the endpoints of marked bodies in one compaction pass.
    pub fn remove_marked(&mut self, axis: usize, gone: &IdMarks, slots: &mut [EndpointSlots]) {
        let mut write = 0;
        for read in 0..self.values.len() {
            let (value, owner) = (self.values[read], self.owners[read]);
            if gone.get(owner_id(owner)) {
                continue;
            }
            if write != read {
                self.place(axis, write, value, owner, slots);
            }
            write += 1;
        }
        self.values.truncate(write);
        self.owners.truncate(write);
    }

    /// Checks that the array is sorted and that every slot points back at its endpoint.
    pub fn check(&self, axis: usize, slots: &[EndpointSlots]) -> Result<(), String> {
        for at in 1..self.values.len() {
            if precedes(
                self.values[at],
                self.owners[at],
                self.values[at - 1],
                self.owners[at - 1],
            ) {
                return Err(format!(
                    "axis {axis}: endpoints {} and {at} out of order",
                    at - 1
                ));
            }
        }
        for (at, &owner) in self.owners.iter().enumerate() {
            let recorded = slots[owner_id(owner) as usize][slot_index(axis, owner)];
            if recorded as usize != at {
                return Err(format!("axis {axis}: endpoint {at} recorded at {recorded}"));
            }
        }
        Ok(())
    }
}
