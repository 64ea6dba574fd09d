//! One region of [`super::RegionSweep`]: the bodies whose boxes touch one cell of a uniform
//! grid, kept sorted along the sweep axis from step to step, and the pairs this region owns.
//!
//! The sort is incremental (insertion sort from last step's order: under coherence a body
//! passes few others, and a region holds tens of bodies, not the whole scene), with a budget:
//! past `REGION_SWAP_BUDGET · n` swaps the region finishes with a sort from scratch, the rule
//! of [`super::AdaptiveSweep`] brought down to one region. The sweep is Ericson's forward
//! sweep (*Real-Time Collision Detection*, §7.5.2) over the members' compact entries.
//!
//! **Who reports a pair.** A box belongs to every cell it touches, so two boxes may share
//! several regions. Each pair is reported by exactly one: the region whose cell holds the
//! *min corner of the two boxes' intersection* (Terdiman's and PhysX's multi-box pruning rule).
//! That corner lies inside both boxes, so its cell is in both boxes' cell ranges; the cell
//! function is monotone, so that cell is the larger of the two boxes' min cells on each axis,
//! and the test needs no shared state between regions.

use super::pair_diff::diff_sorted;
use super::{Pair, ProxyId};
use crate::bounding::Aabb;

/// Insertion sort gives up and sorts from scratch past this many swaps per member.
const REGION_SWAP_BUDGET: u64 = 8;

/// A sweep of few changed members takes at most this many (ids, repeats included): each is
/// looked for by a scan of the members and checked against every owned pair, so more would
/// cost more than the full sweep does.
const MAX_FEW: usize = 16;

/// The integer cell of a coordinate (monotone in `v`; saturates at the `i32` range).
///
/// `f32::floor` is a libm call on the baseline x86-64 target (no SSE4.1 `roundss`), a tenth of
/// a step in a profile; truncation and a correction give the same cell.
#[inline]
pub(super) fn cell_of(v: f32, inverse_size: f32) -> i32 {
    let x = v * inverse_size;
    let truncated = x as i32;
    if (truncated as f32) > x {
        truncated.saturating_sub(1)
    } else {
        truncated
    }
}

/// The cells a box touches, inclusive on both ends, per world axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct CellRange {
    pub lo: [i32; 3],
    pub hi: [i32; 3],
}

impl CellRange {
    /// The cells `aabb` touches for cells of side `1 / inverse_size`.
    pub fn of(aabb: &Aabb, inverse_size: f32) -> Self {
        let cell = |v| cell_of(v, inverse_size);
        Self {
            lo: [cell(aabb.min.x), cell(aabb.min.y), cell(aabb.min.z)],
            hi: [cell(aabb.max.x), cell(aabb.max.y), cell(aabb.max.z)],
        }
    }

    /// How many cells the range covers (saturating: a huge box counts as huge, not as 0).
    pub fn count(&self) -> u64 {
        (0..3).fold(1u64, |n, axis| {
            let span = (i64::from(self.hi[axis]) - i64::from(self.lo[axis]) + 1) as u64;
            n.saturating_mul(span)
        })
    }

    /// Whether the range holds the cell.
    #[inline]
    pub fn contains(&self, cell: [i32; 3]) -> bool {
        (0..3).all(|axis| self.lo[axis] <= cell[axis] && cell[axis] <= self.hi[axis])
    }

    /// Every cell of the range (callers bound the count first).
    pub fn cells(self) -> impl Iterator<Item = [i32; 3]> {
        let [x0, y0, z0] = self.lo;
        let [x1, y1, z1] = self.hi;
        (x0..=x1).flat_map(move |x| (y0..=y1).flat_map(move |y| (z0..=z1).map(move |z| [x, y, z])))
    }
}

/// The bodies of one cell and the pairs it reported at the last commit.
#[derive(Debug, Default)]
pub(super) struct Region {
    /// The cell.
    pub cell: [i32; 3],
    /// The members' sweep entries, sorted along the sweep axis as of the last sweep. An
    /// unchanged body's entry is kept as it is: a sweep of few changed members reads only
    /// theirs again.
    pub entries: Vec<Entry>,
    /// Bodies that changed this commit and touched this cell before or after (arrivals,
    /// departures and movers), in any order, perhaps repeated.
    pub changed: Vec<ProxyId>,
    /// The pairs this region owns: sorted after a full sweep, the changed members' new pairs
    /// appended after a sweep of few (sorted again by the next full sweep, which diffs them).
    pub owned: Vec<Pair>,
    /// Whether pairs were appended to `owned` since it was last sorted.
    owned_unsorted: bool,
    /// At least the longest member's length on the sweep axis, rounded up: how far back a
    /// changed member's backward walk must look. Found by the first sweep of few after a full
    /// sweep (`None` until then: full sweeps do not need it); from then on it only grows (a
    /// member that leaves does not lower it), which keeps it an upper bound.
    longest: Option<f32>,
    /// Queued for this commit's sweep.
    pub dirty: bool,
}

/// What a region needs to know of a body during its sweep.
pub(super) trait BodyView {
    /// The body's sweep entry (axes in `axes` order), if it belongs to `cell` now.
    fn entry(&self, id: ProxyId, cell: [i32; 3], axes: [usize; 3]) -> Option<Entry>;
    /// One past the largest id.
    fn id_bound(&self) -> usize;
}

/// `Entry::owner`'s bit for a static body.
const STATIC: u32 = 1;
/// `Entry::owner`'s bit, during a sweep of few changed members, for a changed one (ids use
/// bits 1 to 30).
const FRESH: u32 = 1 << 31;

/// One member as the sweep reads it: 40 bytes, so a region's entries stay in a few cache
/// lines and insertion sort moves them whole.
#[derive(Clone, Copy, Debug)]
pub(super) struct Entry {
    /// Min on the sweep axis (the sort key).
    pub lo: f32,
    /// Max on the sweep axis.
    pub hi: f32,
    /// `[min_u, max_u, min_v, max_v]` on the other two axes.
    pub cross: [f32; 4],
    /// `id << 1 | STATIC`, plus `FRESH` while a sweep of few changed members runs.
    pub owner: u32,
    /// The cell of the box's min corner, sweep axis first.
    pub low_cell: [i32; 3],
}

impl Entry {
    /// The entry of a box for the axis order `[axis, u, v]`.
    #[inline]
    pub fn new(
        aabb: &Aabb,
        id: ProxyId,
        is_static: bool,
        range: &CellRange,
        axes: [usize; 3],
    ) -> Self {
        let [axis, u, v] = axes;
        // Arrays, not `Vec3` indexing (a three-way branch per read).
        let (min, max) = (aabb.min.to_array(), aabb.max.to_array());
        Self {
            lo: min[axis],
            hi: max[axis],
            cross: [min[u], max[u], min[v], max[v]],
            owner: id << 1 | u32::from(is_static),
            low_cell: [range.lo[axis], range.lo[u], range.lo[v]],
        }
    }

    #[inline]
    fn id(&self) -> ProxyId {
        (self.owner & !FRESH) >> 1
    }

    #[inline]
    fn is_fresh(&self) -> bool {
        self.owner & FRESH != 0
    }
}

/// Reusable buffers of the sweeps.
#[derive(Debug, Default)]
pub(super) struct SweepScratch {
    /// Per id, the number of the last full region sweep that met it.
    met: Vec<u32>,
    /// This region sweep's number.
    sweep_number: u32,
    /// The pairs a sweep found.
    found: Vec<Pair>,
    /// Owned pairs of changed members (few changed).
    dropped: Vec<Pair>,
    /// The changed ids, each once (few changed).
    ids: Vec<ProxyId>,
    /// Where the changed members' entries are after the move (few changed).
    at: Vec<usize>,
}

impl SweepScratch {
    /// A number no id has met yet, with `met` covering ids below `id_bound`.
    fn next_sweep_number(&mut self, id_bound: usize) -> u32 {
        if self.met.len() < id_bound {
            self.met.resize(id_bound, 0);
        }
        self.sweep_number = self.sweep_number.wrapping_add(1);
        if self.sweep_number == 0 {
            // Wrapped: forget every old number rather than mistake one for this sweep's.
            self.met.fill(0);
            self.sweep_number = 1;
        }
        self.sweep_number
    }

    /// Heap bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.met.capacity() * std::mem::size_of::<u32>()
            + (self.found.capacity() + self.dropped.capacity()) * std::mem::size_of::<Pair>()
            + self.ids.capacity() * std::mem::size_of::<ProxyId>()
            + self.at.capacity() * std::mem::size_of::<usize>()
    }
}

/// Counters of one region's sweep.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct SweepCounts {
    pub swaps: u64,
    pub tests: u64,
}

/// The sweep's axis order and cell size.
#[derive(Clone, Copy, Debug)]
pub(super) struct SweepFrame {
    /// Sweep axis, then the two others.
    pub axes: [usize; 3],
    pub inverse_size: f32,
}

impl Region {
    /// Gives a free region to `cell`, keeping its buffers. (A region is freed once a sweep left
    /// it empty, and only a full sweep can: the bounds below are reset for the new cell all
    /// the same.)
    pub fn reuse(&mut self, cell: [i32; 3]) {
        (self.cell, self.longest, self.owned_unsorted) = (cell, None, false);
    }

    /// Asks the cache for what a sweep reads first: the changed ids, the owned pairs and the
    /// members (a line in every 80 bytes of the first 32).
    pub fn prefetch(&self) {
        if let Some(first) = self.changed.first() {
            super::regions::prefetch(first);
        }
        if let Some(first) = self.owned.first() {
            super::regions::prefetch(first);
        }
        for entry in self.entries.iter().step_by(2).take(16) {
            super::regions::prefetch(entry);
        }
    }

    /// Brings the entries up to date with the changed bodies, re-sorts them and finds the pairs
    /// this region owns now, appending the difference with the last ones to `added` and
    /// `removed`. Returns the change in the number of members and the work done.
    ///
    /// When few members changed, only they are read, moved and swept (against their
    /// neighbours in sweep order), and the last pairs between unchanged members are kept: a
    /// region with one mover among thirty costs about one body's sweep, not thirty.
    pub fn sweep(
        &mut self,
        bodies: &impl BodyView,
        frame: SweepFrame,
        scratch: &mut SweepScratch,
        changes: (&mut Vec<Pair>, &mut Vec<Pair>),
    ) -> (isize, SweepCounts) {
        let before = self.entries.len() as isize;
        let [axis, u, v] = frame.axes;
        let cell = [self.cell[axis], self.cell[u], self.cell[v]];
        let few = self.changed.len() * 4 < self.entries.len() && self.changed.len() <= MAX_FEW;
        let counts = if few {
            self.sweep_few(bodies, frame.axes, cell, scratch, changes)
        } else {
            self.sweep_all(bodies, frame.axes, cell, scratch, changes)
        };
        self.changed.clear();
        (self.entries.len() as isize - before, counts)
    }

    /// Every member read again, re-sorted and swept, and the pairs diffed against the last
    /// ones.
    fn sweep_all(
        &mut self,
        bodies: &impl BodyView,
        axes: [usize; 3],
        cell: [i32; 3],
        scratch: &mut SweepScratch,
        (added, removed): (&mut Vec<Pair>, &mut Vec<Pair>),
    ) -> SweepCounts {
        self.refresh_all(bodies, axes, scratch);
        let swaps = sort_entries(&mut self.entries);
        self.longest = None;
        let tests = sweep_owned(&self.entries, cell, &mut scratch.found);
        scratch.found.sort_unstable();
        if std::mem::take(&mut self.owned_unsorted) {
            self.owned.sort_unstable();
        }
        diff_sorted(&self.owned, &scratch.found, added, removed);
        self.set_owned(&scratch.found);
        SweepCounts { swaps, tests }
    }

    /// The changed members moved to their new places and their pairs found again; the others
    /// kept. Only the changed members' old and new pairs are sorted and diffed; the new ones
    /// are appended to the kept ones.
    fn sweep_few(
        &mut self,
        bodies: &impl BodyView,
        axes: [usize; 3],
        cell: [i32; 3],
        scratch: &mut SweepScratch,
        (added, removed): (&mut Vec<Pair>, &mut Vec<Pair>),
    ) -> SweepCounts {
        let (swaps, longest) = self.move_changed(bodies, axes, scratch);
        // The changed ids (at most `MAX_FEW`), not `met`: a scan of a few ids in cache, where
        // `met` was a cache miss per partner id (a third of a sparse step's misses).
        let ids = &scratch.ids;
        let unchanged = |id: ProxyId| ids.iter().all(|&c| c != id);
        let dropped = &mut scratch.dropped;
        dropped.clear();
        self.owned.retain(|p| {
            let keep = unchanged(p.a) && unchanged(p.b);
            if !keep {
                dropped.push(*p);
            }
            keep
        });
        let tests = sweep_changed(
            &self.entries,
            &scratch.at,
            longest,
            cell,
            &mut scratch.found,
        );
        for &i in &scratch.at {
            self.entries[i].owner &= !FRESH;
        }
        scratch.found.sort_unstable();
        scratch.dropped.sort_unstable();
        diff_sorted(&scratch.dropped, &scratch.found, added, removed);
        self.owned.extend_from_slice(&scratch.found);
        self.owned_unsorted |= !scratch.found.is_empty();
        SweepCounts { swaps, tests }
    }

    /// Copies the new owned pairs in. Copied, not swapped with the scratch buffer: a swap
    /// would pass buffers from region to region, and each would keep meeting new highs
    /// (allocations in a steady state).
    fn set_owned(&mut self, pairs: &[Pair]) {
        self.owned.clear();
        self.owned.extend_from_slice(pairs);
    }

    /// Re-reads every member, drops those that left, and appends the changed ids not among
    /// them (told apart by this sweep's number in `met`: no sorting, no search).
    fn refresh_all(
        &mut self,
        bodies: &impl BodyView,
        axes: [usize; 3],
        scratch: &mut SweepScratch,
    ) {
        let seen = scratch.next_sweep_number(bodies.id_bound());
        let (cell, met) = (self.cell, &mut scratch.met);
        self.entries.retain_mut(|e| {
            let id = e.id();
            met[id as usize] = seen;
            bodies
                .entry(id, cell, axes)
                .map(|fresh| *e = fresh)
                .is_some()
        });
        for &id in &self.changed {
            if std::mem::replace(&mut met[id as usize], seen) != seen {
                self.entries.extend(bodies.entry(id, cell, axes));
            }
        }
    }

    /// Brings each changed body's entry up to date at its sorted place, marked `FRESH`: found
    /// among the members by id (the unchanged members' bodies are not read), re-read, and
    /// moved by insertion to its new place (a few places under coherence);
    /// an arrival is inserted, a departure removed. The changed members' places end in
    /// `scratch.at`, the changed ids (each once) in `scratch.ids`. Returns the
    /// places the entries passed (insertion sort's swaps) and the bound on the members'
    /// length.
    fn move_changed(
        &mut self,
        bodies: &impl BodyView,
        axes: [usize; 3],
        scratch: &mut SweepScratch,
    ) -> (u64, f32) {
        let ids = &mut scratch.ids;
        ids.clear();
        let mut swaps = 0;
        for &id in &self.changed {
            // At most `MAX_FEW` ids: a scan in cache tells repeated ones apart.
            if ids.contains(&id) {
                continue;
            }
            ids.push(id);
            let from = find(&self.entries, id);
            match (from, bodies.entry(id, self.cell, axes)) {
                (Some(at), Some(mut entry)) => {
                    entry.owner |= FRESH;
                    self.entries[at] = entry;
                    swaps += settle(&mut self.entries, at);
                }
                (Some(at), None) => {
                    self.entries.remove(at);
                }
                (None, Some(mut entry)) => {
                    entry.owner |= FRESH;
                    let to = self.entries.partition_point(|e| e.lo < entry.lo);
                    self.entries.insert(to, entry);
                }
                (None, None) => {}
            }
        }
        // Each changed member's place (at most `MAX_FEW` scans; a pass over every member for its
        // fresh mark cost a sparse step 3 % more instructions); a departure has none.
        scratch.at.clear();
        let entries = &self.entries;
        scratch
            .at
            .extend(ids.iter().filter_map(|&id| find(entries, id)));
        let longest = match self.longest {
            Some(longest) => scratch.at.iter().fold(longest, |m, &i| {
                m.max((entries[i].hi - entries[i].lo).next_up())
            }),
            None => longest_member(entries),
        };
        self.longest = Some(longest);
        (swaps, longest)
    }
}

/// Moves the entry at `at` left or right until `entries` is sorted by `lo` again (it is but
/// for that entry); returns the places it passed.
fn settle(entries: &mut [Entry], at: usize) -> u64 {
    let mut j = at;
    while j > 0 && entries[j].lo < entries[j - 1].lo {
        entries.swap(j, j - 1);
        j -= 1;
    }
    while j + 1 < entries.len() && entries[j + 1].lo < entries[j].lo {
        entries.swap(j, j + 1);
        j += 1;
    }
    at.abs_diff(j) as u64
}

/// Where `id`'s entry is among `entries`: a linear scan, which the hardware prefetches. A
/// binary search on the sweep-axis min reads five members instead of thirty, but each read
/// waits for the last one: on a region out of cache (a sparse step touches regions it has not
/// seen for a while) it cost a fifth more time per step than the scan.
fn find(entries: &[Entry], id: ProxyId) -> Option<usize> {
    entries.iter().position(|e| e.id() == id)
}

/// The longest member's length on the sweep axis, rounded up: `hi - lo` rounded to nearest
/// can fall short of the true length, and then `a.lo - longest` would stop a backward walk one
/// member early (a touching pair lost). `next_up` is monotone, so rounding the largest length
/// up is rounding each (one call, not one per member).
fn longest_member(entries: &[Entry]) -> f32 {
    entries
        .iter()
        .fold(0.0f32, |m, e| m.max(e.hi - e.lo))
        .next_up()
}

/// Insertion sort by `lo` with a swap budget, then a sort from scratch if it ran out; returns
/// the swaps made.
fn sort_entries(entries: &mut [Entry]) -> u64 {
    let budget = REGION_SWAP_BUDGET * entries.len() as u64;
    let mut swaps = 0u64;
    for i in 1..entries.len() {
        let mut j = i;
        while j > 0 && entries[j].lo < entries[j - 1].lo {
            entries.swap(j, j - 1);
            j -= 1;
        }
        swaps += (i - j) as u64;
        if swaps > budget {
            entries.sort_unstable_by(|a, b| a.lo.total_cmp(&b.lo).then(a.owner.cmp(&b.owner)));
            break;
        }
    }
    swaps
}

/// The pair of two entries overlapping on the cross axes, if this region owns it (see the
/// module doc) and not both are static; the sweep has checked the sweep axis.
///
/// The intersection's min corner is the larger of the two mins on each axis, and the cell
/// function is monotone, so its cell is the larger of the two boxes' min cells: integer
/// compares on cells found once per body, no float work per pair.
#[inline]
fn owned_pair(a: &Entry, b: &Entry, cell: [i32; 3]) -> Option<Pair> {
    let (c, d) = (a.cross, b.cross);
    // `&`, not `&&`: four compares without branches beat unpredictable early exits.
    let overlap = (c[0] <= d[1]) & (d[0] <= c[1]) & (c[2] <= d[3]) & (d[2] <= c[3]);
    if !overlap || a.owner & b.owner & STATIC != 0 {
        return None;
    }
    let (ca, cb) = (a.low_cell, b.low_cell);
    let owned = (ca[0].max(cb[0]) == cell[0])
        & (ca[1].max(cb[1]) == cell[1])
        & (ca[2].max(cb[2]) == cell[2]);
    owned.then(|| Pair::ordered(a.id(), b.id()))
}

/// The forward sweep over all members; `cell` is the region's cell in sweep-axis order.
/// Returns the cross-axis tests made.
fn sweep_owned(entries: &[Entry], cell: [i32; 3], found: &mut Vec<Pair>) -> u64 {
    found.clear();
    let mut tests = 0;
    for (i, a) in entries.iter().enumerate() {
        let rest = &entries[i + 1..];
        let reached = rest.iter().position(|b| b.lo > a.hi).unwrap_or(rest.len());
        for b in &rest[..reached] {
            if let Some(pair) = owned_pair(a, b, cell) {
                found.push(pair);
            }
        }
        tests += reached as u64;
    }
    tests
}

/// Each changed member (at the places `at`, marked `FRESH`) swept against its neighbours:
/// forward over the members starting before it ends, backward over those that may still reach
/// it (no further back than `longest`), skipping changed ones backward (their own forward sweep
/// finds the pair).
fn sweep_changed(
    entries: &[Entry],
    at: &[usize],
    longest: f32,
    cell: [i32; 3],
    found: &mut Vec<Pair>,
) -> u64 {
    found.clear();
    let mut tests = 0;
    for &i in at {
        let a = &entries[i];
        for b in entries[i + 1..].iter().take_while(|b| b.lo <= a.hi) {
            tests += 1;
            found.extend(owned_pair(a, b, cell));
        }
        let reach = a.lo - longest;
        for b in entries[..i].iter().rev().take_while(|b| b.lo >= reach) {
            if !b.is_fresh() && b.hi >= a.lo {
                tests += 1;
                found.extend(owned_pair(a, b, cell));
            }
        }
    }
    tests
}

#[cfg(test)]
#[path = "region_tests.rs"]
mod tests;
