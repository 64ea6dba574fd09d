//! Broad phase: from many moving boxes to the few pairs worth a narrow-phase test.
//!
//! Moving bodies go through sweep and prune; static scenery is indexed once in a uniform grid
//! ([`grid`], the slides' "object vs static scene").
//!
//! The slides' "Sweep and Prune" (DESIGN.md §8): two AABBs intersect iff their projections
//! overlap on x, y and z, so sorted lists of interval endpoints, kept sorted by insertion sort
//! under frame-to-frame coherence, tell which pairs overlap at a cost proportional to how much
//! the scene *changed*, not to its size. [`IncrementalSap`] is that algorithm (with Bullet's
//! refinements, Coumans' `btAxisSweep3`); [`SortAndSweep`] re-sorts from scratch every step and
//! [`BruteForce`] tests all pairs; [`AdaptiveSweep`] is the SAP that falls back to sorting from
//! scratch while insertion sort loses, and [`RegionSweep`] the segmented SAP (a sweep per cell
//! of a self-tuned grid, for large scenes where the whole-scene lists get dense). All implement
//! [`BroadPhase`] so tests and benches can compare them on the same call sequence.
//!
//! # The contract
//! - Bodies are named by caller-chosen [`ProxyId`]s (`0..=MAX_PROXY_ID`). Memory grows with the
//!   largest id used, so ids should be dense-ish (slot indices, not hashes).
//! - [`BroadPhase::insert`], [`BroadPhase::update`] and [`BroadPhase::remove`] only record the
//!   change; [`BroadPhase::commit`] is the step boundary that applies all of them at once (so a
//!   batch of inserts or removals costs one pass, and a body updated twice is sorted once).
//! - After a commit, [`BroadPhase::pairs`] is the set of overlapping pairs (closed boxes:
//!   touching boxes overlap, as [`Aabb::intersects`]) except static–static pairs, and
//!   [`BroadPhase::added`] / [`BroadPhase::removed`] are its *net* changes since the previous
//!   commit, sorted by `(a, b)`. A pair that appears and disappears within one step is in
//!   neither list; so is a pair whose body was removed and re-inserted under the same id within
//!   one step while keeping the overlap (do not reuse an id for a different object in the step
//!   that freed it).
//! - Bad input is an error, never a panic, and a failed call changes nothing.

mod adaptive;
mod body_store;
mod brute_force;
mod endpoints;
pub mod grid;
mod id_marks;
mod large_bodies;
pub(crate) mod pair_diff;
mod pair_set;
mod pair_tracking;
mod positions;
mod region;
mod regions;
mod sap;
mod sort_sweep;

pub use adaptive::AdaptiveSweep;
pub use brute_force::BruteForce;
pub use grid::{GridError, GridQueryCache, GridQueryStats, StaticGrid, StaticGridConfig};
pub use pair_tracking::{AxisBits, AxisTests, PairTracking};
pub use regions::RegionSweep;
pub use sap::IncrementalSap;
pub use sort_sweep::SortAndSweep;

use crate::bounding::Aabb;
use std::fmt;

/// A caller-chosen key naming one body in a broad phase.
pub type ProxyId = u32;

/// The largest accepted [`ProxyId`] (ids share a 32-bit word with two flag bits).
pub const MAX_PROXY_ID: ProxyId = (1 << 30) - 1;

/// Two distinct bodies, stored with `a < b` so each pair has one spelling.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Pair {
    /// The smaller id.
    pub a: ProxyId,
    /// The larger id.
    pub b: ProxyId,
}

impl Pair {
    /// The pair of two ids in either order; `None` when they are equal.
    pub fn new(x: ProxyId, y: ProxyId) -> Option<Self> {
        (x != y).then(|| Self::ordered(x, y))
    }

    /// The pair of two ids known to differ (callers guarantee `x != y`).
    #[inline]
    pub(crate) fn ordered(x: ProxyId, y: ProxyId) -> Self {
        debug_assert_ne!(x, y);
        if x < y {
            Self { a: x, b: y }
        } else {
            Self { a: y, b: x }
        }
    }

    /// One integer with the same order as `(a, b)`: the key of hash maps and sorts.
    #[inline]
    pub fn key(self) -> u64 {
        (u64::from(self.a) << 32) | u64::from(self.b)
    }

    /// The pair back from [`Pair::key`].
    #[inline]
    pub fn from_key(key: u64) -> Self {
        // Truncations are the point: the high and low halves of the key.
        Self {
            a: (key >> 32) as u32,
            b: key as u32,
        }
    }
}

/// Whether a body moves. Static–static pairs are never reported (two parts of the level do not
/// collide with each other), but a moving body passing statics is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BodyKind {
    /// Moves, and is tested against everything.
    Dynamic,
    /// Part of the scenery: tested against dynamic bodies only.
    Static,
}

impl BodyKind {
    /// Whether a pair of these kinds is never reported (two parts of the scenery).
    #[inline]
    pub(crate) fn both_static(a: Self, b: Self) -> bool {
        a == Self::Static && b == Self::Static
    }
}

/// Why a broad-phase call was refused (the structure is left as it was).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BroadPhaseError {
    /// No body with this id is present.
    UnknownId(ProxyId),
    /// A body with this id is already present (or the id appears twice in one bulk insert).
    DuplicateId(ProxyId),
    /// The id is larger than [`MAX_PROXY_ID`].
    IdOutOfRange(ProxyId),
    /// A coordinate of the box is NaN or infinite.
    NonFiniteAabb(ProxyId),
    /// `min > max` on some axis.
    InvertedAabb(ProxyId),
}

impl fmt::Display for BroadPhaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnknownId(id) => write!(f, "broad phase: no body with id {id}"),
            Self::DuplicateId(id) => write!(f, "broad phase: id {id} is already present"),
            Self::IdOutOfRange(id) => {
                write!(f, "broad phase: id {id} exceeds the maximum {MAX_PROXY_ID}")
            }
            Self::NonFiniteAabb(id) => write!(f, "broad phase: box of id {id} is not finite"),
            Self::InvertedAabb(id) => write!(f, "broad phase: box of id {id} has min > max"),
        }
    }
}

impl std::error::Error for BroadPhaseError {}

/// Work done by the last [`BroadPhase::commit`], for benches and debug views.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepStats {
    /// Adjacent transpositions of endpoints (insertion-sort swaps); 0 for the rebuilders.
    pub endpoint_swaps: u64,
    /// Pair tests: box tests for the rebuilders; for incremental sweep and prune, the swaps
    /// that flip an axis overlap (each a cross-axis test, or a table update with
    /// [`AxisBits`]) plus the candidate pairs of the sweep after an insertion.
    pub pair_tests: u64,
    /// The pairs were found again from scratch (the rebuilders; [`AdaptiveSweep`] while it
    /// has fallen back to sorting), not kept up incrementally.
    pub rebuilt: bool,
    /// A body came, went or changed its box since the commit before (an update with the same
    /// box is no change): a commit without reports no pair change, and [`AdaptiveSweep`]
    /// judges only commits with.
    pub changed: bool,
}

/// The common interface of every broad phase.
pub trait BroadPhase {
    /// Records a new body; it takes part in pairs from the next [`BroadPhase::commit`].
    fn insert(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) -> Result<(), BroadPhaseError>;

    /// Records many new bodies at once (all or none: the first bad item refuses the batch).
    fn insert_bulk(&mut self, bodies: &[(ProxyId, Aabb, BodyKind)]) -> Result<(), BroadPhaseError>;

    /// Records a body's new box.
    fn update(&mut self, id: ProxyId, aabb: Aabb) -> Result<(), BroadPhaseError>;

    /// Records that a body is gone; its pairs are reported removed at the next commit.
    fn remove(&mut self, id: ProxyId) -> Result<(), BroadPhaseError>;

    /// The step boundary: applies the recorded changes and computes the pair changes.
    fn commit(&mut self);

    /// The overlapping pairs as of the last commit, in an order that depends only on the
    /// sequence of calls (not sorted in general; see [`BroadPhase::sorted_pairs_into`]).
    fn pairs(&self) -> &[Pair];

    /// Pairs that overlap now and did not at the previous commit, sorted.
    fn added(&self) -> &[Pair];

    /// Pairs that overlapped at the previous commit and do not now, sorted.
    fn removed(&self) -> &[Pair];

    /// Work done by the last commit.
    fn stats(&self) -> StepStats;

    /// Heap bytes held (from capacities; hash tables estimated from their bucket count).
    fn memory_bytes(&self) -> usize;

    /// Number of bodies present (inserts and removals count as soon as they are recorded).
    fn len(&self) -> usize;

    /// Whether a body with this id is present.
    fn contains(&self, id: ProxyId) -> bool;

    /// The latest box given for a body.
    fn aabb(&self, id: ProxyId) -> Option<Aabb>;

    /// True when no body is present.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The current pairs sorted by `(a, b)`, written into a reusable buffer.
    fn sorted_pairs_into(&self, out: &mut Vec<Pair>) {
        out.clear();
        out.extend_from_slice(self.pairs());
        out.sort_unstable();
    }
}

/// A `u32` whose unsigned order is the order of the finite float, for integer sorts (`-0.0`
/// lands just below `0.0`; callers that need them equal add `0.0` first, which turns `-0.0`
/// into `0.0`).
#[inline]
pub(crate) fn float_order_key(value: f32) -> u32 {
    let bits = value.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// Buffers keep at least this many elements of capacity when trimmed.
const KEPT_CAPACITY: usize = 4096;

/// Clears a reusable buffer and gives back memory it no longer needs, so that one large batch
/// (a bulk insert) does not pin its peak allocation for the rest of the run. Capacity up to
/// four times the use just ended (and at least [`KEPT_CAPACITY`]) is kept, so steady work
/// never reallocates.
pub(crate) fn clear_buffer<T>(buffer: &mut Vec<T>) {
    let used = buffer.len();
    buffer.clear();
    if buffer.capacity() > KEPT_CAPACITY.max(4 * used) {
        buffer.shrink_to(KEPT_CAPACITY.max(used));
    }
}

/// Checks an id against [`MAX_PROXY_ID`].
pub(crate) fn check_id(id: ProxyId) -> Result<(), BroadPhaseError> {
    if id > MAX_PROXY_ID {
        Err(BroadPhaseError::IdOutOfRange(id))
    } else {
        Ok(())
    }
}

/// Checks that a box is finite and not inverted.
pub(crate) fn check_aabb(id: ProxyId, aabb: &Aabb) -> Result<(), BroadPhaseError> {
    if !aabb.is_finite() {
        Err(BroadPhaseError::NonFiniteAabb(id))
    } else if !aabb.is_valid() {
        Err(BroadPhaseError::InvertedAabb(id))
    } else {
        Ok(())
    }
}

/// Checks every item of a bulk insert before anything is changed: valid ids and boxes, no id
/// present already (`is_present`) or twice in the batch. `seen` is scratch, left cleared.
pub(crate) fn check_bulk(
    bodies: &[(ProxyId, Aabb, BodyKind)],
    is_present: impl Fn(ProxyId) -> bool,
    seen: &mut Vec<ProxyId>,
) -> Result<(), BroadPhaseError> {
    seen.clear();
    for (id, aabb, _) in bodies {
        check_id(*id)?;
        check_aabb(*id, aabb)?;
        if is_present(*id) {
            return Err(BroadPhaseError::DuplicateId(*id));
        }
        seen.push(*id);
    }
    seen.sort_unstable();
    let duplicate = seen.windows(2).find(|w| w[0] == w[1]).map(|w| w[0]);
    clear_buffer(seen);
    match duplicate {
        Some(id) => Err(BroadPhaseError::DuplicateId(id)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_order_key_sorts_like_the_floats() {
        let values = [
            -f32::MAX,
            -3.5,
            -1.0,
            -1e-40,
            -0.0,
            0.0,
            1e-40,
            0.5,
            2.0,
            f32::MAX,
        ];
        for w in values.windows(2) {
            assert!(
                float_order_key(w[0]) < float_order_key(w[1]),
                "{} vs {}",
                w[0],
                w[1]
            );
        }
        assert_eq!(float_order_key(-0.0 + 0.0), float_order_key(0.0));
    }
}
