//! The point of a collider nearest to a query point (parry's `project_point` with `solid`
//! true, Avian's `SpatialQuery::project_point`): for a solid shape a point inside is its own
//! nearest point, at distance 0, and is reported as inside; a mesh is a surface, so its nearest
//! point is always on a triangle (found through the mesh's hierarchy, a node visited only while
//! its box is nearer than the best triangle so far).

use crate::bvh::QueryScratch;
use crate::geometry::contacts::closest_point_on_segment;
use crate::geometry::convex::signed_distance;
use crate::geometry::{Isometry, MeshCollider, Shape};
use glam::Vec3;
use std::cell::Cell;
use std::ops::ControlFlow;

/// Where a point query met a collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointHit {
    /// The collider's point nearest to the query point (the query point itself when inside).
    pub point: Vec3,
    /// Distance from the query point to it (0 when inside).
    pub distance: f32,
    /// True when the query point is inside (or on) a solid shape.
    pub inside: bool,
}

impl PointHit {
    fn outside(query: Vec3, point: Vec3) -> Self {
        Self {
            point,
            distance: query.distance(point),
            inside: false,
        }
    }

    fn inside(query: Vec3) -> Self {
        Self {
            point: query,
            distance: 0.0,
            inside: true,
        }
    }
}

/// The point of `shape` at `pose` nearest to `p` (module notes); a mesh's search reuses
/// `scratch`.
pub fn nearest_point(
    shape: &Shape,
    pose: &Isometry,
    p: Vec3,
    scratch: &mut QueryScratch,
) -> PointHit {
    let local = pose.inverse_transform_point(p);
    let solid = |inside: bool, nearest_local: Vec3| {
        if inside {
            PointHit::inside(p)
        } else {
            PointHit::outside(p, pose.transform_point(nearest_local))
        }
    };
    match shape {
        Shape::Sphere(s) => {
            let d = local.length();
            solid(d <= s.radius, local * (s.radius / d.max(f32::MIN_POSITIVE)))
        }
        Shape::Cuboid(c) => {
            let clamped = local.clamp(-c.half_extents, c.half_extents);
            solid(clamped == local, clamped)
        }
        Shape::HalfSpace(h) => {
            let height = h.normal.dot(local);
            solid(height <= 0.0, local - h.normal * height)
        }
        Shape::Capsule(c) => {
            let axis = Vec3::new(0.0, 0.0, c.half_length);
            let on_axis = closest_point_on_segment(-axis, axis, local);
            let out = local - on_axis;
            let d = out.length();
            solid(
                d <= c.radius,
                on_axis + out * (c.radius / d.max(f32::MIN_POSITIVE)),
            )
        }
        Shape::Cylinder(_) | Shape::Cone(_) | Shape::Ellipsoid(_) | Shape::ConvexHull(_) => {
            let probe = Isometry::from_translation(local);
            match signed_distance(shape, &Isometry::IDENTITY, &Shape::sphere(0.0), &probe) {
                Some(d) => solid(d.distance <= 0.0, d.on_a),
                None => solid(false, local),
            }
        }
        Shape::TriMesh(m) => {
            let nearest = nearest_on_mesh(m, local, scratch);
            PointHit::outside(p, pose.transform_point(nearest))
        }
    }
}

/// The nearest point of the mesh's triangles to `p`, in the mesh's frame.
fn nearest_on_mesh(mesh: &MeshCollider, p: Vec3, scratch: &mut QueryScratch) -> Vec3 {
    let best = Cell::new((f32::INFINITY, p));
    mesh.bvh().descend(
        scratch,
        |bv| crate::geometry::contacts::obb_distance_squared(bv, p) <= best.get().0,
        |t| {
            if let Some(tri) = mesh.mesh().triangle(t as usize) {
                let q = tri.closest_point(p);
                let d2 = (q - p).length_squared();
                if d2 < best.get().0 {
                    best.set((d2, q));
                }
            }
            ControlFlow::Continue(())
        },
    );
    best.get().1
}
