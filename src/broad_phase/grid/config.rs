//! Settings of a [`StaticGrid`](super::storage::StaticGrid): cell size and the per-object cell
//! budget beyond which an object goes to the always-tested oversize list.

use super::error::GridError;
use glam::Vec3;

/// Smallest accepted cell size on any axis: its reciprocal, which the grid multiplies
/// coordinates by, must stay finite.
pub const MIN_CELL_SIZE: f32 = 1.0e-30;

/// Largest accepted cell size on any axis.
pub const MAX_CELL_SIZE: f32 = 1.0e30;

/// Default per-object cell budget. An object the automatic cell size is made for touches at most
/// 2 cells per axis (8 in all); 64 cells (a 4×4×4 block, or 16×4×1 for a flat slab) leave room
/// for objects a few times larger than the typical one, while bounding the grid's memory to at
/// most 64 list entries per object. Objects beyond it (ground slabs, terrain, long roads) are
/// few and go to the oversize list, which every query tests.
pub const DEFAULT_MAX_CELLS_PER_OBJECT: u32 = 64;

/// Largest accepted per-object cell budget, so that one object can never make the grid allocate
/// an unbounded number of cells.
pub const MAX_CELLS_PER_OBJECT_LIMIT: u32 = 1 << 16;

/// How a [`StaticGrid`](super::storage::StaticGrid) is laid out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticGridConfig {
    /// Size of a cell along x, y, z. `None`: chosen from the objects by
    /// [`suggest_cell_size`](super::cell_size::suggest_cell_size) when the grid is built from a
    /// batch, [`DEFAULT_CELL_SIZE`](super::cell_size::DEFAULT_CELL_SIZE) for an empty grid.
    pub cell_size: Option<Vec3>,
    /// Objects whose AABB touches more cells than this go to the oversize list instead of the
    /// cells (see [`DEFAULT_MAX_CELLS_PER_OBJECT`]). Zero puts every object there, which turns
    /// the grid into a brute-force scan.
    pub max_cells_per_object: u32,
}

impl Default for StaticGridConfig {
    fn default() -> Self {
        Self {
            cell_size: None,
            max_cells_per_object: DEFAULT_MAX_CELLS_PER_OBJECT,
        }
    }
}

impl StaticGridConfig {
    /// Cubic cells of side `size`, default budget.
    pub fn with_cell_size(size: f32) -> Self {
        Self {
            cell_size: Some(Vec3::splat(size)),
            ..Self::default()
        }
    }

    /// Cells of `size` along each axis, default budget.
    pub fn with_cell_size_per_axis(size: Vec3) -> Self {
        Self {
            cell_size: Some(size),
            ..Self::default()
        }
    }
}

/// Accepts a cell size within [`MIN_CELL_SIZE`]..=[`MAX_CELL_SIZE`] on every axis (this also
/// refuses NaN and infinities).
pub(crate) fn check_cell_size(size: Vec3) -> Result<Vec3, GridError> {
    let in_range = size.cmpge(Vec3::splat(MIN_CELL_SIZE)) & size.cmple(Vec3::splat(MAX_CELL_SIZE));
    if in_range.all() {
        Ok(size)
    } else {
        Err(GridError::InvalidCellSize(size))
    }
}

/// Accepts a per-object cell budget up to [`MAX_CELLS_PER_OBJECT_LIMIT`].
pub(crate) fn check_cell_budget(budget: u32) -> Result<u32, GridError> {
    if budget <= MAX_CELLS_PER_OBJECT_LIMIT {
        Ok(budget)
    } else {
        Err(GridError::InvalidCellBudget(budget))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_sizes_outside_the_range_are_refused() {
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, 1.0e-35, 1.0e35] {
            let size = Vec3::new(1.0, bad, 1.0);
            assert!(matches!(
                check_cell_size(size),
                Err(GridError::InvalidCellSize(_))
            ));
        }
        assert!(check_cell_size(Vec3::new(MIN_CELL_SIZE, 1.0, MAX_CELL_SIZE)).is_ok());
    }

    #[test]
    fn the_smallest_cell_size_has_a_finite_reciprocal() {
        assert!((1.0 / MIN_CELL_SIZE).is_finite());
    }

    #[test]
    fn budgets_above_the_limit_are_refused() {
        assert!(check_cell_budget(0).is_ok());
        assert!(check_cell_budget(MAX_CELLS_PER_OBJECT_LIMIT).is_ok());
        assert_eq!(
            check_cell_budget(MAX_CELLS_PER_OBJECT_LIMIT + 1),
            Err(GridError::InvalidCellBudget(MAX_CELLS_PER_OBJECT_LIMIT + 1))
        );
    }
}
