//! A box cast: the first contact of an oriented box translated along a direction (its
//! orientation fixed) with one shape, in closed form where the target is a polytope.
//!
//! - **Box, triangle** (and so meshes, through their hierarchy): the separating-axis test with
//!   velocity (Ericson 2005, *Real-Time Collision Detection* §5.5.8, there for two AABBs; here on
//!   every candidate axis of the pair — the 15 of two boxes, the 13 of a box and a triangle).
//!   Two convex polytopes in linear motion overlap exactly while their projections overlap on
//!   every axis, so the contact begins at the latest of the axes' entry times, if that comes
//!   before the earliest exit. The axis entered last is the contact normal.
//! - **Sphere**: the sphere swept the other way against the box (`ccd`'s exact rounded-box
//!   sweep): only the relative motion matters.
//! - **Half-space**: the box's lowest corner against the plane, one division.
//! - **Capsule**: conservative advancement (Mirtich 1996) on the exact segment–box distance of
//!   `capsule_cuboid.rs`: a rounded shape has no finite axis set.
//!
//! Conventions are those of [`cast_sphere`](super::cast_sphere): a box that starts touching or
//! overlapping hits at distance 0, the normal points out of the target towards the box, meshes
//! are two-sided surfaces.

use super::cast::{CastHit, Ray, cast_at_plane};
use crate::bvh::QueryScratch;
use crate::ccd::{SphereSweep, toi_sphere_shape};
use crate::geometry::contacts::closest_segment_box;
use crate::geometry::convex::signed_distance;
use crate::geometry::{Capsule, HalfSpace, Isometry, MeshCollider, Shape, Sphere};
use glam::{Mat3, Vec3};
use std::cell::Cell;
use std::ops::ControlFlow;

/// A box cast: the box of `half_extents` at `pose`, moving along the unit `direction` for at
/// most `max_distance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxCast {
    /// Where the box starts.
    pub pose: Isometry,
    /// Its half extents.
    pub half_extents: Vec3,
    /// Unit direction of travel.
    pub direction: Vec3,
    /// Farthest travel considered.
    pub max_distance: f32,
}

/// Conservative advancement stops this close to the target (relative to the sizes involved).
pub(crate) const ADVANCE_TOLERANCE: f32 = 1e-5;
/// Conservative advancement gives up (no hit) after this many steps; its steps converge
/// quadratically ([`advance_convex`]), so only a pathological gap function reaches it.
const ADVANCE_ITERATIONS: u32 = 64;

/// The first contact of the cast with `shape` at `target`, or `None` within its reach.
pub fn cast_box(
    cast: &BoxCast,
    shape: &Shape,
    target: &Isometry,
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    match shape {
        Shape::Cuboid(c) => {
            let corners = box_corners(target, c.half_extents);
            let axes = target.rotation_matrix();
            let edges = [axes.x_axis, axes.y_axis, axes.z_axis];
            polytope_cast(
                cast,
                &corners,
                &edges,
                &[axes.x_axis, axes.y_axis, axes.z_axis],
            )
        }
        Shape::Sphere(s) => {
            let me = Shape::cuboid(cast.half_extents);
            let motion = (cast.direction, cast.max_distance);
            against_ball((&me, &cast.pose), motion, target.translation, s, scratch)
        }
        Shape::HalfSpace(h) => {
            let n = target.transform_vector(h.normal);
            let lowest = support(&box_corners(&cast.pose, cast.half_extents), -n);
            let motion = (cast.direction, cast.max_distance);
            against_plane(lowest, 0.0, motion, target, h)
        }
        Shape::Capsule(c) => against_capsule(cast, target, c),
        Shape::Cylinder(_) | Shape::Cone(_) | Shape::Ellipsoid(_) | Shape::ConvexHull(_) => {
            let me = Shape::cuboid(cast.half_extents);
            let motion = (cast.direction, cast.max_distance);
            against_convex((&me, &cast.pose), motion, (shape, target))
        }
        Shape::TriMesh(m) => against_mesh(cast, target, m, scratch),
    }
}

/// A convex caster (`shape` at `pose`, moving along the unit `direction` for at most `max`)
/// against a convex target: conservative advancement on their GJK/EPA signed distance. A pair
/// with no defined distance (two flat shapes in one plane) counts as touching where it is.
pub(crate) fn against_convex(
    (shape, pose): (&Shape, &Isometry),
    (direction, max): (Vec3, f32),
    (target, at): (&Shape, &Isometry),
) -> Option<CastHit> {
    let reach = shape.bounding_radius() + target.bounding_radius();
    let tolerance = ADVANCE_TOLERANCE * (1.0 + reach);
    advance_convex(max, tolerance, direction, |t| {
        let moved = Isometry::new(pose.translation + direction * t, pose.rotation);
        match signed_distance(target, at, shape, &moved) {
            Some(d) => Gap {
                distance: d.distance,
                on_target: d.on_a,
                normal: d.normal,
            },
            None => Gap {
                distance: 0.0,
                on_target: moved.translation,
                normal: -direction,
            },
        }
    })
}

fn box_corners(pose: &Isometry, h: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|k| {
        let sign = |bit: usize| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
        pose.transform_point(h * Vec3::new(sign(0), sign(1), sign(2)))
    })
}

/// The separating-axis test with velocity of the cast against the convex polytope with
/// `vertices`, edge directions `edges` and face normals `faces` (world space).
fn polytope_cast(
    cast: &BoxCast,
    vertices: &[Vec3],
    edges: &[Vec3],
    faces: &[Vec3],
) -> Option<CastHit> {
    let axes = cast.pose.rotation_matrix();
    let own = [axes.x_axis, axes.y_axis, axes.z_axis];
    let corners = box_corners(&cast.pose, cast.half_extents);
    let (mut enter, mut exit) = (f32::NEG_INFINITY, cast.max_distance);
    let mut normal = -cast.direction;
    let mut consider = |axis: Vec3| -> bool {
        let Some(axis) = axis.try_normalize() else {
            return true;
        };
        let (a_lo, a_hi) = extent(&corners, axis);
        let (b_lo, b_hi) = extent(vertices, axis);
        let speed = cast.direction.dot(axis);
        let (t_in, t_out, side) = if speed.abs() <= f32::EPSILON {
            if a_hi < b_lo || b_hi < a_lo {
                return false;
            }
            (f32::NEG_INFINITY, f32::INFINITY, axis)
        } else if speed > 0.0 {
            ((b_lo - a_hi) / speed, (b_hi - a_lo) / speed, -axis)
        } else {
            ((b_hi - a_lo) / speed, (b_lo - a_hi) / speed, axis)
        };
        if t_in > enter {
            enter = t_in;
            normal = side;
        }
        exit = exit.min(t_out);
        enter <= exit
    };
    let face_axes = own.iter().chain(faces);
    let edge_axes = own
        .iter()
        .flat_map(|a| edges.iter().map(move |e| a.cross(*e)));
    for axis in face_axes.copied().chain(edge_axes) {
        if !consider(axis) {
            return None;
        }
    }
    if exit < 0.0 || enter > cast.max_distance {
        return None;
    }
    let distance = enter.max(0.0);
    let moved = cast.direction * distance;
    // Where they meet: midway between the two supports along the normal (both on the plane
    // of contact when the box arrives; for a face against a face, between the two faces'
    // centres of support).
    let on_box = support(&corners, -normal) + moved;
    let on_target = support(vertices, normal);
    Some(CastHit {
        distance,
        point: (on_box + on_target) * 0.5,
        normal,
    })
}

/// The lowest and highest projections of `points` on `axis`.
fn extent(points: &[Vec3], axis: Vec3) -> (f32, f32) {
    points
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            let d = p.dot(axis);
            (lo.min(d), hi.max(d))
        })
}

/// The centre of the points extreme along `dir` (within rounding): a vertex, an edge's midpoint
/// or a face's centre.
fn support(points: &[Vec3], dir: Vec3) -> Vec3 {
    let (_, top) = extent(points, dir);
    let slack = 1e-5 * (1.0 + top.abs());
    let (sum, count) = points
        .iter()
        .filter(|p| p.dot(dir) >= top - slack)
        .fold((Vec3::ZERO, 0.0f32), |(s, n), p| (s + *p, n + 1.0));
    sum / count.max(1.0)
}

/// A caster (`shape` at `pose`, moving along the unit `direction` for at most `max`) against a
/// ball: the ball swept the other way against the caster at rest (`ccd`'s exact sweeps), since
/// only the relative motion matters; the contact then moves with the caster.
pub(crate) fn against_ball(
    (shape, pose): (&Shape, &Isometry),
    (direction, max): (Vec3, f32),
    center: Vec3,
    ball: &Sphere,
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    let sweep = SphereSweep::new(center, ball.radius, -direction * max).ok()?;
    let toi = toi_sphere_shape(&sweep, shape, pose, scratch)?;
    let distance = toi.t * max;
    Some(CastHit {
        distance,
        point: toi.point + direction * distance,
        normal: -toi.normal,
    })
}

/// A caster whose point nearest the plane, grown by `radius`, is `lowest`, moving along the
/// unit `direction` for at most `max`, against the half-space `h` at `pose`.
pub(crate) fn against_plane(
    lowest: Vec3,
    radius: f32,
    (direction, max): (Vec3, f32),
    pose: &Isometry,
    h: &HalfSpace,
) -> Option<CastHit> {
    let ray = Ray::new(lowest, direction).ok()?;
    cast_at_plane(
        &ray,
        radius,
        max,
        pose.translation,
        pose.transform_vector(h.normal),
    )
}

fn against_capsule(cast: &BoxCast, pose: &Isometry, c: &Capsule) -> Option<CastHit> {
    let (a, b) = c.segment(pose);
    let h = cast.half_extents;
    let tolerance = ADVANCE_TOLERANCE * (1.0 + h.max_element() + c.half_length + c.radius);
    advance_convex(cast.max_distance, tolerance, cast.direction, |t| {
        let at = Isometry::new(
            cast.pose.translation + cast.direction * t,
            cast.pose.rotation,
        );
        let (on_axis, on_box) = closest_segment_box(
            at.inverse_transform_point(a),
            at.inverse_transform_point(b),
            h,
        );
        let (on_axis, on_box) = (at.transform_point(on_axis), at.transform_point(on_box));
        let out = (on_box - on_axis)
            .try_normalize()
            .unwrap_or(-cast.direction);
        Gap {
            distance: on_axis.distance(on_box) - c.radius,
            on_target: on_axis + out * c.radius,
            normal: out,
        }
    })
}

/// How far a caster is from a target: the signed distance (negative: overlapping), the
/// target's point nearest the caster, and the unit normal out of the target towards it.
pub(crate) struct Gap {
    pub distance: f32,
    pub on_target: Vec3,
    pub normal: Vec3,
}

/// Conservative advancement for a convex caster against a convex target (`direction` the
/// caster's unit motion). The gap between two convex shapes, one translating, is a convex
/// function of the travel (the distance from a point moving on a line to their Minkowski
/// difference), so the tangent at `t`, of slope `normal · direction`, meets zero no later than
/// the gap does: stepping there (Newton's step, from below) is conservative (Mirtich 1996's
/// conservative advancement with the gap's own slope for the speed bound), and much faster
/// than a unit-speed step when the caster comes at a glance: unit steps shrink geometrically
/// there and ran out of iterations, missing a capsule sliding onto a floor at 2°. A gap that
/// does not shrink never will: no hit. A step that lands inside the target (the normal's
/// rounding) is bisected back to the surface, so a hit is always a place within `tolerance`
/// *outside* the target (or the start, when it starts touching).
pub(crate) fn advance_convex(
    max: f32,
    tolerance: f32,
    direction: Vec3,
    mut gap: impl FnMut(f32) -> Gap,
) -> Option<CastHit> {
    let hit = |t: f32, g: &Gap| CastHit {
        distance: t,
        point: g.on_target,
        normal: g.normal,
    };
    let (mut safe, mut g) = (0.0f32, gap(0.0));
    for _ in 0..ADVANCE_ITERATIONS {
        if g.distance <= tolerance {
            if safe > 0.0 {
                (safe, g) = last_step((safe, g), (max, tolerance), direction, &mut gap);
            }
            return Some(hit(safe, &g));
        }
        // Not closing (or a NaN normal): never nearer.
        let closing = -g.normal.dot(direction);
        if closing.is_nan() || closing <= 0.0 {
            return None;
        }
        let t = safe + g.distance / closing.min(1.0);
        if t.is_nan() || t > max {
            return None;
        }
        let next = gap(t);
        if next.distance < 0.0 {
            let (t, g) = bisect_to_surface((safe, t), g, tolerance, &mut gap);
            return Some(hit(t, &g));
        }
        (safe, g) = (t, next);
    }
    None
}

/// One more conservative step from `(safe, g)`, a place within `tolerance` of the target: the
/// gap is within the tolerance, but the path's remaining length is the gap over the slope at
/// which the path closes it, `tolerance / slope` at most, and a cylinder cast at a slope of
/// 0.06 stopped 0.3 mm short of a floor it was to land on (a user-style probe). The step
/// leaves the error of the tangent's reach, second order in the gap for a flat contact. A
/// step that would pass `max` or land inside is not taken (bisected back, inside).
fn last_step(
    (safe, g): (f32, Gap),
    (max, tolerance): (f32, f32),
    direction: Vec3,
    gap: &mut impl FnMut(f32) -> Gap,
) -> (f32, Gap) {
    let closing = -g.normal.dot(direction);
    if closing.is_nan() || closing <= 0.0 || g.distance <= 0.0 {
        return (safe, g);
    }
    let t = safe + g.distance / closing.min(1.0);
    if t.is_nan() || t > max || t <= safe {
        return (safe, g);
    }
    let next = gap(t);
    if next.distance < 0.0 {
        return bisect_to_surface((safe, t), g, tolerance, gap);
    }
    if next.distance <= g.distance {
        (t, next)
    } else {
        (safe, g)
    }
}

/// The surface between `apart` (the caster clear of the target, its gap `at_apart`) and
/// `inside` (overlapping it), by bisection down to `tolerance` of the path: the last place
/// found apart. Stopped at the first place within `tolerance` of the target instead, a cast
/// came at most that close in gap but up to `tolerance / slope` short along a glancing path
/// (a flat cap landing on a floor, the step landing a rounding inside).
fn bisect_to_surface(
    (mut apart, mut inside): (f32, f32),
    mut at_apart: Gap,
    tolerance: f32,
    gap: &mut impl FnMut(f32) -> Gap,
) -> (f32, Gap) {
    for _ in 0..ADVANCE_ITERATIONS {
        let mid = 0.5 * (apart + inside);
        if inside - apart <= tolerance || mid <= apart || mid >= inside {
            break;
        }
        let g = gap(mid);
        if g.distance < 0.0 {
            inside = mid;
        } else {
            (apart, at_apart) = (mid, g);
        }
    }
    (apart, at_apart)
}

fn against_mesh(
    cast: &BoxCast,
    pose: &Isometry,
    mesh: &MeshCollider,
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    // The cast in the mesh's frame, and a box holding its whole sweep (the box's own axes,
    // stretched along the travel) for the hierarchy's node test.
    let local = BoxCast {
        pose: pose.inv_mul(&cast.pose),
        direction: pose.inverse_transform_vector(cast.direction),
        ..*cast
    };
    let axes: Mat3 = local.pose.rotation_matrix();
    let reach = (axes.transpose() * local.direction).abs() * (0.5 * cast.max_distance);
    let swept = crate::bounding::Obb {
        center: local.pose.translation + local.direction * (0.5 * cast.max_distance),
        axes,
        half_extents: local.half_extents + reach + Vec3::splat(ADVANCE_TOLERANCE),
    };
    let same_frame = crate::bounding::RelativePose::new(&Isometry::IDENTITY);
    let best: Cell<Option<CastHit>> = Cell::new(None);
    use crate::bounding::Bv;
    mesh.bvh().descend(
        scratch,
        |bv| bv.overlaps(&swept, &same_frame),
        |t| {
            let Some(tri) = mesh.mesh().triangle(t as usize) else {
                return ControlFlow::Continue(());
            };
            let v = tri.vertices();
            let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
            let face = edges[0].cross(edges[1]);
            if let Some(hit) = polytope_cast(&local, &v, &edges, &[face])
                && best.get().is_none_or(|b| hit.distance < b.distance)
            {
                best.set(Some(hit));
            }
            ControlFlow::Continue(())
        },
    );
    best.get().map(|hit| CastHit {
        distance: hit.distance,
        point: pose.transform_point(hit.point),
        normal: pose.transform_vector(hit.normal),
    })
}
