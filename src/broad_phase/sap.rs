//! Incremental sweep and prune (the slides' "Sweep and Prune"; Baraff 1992, Cohen et al.
//! I-COLLIDE 1995; in the form of Bullet's `btAxisSweep3`, Coumans).
//!
//! Per axis, a persistent array of interval endpoints kept sorted by insertion sort
//! ([`super::endpoints`]): under frame-to-frame coherence a body moves past few endpoints, so
//! a step costs O(n + swaps), and a body that did not move costs nothing. Every swap of a min
//! and a max of two bodies starts or ends their overlap on that axis, and a [`PairTracking`]
//! turns those events into the `potential_collision` list ([`super::pair_set`]), which is
//! never rebuilt.
//!
//! A commit applies the recorded changes in three batches:
//! 1. removals: the bodies' pairs are unlisted in one pass over the list, and their endpoints
//!    leave each axis in one compaction pass;
//! 2. moves: each moved body's endpoints are rewritten and moved into place one by one
//!    (Bullet's per-body sorts: only the moved endpoints travel); when many bodies moved (see
//!    [`IncrementalSap::with_full_sort_fraction`]), all values are written first and one
//!    insertion sort runs over each whole array (the slides' `InsertionSort_X`: the same
//!    swaps, or fewer, in one sequential pass);
//! 3. insertions: the new endpoints are sorted once, merged into each axis in one pass, and
//!    one sweep over the merged axis finds the pairs involving a new body.
//!
//! The cost of a step grows with the number of endpoint swaps, so it loses to sorting from
//! scratch ([`super::SortAndSweep`]) when bodies move far relative to their spacing.
//! Measured on the bench scenes (see [`super::pair_tracking`] for the setup; CPU time per
//! step on a busy shared machine, ratios more reliable than absolute values):
//!
//! | scene                                   | incremental | sort and sweep | brute force |
//! |-----------------------------------------|------------:|---------------:|------------:|
//! | game-like, 1k bodies                    |    0.023 ms |       0.154 ms |      3.4 ms |
//! | game-like, 10k                          |     0.48 ms |         4.5 ms |      309 ms |
//! | game-like, 100k (4.3M swaps per step)   |       21 ms |         172 ms |           — |
//! | dense cloud at 0.05 per step, 10k       |      2.9 ms |         4.5 ms |             |
//! | dense cloud at 0.05 per step, 100k      |      107 ms |         174 ms |             |
//! | dense cloud, 10k, 0.01 / 0.1 / 0.2 / 1.0 per step | 1.5 / 4.5 / 7.6 / 33 ms | 4.5 ms | |
//! | bulk insert + first commit, 100k        |      210 ms |         179 ms |             |
//!
//! so at 10k bodies of size ~1 the crossover is near a displacement of 0.1 per step.
//!
//! The swap loop is branch-free except for the rare pair to list or unlist (whether a pass
//! flips an overlap, and whether two bodies overlap on a cross axis, are coin tosses that
//! mispredicted branches made twice as slow), and what remains is mostly the cache miss on
//! the passed body's positions.

mod batch;
mod moves;

use super::endpoints::{AxisEndpoints, FreshEndpoint};
use super::id_marks::IdMarks;
use super::pair_set::PairSet;
use super::pair_tracking::{AxisTests, PairTracking};
use super::positions::{CrossSlots, EndpointSlots};
use super::{
    BodyKind, BroadPhase, BroadPhaseError, Pair, ProxyId, StepStats, check_aabb, check_bulk,
    check_id, clear_buffer,
};
use crate::bounding::Aabb;
use std::mem::size_of;

/// Body state flag: the body is present (as far as the caller knows).
const LIVE: u8 = 1;
/// The body's endpoints are in the arrays.
const STORED: u8 = 2;
/// The body is to be inserted at the next commit.
const INSERT: u8 = 4;
/// The body's box changed since the last commit.
const DIRTY: u8 = 8;
/// The body's endpoints are to leave the arrays at the next commit.
const REMOVE: u8 = 16;

/// What the broad phase knows of one id.
#[derive(Clone, Copy, Debug)]
struct BodyRecord {
    /// The latest box given.
    aabb: Aabb,
    kind: BodyKind,
    /// `LIVE | STORED | INSERT | DIRTY | REMOVE` bits.
    state: u8,
}

impl Default for BodyRecord {
    fn default() -> Self {
        Self {
            aabb: Aabb::EMPTY,
            kind: BodyKind::Dynamic,
            state: 0,
        }
    }
}

/// An open interval during the insertion sweep: its owner word and its body's endpoint
/// positions on the other two axes.
#[derive(Clone, Copy, Debug)]
struct OpenInterval {
    owner: u32,
    cross: CrossSlots,
}

/// Buffers reused across commits.
#[derive(Debug, Default)]
struct Scratch {
    /// Ids taken out of a pending list for processing.
    ids: Vec<ProxyId>,
    /// One axis's new endpoints, to be sorted and merged.
    fresh_endpoints: Vec<FreshEndpoint>,
    /// Bodies being removed or inserted in this commit.
    marks: IdMarks,
    /// Sweep state: position of each open body in its active list.
    active_at: Vec<u32>,
    /// Sweep state: open intervals of new bodies.
    active_fresh: Vec<OpenInterval>,
    /// Sweep state: open intervals of old bodies.
    active_old: Vec<OpenInterval>,
    /// Bulk-insert validation.
    seen: Vec<ProxyId>,
}

impl Scratch {
    fn memory_bytes(&self) -> usize {
        (self.ids.capacity() + self.seen.capacity()) * size_of::<ProxyId>()
            + self.fresh_endpoints.capacity() * size_of::<FreshEndpoint>()
            + self.marks.memory_bytes()
            + self.active_at.capacity() * size_of::<u32>()
            + (self.active_fresh.capacity() + self.active_old.capacity())
                * size_of::<OpenInterval>()
    }
}

/// Incremental sweep and prune over three axes, generic over the pair-tracking strategy
/// ([`AxisTests`], the default, or [`super::AxisBits`]).
#[derive(Debug)]
pub struct IncrementalSap<T: PairTracking = AxisTests> {
    axes: [AxisEndpoints; 3],
    /// Per id: where its six endpoints are.
    slots: Vec<EndpointSlots>,
    /// Per id: box, kind, state.
    bodies: Vec<BodyRecord>,
    live: usize,
    to_insert: Vec<ProxyId>,
    to_update: Vec<ProxyId>,
    to_remove: Vec<ProxyId>,
    pairs: PairSet,
    tracker: T,
    stats: StepStats,
    /// Moved bodies / stored bodies at or above which one whole-array insertion sort per axis
    /// replaces per-body moves; `None`: chosen by scene size.
    full_sort_fraction: Option<f32>,
    /// Swaps after which a commit gives up (see [`IncrementalSap::set_max_swaps`]).
    max_swaps: u64,
    /// The last commit gave up.
    abandoned: bool,
    scratch: Scratch,
}

impl<T: PairTracking> Default for IncrementalSap<T> {
    fn default() -> Self {
        Self {
            axes: Default::default(),
            slots: Vec::new(),
            bodies: Vec::new(),
            live: 0,
            to_insert: Vec::new(),
            to_update: Vec::new(),
            to_remove: Vec::new(),
            pairs: PairSet::default(),
            tracker: T::default(),
            stats: StepStats::default(),
            full_sort_fraction: None,
            max_swaps: u64::MAX,
            abandoned: false,
            scratch: Scratch::default(),
        }
    }
}

impl<T: PairTracking> IncrementalSap<T> {
    /// Scenes with at least this many bodies count as large for the choice between per-body
    /// moves and whole-array sorts: their endpoint arrays and positions (72 bytes a body) no
    /// longer fit a 2 MB cache.
    pub const LARGE_SCENE: usize = 50_000;

    /// Default share of moved bodies from which whole arrays are sorted, below
    /// [`IncrementalSap::LARGE_SCENE`] bodies.
    pub const SMALL_SCENE_FULL_SORT_FRACTION: f32 = 0.25;

    /// The same from [`IncrementalSap::LARGE_SCENE`] bodies on.
    pub const LARGE_SCENE_FULL_SORT_FRACTION: f32 = 0.02;

    /// An empty broad phase.
    pub fn new() -> Self {
        Self::default()
    }

    /// Fixes the share of moved bodies (moved / stored) from which a commit writes all moves
    /// first and runs one insertion sort over each whole axis instead of moving each body's
    /// endpoints separately. Both give the same pairs and nearly the same swaps; they trade a
    /// sequential pass over every endpoint against locating each moved body's endpoints, which
    /// costs a cache miss each once the arrays outgrow the cache. `0.0` always sorts whole
    /// arrays, above `1.0` never. By default the share depends on the scene size (see
    /// [`IncrementalSap::LARGE_SCENE`]): measured with 10% of the bodies moving, per-body
    /// moves were 30% faster at 10k bodies and whole arrays 30% faster at 100k.
    #[must_use]
    pub fn with_full_sort_fraction(mut self, fraction: f32) -> Self {
        self.full_sort_fraction = Some(fraction);
        self
    }

    /// The share of moved bodies from which whole arrays are sorted, for `stored` bodies.
    fn full_sort_fraction(&self, stored: usize) -> f32 {
        self.full_sort_fraction
            .unwrap_or(if stored < Self::LARGE_SCENE {
                Self::SMALL_SCENE_FULL_SORT_FRACTION
            } else {
                Self::LARGE_SCENE_FULL_SORT_FRACTION
            })
    }

    /// Makes each commit give up once its insertion sorts have made more than `max_swaps`
    /// swaps, for an owner that then rebuilds from the boxes ([`super::AdaptiveSweep`]: a
    /// losing sort is abandoned at a bounded cost instead of finished). After such a commit
    /// ([`Self::abandoned`]) the structure is inconsistent: only [`BroadPhase::aabb`] of the
    /// live bodies, the pairs listed and their changes so far (every swap made was tracked;
    /// this commit's insertions were not applied) may be read, and it must be dropped.
    pub(crate) fn set_max_swaps(&mut self, max_swaps: u64) {
        self.max_swaps = max_swaps;
    }

    /// Whether the last commit gave up past [`Self::set_max_swaps`]'s budget.
    pub(crate) fn abandoned(&self) -> bool {
        self.abandoned
    }

    /// The pair-tracking state (for its own statistics).
    pub fn tracker(&self) -> &T {
        &self.tracker
    }

    /// Checks the internal invariants: each axis sorted, every recorded position pointing
    /// back at its endpoint, endpoint values equal to the committed boxes. For tests and
    /// debugging; O(n).
    pub fn check_consistency(&self) -> Result<(), String> {
        let stored = self.bodies.iter().filter(|b| b.state & STORED != 0).count();
        for (axis, endpoints) in self.axes.iter().enumerate() {
            if endpoints.len() != 2 * stored {
                return Err(format!(
                    "axis {axis}: {} endpoints, {stored} bodies",
                    endpoints.len()
                ));
            }
            endpoints.check(axis, &self.slots)?;
            for (id, body) in self.bodies.iter().enumerate() {
                let slots = &self.slots[id];
                let pending = body.state & (DIRTY | INSERT | REMOVE) != 0;
                if body.state & STORED == 0 || pending {
                    continue;
                }
                let (min, max) = (body.aabb.min[axis], body.aabb.max[axis]);
                let stored_min = endpoints.value_at(slots[2 * axis] as usize);
                let stored_max = endpoints.value_at(slots[2 * axis + 1] as usize);
                if stored_min != min || stored_max != max {
                    return Err(format!("axis {axis}: body {id} stores stale bounds"));
                }
            }
        }
        Ok(())
    }

    /// The live record of an id.
    fn live_record_mut(&mut self, id: ProxyId) -> Option<&mut BodyRecord> {
        self.bodies
            .get_mut(id as usize)
            .filter(|b| b.state & LIVE != 0)
    }

    fn is_live(&self, id: ProxyId) -> bool {
        self.bodies
            .get(id as usize)
            .is_some_and(|b| b.state & LIVE != 0)
    }

    /// Records an insert whose id and box were checked.
    fn record_insert(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) {
        let at = id as usize;
        if at >= self.bodies.len() {
            self.bodies.resize(at + 1, BodyRecord::default());
            self.slots.resize(at + 1, [0; 6]);
        }
        let body = &mut self.bodies[at];
        // A body removed earlier in this step keeps STORED | REMOVE: its old endpoints leave
        // before the new ones arrive.
        body.state = (body.state & (STORED | REMOVE)) | LIVE | INSERT;
        body.aabb = aabb;
        body.kind = kind;
        self.to_insert.push(id);
        self.live += 1;
    }
}

impl<T: PairTracking> BroadPhase for IncrementalSap<T> {
    fn insert(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) -> Result<(), BroadPhaseError> {
        check_id(id)?;
        check_aabb(id, &aabb)?;
        if self.is_live(id) {
            return Err(BroadPhaseError::DuplicateId(id));
        }
        self.record_insert(id, aabb, kind);
        Ok(())
    }

    fn insert_bulk(&mut self, bodies: &[(ProxyId, Aabb, BodyKind)]) -> Result<(), BroadPhaseError> {
        let mut seen = std::mem::take(&mut self.scratch.seen);
        let checked = check_bulk(bodies, |id| self.is_live(id), &mut seen);
        self.scratch.seen = seen;
        checked?;
        if let Some(max_id) = bodies.iter().map(|b| b.0).max() {
            let missing = (max_id as usize + 1).saturating_sub(self.bodies.len());
            self.bodies.reserve(missing);
            self.slots.reserve(missing);
        }
        for &(id, aabb, kind) in bodies {
            self.record_insert(id, aabb, kind);
        }
        Ok(())
    }

    fn update(&mut self, id: ProxyId, aabb: Aabb) -> Result<(), BroadPhaseError> {
        let body = self
            .live_record_mut(id)
            .ok_or(BroadPhaseError::UnknownId(id))?;
        check_aabb(id, &aabb)?;
        if body.aabb == aabb {
            return Ok(());
        }
        body.aabb = aabb;
        if body.state & (INSERT | DIRTY) == 0 {
            body.state |= DIRTY;
            self.to_update.push(id);
        }
        Ok(())
    }

    fn remove(&mut self, id: ProxyId) -> Result<(), BroadPhaseError> {
        let body = self
            .live_record_mut(id)
            .ok_or(BroadPhaseError::UnknownId(id))?;
        body.state &= !(LIVE | INSERT | DIRTY);
        if body.state & (STORED | REMOVE) == STORED {
            body.state |= REMOVE;
            self.to_remove.push(id);
        }
        self.live -= 1;
        Ok(())
    }

    fn commit(&mut self) {
        // `update` queues a body only when its box differs.
        let changed =
            !(self.to_insert.is_empty() && self.to_update.is_empty() && self.to_remove.is_empty());
        self.stats = StepStats {
            changed,
            ..StepStats::default()
        };
        self.apply_removals();
        self.abandoned = !self.apply_updates();
        if !self.abandoned {
            self.apply_inserts();
        }
        self.pairs.finish_step();
        clear_buffer(&mut self.to_insert);
        clear_buffer(&mut self.to_update);
        clear_buffer(&mut self.to_remove);
        clear_buffer(&mut self.scratch.ids);
        clear_buffer(&mut self.scratch.fresh_endpoints);
    }

    fn pairs(&self) -> &[Pair] {
        self.pairs.as_slice()
    }

    fn added(&self) -> &[Pair] {
        self.pairs.added()
    }

    fn removed(&self) -> &[Pair] {
        self.pairs.removed()
    }

    fn stats(&self) -> StepStats {
        self.stats
    }

    fn memory_bytes(&self) -> usize {
        self.axes
            .iter()
            .map(AxisEndpoints::memory_bytes)
            .sum::<usize>()
            + self.slots.capacity() * size_of::<EndpointSlots>()
            + self.bodies.capacity() * size_of::<BodyRecord>()
            + (self.to_insert.capacity() + self.to_update.capacity() + self.to_remove.capacity())
                * size_of::<ProxyId>()
            + self.pairs.memory_bytes()
            + self.tracker.memory_bytes()
            + self.scratch.memory_bytes()
    }

    fn len(&self) -> usize {
        self.live
    }

    fn contains(&self, id: ProxyId) -> bool {
        self.is_live(id)
    }

    fn aabb(&self, id: ProxyId) -> Option<Aabb> {
        self.bodies
            .get(id as usize)
            .filter(|b| b.state & LIVE != 0)
            .map(|b| b.aabb)
    }
}
