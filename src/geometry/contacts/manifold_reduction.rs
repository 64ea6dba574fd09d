//! Reducing a contact polygon to at most [`MAX_MANIFOLD_POINTS`] points that keep its
//! support: the deepest point, then the point farthest from it, then the one spanning the
//! largest triangle, then the one adding the most area outside that triangle (Gregorius 2015,
//! "Robust Contact Creation for Physics Simulations", GDC; the same idea as Bullet's
//! `btPersistentManifold::sortCachedPoints`).
//!
//! The deepest point keeps the penetration a solver must resolve; the area-maximising ones keep
//! the manifold wide enough to stop the body from rocking. Exact duplicates (a zero-size box's
//! collapsed face) add no distance and are dropped, and so are points that add less area than
//! [`MIN_AREA_FRACTION`] of the square of the first two points' distance (nearly collinear points,
//! such as the two sides of a sliver clipped from a zero-width face).

use crate::geometry::{ContactPoint, MAX_MANIFOLD_POINTS};
use glam::Vec3;

/// A third or fourth point must add at least this fraction of `|p1 - p0|²` in area (that is, lie
/// farther than this fraction of `|p1 - p0|` from the hull so far) to be kept.
const MIN_AREA_FRACTION: f32 = 1e-3;

/// Indices of at most [`MAX_MANIFOLD_POINTS`] of `points` (all lying roughly in a plane of
/// normal `normal`) and how many there are, chosen as the module describes; ties go to the
/// lower index.
pub(crate) fn spread_points(
    points: &[ContactPoint],
    normal: Vec3,
) -> ([usize; MAX_MANIFOLD_POINTS], usize) {
    let mut chosen = [0usize; MAX_MANIFOLD_POINTS];
    let Some(deepest) = argmax(points, |p| p.depth) else {
        return (chosen, 0);
    };
    chosen[0] = deepest;
    let p0 = points[deepest].point;

    let Some(far) = argmax(points, |p| (p.point - p0).length_squared()).filter(|&i| i != deepest)
    else {
        return (chosen, 1);
    };
    let far_distance = (points[far].point - p0).length_squared();
    if far_distance <= 0.0 {
        return (chosen, 1);
    }
    chosen[1] = far;
    let p1 = points[far].point;

    let signed_area = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).dot(normal);
    let Some(third) = argmax(points, |p| signed_area(p0, p1, p.point).abs()) else {
        return (chosen, 2);
    };
    let third_area = signed_area(p0, p1, points[third].point);
    let min_area = MIN_AREA_FRACTION * far_distance;
    if third_area.abs() <= min_area || third_area.is_nan() {
        return (chosen, 2);
    }
    chosen[2] = third;
    // Order the triangle counter-clockwise about `normal`, so "outside an edge" is a negative
    // signed area for every edge.
    let (a, b, c) = if third_area > 0.0 {
        (p0, p1, points[third].point)
    } else {
        (p1, p0, points[third].point)
    };

    let outside = |p: &ContactPoint| {
        let q = p.point;
        (-signed_area(a, b, q))
            .max(-signed_area(b, c, q))
            .max(-signed_area(c, a, q))
    };
    match argmax(points, outside) {
        Some(fourth) if outside(&points[fourth]) > min_area => {
            chosen[3] = fourth;
            (chosen, 4)
        }
        _ => (chosen, 3),
    }
}

/// Index of the first point maximising `key` (NaN keys never win), or `None` when empty.
fn argmax(points: &[ContactPoint], key: impl Fn(&ContactPoint) -> f32) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (i, p) in points.iter().enumerate() {
        let k = key(p);
        if best.is_none_or(|(_, b)| k > b) {
            best = Some((i, k));
        }
    }
    best.map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f32, y: f32, depth: f32) -> ContactPoint {
        ContactPoint {
            point: Vec3::new(x, y, 0.0),
            depth,
        }
    }

    #[test]
    fn an_octagon_keeps_its_deepest_point_and_a_wide_quad() {
        let r = 2f32.sqrt() - 1.0;
        let octagon = [
            at(1.0, r, 0.1),
            at(r, 1.0, 0.1),
            at(-r, 1.0, 0.1),
            at(-1.0, r, 0.3),
            at(-1.0, -r, 0.1),
            at(-r, -1.0, 0.1),
            at(r, -1.0, 0.1),
            at(1.0, -r, 0.1),
        ];
        let (idx, n) = spread_points(&octagon, Vec3::Z);
        assert_eq!(n, 4);
        assert_eq!(idx[0], 3, "deepest first");
        assert_eq!(idx[1], 7, "then the farthest from it (the opposite vertex)");
        // The kept quad covers more than 60% of the octagon's area (2·(1+√2)·side², side 2r).
        // Its diagonals are the first two points and the last two (one on each side).
        let q: Vec<Vec3> = idx.iter().map(|&i| octagon[i].point).collect();
        let quad = (q[0] - q[1]).cross(q[2] - q[3]).length() * 0.5;
        let full = 2.0 * (1.0 + 2f32.sqrt()) * (2.0 * r) * (2.0 * r);
        assert!(quad > 0.6 * full, "{quad} vs {full}");
    }

    #[test]
    fn a_rectangle_keeps_its_four_corners_and_duplicates_collapse() {
        let rect = [
            at(1.0, 2.0, 0.0),
            at(-1.0, 2.0, 0.0),
            at(-1.0, -2.0, 0.0),
            at(1.0, -2.0, 0.0),
        ];
        let (idx, n) = spread_points(&rect, Vec3::Z);
        assert_eq!(n, 4);
        let mut sorted = idx;
        sorted.sort_unstable();
        assert_eq!(sorted, [0, 1, 2, 3]);

        let same = [at(0.5, 0.5, 0.2); 4];
        assert_eq!(spread_points(&same, Vec3::Z).1, 1);
        let segment = [
            at(0.0, 0.0, 0.1),
            at(0.0, 0.0, 0.1),
            at(1.0, 0.0, 0.0),
            at(1.0, 0.0, 0.0),
        ];
        let (idx, n) = spread_points(&segment, Vec3::Z);
        assert_eq!((n, idx[0], idx[1]), (2, 0, 2));
        assert_eq!(spread_points(&[], Vec3::Z).1, 0);
        // A sliver: the two long sides 1e-5 apart count as one segment.
        let sliver = [
            at(0.0, 0.0, 0.2),
            at(1.0, 0.0, 0.1),
            at(1.0, 1e-5, 0.1),
            at(0.0, 1e-5, 0.2),
        ];
        let (idx, n) = spread_points(&sliver, Vec3::Z);
        assert_eq!((n, idx[0], idx[1]), (2, 0, 1));
    }
}
