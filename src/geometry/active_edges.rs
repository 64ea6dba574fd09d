//! Internal edges of a triangle mesh, and the contact normals that ignore them (ghost-collision
//! removal).
//!
//! A body sliding across a flat floor made of many triangles touches, besides the triangle under
//! it, the shared edges of its neighbours; the closest-point normal at such an edge leans
//! sideways, and the merged normal leans with it: a ball or capsule resting on a tessellated
//! floor creeps, a sliding body bumps on the seams. These edges are *internal*: the surface is
//! flat across them, so they are not really there. As in Jolt (`ActiveEdges.h`: an edge is
//! active unless the two triangles sharing it are nearly coplanar) each triangle's three edges
//! are marked once, when the collider is built, and a contact whose closest point on a triangle
//! lies only on inactive edges takes that triangle's face normal instead (Erin Catto, "Ghost
//! Collisions", 2024, describes the same fix in Box2D v3's chain shapes).
//!
//! Edges whose triangles (two, or more where a mesh repeats a triangle) all lie within
//! [`COPLANAR_DEGREES`] of each other (either orientation: urto's triangles are two-sided) are
//! inactive; boundary edges and creases stay active.

use crate::geometry::{TriMesh, Triangle};
use glam::Vec3;

/// Neighbours closer than this to coplanar share an inactive edge (Jolt's default threshold).
pub const COPLANAR_DEGREES: f32 = 5.0;

/// Every edge active: a lone triangle, or a contact test that does not know its mesh.
pub const ALL_EDGES_ACTIVE: u8 = 0b111;

/// Neighbours closer than this to coplanar share a *flat* edge (bit `3 + k` of
/// `active_edges`'s byte): the surface continues past it without a fold worth a contact of
/// its own, so a convex part beside it is its neighbour's alone (`trimesh_convex.rs`).
pub const FLAT_DEGREES: f32 = 0.5;

/// For each triangle, bit `k` set when its edge `k` (from corner `k` to corner `k + 1`) is
/// active (see the module notes), and bit `3 + k` when it is flat (within [`FLAT_DEGREES`]).
/// Corners at the same position count as one vertex, so unwelded meshes are handled too.
pub(crate) fn active_edges(mesh: &TriMesh) -> Vec<u8> {
    let ids = mesh.position_ids();
    let mut edges: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(3 * mesh.triangle_count());
    for (t, tri) in mesh.triangles().iter().enumerate() {
        let c = tri.map(|i| ids[i as usize]);
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), t as u32, k as u8));
        }
    }
    edges.sort_unstable();
    let mut active = vec![ALL_EDGES_ACTIVE; mesh.triangle_count()];
    let cos = COPLANAR_DEGREES.to_radians().cos();
    let flat_cos = FLAT_DEGREES.to_radians().cos();
    let normal = |t: u32| mesh.triangle(t as usize).and_then(|tri| tri.normal());
    for group in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if group.len() < 2 {
            continue;
        }
        let Some(first) = normal(group[0].2) else {
            continue;
        };
        let within = |cos: f32| {
            group[1..]
                .iter()
                .all(|e| normal(e.2).is_some_and(|n| n.dot(first).abs() >= cos))
        };
        if within(cos) {
            let flat = within(flat_cos);
            for &(_, _, t, k) in group {
                active[t as usize] &= !(1 << k);
                active[t as usize] |= u8::from(flat) << (3 + k);
            }
        }
    }
    active
}

/// The face normal of `tri` on the side of `normal`, when the contact's closest point on the
/// triangle, `on_triangle`, lies on its boundary and only on edges that `active` marks inactive;
/// `None` when the contact's own normal stands (an interior point, an active edge, a degenerate
/// triangle).
pub(crate) fn face_normal_at_inactive_edge(
    tri: &Triangle,
    active: u8,
    on_triangle: Vec3,
    normal: Vec3,
) -> Option<Vec3> {
    if active == ALL_EDGES_ACTIVE {
        return None;
    }
    let on = edges_holding(tri, on_triangle);
    if on == 0 || on & active != 0 {
        return None;
    }
    let face = tri.normal()?;
    Some(if face.dot(normal) < 0.0 { -face } else { face })
}

/// The edges of `tri` that `point` lies on (bit `k` for the edge from corner `k` to `k + 1`),
/// within `1e-5` of the longest edge; 0 for an interior point.
pub(crate) fn edges_holding(tri: &Triangle, point: Vec3) -> u8 {
    let v = tri.vertices();
    let longest = (0..3)
        .map(|k| (v[(k + 1) % 3] - v[k]).length_squared())
        .fold(0.0f32, f32::max)
        .sqrt();
    let tolerance = 1e-5 * longest;
    let mut on = 0;
    for k in 0..3 {
        let (a, b) = (v[k], v[(k + 1) % 3]);
        let ab = b - a;
        let s = ((point - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        if (a + ab * s - point).length() <= tolerance {
            on |= 1 << k;
        }
    }
    on
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_grid_has_only_its_rim_active_and_a_cube_only_its_twelve_edges() {
        let ones =
            |marks: &[u8], mask: u8| -> u32 { marks.iter().map(|m| (m & mask).count_ones()).sum() };
        let grid = active_edges(&TriMesh::grid_floor(4.0, 4).unwrap());
        // A 4×4 grid's rim is 16 cell sides, each the edge of one triangle; the other 80
        // triangle edges (32 triangles) are inactive and flat.
        assert_eq!(ones(&grid, ALL_EDGES_ACTIVE), 16);
        assert_eq!(ones(&grid, ALL_EDGES_ACTIVE << 3), 80);
        let cube = active_edges(&TriMesh::cuboid(Vec3::splat(0.5)).unwrap());
        // 12 edges, each active in both its triangles; the face diagonals are inactive, flat.
        assert_eq!(ones(&cube, ALL_EDGES_ACTIVE), 24);
        assert_eq!(ones(&cube, ALL_EDGES_ACTIVE << 3), 12);
    }

    #[test]
    fn a_fold_of_2_degrees_is_inactive_but_not_flat_and_one_of_a_quarter_degree_is_flat() {
        for (degrees, flat) in [(2.0f32, false), (0.25, true)] {
            let z = degrees.to_radians().tan();
            let vertices = vec![
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(0.0, -1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(1.0, 0.0, z),
            ];
            let marks = active_edges(&TriMesh::new(vertices, vec![[0, 1, 2], [2, 1, 3]]).unwrap());
            // The shared edge is edge 1 (corners 1 → 2) of the first triangle.
            assert_eq!(marks[0] & 0b010, 0, "{degrees}°: the fold is inactive");
            assert_eq!(marks[0] & (0b010 << 3) != 0, flat, "{degrees}°");
        }
    }

    #[test]
    fn only_points_on_inactive_edges_take_the_face_normal() {
        let tri = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let up = Vec3::Z;
        let leaning = Vec3::new(-0.3, 0.0, 0.95).normalize();
        let on_edge_2 = Vec3::new(0.0, 0.5, 0.0); // edge 2 runs from c to a, along x = 0
        assert_eq!(
            face_normal_at_inactive_edge(&tri, 0b011, on_edge_2, leaning),
            Some(up)
        );
        assert_eq!(
            face_normal_at_inactive_edge(&tri, 0b111, on_edge_2, leaning),
            None
        );
        assert_eq!(
            face_normal_at_inactive_edge(&tri, 0b100, on_edge_2, leaning),
            None
        );
        let inside = Vec3::new(0.2, 0.2, 0.0);
        assert_eq!(face_normal_at_inactive_edge(&tri, 0, inside, leaning), None);
        // Corner a lies on edges 0 and 2: both must be inactive.
        assert_eq!(
            face_normal_at_inactive_edge(&tri, 0b001, Vec3::ZERO, -leaning),
            None
        );
        assert_eq!(
            face_normal_at_inactive_edge(&tri, 0b010, Vec3::ZERO, -leaning),
            Some(-up)
        );
    }
}
