//! Cuboid–half-space: a box on the ground. A box is the convex hull of its eight vertices, so
//! it reaches below the plane exactly where some vertex does, and the deepest vertices span the
//! contact region (a box resting flat has four at depth 0, a tilted one fewer).
//!
//! The box's half axes are put in world space once (`u_i = R e_i h_i`); a vertex is then
//! `c + Σ ±u_i` and its height above the plane `h_c + Σ ±(n·u_i)`, so the eight heights cost
//! three dot products and the kept vertices three additions each.

use crate::geometry::MAX_MANIFOLD_POINTS;
use crate::geometry::{ContactManifold, ContactPoint, Cuboid, FeatureId, HalfSpace, Isometry};
use glam::{Mat3, Vec3};

/// Contact between a box at `pose_a` (shape A) and a half-space at `pose_b` (shape B).
///
/// The normal from A to B is the plane's inward normal. The points are the (up to four) deepest
/// vertices at or below the plane, deepest first (ties by vertex index), each moved halfway to
/// the plane, named by its vertex ([`FeatureId`]). Vertices that coincide because a half extent
/// is zero are counted once.
pub fn contact_cuboid_halfspace(
    pose_a: &Isometry,
    a: &Cuboid,
    pose_b: &Isometry,
    h: &HalfSpace,
) -> Option<ContactManifold> {
    let n = pose_b.transform_vector(h.normal);
    let centre_height = n.dot(pose_a.translation - pose_b.translation);
    let rotation = Mat3::from_quat(pose_a.rotation);
    let half_axes = [
        rotation.x_axis * a.half_extents.x,
        rotation.y_axis * a.half_extents.y,
        rotation.z_axis * a.half_extents.z,
    ];
    // Signed contribution of each half axis to a vertex's height above the plane.
    let reach = Vec3::new(
        n.dot(half_axes[0]),
        n.dot(half_axes[1]),
        n.dot(half_axes[2]),
    );
    // The lowest vertex, summed in the same order as `vertex_height`, so that this early exit
    // agrees bit for bit with the per-vertex test below.
    let lowest = centre_height - reach.x.abs() - reach.y.abs() - reach.z.abs();
    if lowest > 0.0 {
        return None;
    }

    let mut kept = [(0.0f32, 0usize); MAX_MANIFOLD_POINTS];
    let mut len = 0;
    for vertex in 0..8 {
        if is_duplicate_vertex(vertex, a.half_extents) {
            continue;
        }
        let height = vertex_height(centre_height, reach, vertex);
        if height <= 0.0 {
            // `0 - x` rather than `-x`: touching gives depth +0, not -0.
            len = insert_by_depth(&mut kept, len, (0.0 - height, vertex));
        }
    }

    let mut manifold = ContactManifold::new(-n);
    for &(depth, vertex) in &kept[..len] {
        let s = vertex_signs(vertex);
        let corner =
            pose_a.translation + half_axes[0] * s.x + half_axes[1] * s.y + half_axes[2] * s.z;
        manifold.push(ContactPoint {
            // Halfway between the vertex (on A) and its projection on the plane (on B).
            point: corner + n * (depth * 0.5),
            depth,
            feature: FeatureId::single(1 + vertex as u32),
        });
    }
    Some(manifold)
}

/// The signs of vertex `k`'s local coordinates: bit `i` set means `+` along axis `i`.
fn vertex_signs(k: usize) -> Vec3 {
    let sign = |bit: usize| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
    Vec3::new(sign(0), sign(1), sign(2))
}

/// Height of vertex `k` above the plane.
fn vertex_height(centre_height: f32, reach: Vec3, k: usize) -> f32 {
    let s = vertex_signs(k);
    centre_height + s.x * reach.x + s.y * reach.y + s.z * reach.z
}

/// True when vertex `k` coincides with a lower-numbered one: along an axis of zero extent only
/// the `-` vertex is kept.
fn is_duplicate_vertex(k: usize, half_extents: Vec3) -> bool {
    (0..3).any(|i| k & (1 << i) != 0 && half_extents[i] == 0.0)
}

/// Inserts `(depth, vertex)` into the first `len` entries of `kept`, sorted by decreasing depth
/// (equal depths keep arrival order), dropping the shallowest when full; returns the new length.
fn insert_by_depth(
    kept: &mut [(f32, usize); MAX_MANIFOLD_POINTS],
    len: usize,
    item: (f32, usize),
) -> usize {
    let at = kept[..len]
        .iter()
        .position(|&(depth, _)| item.0 > depth)
        .unwrap_or(len);
    if at >= MAX_MANIFOLD_POINTS {
        return len;
    }
    let new_len = (len + 1).min(MAX_MANIFOLD_POINTS);
    kept.copy_within(at..new_len - 1, at + 1);
    kept[at] = item;
    new_len
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn ground() -> (Isometry, HalfSpace) {
        (Isometry::IDENTITY, HalfSpace { normal: Vec3::Z })
    }

    #[test]
    fn box_resting_flat_gives_four_points_at_its_bottom_corners() {
        let (g, h) = ground();
        let b = Cuboid {
            half_extents: Vec3::new(0.5, 1.0, 0.25),
        };
        let touching = Isometry::from_translation(Vec3::new(3.0, -2.0, 0.25));
        let m = contact_cuboid_halfspace(&touching, &b, &g, &h).unwrap();
        assert_eq!(m.normal, -Vec3::Z);
        assert_eq!(m.len(), 4);
        for p in m.points() {
            assert_eq!(p.depth, 0.0);
            assert_eq!(p.point.z, 0.0);
            assert_eq!((p.point.x - 3.0).abs(), 0.5);
            assert_eq!((p.point.y + 2.0).abs(), 1.0);
        }
        let gap = Isometry::from_translation(Vec3::new(3.0, -2.0, 0.25f32.next_up()));
        assert!(contact_cuboid_halfspace(&gap, &b, &g, &h).is_none());
        let sunk = Isometry::from_translation(Vec3::new(3.0, -2.0, 0.15));
        let m = contact_cuboid_halfspace(&sunk, &b, &g, &h).unwrap();
        assert_eq!(m.len(), 4);
        for p in m.points() {
            assert!((p.depth - 0.1).abs() < 1e-6);
            assert!((p.point.z + 0.05).abs() < 1e-6);
        }
    }

    #[test]
    fn tilted_box_touches_with_an_edge_or_a_corner() {
        let (g, h) = ground();
        let b = Cuboid {
            half_extents: Vec3::ONE,
        };
        // Rolled 45° about x: the lowest edge (two vertices) is sqrt(2) below the centre.
        let rot = Quat::from_rotation_x(std::f32::consts::FRAC_PI_4);
        let pose = Isometry::new(Vec3::new(0.0, 0.0, 2f32.sqrt() - 0.1), rot);
        let m = contact_cuboid_halfspace(&pose, &b, &g, &h).unwrap();
        assert_eq!(m.len(), 2);
        for p in m.points() {
            assert!((p.depth - 0.1).abs() < 1e-5);
            assert!((p.point.z + 0.05).abs() < 1e-5);
        }
        // Balanced on a corner: one vertex, sqrt(3) below the centre.
        let corner_down = Quat::from_rotation_arc(Vec3::ONE.normalize(), -Vec3::Z);
        let pose = Isometry::new(Vec3::new(1.0, 1.0, 3f32.sqrt() - 0.2), corner_down);
        let m = contact_cuboid_halfspace(&pose, &b, &g, &h).unwrap();
        assert_eq!(m.len(), 1);
        assert!((m.max_depth() - 0.2).abs() < 1e-5);
        assert!((m.points()[0].point - Vec3::new(1.0, 1.0, -0.1)).length() < 1e-5);
    }

    #[test]
    fn a_deeply_sunk_box_keeps_its_four_deepest_vertices_deepest_first() {
        let (g, h) = ground();
        let b = Cuboid {
            half_extents: Vec3::ONE,
        };
        let pose = Isometry::new(Vec3::new(0.0, 0.0, -5.0), Quat::from_rotation_y(0.2));
        let m = contact_cuboid_halfspace(&pose, &b, &g, &h).unwrap();
        assert_eq!(m.len(), 4);
        let mut depths: Vec<f32> = (0..8)
            .map(|k| -pose.transform_point(vertex_signs(k)).z)
            .collect();
        depths.sort_by(|x, y| y.total_cmp(x));
        for (p, expected) in m.points().iter().zip(&depths) {
            assert!((p.depth - expected).abs() < 1e-5);
        }
        assert!(m.points().windows(2).all(|w| w[0].depth >= w[1].depth));
    }

    #[test]
    fn tilted_ground_and_zero_size_boxes() {
        let g = Isometry::new(Vec3::new(0.0, 0.0, 1.0), Quat::from_rotation_y(0.4));
        let h = HalfSpace { normal: Vec3::Z };
        let n = g.transform_vector(Vec3::Z);
        // A point box 0.1 below the tilted plane: one point, depth 0.1, normal = inward normal.
        let point = Cuboid {
            half_extents: Vec3::ZERO,
        };
        let pose = Isometry::from_translation(g.translation - n * 0.1);
        let m = contact_cuboid_halfspace(&pose, &point, &g, &h).unwrap();
        assert_eq!(m.len(), 1);
        assert!((m.normal + n).length() < 1e-6);
        assert!((m.max_depth() - 0.1).abs() < 1e-6);
        // A flat square (zero height) sunk 1e-3 into the plane, parallel to it: four distinct
        // corners, not eight.
        let square = Cuboid {
            half_extents: Vec3::new(0.5, 0.5, 0.0),
        };
        let lying = Isometry::new(g.translation - n * 1e-3, g.rotation);
        let m = contact_cuboid_halfspace(&lying, &square, &g, &h).unwrap();
        assert_eq!(m.len(), 4);
        for (i, p) in m.points().iter().enumerate() {
            assert!((p.depth - 1e-3).abs() < 1e-6 && p.point.is_finite());
            for q in &m.points()[..i] {
                assert!((p.point - q.point).length() > 0.9);
            }
        }
    }
}
