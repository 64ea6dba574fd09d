//! The uniform grid over the static scene: the slides' "CD e CR tra un oggetto e la scena
//! statica". The scene does not move, so space is indexed once: each cell lists the static
//! objects whose AABB touches it, and a moving object is tested only against the objects listed
//! in the cells its own AABB touches (Ericson 2005, *Real-Time Collision Detection*, §7.1).
//!
//! Choices beyond the slides:
//! - **Hashed cells, no bounds.** Cells live in a hash table keyed by their integer coordinates
//!   (Teschner et al. 2003, "Optimized Spatial Hashing for Collision Detection of Deformable
//!   Objects"), so the grid covers all of space and only occupied cells cost memory. The hasher
//!   is fixed ([`CellHashBuilder`]) and only used for look-ups: no output depends on a table's
//!   iteration order.
//! - **Automatic, per-axis cell size** from the objects' sizes ([`suggest_cell_size`]),
//!   overridable through [`StaticGridConfig`].
//! - **Oversize list.** An object touching more than
//!   [`max_cells_per_object`](StaticGridConfig::max_cells_per_object) cells (a ground slab,
//!   terrain) is kept in a list that every query tests, so one object cannot fill memory.
//! - **Dense slots.** Objects carry caller-chosen `u32` ids; inside, each has a slot in flat
//!   arrays. What a query reads for every candidate (box, id, stamp) sits together in one
//!   32-byte-aligned [`SlotObject`] that never straddles a cache line; the placement, read
//!   only by edits, is kept apart.
//!   Removed slots are recycled, so removing or moving an object touches only its cells.
//!
//! Queries live in `query.rs`, kept answers in `query_cache.rs`.

use super::cell_hasher::CellHashBuilder;
use super::cell_list::CellList;
use super::cell_size::{DEFAULT_CELL_SIZE, suggest_cell_size};
use super::cells::{CellCoord, CellRange};
use super::config::{
    DEFAULT_MAX_CELLS_PER_OBJECT, StaticGridConfig, check_cell_budget, check_cell_size,
};
use super::error::{GridError, check_aabb};
use crate::bounding::Aabb;
use glam::Vec3;
use std::collections::HashMap;
use std::mem::size_of;
use std::sync::atomic::{AtomicU64, Ordering};

/// Where a slot's object is indexed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Placement {
    /// The slot is free (its object was removed); it is on the free list.
    Vacant,
    /// The object is listed in every cell of this range.
    Cells(CellRange),
    /// The object is at this position of the oversize list.
    Oversize { position: u32 },
}

/// What a query reads for each candidate, packed into (and aligned to) 32 bytes so that one
/// candidate costs one cache line.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(super) struct SlotObject {
    pub(super) aabb: Aabb,
    /// The caller's id.
    pub(super) id: u32,
    /// The last query generation that met this object (see `query.rs`).
    pub(super) stamp: u32,
}

/// A uniform hashed grid over static objects; see the module docs.
///
/// Queries ([`StaticGrid::query`]) return each object whose AABB intersects the query AABB,
/// once, in ascending id order.
#[derive(Clone, Debug)]
pub struct StaticGrid {
    pub(super) cell_size: Vec3,
    /// `1 / cell_size`: cells are found by multiplying, which is as monotone as dividing.
    pub(super) inv_cell_size: Vec3,
    pub(super) max_cells_per_object: u32,
    /// Occupied cells only: slots of the objects touching each (short lists inline, see
    /// [`CellList`]). A cell whose list empties is removed.
    pub(super) cells: HashMap<CellCoord, CellList, CellHashBuilder>,
    pub(super) slot_of_id: HashMap<u32, u32, CellHashBuilder>,
    /// Per slot: what queries read, and where the object is indexed.
    pub(super) objects: Vec<SlotObject>,
    pub(super) placements: Vec<Placement>,
    /// Vacant slots, reused last-in first-out.
    pub(super) free_slots: Vec<u32>,
    /// Slots of the oversize objects.
    pub(super) oversize: Vec<u32>,
    /// Objects listed in cells (live objects minus oversize ones).
    pub(super) gridded_count: usize,
    /// A range holding every occupied cell (it grows with insertions and is reset only when no
    /// object is left in cells), so queries skip the part of their range that cannot hold
    /// anything.
    pub(super) occupied: Option<CellRange>,
    /// Stamp of the current query; see `query.rs`.
    pub(super) generation: u32,
    /// Names this grid's contents: see [`StaticGrid::revision`].
    revision: u64,
}

/// The next revision any grid takes: one counter for all grids, so two grids (or one grid before
/// and after an edit) never share a revision unless one is a clone of the other, unchanged.
static NEXT_REVISION: AtomicU64 = AtomicU64::new(1);

fn new_revision() -> u64 {
    NEXT_REVISION.fetch_add(1, Ordering::Relaxed)
}

impl StaticGrid {
    /// An empty grid. Without a cell size in `config`, cells are [`DEFAULT_CELL_SIZE`]: prefer
    /// [`StaticGrid::build`] when the objects are known, so the size fits them.
    pub fn new(config: StaticGridConfig) -> Result<Self, GridError> {
        let cell_size = check_cell_size(config.cell_size.unwrap_or(DEFAULT_CELL_SIZE))?;
        let max_cells_per_object = check_cell_budget(config.max_cells_per_object)?;
        Ok(Self::with_checked(cell_size, max_cells_per_object))
    }

    /// An empty grid of cells already checked by [`check_cell_size`] and [`check_cell_budget`].
    fn with_checked(cell_size: Vec3, max_cells_per_object: u32) -> Self {
        Self {
            cell_size,
            inv_cell_size: cell_size.recip(),
            max_cells_per_object,
            cells: HashMap::with_hasher(CellHashBuilder),
            slot_of_id: HashMap::with_hasher(CellHashBuilder),
            objects: Vec::new(),
            placements: Vec::new(),
            free_slots: Vec::new(),
            oversize: Vec::new(),
            gridded_count: 0,
            occupied: None,
            generation: 0,
            revision: new_revision(),
        }
    }

    /// A grid holding `objects`, with the cell size chosen from them ([`suggest_cell_size`]).
    pub fn build(objects: &[(u32, Aabb)]) -> Result<Self, GridError> {
        Self::build_with(objects, StaticGridConfig::default())
    }

    /// A grid holding `objects`; the cell size is `config`'s, or chosen from the objects.
    pub fn build_with(
        objects: &[(u32, Aabb)],
        config: StaticGridConfig,
    ) -> Result<Self, GridError> {
        check_batch(objects)?;
        let cell_size = config
            .cell_size
            .unwrap_or_else(|| suggest_cell_size(objects.iter().map(|(_, aabb)| aabb)));
        let mut grid = Self::new(StaticGridConfig {
            cell_size: Some(cell_size),
            ..config
        })?;
        grid.insert_checked_batch(objects);
        Ok(grid)
    }

    /// Indexes object `id` with box `aabb`.
    ///
    /// Errors: a non-finite or inverted box, or an id already in the grid.
    pub fn insert(&mut self, id: u32, aabb: Aabb) -> Result<(), GridError> {
        check_aabb(&aabb, Some(id))?;
        if self.slot_of_id.contains_key(&id) {
            return Err(GridError::DuplicateId(id));
        }
        self.insert_checked(id, aabb);
        Ok(())
    }

    /// Indexes a batch of objects: all of them, or (on the first bad box or repeated id) none.
    pub fn insert_bulk(&mut self, objects: &[(u32, Aabb)]) -> Result<(), GridError> {
        check_batch(objects)?;
        if let Some(&(id, _)) = objects
            .iter()
            .find(|(id, _)| self.slot_of_id.contains_key(id))
        {
            return Err(GridError::DuplicateId(id));
        }
        self.insert_checked_batch(objects);
        Ok(())
    }

    /// Removes object `id` from its cells (or the oversize list) and returns its box.
    pub fn remove(&mut self, id: u32) -> Result<Aabb, GridError> {
        let slot = self
            .slot_of_id
            .remove(&id)
            .ok_or(GridError::UnknownId(id))?;
        self.unplace(slot);
        self.placements[slot as usize] = Placement::Vacant;
        self.free_slots.push(slot);
        self.revision = new_revision();
        Ok(self.objects[slot as usize].aabb)
    }

    /// Gives object `id` a new box. Only the cells the object leaves or enters are touched; a
    /// box that stays in the same cells touches none.
    pub fn update(&mut self, id: u32, aabb: Aabb) -> Result<(), GridError> {
        check_aabb(&aabb, Some(id))?;
        let slot = *self.slot_of_id.get(&id).ok_or(GridError::UnknownId(id))?;
        let old = self.placements[slot as usize];
        self.objects[slot as usize].aabb = aabb;
        self.revision = new_revision();
        let same_place = match (old, self.cell_range_if_gridded(&aabb)) {
            (Placement::Cells(before), Some(after)) => before == after,
            (Placement::Oversize { .. }, None) => true,
            _ => false,
        };
        if !same_place {
            self.unplace(slot);
            self.place(slot);
        }
        Ok(())
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.slot_of_id.len()
    }

    /// True when the grid holds no object.
    pub fn is_empty(&self) -> bool {
        self.slot_of_id.is_empty()
    }

    /// True when object `id` is in the grid.
    pub fn contains(&self, id: u32) -> bool {
        self.slot_of_id.contains_key(&id)
    }

    /// The box of object `id`.
    pub fn aabb(&self, id: u32) -> Option<Aabb> {
        self.slot_of_id
            .get(&id)
            .map(|&slot| self.objects[slot as usize].aabb)
    }

    /// True when object `id` is on the oversize list (tested by every query), `None` for an
    /// unknown id.
    pub fn is_oversize(&self, id: u32) -> Option<bool> {
        let slot = *self.slot_of_id.get(&id)?;
        Some(matches!(
            self.placements[slot as usize],
            Placement::Oversize { .. }
        ))
    }

    /// A number naming the grid's contents: every edit (insert, update, remove) gives the grid
    /// a new one, never used before by any grid, so whoever keeps an answer of this grid can
    /// tell whether it still holds ([`super::GridQueryCache`]).
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Size of a cell along x, y, z.
    pub fn cell_size(&self) -> Vec3 {
        self.cell_size
    }

    /// The per-object cell budget beyond which objects go to the oversize list.
    pub fn max_cells_per_object(&self) -> u32 {
        self.max_cells_per_object
    }

    /// Number of objects on the oversize list.
    pub fn oversize_count(&self) -> usize {
        self.oversize.len()
    }

    /// Number of cells listing at least one object.
    pub fn occupied_cell_count(&self) -> usize {
        self.cells.len()
    }

    /// An estimate of the heap and inline bytes the grid holds: the capacity of every buffer,
    /// hash tables counted as capacity × (entry + 1 control byte), allocator overhead excluded.
    /// Walks every occupied cell, so it costs O(cells): a diagnostic, not for every frame.
    pub fn memory_bytes(&self) -> usize {
        let lists: usize = self.cells.values().map(CellList::heap_bytes).sum();
        size_of::<Self>()
            + table_bytes::<CellCoord, CellList>(self.cells.capacity())
            + lists
            + table_bytes::<u32, u32>(self.slot_of_id.capacity())
            + self.objects.capacity() * size_of::<SlotObject>()
            + self.placements.capacity() * size_of::<Placement>()
            + self.free_slots.capacity() * size_of::<u32>()
            + self.oversize.capacity() * size_of::<u32>()
    }

    /// The cells `aabb` would be listed in, `None` when it would go to the oversize list.
    fn cell_range_if_gridded(&self, aabb: &Aabb) -> Option<CellRange> {
        let range = CellRange::of_aabb(aabb, self.inv_cell_size);
        (range.cell_count() <= u128::from(self.max_cells_per_object)).then_some(range)
    }

    /// Inserts a batch already checked for bad boxes and repeated ids.
    fn insert_checked_batch(&mut self, objects: &[(u32, Aabb)]) {
        let additional = objects.len().saturating_sub(self.free_slots.len());
        self.slot_of_id.reserve(objects.len());
        self.objects.reserve(additional);
        self.placements.reserve(additional);
        for &(id, aabb) in objects {
            self.insert_checked(id, aabb);
        }
    }

    /// Inserts an object already checked for a bad box and a repeated id.
    fn insert_checked(&mut self, id: u32, aabb: Aabb) {
        // Stamp 0 is never a query's generation (they skip 0), so the object is unseen.
        let object = SlotObject { aabb, id, stamp: 0 };
        let slot = match self.free_slots.pop() {
            Some(slot) => {
                self.objects[slot as usize] = object;
                slot
            }
            None => {
                // Ids are distinct `u32`s and vacant slots are reused first, so there are
                // never more than 2³² slots and the index fits a `u32`.
                let slot = self.objects.len() as u32;
                self.objects.push(object);
                self.placements.push(Placement::Vacant);
                slot
            }
        };
        self.slot_of_id.insert(id, slot);
        self.place(slot);
        self.revision = new_revision();
    }

    /// Lists the slot's object in its cells, or on the oversize list.
    fn place(&mut self, slot: u32) {
        let aabb = self.objects[slot as usize].aabb;
        self.placements[slot as usize] = match self.cell_range_if_gridded(&aabb) {
            Some(range) => {
                for cell in range.iter() {
                    self.cells.entry(cell).or_default().push(slot);
                }
                self.gridded_count += 1;
                self.occupied = Some(self.occupied.map_or(range, |o| o.union(&range)));
                Placement::Cells(range)
            }
            None => {
                // The oversize list holds at most one entry per slot: its length fits a `u32`.
                let position = self.oversize.len() as u32;
                self.oversize.push(slot);
                Placement::Oversize { position }
            }
        };
    }

    /// Takes the slot's object out of its cells or the oversize list (its placement is left
    /// stale: the caller sets it).
    fn unplace(&mut self, slot: u32) {
        match self.placements[slot as usize] {
            Placement::Vacant => {}
            Placement::Cells(range) => {
                for cell in range.iter() {
                    self.remove_from_cell(cell, slot);
                }
                self.gridded_count -= 1;
                if self.gridded_count == 0 {
                    self.occupied = None;
                }
            }
            Placement::Oversize { position } => {
                self.oversize.swap_remove(position as usize);
                if let Some(&moved) = self.oversize.get(position as usize) {
                    self.placements[moved as usize] = Placement::Oversize { position };
                }
            }
        }
    }

    /// Removes `slot` from one cell's list, and the cell itself when it empties. Linear in the
    /// cell's population, which the cell-size rule keeps small.
    fn remove_from_cell(&mut self, cell: CellCoord, slot: u32) {
        let Some(list) = self.cells.get_mut(&cell) else {
            return;
        };
        list.remove(slot);
        if list.is_empty() {
            self.cells.remove(&cell);
        }
    }
}

/// Accepts a batch whose boxes are all indexable and whose ids are distinct.
fn check_batch(objects: &[(u32, Aabb)]) -> Result<(), GridError> {
    for (id, aabb) in objects {
        check_aabb(aabb, Some(*id))?;
    }
    let mut ids: Vec<u32> = objects.iter().map(|&(id, _)| id).collect();
    ids.sort_unstable();
    match ids.windows(2).find(|pair| pair[0] == pair[1]) {
        Some(pair) => Err(GridError::DuplicateId(pair[0])),
        None => Ok(()),
    }
}

/// Bytes of a hash table of `capacity` entries: the entries plus one control byte each.
fn table_bytes<K, V>(capacity: usize) -> usize {
    capacity * (size_of::<(K, V)>() + 1)
}

/// An empty grid of [`DEFAULT_CELL_SIZE`] cells and the default budget (the
/// [`StaticGridConfig::default`] grid, which needs no check).
impl Default for StaticGrid {
    fn default() -> Self {
        Self::with_checked(DEFAULT_CELL_SIZE, DEFAULT_MAX_CELLS_PER_OBJECT)
    }
}

#[cfg(test)]
#[path = "storage_tests.rs"]
mod tests;
