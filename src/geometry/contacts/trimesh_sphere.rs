//! Mesh–sphere: the sphere, carried into the mesh's frame, descends the mesh's OBB hierarchy
//! (a node is kept while its box comes within the radius of the centre, Arvo 1990's clamp in the
//! box's frame), and every triangle of the leaves reached is tested exactly by
//! [`contact_triangle_sphere_with_edges`] (Ericson 2005's closest point; at a mesh's internal
//! edges, the face normal: see [`active_edges`](crate::geometry::active_edges)). The triangle contacts are merged
//! into one manifold as `mesh_manifold.rs` explains.
//!
//! Triangles are two-sided surfaces: a sphere is pushed away from whichever side of a triangle
//! it is on, and a sphere entirely inside a closed mesh touches nothing.

use super::mesh_scratch::ContactScratch;
use crate::bounding::{Obb, RELATIVE_SLACK};
use crate::geometry::{
    ContactManifold, Isometry, MeshCollider, Sphere, contact_triangle_sphere_with_edges,
};
use glam::Vec3;

/// Contact between a mesh at `pose_mesh` (shape A) and a sphere centred at `center` (shape B).
///
/// The normal (from the mesh to the sphere) is the depth-weighted average of the normals of the
/// triangles in contact; the points are the deepest and widest few of their contact points,
/// each with its own depth. Fills `scratch`'s hits when recording is on, and adds the hierarchy
/// work to its counters.
pub fn contact_trimesh_sphere(
    pose_mesh: &Isometry,
    mesh: &MeshCollider,
    center: Vec3,
    sphere: &Sphere,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    let local = pose_mesh.inverse_transform_point(center);
    // Rounding slack of the carried centre, so the box test never rejects a touching sphere.
    let reach =
        sphere.radius + RELATIVE_SLACK * (local.abs().max_element() + mesh.bounding_radius());
    let reach2 = reach * reach;
    scratch.collect_triangle_contacts(
        mesh,
        |bv| obb_within(bv, local, reach2),
        |t, tri| contact_triangle_sphere_with_edges(tri, mesh.active_edges(t), local, sphere),
    );
    scratch.merge(pose_mesh)
}

/// True when the box comes within `sqrt(reach2)` of `p` (both in the mesh's frame).
#[inline]
pub(crate) fn obb_within(bv: &Obb, p: Vec3, reach2: f32) -> bool {
    obb_distance_squared(bv, p) <= reach2
}

/// The squared distance from `p` to the box (0 inside), both in the mesh's frame.
#[inline]
pub(crate) fn obb_distance_squared(bv: &Obb, p: Vec3) -> f32 {
    let q = bv.axes.transpose() * (p - bv.center);
    let outside = (q.abs() - bv.half_extents).max(Vec3::ZERO);
    outside.length_squared()
}
