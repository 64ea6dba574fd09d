//! A capsule cast: the first contact of a capsule translated along a direction (its
//! orientation fixed), the sweep a character controller makes before it moves.
//!
//! - **Sphere**: the sphere swept the other way against the capsule (`ccd`'s exact capsule
//!   sweep: a cylinder and two balls); only the relative motion matters.
//! - **Half-space**: the capsule's lower cap against the plane, one division.
//! - **Box, capsule**: conservative advancement (Mirtich 1996) on the exact distance from the
//!   capsule's inner segment — to a box (the piecewise-quadratic distance of
//!   `capsule_cuboid.rs`), to a segment (Ericson §5.1.9) — stepping to where the gap's tangent
//!   meets zero (`advance_convex`: the gap of a translating convex pair is convex in the travel).
//! - **Mesh**: each triangle its swept box meets, as any convex cast does
//!   ([`super::shape_cast`]): a character's capsule sliding onto a floor at a glance finds it.
//!
//! Conventions are those of [`cast_sphere`](super::cast_sphere): a capsule that starts touching
//! or overlapping hits at distance 0, the normal points out of the target towards the capsule,
//! meshes are two-sided surfaces.

use super::box_cast::{
    ADVANCE_TOLERANCE, Gap, advance_convex, against_ball, against_convex, against_plane,
};
use super::cast::CastHit;
use super::shape_cast::against_mesh;
use crate::bvh::QueryScratch;
use crate::geometry::contacts::{Segment, closest_segment_box, closest_segment_points};
use crate::geometry::{Capsule, Isometry, Shape};
use glam::Vec3;

/// A capsule cast: `capsule` at `pose`, moving along the unit `direction` for at most
/// `max_distance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CapsuleCast {
    /// Where the capsule starts.
    pub pose: Isometry,
    /// Its shape.
    pub capsule: Capsule,
    /// Unit direction of travel.
    pub direction: Vec3,
    /// Farthest travel considered.
    pub max_distance: f32,
}

impl CapsuleCast {
    /// The inner segment's ends after travelling `t`.
    fn segment_at(&self, t: f32) -> (Vec3, Vec3) {
        let (a, b) = self.capsule.segment(&self.pose);
        let moved = self.direction * t;
        (a + moved, b + moved)
    }
}

/// The first contact of the cast with `shape` at `target`, or `None` within its reach.
pub fn cast_capsule(
    cast: &CapsuleCast,
    shape: &Shape,
    target: &Isometry,
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    let r = cast.capsule.radius;
    // Relative to the caster: a capsule cast at a kilometre-wide terrain mesh must not stop
    // metres short of it.
    let tolerance = ADVANCE_TOLERANCE * (1.0 + cast.capsule.half_length + r);
    // The gap from the capsule's segment to the target's closest points (target, segment).
    let gap_from = |on_target: Vec3, on_axis: Vec3, target_radius: f32| {
        let out = (on_axis - on_target)
            .try_normalize()
            .unwrap_or(-cast.direction);
        Gap {
            distance: on_target.distance(on_axis) - r - target_radius,
            on_target: on_target + out * target_radius,
            normal: out,
        }
    };
    match shape {
        Shape::Sphere(s) => {
            let me = Shape::Capsule(cast.capsule);
            let motion = (cast.direction, cast.max_distance);
            against_ball((&me, &cast.pose), motion, target.translation, s, scratch)
        }
        Shape::HalfSpace(h) => {
            let n = target.transform_vector(h.normal);
            let (a, b) = cast.segment_at(0.0);
            let low = if n.dot(a) <= n.dot(b) { a } else { b };
            against_plane(low, r, (cast.direction, cast.max_distance), target, h)
        }
        Shape::Cuboid(c) => advance_convex(cast.max_distance, tolerance, cast.direction, |t| {
            let (a, b) = cast.segment_at(t);
            let local = (
                target.inverse_transform_point(a),
                target.inverse_transform_point(b),
            );
            let (on_axis, on_box) = closest_segment_box(local.0, local.1, c.half_extents);
            gap_from(
                target.transform_point(on_box),
                target.transform_point(on_axis),
                0.0,
            )
        }),
        Shape::Capsule(other) => {
            let (c0, c1) = other.segment(target);
            advance_convex(cast.max_distance, tolerance, cast.direction, |t| {
                let (a, b) = cast.segment_at(t);
                let (on_axis, on_other) = closest_segment_points(
                    Segment { start: a, end: b },
                    Segment { start: c0, end: c1 },
                );
                gap_from(on_other, on_axis, other.radius)
            })
        }
        Shape::Cylinder(_) | Shape::Cone(_) | Shape::Ellipsoid(_) | Shape::ConvexHull(_) => {
            let me = Shape::Capsule(cast.capsule);
            let motion = (cast.direction, cast.max_distance);
            against_convex((&me, &cast.pose), motion, (shape, target))
        }
        Shape::TriMesh(m) => {
            let me = Shape::Capsule(cast.capsule);
            let motion = (cast.direction, cast.max_distance);
            against_mesh((&me, &cast.pose), motion, target, m, scratch)
        }
    }
}
