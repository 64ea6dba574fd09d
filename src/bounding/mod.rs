//! Bounding volumes: cheap primitives that contain an object, so that disjoint BVs prove
//! disjoint objects (the slides' "Bounding Volumes").

mod aabb;

pub use aabb::Aabb;
