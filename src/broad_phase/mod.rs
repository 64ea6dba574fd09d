//! Broad phase: cheap tests that prune the pairs the narrow phase must examine.

pub mod grid;

pub use grid::{GridError, GridQueryStats, StaticGrid, StaticGridConfig};
