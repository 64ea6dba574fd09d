//! Dynamics: integrators (linear and rotational), forces, collision response, the rigid-body
//! solver and islands (plain Rust, no ECS).

pub mod forces;
pub mod free_rotation;
pub mod integrators;
pub mod islands;
pub mod response;
pub mod rotation;
pub mod solver;
pub mod stillness;

pub use forces::{ForceModel, Spring, SpringEnd};
pub use integrators::{AccelerationField, Integrator, IntegratorScratch, integrate};
pub use rotation::{AngularBody, RotationOptions, integrate_rotations};
