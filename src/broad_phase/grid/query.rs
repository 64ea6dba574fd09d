//! Queries of a [`StaticGrid`]: which static objects a moving object's AABB may hit.
//!
//! A query visits the cells its AABB touches (clipped to the range of occupied cells), reads
//! the objects listed there, and keeps those whose AABB intersects the query's (closed boxes:
//! touching counts, as in [`Aabb::intersects`]). Oversize objects are tested by every query.
//!
//! - **Deduplication without a set.** An object spanning several visited cells is listed
//!   several times. Each query takes a new *generation* number and stamps every object it
//!   meets; an object already stamped with the current generation is skipped. One `u32` per
//!   object, no clearing between queries (only when the counter wraps, once per 2³² queries).
//! - **Deterministic order.** Results are sorted by ascending id, so they depend only on the
//!   grid's contents, never on hash-table layout or insertion history.
//! - **Huge queries stay cheap.** A query touching more cells than the grid has objects in cells
//!   scans those objects instead of visiting cells, so its cost is O(min(cells, objects)) and a
//!   box spanning the world never loops over billions of empty cells.

use super::cells::{CellCoord, CellRange};
use super::error::{GridError, check_aabb};
use super::stats::GridQueryStats;
use super::storage::{Placement, StaticGrid};
use crate::bounding::Aabb;
use glam::Vec3;

/// Which objects a query keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Filter {
    /// Objects whose AABB intersects the query AABB.
    Intersecting,
    /// Every object sharing a cell with the query, plus every oversize object.
    Candidates,
}

impl StaticGrid {
    /// Writes to `out` (cleared first) the id of every object whose AABB intersects `query`,
    /// once each, in ascending order, and returns what it cost.
    ///
    /// Errors: a non-finite or inverted query box (`out` is then left untouched).
    pub fn query(&mut self, query: &Aabb, out: &mut Vec<u32>) -> Result<GridQueryStats, GridError> {
        self.collect(query, out, Filter::Intersecting)
    }

    /// Like [`StaticGrid::query`] without the exact box test: every object listed in a cell
    /// `query` touches, plus every oversize object (what a debug view shows as "candidates").
    /// A superset of [`StaticGrid::query`]'s answer, in ascending id order.
    pub fn query_candidates(
        &mut self,
        query: &Aabb,
        out: &mut Vec<u32>,
    ) -> Result<GridQueryStats, GridError> {
        self.collect(query, out, Filter::Candidates)
    }

    /// The cells `aabb` touches, for debug drawing (see [`StaticGrid::cell_bounds`]). The range
    /// is not clipped to occupied cells and can be huge: check
    /// [`CellRange::cell_count`] before iterating it.
    pub fn cells_touching(&self, aabb: &Aabb) -> Result<CellRange, GridError> {
        check_aabb(aabb, None)?;
        Ok(CellRange::of_aabb(aabb, self.inv_cell_size))
    }

    /// The region of space a cell covers (approximate for cells beyond ±2³¹, where
    /// coordinates saturate).
    pub fn cell_bounds(&self, cell: CellCoord) -> Aabb {
        let min = cell.as_vec3() * self.cell_size;
        Aabb::new(min, min + self.cell_size)
    }

    /// The region of space a whole cell range covers.
    pub fn range_bounds(&self, range: &CellRange) -> Aabb {
        let min = range.min.as_vec3() * self.cell_size;
        let max = (range.max.as_vec3() + Vec3::ONE) * self.cell_size;
        Aabb::new(min, max)
    }

    /// Writes to `out` (cleared first) the ids of the objects listed in `cell`, ascending.
    pub fn objects_in_cell(&self, cell: CellCoord, out: &mut Vec<u32>) {
        out.clear();
        if let Some(list) = self.cells.get(&cell) {
            out.extend(list.iter().map(|slot| self.objects[slot as usize].id));
            out.sort_unstable();
        }
    }

    /// Writes to `out` (cleared first) the ids of the oversize objects, ascending.
    pub fn oversize_ids(&self, out: &mut Vec<u32>) {
        out.clear();
        out.extend(
            self.oversize
                .iter()
                .map(|&slot| self.objects[slot as usize].id),
        );
        out.sort_unstable();
    }

    fn collect(
        &mut self,
        query: &Aabb,
        out: &mut Vec<u32>,
        filter: Filter,
    ) -> Result<GridQueryStats, GridError> {
        check_aabb(query, None)?;
        out.clear();
        let stats = self.collect_with(query, filter, |_, id| out.push(id));
        out.sort_unstable();
        Ok(stats)
    }

    /// Appends to `out` the slots of the objects whose AABB intersects `query` (a box already
    /// checked), in ascending id order: what [`super::GridQueryCache`] keeps.
    pub(super) fn intersecting_slots(
        &mut self,
        query: &Aabb,
        out: &mut Vec<u32>,
        scratch: &mut Vec<u64>,
    ) -> GridQueryStats {
        scratch.clear();
        let stats = self.collect_with(query, Filter::Intersecting, |slot, id| {
            scratch.push(u64::from(id) << 32 | u64::from(slot))
        });
        // Ids are distinct, so sorting the packed words sorts by id.
        scratch.sort_unstable();
        out.extend(scratch.iter().map(|&packed| packed as u32));
        stats
    }

    /// Hands every object `filter` keeps to `emit` (its slot, then its id), once each, in no
    /// particular order.
    fn collect_with(
        &mut self,
        query: &Aabb,
        filter: Filter,
        mut emit: impl FnMut(u32, u32),
    ) -> GridQueryStats {
        let mut stats = GridQueryStats::default();
        self.collect_oversize(query, filter, &mut emit, &mut stats);
        let touched = CellRange::of_aabb(query, self.inv_cell_size);
        if let Some(range) = self
            .occupied
            .and_then(|occupied| occupied.intersection(&touched))
        {
            if range.cell_count() > self.gridded_count as u128 {
                self.scan_gridded(query, &range, filter, &mut emit, &mut stats);
            } else {
                self.visit_cells(query, &range, filter, &mut emit, &mut stats);
            }
        }
        stats
    }

    /// Oversize objects are in no cell: every query reads them all.
    fn collect_oversize(
        &self,
        query: &Aabb,
        filter: Filter,
        emit: &mut impl FnMut(u32, u32),
        stats: &mut GridQueryStats,
    ) {
        stats.candidates_listed += self.oversize.len();
        for &slot in &self.oversize {
            let object = &self.objects[slot as usize];
            if filter == Filter::Intersecting {
                stats.exact_tests += 1;
                if !object.aabb.intersects(query) {
                    continue;
                }
            }
            emit(slot, object.id);
        }
    }

    /// The slides' algorithm: read the lists of the cells in `range`, once per object.
    fn visit_cells(
        &mut self,
        query: &Aabb,
        range: &CellRange,
        filter: Filter,
        emit: &mut impl FnMut(u32, u32),
        stats: &mut GridQueryStats,
    ) {
        let generation = self.next_generation();
        let Self { cells, objects, .. } = self;
        for cell in range.iter() {
            stats.cells_visited += 1;
            let Some(list) = cells.get(&cell) else {
                continue;
            };
            stats.candidates_listed += list.len();
            for slot in list.iter() {
                let object = &mut objects[slot as usize];
                if object.stamp == generation {
                    continue;
                }
                object.stamp = generation;
                if filter == Filter::Intersecting {
                    stats.exact_tests += 1;
                    if !object.aabb.intersects(query) {
                        continue;
                    }
                }
                emit(slot, object.id);
            }
        }
    }

    /// The fallback for queries touching more cells than there are objects in cells: read every
    /// object once. A candidate is an object whose cells overlap `range`, as `visit_cells`
    /// would have found it.
    fn scan_gridded(
        &self,
        query: &Aabb,
        range: &CellRange,
        filter: Filter,
        emit: &mut impl FnMut(u32, u32),
        stats: &mut GridQueryStats,
    ) {
        stats.object_scans += 1;
        stats.candidates_listed += self.gridded_count;
        for (slot, placement) in self.placements.iter().enumerate() {
            let Placement::Cells(cells) = placement else {
                continue;
            };
            let keep = match filter {
                Filter::Intersecting => {
                    stats.exact_tests += 1;
                    self.objects[slot].aabb.intersects(query)
                }
                Filter::Candidates => cells.overlaps(range),
            };
            if keep {
                // Slots are numbered in u32 (see `insert_checked`).
                emit(slot as u32, self.objects[slot].id);
            }
        }
    }

    /// A stamp no object carries yet. On wrap-around every stamp is cleared, so an old stamp
    /// can never be mistaken for the new generation.
    fn next_generation(&mut self) -> u32 {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.objects.iter_mut().for_each(|object| object.stamp = 0);
            self.generation = 1;
        }
        self.generation
    }
}
