//! Continuous collision detection: the **time of impact** (TOI) of a sphere swept along a
//! straight displacement during one step, so that a fast body stops at a thin wall instead of
//! tunnelling through it (the slides' "oggetti veloci o sottili", cured here without substeps).
//!
//! A body's centre moves along a straight displacement `d` (velocity × dt) during a step. The
//! moving body is a sphere about that centre (a body of another shape sweeps its bounding
//! sphere, which is conservative whatever it turns); the obstacle is static (two moving spheres
//! use their relative motion). Every query answers: the first fraction `t ∈ [0, 1]` of `d` at
//! which the sphere touches the obstacle, or `None`. [`toi_shape_from`] then brings a convex
//! body on from its sphere's impact to its own, turning as it goes (conservative advancement),
//! and [`toi_parts_from`] a compound of convex parts to the first of theirs.
//!
//! # How each TOI is found
//!
//! A sphere of radius `r` touches a convex obstacle exactly when its centre enters the obstacle
//! inflated by `r` (the Minkowski sum with the ball), so every query is a *ray* (the centre's
//! segment) against an inflated shape (Ericson 2005, *Real-Time Collision Detection* §5.5):
//!
//! | obstacle      | inflated shape                          | method                         |
//! |---------------|-----------------------------------------|--------------------------------|
//! | half-space    | the half-space moved out by `r`         | one division                   |
//! | sphere        | a ball of radius `r + r_b`              | a quadratic, `‖m + t·d‖ = R`   |
//! | oriented box  | a rounded box: 3 slabs, 12 cylinders, 8 balls | exact (slabs first)      |
//! | capsule       | a capsule of radius `r + r_b`: 1 cylinder, 2 balls | exact               |
//! | triangle      | a prism, 3 edge cylinders, 3 vertex balls | exact (face first)           |
//! | triangle mesh | the union of its triangles' sums        | BVH descent, earliest triangle |
//!
//! The inflated shapes are unions of convex pieces, and a ray that starts outside all of them
//! enters the union first where it enters the earliest piece, so each exact query is a minimum
//! over simple ray tests (`swept_point.rs`). Conservative advancement (Mirtich 1996, *Impulse-based
//! dynamic simulation of rigid body systems*, PhD thesis, §3) is provided as a generic fallback for
//! any obstacle with a distance function, and is the cross-check of the exact queries in the tests.
//!
//! # Conventions (shared by every query)
//!
//! - **Motion.** The centre is at `c(t) = center + t·displacement`, `t ∈ [0, 1]`.
//! - **Touching counts.** Contact means distance between centre and obstacle `<= r` (the closed
//!   convention of [`ContactManifold`](crate::geometry::ContactManifold)); a sphere that only grazes
//!   the obstacle at the tangent instant hits at that instant, and a touch at exactly `t = 1`
//!   counts.
//! - **Result.** [`Toi`]: `t`, the unit `normal` pointing **from the obstacle toward the sphere**
//!   (the direction that pushes the sphere out: reflect the velocity about it), and the contact
//!   `point` on both surfaces at time `t`. Triangles are two-sided, as everywhere in urto.
//! - **Already in contact at `t = 0`.** Reported as `t = 0` with the separating normal and point
//!   of the static contact test of the same pair (so CCD and the narrow phase agree), under the
//!   sweep's [`InitialOverlap`] policy: `Report` (the default) always reports it;
//!   `ApproachingOnly` reports it only when the displacement moves deeper
//!   (`displacement · normal < 0`), so that a body resting on or leaving a surface is not stopped
//!   by it. Every piece is convex, so a sphere leaving a piece never re-enters it during the sweep.
//! - **Tolerance.** [`SphereSweep::tolerance`] is `1e-5 × (r + |d|)`: conservative advancement stops
//!   within it, the exact queries accept face hits that miss a face by at most it (plus the
//!   rounding of the coordinates) so that a ray through a shared mesh edge cannot slip between two
//!   triangles, and BVH culling is padded by it.
//! - **Degenerate cases never give NaN.** Zero displacement: `t = 0` if in contact, else `None`.
//!   Zero radius: the sphere is a point and the query a ray test; its normal at an edge or a
//!   vertex, where the surface has none, is `-d/|d|`. A displacement parallel to a face never hits
//!   that face (its edges still can). Zero-area triangles collide as their edges; zero-size boxes
//!   as points.
//! - **Bad input.** A sweep with a non-finite centre, displacement or radius, or a negative radius,
//!   is refused by [`SphereSweep::new`]. Non-finite obstacles are refused upstream (as for the
//!   static tests): the queries do not panic on them, but their output is unspecified.
//! - **Determinism.** Ties between pieces or triangles go to the first in a fixed order (pieces in
//!   the order of their files' docs, triangles in BVH descent order); on a mesh, a face hit wins
//!   over an edge or vertex hit within the time it takes to travel the tolerance, so that a ball
//!   landing next to an edge of a flat floor gets the floor's normal (`toi_sphere_trimesh.rs`).
//!
//! # Using it in a step
//!
//! Build one [`SphereSweep`] per fast body with `displacement = velocity × remaining time` and
//! [`InitialOverlap::ApproachingOnly`]; query the candidates from the broad phase (fed with
//! [`SphereSweep::swept_aabb`]); take the smallest `t`; move the body to
//! [`SphereSweep::position_at`]`(t)`, respond about `normal`, and sweep the rest of the step
//! (`remaining × (1 − t)`) again, a bounded number of times. `tests/core/ccd_robustness.rs` runs this
//! loop on the core alone.
//!
//! Against a moving obstacle, sweep in the pair's relative motion (the sphere's displacement
//! minus the obstacle's, the obstacle held at its start); [`pairs_with_a_fast_body`] finds which
//! fast bodies' swept boxes meet which moving bodies' boxes (the ECS clamps a fast body at its
//! first such impact, `plugins/ccd/movers.rs`).

mod advancement;
mod mover_pairs;
mod sweep;
mod sweep_cull;
mod swept_aabb;
mod swept_point;
mod toi;
mod toi_shape;
mod toi_sphere_capsule;
mod toi_sphere_convex;
mod toi_sphere_cuboid;
mod toi_sphere_halfspace;
mod toi_sphere_sphere;
mod toi_sphere_triangle;
mod toi_sphere_trimesh;

pub use advancement::{
    Advancement, DEFAULT_MAX_ADVANCEMENT_ITERATIONS, conservative_advancement,
    toi_sphere_by_advancement,
};
pub use mover_pairs::{MoverPairScratch, pairs_with_a_fast_body};
pub use sweep::{CONTACT_TOLERANCE_RELATIVE, InitialOverlap, SphereSweep, SweepError};
pub use sweep_cull::SweepCull;
pub use swept_aabb::swept_aabb;
pub(crate) use swept_point::segment_in_box;
pub use toi::{MeshToi, Toi, toi_sphere_shape};
pub use toi_shape::{
    MAX_REFINED_PARTS, MAX_REFINED_TURN, MAX_SHAPE_ADVANCEMENT_ITERATIONS, ShapeOnSweep,
    depth_at_start, toi_parts_from, toi_shape_from,
};
pub use toi_sphere_capsule::toi_sphere_capsule;
pub use toi_sphere_convex::toi_sphere_convex;
pub use toi_sphere_cuboid::toi_sphere_cuboid;
pub use toi_sphere_halfspace::toi_sphere_halfspace;
pub use toi_sphere_sphere::{toi_sphere_sphere, toi_spheres_moving};
pub use toi_sphere_triangle::toi_sphere_triangle;
pub use toi_sphere_trimesh::toi_sphere_trimesh;
