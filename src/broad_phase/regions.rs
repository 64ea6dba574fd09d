//! Segmented sweep and prune (issue 12): space cut into the cells of a uniform grid, each cell
//! a region with its own sweep over the few bodies that touch it, so that the density of
//! endpoints per sorted list stays low whatever the scene's size or shape.
//!
//! The incremental SAP ([`super::IncrementalSap`]) keeps one sorted list per axis for the whole
//! scene; where every endpoint passes hundreds of others (a dense cloud all moving, bodies strung
//! along an axis) insertion sort does O(n²) work. Multi-box pruning (Terdiman, *Box pruning
//! revisited*; PhysX's MBP and ABP) and Tracy et al.'s segmented interval lists (2009) cut the
//! lists by space instead. Here:
//!
//! - **Regions.** A body joins every cell its box touches ([`region`]); a region sorts its
//!   members along the sweep axis incrementally (last step's order, insertion sort with a
//!   budget, then a sort from scratch) and sweeps them. A pair is reported by the one region
//!   that holds the min corner of the two boxes' intersection, so bodies straddling cells make
//!   no duplicates. Only regions a change touched are swept again; the others keep their pairs.
//! - **Large bodies** (more than [`RegionSweep::LARGE_CELLS`] cells) stay out of the regions
//!   ([`large_bodies`]).
//! - **Adaptive layout, no user tuning.** The cell side starts at four times the median box's
//!   largest extent, the sweep axis is the one where the centres spread most; after a layout,
//!   the measured members per region tune the side: doubled below
//!   [`RegionSweep::SPARSE_REGION`] members or while more than `16 + n / 128` bodies are large
//!   (and then never halved below that side again, so the two rules cannot flip it back and
//!   forth), halved above [`RegionSweep::DENSE_REGION`] but not below the median extent. A round
//!   of up to six tunings follows a layout; then every [`RegionSweep::CHECK_PERIOD`] commits
//!   the occupancy is checked again with a band twice as wide. Boxes of median extent 1e-6 or
//!   less (points) start from the bounds' size over `∛n` instead.
//! - **Prefetch.** While one queued region is swept, the next one's changed ids, owned pairs
//!   and first members are asked for, and the region record of the one after it (where those
//!   live): in a sparse step most of the time is waiting for memory (1 % of 100k boxes moving,
//!   caches flushed between steps: 1.28 → 0.95 ms a step from the prefetch alone).
//! - **Memory** grows with the largest id, as the contract says: about 90 bytes an id (the box,
//!   the placement and up to eight remembered regions), plus 40 bytes per region membership.
//! - **Net changes.** Each region diffs its new pairs against its last ones; removals are
//!   applied before additions, so a pair whose owning cell changed cancels out in the pair
//!   set's log, and [`BroadPhase::added`] / [`BroadPhase::removed`] are the net changes.
//!
//! [`region`]: super::region
//! [`large_bodies`]: super::large_bodies

use super::large_bodies::{LargeBodies, LargeView};
use super::pair_set::PairSet;
use super::region::{BodyView, CellRange, Entry, Region, SweepFrame, SweepScratch};
use super::{
    BodyKind, BroadPhase, BroadPhaseError, Pair, ProxyId, StepStats, check_aabb, check_bulk,
    check_id,
};
use crate::bounding::Aabb;
use crate::pair_hash::{PairHashBuilder, hash_map_bytes};
use std::collections::HashMap;
use std::mem::size_of;

/// Asks the cache for the line holding `x` (a hint; nothing on other targets).
#[inline]
pub(super) fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    safe_arch::prefetch_t0(x);
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// Where a body sits as of the last commit.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Placement {
    Absent,
    Cells(CellRange),
    Large,
}

/// One id's state.
#[derive(Clone, Copy, Debug)]
struct Slot {
    aabb: Aabb,
    kind: BodyKind,
    present: bool,
    /// In `changed` for the coming commit.
    queued: bool,
    placed: Placement,
    /// The regions of `placed`'s cells in `CellRange::cells` order, when there are at most
    /// [`HOMES`] of them (`home_count` of them; 0 when not kept), so that a body moving within
    /// its cells finds its regions without hashing.
    homes: [u32; HOMES],
    home_count: u8,
}

/// Regions a slot remembers (a box up to two cells wide on every axis).
const HOMES: usize = 8;

impl Default for Slot {
    fn default() -> Self {
        Self {
            aabb: Aabb::EMPTY,
            kind: BodyKind::Dynamic,
            present: false,
            queued: false,
            placed: Placement::Absent,
            homes: [0; HOMES],
            home_count: 0,
        }
    }
}

/// The slots seen by a region's sweep and by the large bodies.
struct Slots<'a>(&'a [Slot]);

impl BodyView for Slots<'_> {
    #[inline]
    fn entry(&self, id: ProxyId, cell: [i32; 3], axes: [usize; 3]) -> Option<Entry> {
        let slot = &self.0[id as usize];
        match &slot.placed {
            Placement::Cells(range) if range.contains(cell) => {
                let is_static = slot.kind == BodyKind::Static;
                Some(Entry::new(&slot.aabb, id, is_static, range, axes))
            }
            _ => None,
        }
    }

    fn id_bound(&self) -> usize {
        self.0.len()
    }
}

impl LargeView for Slots<'_> {
    fn body(&self, id: ProxyId) -> Option<(Aabb, BodyKind, bool)> {
        let slot = self.0.get(id as usize).filter(|s| s.present)?;
        Some((slot.aabb, slot.kind, slot.placed == Placement::Large))
    }

    fn changed(&self, id: ProxyId) -> bool {
        self.0[id as usize].queued
    }
}

/// The grid of the current layout.
#[derive(Clone, Copy, Debug)]
struct Layout {
    frame: SweepFrame,
    /// The smallest side tuning may choose (the median box's largest extent).
    floor: f32,
}

/// Segmented sweep and prune (see the module doc).
#[derive(Debug, Default)]
pub struct RegionSweep {
    slots: Vec<Slot>,
    len: usize,
    changed: Vec<ProxyId>,
    layout: Option<Layout>,
    /// A new cell side to lay the regions out with at the next commit.
    relayout_to: Option<f32>,
    /// The smallest side tuning may halve to, raised when too many large bodies grew it.
    min_side: f32,
    cells: HashMap<[i32; 3], u32, PairHashBuilder>,
    regions: Vec<Region>,
    free_regions: Vec<u32>,
    dirty: Vec<u32>,
    /// Memberships over all regions (a body counts once per cell).
    memberships: usize,
    large: LargeBodies,
    large_changed: bool,
    scratch: SweepScratch,
    added: Vec<Pair>,
    removed: Vec<Pair>,
    pairs: PairSet,
    stats: StepStats,
    commits_since_check: u32,
    tunings_left: u32,
    layouts: u64,
    seen: Vec<ProxyId>,
}

impl RegionSweep {
    /// Bodies touching more cells than this are kept out of the regions.
    pub const LARGE_CELLS: u64 = 64;
    /// Mean members per region below which the cells grow.
    pub const SPARSE_REGION: f64 = 6.0;
    /// Mean members per region above which the cells shrink.
    pub const DENSE_REGION: f64 = 96.0;
    /// Commits between occupancy checks once tuned.
    pub const CHECK_PERIOD: u32 = 64;
    /// Tuning steps after a layout.
    const TUNINGS: u32 = 6;

    /// An empty broad phase.
    pub fn new() -> Self {
        Self::default()
    }

    /// The side of the cells, once bodies have been committed.
    pub fn cell_size(&self) -> Option<f32> {
        self.layout.map(|l| 1.0 / l.frame.inverse_size)
    }

    /// Regions holding at least one body.
    pub fn region_count(&self) -> usize {
        self.regions.len() - self.free_regions.len()
    }

    /// Mean bodies per region (a body counts once in each region it touches); 0 when empty.
    pub fn members_per_region(&self) -> f64 {
        self.memberships as f64 / self.region_count().max(1) as f64
    }

    /// Bodies kept out of the regions for their size (as of the last time one changed).
    pub fn large_bodies(&self) -> usize {
        self.large.count()
    }

    /// Times the regions were laid out (the first layout and each re-tuning).
    pub fn layouts(&self) -> u64 {
        self.layouts
    }

    fn slot(&self, id: ProxyId) -> Option<&Slot> {
        self.slots.get(id as usize).filter(|s| s.present)
    }

    fn queue(&mut self, id: ProxyId) {
        let slot = &mut self.slots[id as usize];
        if !slot.queued {
            slot.queued = true;
            self.changed.push(id);
        }
    }

    fn push(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) {
        let at = id as usize;
        if at >= self.slots.len() {
            self.slots.resize(at + 1, Slot::default());
        }
        let slot = &mut self.slots[at];
        (slot.aabb, slot.kind, slot.present) = (aabb, kind, true);
        self.len += 1;
        self.queue(id);
    }
}

// ---------------------------------------------------------------- layout

impl RegionSweep {
    /// Whether the next commit lays the regions out (first bodies, or a tuning asked for it).
    fn wants_layout(&self) -> bool {
        (self.layout.is_none() && self.len > 0) || self.relayout_to.is_some()
    }

    /// Lays the regions out anew: every pair handed to `removed`, every present body queued
    /// for placement in the new cells.
    fn relayout(&mut self) {
        for region in &mut self.regions {
            self.removed.append(&mut region.owned);
        }
        self.large.clear(&mut self.removed);
        self.regions.clear();
        self.free_regions.clear();
        self.cells.clear();
        self.memberships = 0;
        let size = self.relayout_to.take();
        if size.is_none() {
            self.tunings_left = Self::TUNINGS;
        }
        self.layout = self.first_layout().map(|mut layout| {
            if let Some(size) = size {
                layout.frame.inverse_size = 1.0 / size;
            }
            layout
        });
        for id in 0..self.slots.len() as ProxyId {
            let slot = &mut self.slots[id as usize];
            slot.placed = Placement::Absent;
            slot.home_count = 0;
            if slot.present {
                self.queue(id);
            }
        }
        self.large_changed = true;
        self.layouts += 1;
        self.stats.rebuilt = true;
    }

    /// The sweep axis and the starting cell side for the present bodies.
    fn first_layout(&self) -> Option<Layout> {
        let boxes: Vec<Aabb> = self
            .slots
            .iter()
            .filter(|s| s.present)
            .map(|s| s.aabb)
            .collect();
        let mut extents: Vec<f32> = boxes.iter().map(|b| b.extents().max_element()).collect();
        let middle = (extents.len() / 2).min(extents.len().checked_sub(1)?);
        let median = *extents.select_nth_unstable_by(middle, f32::total_cmp).1;
        let size = if median > 1e-6 && (4.0 * median).is_finite() {
            4.0 * median
        } else {
            let bounds = boxes.iter().fold(Aabb::EMPTY, |u, b| u.union(b));
            let spread = bounds.extents().max_element() / (boxes.len() as f32).cbrt();
            if spread.is_finite() && spread > 1e-3 {
                spread
            } else {
                1.0
            }
        };
        let axis = super::sort_sweep::sweep_axis(&boxes);
        Some(Layout {
            frame: SweepFrame {
                axes: [axis, (axis + 1) % 3, (axis + 2) % 3],
                inverse_size: 1.0 / size,
            },
            floor: if median > 1e-6 { median } else { size / 8.0 },
        })
    }

    /// After a commit: whether the cells should grow or shrink (applied at the next commit).
    fn tune(&mut self) {
        let Some(layout) = self.layout else {
            return;
        };
        self.commits_since_check += 1;
        if self.tunings_left == 0 && self.commits_since_check < Self::CHECK_PERIOD {
            return;
        }
        self.commits_since_check = 0;
        let regions = self.region_count();
        if regions == 0 {
            return;
        }
        let mean = self.memberships as f64 / regions as f64;
        let size = 1.0 / layout.frame.inverse_size;
        // Once tuned, only a clear drift (a factor two past the band) starts tuning again.
        let slack = if self.tunings_left > 0 { 1.0 } else { 2.0 };
        // Too many bodies over `LARGE_CELLS` cells would make the large-body tests quadratic.
        let too_many_large = self.large.count() > 16 + self.len / 128;
        if too_many_large {
            self.min_side = self.min_side.max(size * 2.0);
        }
        let smallest = layout.floor.max(self.min_side);
        let next = if too_many_large || (mean < Self::SPARSE_REGION / slack && regions > 1) {
            Some(size * 2.0)
        } else if mean > Self::DENSE_REGION * slack && size / 2.0 >= smallest {
            Some(size / 2.0)
        } else {
            None
        };
        match next.filter(|s| s.is_finite()) {
            Some(size) => {
                self.relayout_to = Some(size);
                // A periodic check that finds drift starts a new round of tuning.
                self.tunings_left = self
                    .tunings_left
                    .checked_sub(1)
                    .unwrap_or(Self::TUNINGS - 1);
            }
            None => self.tunings_left = 0,
        }
    }
}

// ---------------------------------------------------------------- commit

impl RegionSweep {
    /// The region of a cell, created if missing.
    fn region_at(&mut self, cell: [i32; 3]) -> u32 {
        if let Some(&at) = self.cells.get(&cell) {
            return at;
        }
        let at = self.free_regions.pop().unwrap_or(self.regions.len() as u32);
        if at as usize == self.regions.len() {
            self.regions.push(Region::default());
        }
        self.regions[at as usize].reuse(cell);
        self.cells.insert(cell, at);
        at
    }

    /// Tells a region that a body of its cell (before or now) changed, and queues it.
    fn touch(&mut self, at: u32, id: ProxyId) {
        let region = &mut self.regions[at as usize];
        region.changed.push(id);
        if !region.dirty {
            region.dirty = true;
            self.dirty.push(at);
        }
    }

    /// Moves a changed body from its old cells to its new ones, queuing every region touched.
    fn place(&mut self, id: ProxyId, inverse_size: f32) {
        let slot = self.slots[id as usize];
        let range = CellRange::of(&slot.aabb, inverse_size);
        if slot.present && slot.placed == Placement::Cells(range) {
            // Moved within its cells, the common case under coherence: its regions re-read it
            // (the remembered ones without hashing; a body over more cells than it remembers
            // finds them once, where leaving and re-entering found them twice).
            self.leave(&slot, id);
            return;
        }
        let new = if !slot.present {
            Placement::Absent
        } else if range.count() > Self::LARGE_CELLS {
            Placement::Large
        } else {
            Placement::Cells(range)
        };
        self.leave(&slot, id);
        let (mut kept, mut count) = ([0; HOMES], 0);
        if let Placement::Cells(range) = new {
            let remember = range.count() <= HOMES as u64;
            for cell in range.cells() {
                let at = self.region_at(cell);
                self.touch(at, id);
                if remember {
                    kept[count] = at;
                    count += 1;
                }
            }
        }
        self.large_changed |= slot.placed == Placement::Large || new == Placement::Large;
        let slot = &mut self.slots[id as usize];
        (slot.placed, slot.homes, slot.home_count) = (new, kept, count as u8);
    }

    /// Touches the regions of a body's old cells (their sweep drops it if it left).
    fn leave(&mut self, slot: &Slot, id: ProxyId) {
        let homes = &slot.homes[..usize::from(slot.home_count)];
        if !homes.is_empty() {
            for &at in homes {
                self.touch(at, id);
            }
        } else if let Placement::Cells(old) = slot.placed {
            for cell in old.cells() {
                if let Some(&at) = self.cells.get(&cell) {
                    self.touch(at, id);
                }
            }
        }
    }

    /// Sweeps one queued region; empty regions are freed.
    fn sweep_region(&mut self, at: u32, frame: SweepFrame) {
        let region = &mut self.regions[at as usize];
        region.dirty = false;
        let changes = (&mut self.added, &mut self.removed);
        let (delta, counts) = region.sweep(&Slots(&self.slots), frame, &mut self.scratch, changes);
        self.memberships = self.memberships.saturating_add_signed(delta);
        if region.entries.is_empty() {
            // Its pairs were all reported removed by the sweep.
            self.cells.remove(&region.cell);
            self.free_regions.push(at);
        }
        self.stats.endpoint_swaps += counts.swaps;
        self.stats.pair_tests += counts.tests;
    }
}

impl BroadPhase for RegionSweep {
    fn insert(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) -> Result<(), BroadPhaseError> {
        check_id(id)?;
        check_aabb(id, &aabb)?;
        if self.slot(id).is_some() {
            return Err(BroadPhaseError::DuplicateId(id));
        }
        self.push(id, aabb, kind);
        Ok(())
    }

    fn insert_bulk(&mut self, bodies: &[(ProxyId, Aabb, BodyKind)]) -> Result<(), BroadPhaseError> {
        let mut seen = std::mem::take(&mut self.seen);
        let checked = check_bulk(bodies, |id| self.slot(id).is_some(), &mut seen);
        self.seen = seen;
        checked?;
        for &(id, aabb, kind) in bodies {
            self.push(id, aabb, kind);
        }
        Ok(())
    }

    fn update(&mut self, id: ProxyId, aabb: Aabb) -> Result<(), BroadPhaseError> {
        self.slot(id).ok_or(BroadPhaseError::UnknownId(id))?;
        check_aabb(id, &aabb)?;
        // The same box again is no change (a game may re-send unchanged boxes).
        if self.slots[id as usize].aabb != aabb {
            self.slots[id as usize].aabb = aabb;
            self.queue(id);
        }
        Ok(())
    }

    fn remove(&mut self, id: ProxyId) -> Result<(), BroadPhaseError> {
        self.slot(id).ok_or(BroadPhaseError::UnknownId(id))?;
        self.slots[id as usize].present = false;
        self.len -= 1;
        self.queue(id);
        Ok(())
    }

    fn commit(&mut self) {
        self.stats = StepStats {
            changed: !self.changed.is_empty(),
            ..StepStats::default()
        };
        self.added.clear();
        self.removed.clear();
        if self.wants_layout() {
            self.relayout();
        }
        if let Some(layout) = self.layout {
            let changed = std::mem::take(&mut self.changed);
            for &id in &changed {
                self.place(id, layout.frame.inverse_size);
            }
            let dirty = std::mem::take(&mut self.dirty);
            for (k, &at) in dirty.iter().enumerate() {
                if let Some(&ahead) = dirty.get(k + 2) {
                    prefetch(&self.regions[ahead as usize]);
                }
                if let Some(&next) = dirty.get(k + 1) {
                    self.regions[next as usize].prefetch();
                }
                self.sweep_region(at, layout.frame);
            }
            self.dirty = dirty;
            self.dirty.clear();
            if self.large_changed || !self.large.is_idle() {
                self.stats.pair_tests += self.large.refresh(
                    &Slots(&self.slots),
                    &changed,
                    self.large_changed,
                    (&mut self.added, &mut self.removed),
                );
            }
            self.changed = changed;
        }
        for &id in &self.changed {
            self.slots[id as usize].queued = false;
        }
        self.changed.clear();
        self.large_changed = false;
        for &pair in &self.removed {
            self.pairs.remove(pair);
        }
        for &pair in &self.added {
            self.pairs.add(pair);
        }
        self.pairs.finish_step();
        self.tune();
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
        let regions: usize = self
            .regions
            .iter()
            .map(|r| {
                r.entries.capacity() * size_of::<Entry>()
                    + r.changed.capacity() * size_of::<ProxyId>()
                    + r.owned.capacity() * size_of::<Pair>()
            })
            .sum();
        self.slots.capacity() * size_of::<Slot>()
            + (self.changed.capacity() + self.seen.capacity()) * size_of::<ProxyId>()
            + self.regions.capacity() * size_of::<Region>()
            + regions
            + (self.free_regions.capacity() + self.dirty.capacity()) * size_of::<u32>()
            + hash_map_bytes(&self.cells)
            + self.large.memory_bytes()
            + self.scratch.memory_bytes()
            + (self.added.capacity() + self.removed.capacity()) * size_of::<Pair>()
            + self.pairs.memory_bytes()
    }

    fn len(&self) -> usize {
        self.len
    }

    fn contains(&self, id: ProxyId) -> bool {
        self.slot(id).is_some()
    }

    fn aabb(&self, id: ProxyId) -> Option<Aabb> {
        self.slot(id).map(|s| s.aabb)
    }
}
