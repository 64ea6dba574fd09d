//! urto: collision detection and rigid-body dynamics for Bevy-style ECS games.

pub mod bounding;
pub mod geometry;
