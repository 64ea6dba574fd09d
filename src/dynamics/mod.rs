//! Dynamics: integrators, forces and collision response (plain Rust, no ECS).

pub mod forces;
pub mod integrators;
pub mod response;

pub use forces::{ForceModel, Spring, SpringEnd};
pub use integrators::{AccelerationField, Integrator, IntegratorScratch, integrate};
