//! Mesh–box: the box, carried into the mesh's frame as an oriented box, descends the mesh's OBB
//! hierarchy (the 15-axis box–box test of Gottschalk, Lin and Manocha 1996 at every node), and
//! every triangle of the leaves reached gets the separating-axis contact of
//! `triangle_cuboid.rs`. The triangle contacts are merged into one manifold as
//! `mesh_manifold.rs` explains.

use super::mesh_scratch::{ContactScratch, NO_TRIANGLE, push_contribution};
use super::triangle_cuboid::triangle_box_contact;
use crate::bounding::{Bv, Obb, RELATIVE_SLACK, RelativePose};
use crate::geometry::{ContactManifold, Cuboid, Isometry, MeshCollider};
use glam::Vec3;
use std::ops::ControlFlow;

/// Contact between a mesh at `pose_mesh` (shape A) and a box at `pose_box` (shape B).
///
/// The normal (from the mesh to the box) is the depth-weighted average of the triangles'
/// separating axes; the points are the deepest and widest few of their candidate points. Fills
/// `scratch`'s hits when recording is on, and adds the hierarchy work to its counters.
pub fn contact_trimesh_cuboid(
    pose_mesh: &Isometry,
    mesh: &MeshCollider,
    pose_box: &Isometry,
    cuboid: &Cuboid,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    scratch.begin_query();
    let box_in_mesh = pose_mesh.inv_mul(pose_box);
    let mesh_in_box = box_in_mesh.inverse();
    let h = cuboid.half_extents;
    // Rounding slack of the carried box, so the node test never rejects a touching triangle.
    let pad = RELATIVE_SLACK
        * (box_in_mesh.translation.abs().max_element() + h.max_element() + mesh.bounding_radius());
    let probe = Obb {
        center: box_in_mesh.translation,
        axes: box_in_mesh.rotation_matrix(),
        half_extents: h + Vec3::splat(pad),
    };
    let same_frame = RelativePose::new(&Isometry::IDENTITY);
    let record = scratch.records_hits();
    let ContactScratch {
        query,
        hits,
        contributions,
        points,
        ..
    } = scratch;
    let stats = mesh.bvh().descend(
        query,
        |bv| bv.overlaps(&probe, &same_frame),
        |t| {
            let Some(tri) = mesh.mesh().triangle(t as usize) else {
                return ControlFlow::Continue(());
            };
            let local = tri.vertices().map(|p| mesh_in_box.transform_point(p));
            if let Some(c) = triangle_box_contact(local, mesh.active_edges(t), h) {
                push_contribution(contributions, points, c.normal, c.depth, 0, c.points());
                if record {
                    hits.push([t, NO_TRIANGLE]);
                }
            }
            ControlFlow::Continue(())
        },
    );
    scratch.count(stats);
    scratch.merge(pose_box)
}
