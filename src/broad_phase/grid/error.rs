//! Why a [`StaticGrid`](super::storage::StaticGrid) operation was refused.
//!
//! Every refusal happens before the grid changes, so a failed call leaves the grid as it was.

use glam::Vec3;
use std::fmt;

/// A refused grid operation.
#[derive(Clone, Debug, PartialEq)]
pub enum GridError {
    /// A box with a NaN or infinite coordinate. `id` is the object's, `None` for a query box.
    NonFiniteAabb {
        /// The object whose box was refused, `None` for a query box.
        id: Option<u32>,
    },
    /// A box with `min > max` on some axis. `id` is the object's, `None` for a query box.
    InvertedAabb {
        /// The object whose box was refused, `None` for a query box.
        id: Option<u32>,
    },
    /// An insertion with an id the grid already holds (or that appears twice in one bulk insert).
    DuplicateId(u32),
    /// A removal or update of an id the grid does not hold.
    UnknownId(u32),
    /// A cell size that is NaN, infinite or outside
    /// [`MIN_CELL_SIZE`](super::config::MIN_CELL_SIZE)..=[`MAX_CELL_SIZE`](super::config::MAX_CELL_SIZE).
    InvalidCellSize(Vec3),
    /// A per-object cell budget above
    /// [`MAX_CELLS_PER_OBJECT_LIMIT`](super::config::MAX_CELLS_PER_OBJECT_LIMIT).
    InvalidCellBudget(u32),
}

impl fmt::Display for GridError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFiniteAabb { id: Some(id) } => {
                write!(f, "object {id} has a NaN or infinite AABB coordinate")
            }
            Self::NonFiniteAabb { id: None } => {
                write!(f, "query AABB has a NaN or infinite coordinate")
            }
            Self::InvertedAabb { id: Some(id) } => {
                write!(f, "object {id} has an AABB with min > max on some axis")
            }
            Self::InvertedAabb { id: None } => {
                write!(f, "query AABB has min > max on some axis")
            }
            Self::DuplicateId(id) => write!(f, "object id {id} is already in the grid"),
            Self::UnknownId(id) => write!(f, "object id {id} is not in the grid"),
            Self::InvalidCellSize(size) => write!(
                f,
                "cell size must be finite and within [{:e}, {:e}] on every axis, got {size}",
                super::config::MIN_CELL_SIZE,
                super::config::MAX_CELL_SIZE
            ),
            Self::InvalidCellBudget(budget) => write!(
                f,
                "max cells per object must be at most {}, got {budget}",
                super::config::MAX_CELLS_PER_OBJECT_LIMIT
            ),
        }
    }
}

impl std::error::Error for GridError {}

/// Accepts a box the grid can index: finite, and `min <= max` on every axis (flat and point
/// boxes are fine). `id` names the object in the error, `None` for a query box.
pub(crate) fn check_aabb(aabb: &crate::bounding::Aabb, id: Option<u32>) -> Result<(), GridError> {
    if !aabb.is_finite() {
        return Err(GridError::NonFiniteAabb { id });
    }
    if !aabb.is_valid() {
        return Err(GridError::InvertedAabb { id });
    }
    Ok(())
}
