//! The uniform grid for static scenery (the slides' "CD e CR tra un oggetto e la scena
//! statica"): space is cut into cells, each listing the static objects that touch it, so a moving
//! body is tested only against the objects in the cells it overlaps. Cells are hashed, so the
//! grid has no bounds; see [`StaticGrid`] for the rules (cell size, oversize objects, order).

mod cell_hasher;
mod cell_list;
mod cell_size;
mod cells;
mod config;
mod error;
mod query;
mod query_cache;
mod stats;
mod storage;

pub use cell_hasher::{CellHashBuilder, CellHasher};
pub use cell_size::{CELL_SIZE_PERCENTILE, DEFAULT_CELL_SIZE, MAX_CELL_ASPECT, suggest_cell_size};
pub use cells::{CellCoord, CellRange, CellRangeIter};
pub use config::{
    DEFAULT_MAX_CELLS_PER_OBJECT, MAX_CELL_SIZE, MAX_CELLS_PER_OBJECT_LIMIT, MIN_CELL_SIZE,
    StaticGridConfig,
};
pub use error::GridError;
pub use query_cache::{FAT_FRACTION, GridQueryCache};
pub use stats::GridQueryStats;
pub use storage::StaticGrid;
