//! Mesh–capsule: the capsule, carried into the mesh's frame, descends the mesh's OBB hierarchy
//! inside its own oriented box (the 15-axis box–box test of Gottschalk, Lin and Manocha 1996 at
//! every node, as mesh–box does), and every triangle of the leaves reached gets the exact
//! segment test of `triangle_capsule.rs`. The triangle contacts are merged into one manifold as
//! `mesh_manifold.rs` explains.

use super::contact_triangle_capsule;
use super::mesh_scratch::{ContactScratch, NO_TRIANGLE, push_contribution};
use crate::bounding::{Bv, Obb, RELATIVE_SLACK, RelativePose};
use crate::geometry::{Capsule, ContactManifold, Isometry, MeshCollider};
use glam::Vec3;
use std::ops::ControlFlow;

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
    scratch.begin_query();
    let in_mesh = pose_mesh.inv_mul(pose_capsule);
    let (p0, p1) = capsule.segment(&in_mesh);
    let half = Vec3::new(
        capsule.radius,
        capsule.radius,
        capsule.half_length + capsule.radius,
    );
    // Rounding slack of the carried capsule, so the node test never rejects a touching triangle.
    let pad = RELATIVE_SLACK
        * (in_mesh.translation.abs().max_element() + half.max_element() + mesh.bounding_radius());
    let probe = Obb {
        center: in_mesh.translation,
        axes: in_mesh.rotation_matrix(),
        half_extents: half + Vec3::splat(pad),
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
            let active = mesh.active_edges(t);
            if let Some(m) = contact_triangle_capsule(&tri, active, p0, p1, capsule.radius) {
                push_contribution(
                    contributions,
                    points,
                    m.normal,
                    m.max_depth(),
                    0,
                    m.points(),
                );
                if record {
                    hits.push([t, NO_TRIANGLE]);
                }
            }
            ControlFlow::Continue(())
        },
    );
    scratch.count(stats);
    scratch.merge(pose_mesh)
}
