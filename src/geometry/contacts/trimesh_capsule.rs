//! Mesh–capsule: the capsule, carried into the mesh's frame, descends the mesh's OBB hierarchy
//! inside its own oriented box (the 15-axis box–box test of Gottschalk, Lin and Manocha 1996 at
//! every node, as mesh–box does), and every triangle of the leaves reached gets the exact
//! segment test of `triangle_capsule.rs`. The triangle contacts are merged into one manifold as
//! `mesh_manifold.rs` explains.

use super::contact_triangle_capsule;
use super::mesh_scratch::ContactScratch;
use super::trimesh_cuboid::carried_box;
use crate::bounding::{Bv, RelativePose};
use crate::geometry::{Capsule, ContactManifold, Isometry, MeshCollider};
use glam::Vec3;

/// Contact between a mesh at `pose_mesh` (shape A) and a capsule at `pose_capsule` (shape B).
///
/// The normal (from the mesh to the capsule) is the depth-weighted average of the triangles'
/// normals; the points are the deepest and widest few. Fills `scratch`'s hits when recording is
/// on, and adds the hierarchy work to its counters.
pub fn contact_trimesh_capsule(
    pose_mesh: &Isometry,
    mesh: &MeshCollider,
    pose_capsule: &Isometry,
    capsule: &Capsule,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    let in_mesh = pose_mesh.inv_mul(pose_capsule);
    let (p0, p1) = capsule.segment(&in_mesh);
    let (r, h) = (capsule.radius, capsule.half_length);
    let probe = carried_box(&in_mesh, Vec3::new(r, r, h + r), mesh);
    let same_frame = RelativePose::new(&Isometry::IDENTITY);
    scratch.collect_triangle_contacts(
        mesh,
        |bv| bv.overlaps(&probe, &same_frame),
        |t, tri| contact_triangle_capsule(tri, mesh.active_edges(t), p0, p1, r),
    );
    scratch.merge(pose_mesh)
}
