//! Geometry: poses, shapes (primitives and triangle meshes), and the shape-pair tests that
//! produce contacts.

pub mod active_edges;
mod contact;
pub mod contacts;
pub mod convex;
mod convex_hull;
#[cfg(test)]
pub(crate) use convex_hull::box_hull;
mod hull_lanes;
mod isometry;
mod lengths;
mod mass_properties;
mod mesh_collider;
mod mesh_intersects;
pub mod mesh_io;
pub(crate) mod predicates;
mod primitives_mesh;
mod shapes;
pub mod tri_tri;
mod triangle;
mod trimesh;
mod weld;

pub use contact::{ContactManifold, ContactPoint, FeatureId, MAX_MANIFOLD_POINTS};
pub use convex_hull::{ConvexHull, HullError, HullFace};
pub use isometry::Isometry;
pub use lengths::{is_unit_rotation, length_or_zero};
pub use mass_properties::MassProperties;
pub use mesh_collider::{MeshCollider, MeshColliderError};
pub use mesh_intersects::BadPose;
pub use primitives_mesh::MAX_PROCEDURAL_VERTICES;
pub use shapes::{
    Capsule, Cone, Cuboid, Cylinder, Ellipsoid, HalfSpace, Shape, ShapeError, Sphere,
};
pub use tri_tri::{TriTriIntersection, tri_tri_intersect, tri_tri_intersection};
pub use triangle::{
    Triangle, contact_triangle_halfspace, contact_triangle_sphere,
    contact_triangle_sphere_with_edges, intersects_triangle_aabb, intersects_triangle_cuboid,
    triangle_box_overlap,
};
pub use trimesh::{MeshError, MeshReport, TriMesh};
