//! Mesh–box: the box, carried into the mesh's frame as an oriented box, descends the mesh's OBB
//! hierarchy (the 15-axis box–box test of Gottschalk, Lin and Manocha 1996 at every node), and
//! every triangle of the leaves reached gets the separating-axis contact of
//! `triangle_cuboid.rs`. The triangle contacts are merged into one manifold as
//! `mesh_manifold.rs` explains.

use super::mesh_scratch::ContactScratch;
use super::triangle_cuboid::triangle_box_contact;
use crate::bounding::{Bv, Obb, RELATIVE_SLACK, RelativePose};
use crate::geometry::{ContactManifold, Cuboid, Isometry, MeshCollider};
use glam::Vec3;

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
    let box_in_mesh = pose_mesh.inv_mul(pose_box);
    let mesh_in_box = box_in_mesh.inverse();
    let h = cuboid.half_extents;
    let probe = carried_box(&box_in_mesh, h, mesh);
    let same_frame = RelativePose::new(&Isometry::IDENTITY);
    scratch.collect_triangle_contacts(
        mesh,
        |bv| bv.overlaps(&probe, &same_frame),
        |t, tri| {
            let local = tri.transformed(&mesh_in_box).vertices();
            triangle_box_contact(local, mesh.active_edges(t), h)
        },
    );
    scratch.merge(pose_box)
}

/// The box of half extents `half` at `in_mesh` (its pose in the mesh's frame), grown by the
/// rounding slack of the carried pose, so that the node test never rejects a touching triangle.
pub(crate) fn carried_box(in_mesh: &Isometry, half: Vec3, mesh: &MeshCollider) -> Obb {
    let pad = RELATIVE_SLACK
        * (in_mesh.translation.abs().max_element() + half.max_element() + mesh.bounding_radius());
    Obb {
        center: in_mesh.translation,
        axes: in_mesh.rotation_matrix(),
        half_extents: half + Vec3::splat(pad),
    }
}
