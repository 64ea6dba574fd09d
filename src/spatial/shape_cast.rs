//! A cast of any convex shape: the first contact of a ball, box, capsule, cylinder, cone,
//! ellipsoid or convex hull translated along a direction (its orientation fixed) with one
//! shape, what Avian's `cast_shape` and rapier's `cast_shape` answer for any collider.
//!
//! - **Ball, box, capsule casters** take their own casts ([`cast_sphere`], [`cast_box`],
//!   [`cast_capsule`]): closed forms and exact distances.
//! - **Cylinder, cone, ellipsoid and hull casters**, by target:
//!   - a half-space: the caster's support point along the plane's inward normal, one division;
//!   - a convex shape, a ball included: conservative advancement (Mirtich 1996) on the GJK/EPA
//!     signed distance,
//!     stepping to where the gap's tangent meets zero (the gap of a translating convex pair is
//!     convex in the travel, so the step is safe; see `advance_convex`);
//!   - a mesh: its hierarchy walked along the path of the caster's bounding sphere, nearest
//!     node first (a node or a triangle whose box, grown by that sphere, the path enters
//!     beyond the nearest hit so far is passed over), and each triangle met by conservative
//!     advancement on the GJK distance between the caster and the triangle (meshes are
//!     two-sided surfaces).
//!
//! Half-spaces and meshes are not castable (one is unbounded, the other not convex):
//! [`castable`] says so before any query. Conventions are those of [`cast_sphere`]: a caster
//! that starts touching or overlapping hits at distance 0, the normal points out of the target
//! towards the caster.

use super::box_cast::{
    ADVANCE_TOLERANCE, BoxCast, Gap, advance_convex, against_convex, against_plane, cast_box,
};
use super::capsule_cast::{CapsuleCast, cast_capsule};
use super::cast::{CastHit, Ray, cast_sphere};
use crate::bvh::QueryScratch;
use crate::ccd::SweepCull;
use crate::geometry::convex::core_distance;
use crate::geometry::convex::support::ConvexPart;
use crate::geometry::{Isometry, MeshCollider, Shape};
use glam::Vec3;

/// A shape cast: `shape` at `pose`, moving along the unit `direction` for at most
/// `max_distance`.
#[derive(Clone, Copy, Debug)]
pub struct ShapeCast<'a> {
    /// Where the shape starts.
    pub pose: Isometry,
    /// The shape cast: convex ([`castable`]).
    pub shape: &'a Shape,
    /// Unit direction of travel.
    pub direction: Vec3,
    /// Farthest travel considered.
    pub max_distance: f32,
}

/// Whether `shape` can be cast: every convex shape; not a half-space or a mesh.
pub fn castable(shape: &Shape) -> bool {
    !matches!(shape, Shape::HalfSpace(_) | Shape::TriMesh(_))
}

/// The first contact of the cast with `target` at `at`, or `None` within its reach (or for a
/// caster that is not [`castable`]).
pub fn cast_shape(
    cast: &ShapeCast,
    target: &Shape,
    at: &Isometry,
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    let (pose, direction, max) = (cast.pose, cast.direction, cast.max_distance);
    match cast.shape {
        Shape::Sphere(s) => {
            let ray = Ray::new(pose.translation, direction).ok()?;
            let aabb = target.world_aabb(at);
            cast_sphere(&ray, s.radius, max, (target, at, &aabb), scratch)
        }
        Shape::Cuboid(c) => {
            let cast = BoxCast {
                pose,
                half_extents: c.half_extents,
                direction,
                max_distance: max,
            };
            cast_box(&cast, target, at, scratch)
        }
        Shape::Capsule(c) => {
            let cast = CapsuleCast {
                pose,
                capsule: *c,
                direction,
                max_distance: max,
            };
            cast_capsule(&cast, target, at, scratch)
        }
        Shape::HalfSpace(_) | Shape::TriMesh(_) => None,
        caster => convex_cast((caster, &pose), (direction, max), (target, at), scratch),
    }
}

/// A convex caster without a cast of its own against any target (see the [module](self)).
fn convex_cast(
    (shape, pose): (&Shape, &Isometry),
    motion: (Vec3, f32),
    (target, at): (&Shape, &Isometry),
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    match target {
        // A ball is a convex target like the others: the advancement on the exact gap ends
        // within its tolerance along the path. Swept the other way round, as continuous
        // collision sweeps a ball, it stopped within the sweep's coarser tolerance, up to 0.3
        // mm of gap and 5 mm of path short at a glance (a user-style probe).
        Shape::HalfSpace(h) => {
            let part = ConvexPart::of_shape(shape, *pose)?;
            let inward = -at.transform_vector(h.normal);
            against_plane(part.support(inward), part.rounding, motion, at, h)
        }
        Shape::TriMesh(m) => against_mesh((shape, pose), motion, at, m, scratch),
        _ => against_convex((shape, pose), motion, (target, at)),
    }
}

/// A convex caster against a mesh's triangles, in the mesh's frame (see the [module](self)):
/// the hierarchy walked nearest node first along the caster's path (by the nodes' swept-sphere
/// entries, [`SweepCull::sweep_entry`]), so that the first hits found bound the rest of the
/// walk.
pub(super) fn against_mesh(
    (shape, pose): (&Shape, &Isometry),
    (direction, max): (Vec3, f32),
    at: &Isometry,
    mesh: &MeshCollider,
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    let start = at.inv_mul(pose);
    let local = at.inverse_transform_vector(direction);
    // Within this of the centre's path the caster may touch (its bounding sphere, and the
    // advancement's tolerance).
    let radius = shape.bounding_radius();
    let reach = radius + ADVANCE_TOLERANCE * (2.0 + radius);
    let tolerance = ADVANCE_TOLERANCE * (1.0 + radius);
    let entry =
        |bv: &dyn SweepCull, limit: f32| bv.sweep_entry(start.translation, local, reach, limit);
    let (nodes, order) = (mesh.bvh().nodes(), mesh.bvh().triangle_order());
    let mut best: Option<CastHit> = None;
    let stack = &mut scratch.along;
    stack.clear();
    stack.extend(entry(&nodes[0].bv, max).map(|t| (0, t)));
    // Hits within the tolerance of each other are one contact seen from several triangles: the
    // more head-on normal wins (a flat caster landing across a seam touches the triangle
    // beside it only at its edge, where the closest points lie side by side and the normal
    // came out level: `(1, 0, 0)` for a cylinder dropped onto a tessellated floor), at the
    // nearer of the two distances (never later than a triangle's own hit).
    let reach_of = |best: Option<CastHit>| best.map_or(max, |b| (b.distance + tolerance).min(max));
    let chosen = |hit: CastHit, best: CastHit| {
        if (hit.distance - best.distance).abs() > tolerance {
            return if hit.distance < best.distance {
                hit
            } else {
                best
            };
        }
        let distance = hit.distance.min(best.distance);
        let head_on = if hit.normal.dot(local) < best.normal.dot(local) {
            hit
        } else {
            best
        };
        CastHit {
            distance,
            ..head_on
        }
    };
    while let Some((index, at_entry)) = stack.pop() {
        // Only a nearer hit than the best so far matters (or a tie, for its normal).
        let limit = reach_of(best);
        if at_entry > limit {
            continue;
        }
        let node = &nodes[index as usize];
        if let Some(children) = node.children() {
            let [a, b] = children.map(|c| entry(&nodes[c as usize].bv, limit).map(|t| (c, t)));
            // The nearer child on top of the stack.
            let (first, second) = match (a, b) {
                (Some(x), Some(y)) if y.1 < x.1 => (Some(y), Some(x)),
                _ => (a, b),
            };
            stack.extend(second);
            stack.extend(first);
            continue;
        }
        for &t in node.triangle_range().map_or(&[][..], |r| &order[r]) {
            let Some(tri) = mesh.mesh().triangle(t as usize) else {
                continue;
            };
            let limit = reach_of(best);
            if entry(&tri.aabb(), limit).is_none() {
                continue;
            }
            let triangle = ConvexPart::triangle(&tri);
            let hit = advance_convex(limit, tolerance, local, |t| {
                let moved = Isometry::new(start.translation + local * t, start.rotation);
                triangle_gap(&triangle, shape, &moved, local)
            });
            if let Some(hit) = hit {
                best = Some(best.map_or(hit, |best| chosen(hit, best)));
            }
        }
    }
    best.map(|hit| CastHit {
        distance: hit.distance,
        point: at.transform_point(hit.point),
        normal: at.transform_vector(hit.normal),
    })
}

/// The gap between a triangle and the caster at `moved` (both in the mesh's frame); a pair
/// with no defined distance (a flat caster in the triangle's plane) counts as touching.
fn triangle_gap(triangle: &ConvexPart, shape: &Shape, moved: &Isometry, direction: Vec3) -> Gap {
    let touching = Gap {
        distance: 0.0,
        on_target: moved.translation,
        normal: -direction,
    };
    let Some(caster) = ConvexPart::of_shape(shape, *moved) else {
        return touching;
    };
    match core_distance(triangle, &caster) {
        Some(d) => Gap {
            distance: d.distance,
            on_target: d.on_a,
            normal: d.normal,
        },
        None => touching,
    }
}
