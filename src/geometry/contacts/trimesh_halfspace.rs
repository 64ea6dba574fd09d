//! Mesh–half-space: a mesh on a ground plane. A mesh reaches below the plane exactly where some
//! vertex does (its triangles are the convex hulls of their corners), so the hierarchy is
//! descended with the plane (a node is kept while its box reaches the plane) and the vertices of
//! the reached triangles that lie at or below it are the contact candidates; the deepest and
//! widest few make the manifold.

use super::mesh_manifold::reduce_to_manifold;
use super::mesh_scratch::ContactScratch;
use crate::bounding::{Obb, RELATIVE_SLACK};
use crate::geometry::{
    ContactManifold, ContactPoint, FeatureId, HalfSpace, Isometry, MeshCollider,
};
use glam::Vec3;
use std::ops::ControlFlow;

/// Contact between a mesh at `pose_mesh` (shape A) and a half-space at `pose_h` (shape B).
///
/// The normal from A to B is the plane's inward normal, as for the box; the points are chosen
/// among the vertices at or below the plane (each counted once however many triangles share it):
/// the deepest, then the widest spread, each moved halfway to the plane.
pub fn contact_trimesh_halfspace(
    pose_mesh: &Isometry,
    mesh: &MeshCollider,
    pose_h: &Isometry,
    h: &HalfSpace,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    scratch.begin_query();
    let world_normal = pose_h.transform_vector(h.normal);
    let n = pose_mesh.inverse_transform_vector(world_normal);
    let origin = pose_mesh.inverse_transform_point(pose_h.translation);
    let offset = n.dot(origin);
    // Rounding slack of the carried plane, so the box test never rejects a touching vertex.
    let slack = RELATIVE_SLACK * (origin.abs().max_element() + mesh.bounding_radius());
    let height = |p: Vec3| n.dot(p) - offset;
    let record = scratch.records_hits();
    let vertices = mesh.mesh().vertices();
    let triangles = mesh.mesh().triangles();
    let ContactScratch {
        query,
        hits,
        vertices: below,
        ..
    } = scratch;
    let stats = mesh.bvh().descend(
        query,
        |bv| obb_lowest(bv, n) - offset <= slack,
        |t| {
            let Some(&corners) = triangles.get(t as usize) else {
                return ControlFlow::Continue(());
            };
            let before = below.len();
            below.extend(
                corners
                    .into_iter()
                    .filter(|&i| height(vertices[i as usize]) <= 0.0),
            );
            if record && below.len() > before {
                hits.push([t, super::NO_TRIANGLE]);
            }
            ControlFlow::Continue(())
        },
    );
    scratch.count(stats);
    scratch.vertices.sort_unstable();
    scratch.vertices.dedup();
    for &i in &scratch.vertices {
        let v = vertices[i as usize];
        let signed = height(v);
        scratch.points.push(ContactPoint {
            point: v - n * (0.5 * signed),
            // `0 - x` rather than `-x`: touching gives depth +0, not -0.
            depth: 0.0 - signed,
            // Named by the mesh's vertex.
            feature: FeatureId::single(1).of_part(i),
        });
    }
    let mut manifold = reduce_to_manifold(-n, &scratch.points, pose_mesh)?;
    // The plane's own normal, not its round trip through the mesh's frame.
    manifold.normal = -world_normal;
    Some(manifold)
}

/// The lowest value of `n·x` over the box.
#[inline]
fn obb_lowest(bv: &Obb, n: Vec3) -> f32 {
    let along = (bv.axes.transpose() * n).abs();
    n.dot(bv.center) - along.dot(bv.half_extents)
}
