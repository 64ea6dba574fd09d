//! Spatial queries and collision layers: what a game asks of the physics world besides
//! stepping it — "what does this ray hit?", "what is inside this volume?", "which colliders
//! may touch?" (rapier's query pipeline and `InteractionGroups`, Avian's `SpatialQuery` and
//! `CollisionLayers`).
//!
//! - [`layers`]: membership and filter bit masks, checked per collider pair in the narrow phase
//!   and per candidate in the queries.
//! - [`tree`]: a bounding-volume tree over the colliders' boxes, refitted while the colliders
//!   stay the same.
//! - [`collider_tree`]: that tree as colliders come and go (a small tree for the new ones,
//!   the gone ones retired, a rebuild once they are many).
//! - [`cast`]: a ray or a sphere cast against one shape, through the exact times of impact of
//!   [`crate::ccd`] (a ray is a sweep of radius 0).
//! - [`box_cast`]: a box cast against one shape (separating axes with velocity for polytopes).
//! - [`capsule_cast`]: a capsule cast against one shape (conservative advancement on exact
//!   distances, closed forms for balls and planes).
//! - [`shape_cast`]: a cast of any convex shape against one shape (the casts above for balls,
//!   boxes and capsules; conservative advancement on GJK distances for the others).
//! - [`stable_ids`]: small ids that stay with their colliders while others come and go.
//! - [`nearest`]: the point of one collider nearest to a query point.
//! - [`index`]: the queries over the tree — ray casts (first hit, all hits), sphere casts,
//!   overlaps, the colliders containing a point and the nearest one — with a filter, never a
//!   scan of every collider.
//!
//! The ECS face is [`SpatialQuery`](crate::plugins::SpatialQuery), which keeps a
//! [`SpatialIndex`] of the colliders' world poses after each step.

pub mod box_cast;
pub mod capsule_cast;
pub mod cast;
pub mod collider_tree;
pub mod index;
pub mod layers;
pub mod nearest;
mod ray_convex;
pub mod shape_cast;
pub mod stable_ids;
pub mod tree;

pub use box_cast::{BoxCast, cast_box};
pub use capsule_cast::{CapsuleCast, cast_capsule};
pub use cast::{CastHit, QueryError, Ray, cast_sphere};
pub use collider_tree::ColliderTree;
pub use index::{ColliderLookup, IndexUpdate, QueryHit, SpatialIndex};
pub use layers::{LayerMask, Layers};
pub use nearest::{PointHit, nearest_point};
pub use shape_cast::{ShapeCast, cast_shape, castable};
pub use stable_ids::StableIds;
pub use tree::{AabbTree, RaySegment};
