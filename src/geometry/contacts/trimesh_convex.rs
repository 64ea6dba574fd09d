//! Mesh–convex for the shapes without a closed form (cylinders, ellipsoids, hulls): the shape,
//! carried into the mesh's frame, descends the mesh's OBB hierarchy inside its own oriented box
//! (as mesh–box does), and every triangle reached is a convex part of its own for GJK/EPA and
//! the feature clip of `convex_convex.rs`. A contact that touches a triangle only on its
//! inactive edges takes the face normal ([`active_edges`](crate::geometry::active_edges)), so a
//! cylinder rolling across a tessellated floor does not bump on the seams.
//!
//! A *flat* seam (its triangles coplanar within
//! [`FLAT_DEGREES`](crate::geometry::active_edges::FLAT_DEGREES)) hands a part that is still
//! apart to the neighbour when it sees the part more than 5° off its face normal: the part is
//! over the neighbour, which reports it. Read along this face's normal it would be a second,
//! speculative point on the part's curved side ahead of where it rests, whose row (assuming
//! the point keeps its downward speed for the whole step) brakes a rolling cylinder: 12 seams
//! took 20 % of its speed, now 4 % (`scenarios/convex.rs`). A part the seam sees side-on
//! (more than 60° off its face normal: a lying cylinder's flat end over the seam), touching or
//! not, is handed over too: read along the face from here its point lay at the floor's level.
//! Where the face normal is taken, its side is the part's (its middle along the normal), not
//! the sign of a contact normal lying along the face. Only flat seams: across a fold of
//! a few degrees the neighbour may rise towards the part (a valley) or every face around a
//! vertex may see it steeply (a low peak), and the seam's own reading is what holds it there.
//!
//! The triangle contacts are merged into one manifold as `mesh_manifold.rs` explains.

use super::closest_segment_points::closest_point_on_segment;
use super::convex_convex::manifold;
use super::mesh_scratch::ContactScratch;
use super::trimesh_cuboid::carried_box;
use crate::bounding::{Bv, RelativePose};
use crate::geometry::active_edges::{
    COPLANAR_DEGREES, edges_holding, face_normal_at_inactive_edge,
};
use crate::geometry::convex::support::ConvexPart;
use crate::geometry::convex::{SignedDistance, core_distance_within};
use crate::geometry::{ContactManifold, Isometry, MeshCollider, Shape, Triangle};
use glam::Vec3;

/// Contact between a mesh at `pose_mesh` (shape A) and the convex `shape` at `pose_shape`
/// (shape B), with a speculative `margin`; `None` when `shape` is not convex or nothing is
/// within the margin.
pub(crate) fn contact_trimesh_convex(
    (pose_mesh, mesh): (&Isometry, &MeshCollider),
    (pose_shape, shape): (&Isometry, &Shape),
    margin: f32,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    let in_mesh = pose_mesh.inv_mul(pose_shape);
    let part = ConvexPart::of_shape(shape, in_mesh)?;
    let half = local_half_extents(shape) + Vec3::splat(margin.max(0.0));
    let probe = carried_box(&in_mesh, half, mesh);
    let same_frame = RelativePose::new(&Isometry::IDENTITY);
    scratch.collect_triangle_contacts(
        mesh,
        |bv| bv.overlaps(&probe, &same_frame),
        |t, tri| {
            let edges = (mesh.active_edges(t), mesh.flat_edges(t));
            triangle_contact(tri, edges, &part, margin)
        },
    );
    let merged = scratch.merge(pose_mesh)?;
    Some(under_the_axis(merged, shape, pose_shape))
}

/// A cylinder lying on the mesh (its side square to the normal) touches it along the line
/// under its axis, so each point is moved across the normal to under the axis (its depth
/// kept). The solver follows a rounded side's point as its core's, `ρ` below it along the
/// normal (`contact_normals.rs`, "Rounded sides roll"); a point of a triangle reaching under
/// the cylinder only beyond a seam came from the seam, on the cylinder's curve ahead of the
/// line, and its core was read that far ahead of the axis: rolling at 10 rad/s across the
/// grid's lines at 0.3 rad, such a point 26 mm ahead sank 1.1 mm a substep by the solver's
/// reckoning, and the push kicked the cylinder 3.5 mm up. Under the axis, rolling keeps it
/// where it is.
fn under_the_axis(m: ContactManifold, shape: &Shape, pose: &Isometry) -> ContactManifold {
    let Shape::Cylinder(c) = shape else {
        return m;
    };
    if shape.rounding_along(pose.rotation, m.normal) == 0.0 {
        return m;
    }
    let half = pose.rotation * Vec3::Z * c.half_height;
    let (bottom, top) = (pose.translation - half, pose.translation + half);
    let n = m.normal;
    m.with_points_moved(|p| {
        let core = closest_point_on_segment(bottom, top, p);
        core + n * (p - core).dot(n)
    })
}

/// Half extents of a box about the shape's origin that holds it (its local box, made
/// symmetric: a hull's need not be centred on its origin).
fn local_half_extents(shape: &Shape) -> Vec3 {
    let b = shape.world_aabb(&Isometry::IDENTITY);
    b.min.abs().max(b.max.abs())
}

/// One triangle (A) against the convex part (B), in the mesh's frame; `(active, flat)` are
/// the triangle's edge marks (see [`MeshCollider::flat_edges`]).
fn triangle_contact(
    tri: &Triangle,
    (active, flat): (u8, u8),
    part: &ConvexPart,
    margin: f32,
) -> Option<ContactManifold> {
    let face = ConvexPart::triangle(tri);
    let d = core_distance_within(&face, part, margin)?;
    if d.distance > margin {
        return None;
    }
    let side = side_of(tri, &d, part);
    let d = match face_normal_at_inactive_edge(tri, active, d.on_a, side) {
        Some(up) if beside_a_flat_seam(tri, flat, &d, up) => return None,
        Some(up) => along_face(tri, up, &d),
        None => d,
    };
    (d.distance <= margin).then(|| manifold(&face, part, &d, margin))
}

/// A contact normal at least this far off the face (cosine, 60°) runs along it: the part
/// touches the triangle's edge side-on.
const SIDEWAYS_COSINE: f32 = 0.5;

/// Whether the part is beside a flat seam, over the neighbour, which reports it (module
/// notes): the closest pair lies only on flat edges (it lies on some edge: the face normal was
/// taken), and the seam sees the part, apart, more steeply than [`COPLANAR_DEGREES`] (5°, ten
/// times the fold a flat seam may have), or, touching or not, side-on (a lying cylinder's flat
/// end over a seam: read along the face from here, its point came out at the floor's level,
/// 1 mm shallow where the log lay 1 mm deep).
fn beside_a_flat_seam(tri: &Triangle, flat: u8, d: &SignedDistance, up: Vec3) -> bool {
    let along = d.normal.dot(up);
    let steep = d.distance > 0.0 && along < COPLANAR_DEGREES.to_radians().cos();
    (steep || along.abs() < SIDEWAYS_COSINE) && edges_holding(tri, d.on_a) & !flat == 0
}

/// The side of the triangle the part is on, to choose the face normal taken at an inactive
/// edge: the contact normal's, unless that runs along the face, where its sign is the
/// rounding's; then the side of the part's middle along the face normal (midway between its
/// extremes). A level normal picked the face normal below a floor, and the part was read from
/// underneath: a log lying 1 mm into a tessellated incline with its flat end over a seam read
/// 199 mm deep and was pushed through (14 mm into the incline as it rolled down).
fn side_of(tri: &Triangle, d: &SignedDistance, part: &ConvexPart) -> Vec3 {
    let Some(face) = tri.normal() else {
        return d.normal;
    };
    if face.dot(d.normal).abs() >= SIDEWAYS_COSINE {
        return d.normal;
    }
    let middle = 0.5 * (part.support(face) + part.support(-face));
    let height = face.dot(middle - tri.a);
    if height == 0.0 {
        d.normal
    } else {
        face * height.signum()
    }
}

/// The contact read along the face normal `up` (towards the part) when the surface continues
/// flat past an inactive edge: the closest pair `d` on this triangle keeps its points, and the
/// part's point's height above the triangle's plane becomes the distance. (The part's lowest
/// point overall may lie over a neighbour: a cylinder lying across a seam is 7 mm above this
/// triangle where it comes closest to it, and that, not the neighbour's contact, is this
/// triangle's. Moving the points under the part's lowest point instead, or under `d.on_b`,
/// was measured worse: a standing cylinder drifted 8.5 mm in 3 s on a tessellated floor, a
/// rolling one veered 10 cm.)
fn along_face(tri: &Triangle, up: Vec3, d: &SignedDistance) -> SignedDistance {
    SignedDistance {
        distance: up.dot(d.on_b - tri.a),
        normal: up,
        ..*d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::TriMesh;
    use crate::geometry::contacts::{ContactScratch, contact_with_scratch};
    use glam::Quat;

    #[test]
    fn a_log_on_a_tessellated_incline_with_its_ends_over_seams_reads_every_point_at_its_depth_within_1e_5()
     {
        // Its flat ends lie over the grid's seams: the triangles beyond them, touched side-on,
        // read it from underneath (199 mm deep) or at the floor's level (1 mm shallow).
        let tilt = Quat::from_rotation_y(-20f32.to_radians());
        let normal = tilt * Vec3::Z;
        let grid = TriMesh::grid_floor(40.0, 80).unwrap(); // 0.5 m cells
        let floor = Shape::TriMesh(MeshCollider::new(grid).unwrap());
        let floor_pose = Isometry::new(Vec3::ZERO, tilt);
        let (log, radius, depth) = (Shape::cylinder(1.0, 0.1), 0.1, 1e-3);
        let lying = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
        let mut scratch = ContactScratch::default();
        for i in 0..600 {
            // Rolled down the incline by 5 mm a pose, turned as it rolls.
            let along = -0.005 * i as f32;
            let turn = tilt * Quat::from_rotation_y(-along / radius) * lying;
            let at = tilt * Vec3::X * along + normal * (radius - depth);
            let pose = Isometry::new(at, turn);
            let m = contact_with_scratch(&log, &pose, &floor, &floor_pose, &mut scratch);
            let m = m.unwrap_or_else(|| panic!("pose {i}: no contact"));
            assert!(
                m.normal.dot(-normal) > 1.0 - 1e-6,
                "pose {i}: normal {}",
                m.normal
            );
            for p in m.points() {
                assert!((p.depth - depth).abs() < 1e-5, "pose {i}: {m:?}");
            }
        }
    }
}
