//! Closest points of two triangles that do not meet: the gap a speculative mesh–mesh contact
//! measures before the surfaces touch.
//!
//! Two disjoint triangles are closest either at a corner of one and a point of the other (6
//! corner–triangle pairs, Ericson 2005 §5.1.5) or at a point of an edge of each (9 edge–edge
//! pairs, §5.1.9); the distance is the least of the 15 (Ericson §5.1.10, after Eberly). For
//! triangles that cross, the 15 candidates miss the crossing, so callers decide intersection
//! first (`tri_tri.rs`).

use super::closest_segment_points::{Segment, closest_segment_points};
use crate::geometry::Triangle;
use glam::Vec3;

/// The closest points `(on a, on b)` of two triangles that do not intersect (see the module
/// notes; for intersecting triangles the pair is some close pair, not a crossing point).
///
/// Ties go to the first candidate in a fixed order (A's corners, B's corners, then edge pairs),
/// so the answer is deterministic; degenerate triangles act as the segment or point they are.
pub fn closest_points_triangle_triangle(a: &Triangle, b: &Triangle) -> (Vec3, Vec3) {
    let (ca, cb) = (a.vertices(), b.vertices());
    let mut best = (ca[0], b.closest_point(ca[0]));
    let mut best_d2 = best.0.distance_squared(best.1);
    let mut consider = |p: Vec3, q: Vec3| {
        let d2 = p.distance_squared(q);
        if d2 < best_d2 {
            best_d2 = d2;
            best = (p, q);
        }
    };
    for &p in &ca[1..] {
        consider(p, b.closest_point(p));
    }
    for &q in &cb {
        consider(a.closest_point(q), q);
    }
    let edges = |c: [Vec3; 3]| {
        [0, 1, 2].map(|k| Segment {
            start: c[k],
            end: c[(k + 1) % 3],
        })
    };
    for ea in edges(ca) {
        for eb in edges(cb) {
            let (p, q) = closest_segment_points(ea, eb);
            consider(p, q);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_above_a_face_and_two_crossed_edges_give_their_exact_gaps() {
        let floor = Triangle::new(
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        let tip_down = Triangle::new(
            Vec3::new(0.1, 0.0, 0.25),
            Vec3::new(1.0, 0.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        );
        let (p, q) = closest_points_triangle_triangle(&floor, &tip_down);
        assert!(p.abs_diff_eq(Vec3::new(0.1, 0.0, 0.0), 1e-6), "{p}");
        assert!(q.abs_diff_eq(Vec3::new(0.1, 0.0, 0.25), 1e-6), "{q}");
        // Two slivers whose long edges cross 0.5 apart: the gap is between edge interiors.
        let along_x = Triangle::new(
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -1.0),
        );
        let along_y = Triangle::new(
            Vec3::new(0.0, -1.0, 0.5),
            Vec3::new(0.0, 1.0, 0.5),
            Vec3::new(0.0, 0.0, 1.5),
        );
        let (p, q) = closest_points_triangle_triangle(&along_x, &along_y);
        assert!((p.distance(q) - 0.5).abs() < 1e-6);
        assert!(p.abs_diff_eq(Vec3::ZERO, 1e-6) && q.abs_diff_eq(Vec3::new(0.0, 0.0, 0.5), 1e-6));
    }
}
