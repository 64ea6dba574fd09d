//! Geometry: poses, shapes, and the shape-pair tests that produce contacts.

mod contact;
pub mod contacts;
mod isometry;
mod shapes;

pub use contact::{ContactManifold, ContactPoint, MAX_MANIFOLD_POINTS};
pub use isometry::Isometry;
pub use shapes::{Cuboid, HalfSpace, Shape, ShapeError, Sphere};
