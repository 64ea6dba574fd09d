//! Grid queries answered again without visiting cells, for bodies that moved little since the
//! last step: the fattened-AABB idea of Box2D's dynamic tree (`b2_aabbMargin`) and Bullet's
//! `btDbvt`, applied to the queries of the static grid instead of to the tree's leaves.
//!
//! A query of `key` with box `b` asks the grid for every static meeting a *fattened* box
//! `f ⊇ b` (`b` grown by [`FAT_FRACTION`] of its size on each axis) and keeps that list. The
//! next round, if `b'` still lies inside `f` and the grid has not changed, every static meeting
//! `b'` is in the list (it meets `b' ⊆ f`), so the answer is the list filtered by the exact box
//! test: no cell is hashed, no object stamped, nothing sorted. A resting body sits inside its
//! fattened box step after step; a body crossing it queries the grid again with a new one.
//!
//! **The answer is exactly [`StaticGrid::query`]'s** (the same ids in the same ascending order):
//! the cache changes only what an answer costs. That holds because every edit of the grid gives
//! it a new revision ([`StaticGrid::revision`]), and a query that sees a new revision forgets
//! every list.
//!
//! The lists live in two flat buffers: the lists kept last round are read while this round's
//! are written, so a body that slept (and was not queried) loses its list and memory stays
//! proportional to the bodies queried in one round.

use super::error::{GridError, check_aabb};
use super::stats::GridQueryStats;
use super::storage::StaticGrid;
use crate::bounding::Aabb;
use crate::broad_phase::MAX_PROXY_ID;

/// How much a kept query box is grown on each side, as a fraction of its size along that axis
/// (a quarter: a resting body's jitter and a slow body's few steps stay inside, while a moving
/// body's list grows by at most half its box in each direction).
pub const FAT_FRACTION: f32 = 0.25;

/// What one key's last query kept.
#[derive(Clone, Copy, Debug)]
struct Entry {
    /// The fattened box the list answers for.
    fat: Aabb,
    /// Where the list is in the buffer of the round named by `round`.
    start: u32,
    len: u32,
    /// The round that wrote the list (0: none).
    round: u32,
}

const NO_ENTRY: Entry = Entry {
    fat: Aabb::EMPTY,
    start: 0,
    len: 0,
    round: 0,
};

/// Kept answers of [`StaticGrid`] queries, by caller-chosen key (a moving body's proxy id); see
/// the module docs. Call [`GridQueryCache::begin_round`] once per step, then
/// [`GridQueryCache::query`] for each body.
#[derive(Clone, Debug, Default)]
pub struct GridQueryCache {
    entries: Vec<Entry>,
    /// The slots (in ascending id order) of the lists written this round.
    lists: Vec<u32>,
    /// The lists of the previous round, read by this round's reused queries.
    previous: Vec<u32>,
    /// The current round (0 before the first).
    round: u32,
    /// The grid revision the lists were taken from.
    revision: Option<u64>,
    /// Scratch for a query of the grid.
    packed: Vec<u64>,
}

impl GridQueryCache {
    /// Starts a round (a step): the lists written in the last round become readable (to the
    /// queries of a grid unchanged since they were taken; `query` checks).
    pub fn begin_round(&mut self) {
        std::mem::swap(&mut self.lists, &mut self.previous);
        self.lists.clear();
        self.round = self.round.wrapping_add(1);
        if self.round == 0 {
            // 2³² rounds later: no entry may look as if this round wrote it.
            self.entries.clear();
            self.round = 1;
        }
    }

    /// Writes to `out` (cleared first) what `grid.query(aabb, out)` would: the id of every
    /// object whose AABB intersects `aabb`, once each, ascending. Reuses `key`'s list when
    /// `aabb` lies inside the box it was taken for and `grid` has not changed since it was
    /// taken. Memory grows with the largest key, as
    /// a broad phase's with its largest id: keys above [`MAX_PROXY_ID`] are answered by the
    /// grid without keeping a list.
    ///
    /// Errors: a non-finite or inverted box (`out` is then left untouched).
    pub fn query(
        &mut self,
        grid: &mut StaticGrid,
        key: u32,
        aabb: &Aabb,
        out: &mut Vec<u32>,
    ) -> Result<GridQueryStats, GridError> {
        check_aabb(aabb, None)?;
        if key > MAX_PROXY_ID {
            // Keys index a list: one past the broad phase's bound would grow it without end.
            return grid.query(aabb, out);
        }
        // A grid edited since the lists were taken costs them, never a stale answer.
        self.forget_if_changed(grid);
        let index = key as usize;
        if index >= self.entries.len() {
            self.entries.resize(index + 1, NO_ENTRY);
        }
        let entry = self.entries[index];
        let kept = if entry.fat.contains(aabb) {
            self.kept(entry)
        } else {
            None
        };
        let (fat, start, len, mut stats) = match kept {
            Some((start, len)) => {
                let reused = GridQueryStats {
                    reused_queries: 1,
                    ..GridQueryStats::default()
                };
                (entry.fat, start, len, reused)
            }
            None => {
                let fat = fattened(aabb);
                let start = self.lists.len();
                let stats = grid.intersecting_slots(&fat, &mut self.lists, &mut self.packed);
                (fat, start, self.lists.len() - start, stats)
            }
        };
        let list = &self.lists[start..start + len];
        out.clear();
        out.extend(
            list.iter()
                .map(|&slot| &grid.objects[slot as usize])
                .filter(|object| object.aabb.intersects(aabb))
                .map(|object| object.id),
        );
        stats.exact_tests += len;
        // The buffers hold at most one list per key and round, each at most one entry per grid
        // slot: offsets fit a u32 as the grid's slots do.
        self.entries[index] = Entry {
            fat,
            start: start as u32,
            len: len as u32,
            round: self.round,
        };
        Ok(stats)
    }

    /// Forgets every list if `grid` is not the grid they were taken from, unchanged.
    fn forget_if_changed(&mut self, grid: &StaticGrid) {
        if self.revision.replace(grid.revision()) != Some(grid.revision()) {
            self.previous.clear();
            self.entries.clear();
        }
    }

    /// Where `entry`'s list is in this round's buffer (copied there if the last round wrote
    /// it), or `None` if no list of it is kept (never written, or older than the last round).
    fn kept(&mut self, entry: Entry) -> Option<(usize, usize)> {
        let (start, len) = (entry.start as usize, entry.len as usize);
        if entry.round == 0 {
            None
        } else if entry.round == self.round {
            Some((start, len))
        } else if entry.round.wrapping_add(1) == self.round {
            let moved = self.lists.len();
            self.lists
                .extend_from_slice(&self.previous[start..start + len]);
            Some((moved, len))
        } else {
            None
        }
    }

    /// Bytes held by the buffers (capacity), for memory reports.
    pub fn memory_bytes(&self) -> usize {
        self.entries.capacity() * std::mem::size_of::<Entry>()
            + (self.lists.capacity() + self.previous.capacity()) * 4
            + self.packed.capacity() * 8
    }
}

/// `aabb` grown by [`FAT_FRACTION`] of its size on each side; `aabb` itself when growing would
/// overflow (a box near the float range stays exact).
fn fattened(aabb: &Aabb) -> Aabb {
    let grow = (aabb.max - aabb.min) * FAT_FRACTION;
    let fat = Aabb::new(aabb.min - grow, aabb.max + grow);
    if fat.is_finite() { fat } else { *aabb }
}

#[cfg(test)]
#[path = "query_cache_tests.rs"]
mod tests;
