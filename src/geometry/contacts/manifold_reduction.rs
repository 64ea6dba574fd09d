//! Reducing a contact polygon to at most [`MAX_MANIFOLD_POINTS`] points that keep its
//! support: the deepest point, then the point farthest from it, then the one spanning the
//! largest triangle, then the one adding the most area outside that triangle (Gregorius 2015,
//! "Robust Contact Creation for Physics Simulations", GDC; the same idea as Bullet's
//! `btPersistentManifold::sortCachedPoints`).
//!
//! The deepest point keeps the penetration a solver must resolve; the area-maximising ones keep
//! the manifold wide enough to stop the body from rocking. Points within [`FRONT_WINDOW`] of the
//! deepest (the *front*: what the body rests on) are preferred over points farther apart while
//! they span at least [`FRONT_PREFERENCE`] as much: a speculative manifold (`speculative.rs`)
//! also holds points still centimetres apart, and a ring of them just outside a torus's resting
//! ring would otherwise win on area and leave the torus on one real point. Exact duplicates (a zero-size box's
//! collapsed face) add no distance and are dropped, and so are points that add less area than
//! [`MIN_AREA_FRACTION`] of the square of the first two points' distance (nearly collinear points,
//! such as the two sides of a sliver clipped from a zero-width face).

use crate::geometry::{ContactPoint, MAX_MANIFOLD_POINTS};
use glam::Vec3;

/// Points at most this much shallower than the deepest form the front (m; Box2D's linear slop).
pub(crate) const FRONT_WINDOW: f32 = 0.005;

/// A front point is chosen over a point outside the front while its measure (squared distance,
/// or area) reaches this fraction of the other's: half the distance, a quarter of the area.
pub(crate) const FRONT_PREFERENCE: f32 = 0.25;

/// A third or fourth point must add at least this fraction of `|p1 - p0|²` in area (that is, lie
/// farther than this fraction of `|p1 - p0|` from the hull so far) to be kept.
const MIN_AREA_FRACTION: f32 = 1e-2;

/// Indices of at most [`MAX_MANIFOLD_POINTS`] of `points` (all lying roughly in a plane of
/// normal `normal`) and how many there are, chosen as the module describes; ties go to the
/// lower index.
pub(crate) fn spread_points(
    points: &[ContactPoint],
    normal: Vec3,
) -> ([usize; MAX_MANIFOLD_POINTS], usize) {
    let mut chosen = [0usize; MAX_MANIFOLD_POINTS];
    let Some(deepest) = deepest_corner(points) else {
        return (chosen, 0);
    };
    chosen[0] = deepest;
    let p0 = points[deepest].point;
    let front_depth = points[deepest].depth - FRONT_WINDOW;
    let in_front = |p: &ContactPoint| p.depth >= front_depth;

    let Some(far) =
        pick(points, in_front, |p| (p.point - p0).length_squared()).filter(|&i| i != deepest)
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
    let Some(third) = pick(points, in_front, |p| signed_area(p0, p1, p.point).abs()) else {
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
    match pick(points, in_front, outside) {
        Some(fourth) if outside(&points[fourth]) > min_area => {
            chosen[3] = fourth;
            (chosen, 4)
        }
        _ => (chosen, 3),
    }
}

/// The point maximising `key` among those `in_front`, unless a point outside the front has a
/// key more than 1 / [`FRONT_PREFERENCE`] times larger: then that one. One pass, each key
/// computed once (two `argmax` passes cost a twentieth of a box pyramid's step, callgrind);
/// ties go to the lower index in both maxima, as `argmax`'s.
fn pick(
    points: &[ContactPoint],
    in_front: impl Fn(&ContactPoint) -> bool,
    key: impl Fn(&ContactPoint) -> f32,
) -> Option<usize> {
    let mut any: Option<(usize, f32)> = None;
    let mut front: Option<(usize, f32)> = None;
    for (i, p) in points.iter().enumerate() {
        let k = key(p);
        if k.is_nan() {
            continue;
        }
        if any.is_none_or(|(_, b)| k > b) {
            any = Some((i, k));
        }
        if in_front(p) && front.is_none_or(|(_, b)| k > b) {
            front = Some((i, k));
        }
    }
    let (any, largest) = any?;
    match front {
        Some((f, k)) if k >= FRONT_PREFERENCE * largest => Some(f),
        _ => Some(any),
    }
}

/// The deepest point; among points as deep within [`DEPTH_TIE`] (a face resting flat, whose
/// depths differ by rounding), the one farthest from the points' mean, a corner of the polygon.
/// By depth alone, rounding picked the first, which on a tessellated floor could be where a
/// seam crosses the box's side: the manifold then kept that point instead of the corner beside
/// it, and took other points each step as the box slid. A regular polygon within 1 mrad of
/// flat ([`round_and_flat`]) starts from a corner that stays put instead.
pub(crate) fn deepest_corner(points: &[ContactPoint]) -> Option<usize> {
    let deepest = argmax(points, |p| p.depth)?;
    if let Some(corner) = round_and_flat(points, points[deepest].depth) {
        return Some(corner);
    }
    let floor = points[deepest].depth - DEPTH_TIE;
    let tied = points.iter().filter(|p| p.depth >= floor).count();
    if tied < 3 {
        return Some(deepest);
    }
    let mean = mean_point(points);
    let spread = |p: &ContactPoint| {
        if p.depth >= floor {
            (p.point - mean).length_squared()
        } else {
            f32::NAN
        }
    };
    argmax(points, spread).or(Some(deepest))
}

/// For a polygon of five or more corners all as far from their mean (within [`SPREAD_TIE`]:
/// a cylinder's or cone's cap) and all within [`FLAT_SLOPE`] of its radius of the deepest
/// `depth`: the corner of the lowest feature number (then the lowest index). Else `None`.
///
/// A cone's base rocking by 0.07 mrad on a 30° slope had its deepest corner pass from one to
/// its neighbour, and the manifold switch between the corners at 0°, 90°, 180° and 270° and
/// those at 45°, 135°, …: each switch lost the friction impulses' warm start, and it crept
/// 84 mm in 10 s. The lowest number is no ranking, only a choice that stays put while the
/// corners do (a cap met square on numbers its corners, `support.rs`; a cap tilted by more,
/// whose corners turn with the tilt, is never this flat).
fn round_and_flat(points: &[ContactPoint], depth: f32) -> Option<usize> {
    if points.len() < 5 {
        return None;
    }
    let mean = mean_point(points);
    let spread = |p: &ContactPoint| (p.point - mean).length_squared();
    let (near, far) = points
        .iter()
        .map(spread)
        .fold((f32::INFINITY, 0.0f32), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    let flat = depth - FLAT_SLOPE * far.sqrt();
    let round = near >= far * (1.0 - SPREAD_TIE) && far > 0.0;
    let corner = points
        .iter()
        .enumerate()
        .min_by_key(|&(i, p)| (p.feature.0, i))
        .map(|(i, _)| i);
    corner.filter(|_| round && points.iter().all(|p| p.depth >= flat))
}

/// The mean of the points' positions.
fn mean_point(points: &[ContactPoint]) -> Vec3 {
    points.iter().map(|p| p.point).sum::<Vec3>() / points.len() as f32
}

/// Depths this close to the deepest tie with it (m): rounding on a flat contact, far below
/// any tilt a solver resolves.
const DEPTH_TIE: f32 = 1e-6;

/// A regular polygon whose depths all lie within this fraction of its radius of the deepest
/// (tilted by less than 1 mrad) reads as flat, as a cylinder's cap met square on does
/// (`support.rs`): the corner it starts from is then at most `FLAT_SLOPE` of the radius
/// shallower than the deepest.
const FLAT_SLOPE: f32 = 1e-3;

/// Squared distances from the mean within this fraction of each other: the corners of a
/// regular polygon, equal but for rounding.
const SPREAD_TIE: f32 = 1e-4;

/// Index of the first point maximising `key` (NaN keys never win), or `None` when empty or
/// every key is NaN.
fn argmax(points: &[ContactPoint], key: impl Fn(&ContactPoint) -> f32) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (i, p) in points.iter().enumerate() {
        let k = key(p);
        if !k.is_nan() && best.is_none_or(|(_, b)| k > b) {
            best = Some((i, k));
        }
    }
    best.map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::FeatureId;

    fn at(x: f32, y: f32, depth: f32) -> ContactPoint {
        ContactPoint::new(Vec3::new(x, y, 0.0), depth)
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

    #[test]
    fn a_resting_ring_beats_a_wider_ring_2cm_apart() {
        // Eight points on a ring of radius 1 resting (depth 1 mm), eight on a ring of radius
        // 1.2 still 2 cm apart: the four kept points are all on the resting ring.
        let ring = |r: f32, depth: f32, turn: f32| {
            (0..8).map(move |k| {
                let a = (k as f32 + turn) * std::f32::consts::FRAC_PI_4;
                at(r * a.cos(), r * a.sin(), depth)
            })
        };
        let points: Vec<_> = ring(1.0, 0.001, 0.0).chain(ring(1.2, -0.02, 0.5)).collect();
        let (idx, n) = spread_points(&points, Vec3::Z);
        assert_eq!(n, 4);
        assert!(idx.iter().all(|&i| i < 8), "{idx:?}");
        // A far point is still taken when the front is one point (a box landing on a corner).
        let corner = [
            at(0.0, 0.0, 0.001),
            at(1.0, 0.0, -0.03),
            at(0.0, 1.0, -0.03),
        ];
        assert_eq!(spread_points(&corner, Vec3::Z).1, 3);
    }

    #[test]
    fn a_cap_tilted_under_1_mrad_keeps_the_same_four_corners_whichever_way_it_rocks() {
        // A cap of radius 0.5, its eight corners named 101..108 as a cap met square on
        // names them, tilted by 0.07 mrad towards each corner in turn.
        let cap = |tilt: f32, towards: f32| -> Vec<ContactPoint> {
            (0..8)
                .map(|k| {
                    let a = k as f32 * std::f32::consts::FRAC_PI_4;
                    let depth = 1e-4 + 0.5 * tilt * (a - towards).cos();
                    let p = at(0.5 * a.cos(), 0.5 * a.sin(), depth);
                    p.with_feature(FeatureId(101 + k))
                })
                .collect()
        };
        let kept = |points: &[ContactPoint]| {
            let (idx, n) = spread_points(points, Vec3::Z);
            let mut ids: Vec<u32> = idx[..n].iter().map(|&i| points[i].feature.0).collect();
            ids.sort_unstable();
            ids
        };
        let square = kept(&cap(0.0, 0.0));
        assert_eq!(square.len(), 4);
        for k in 0..8 {
            let towards = k as f32 * std::f32::consts::FRAC_PI_4 + 0.1;
            assert_eq!(
                kept(&cap(7e-5, towards)),
                square,
                "rocking towards corner {k}"
            );
        }
        // Tilted by 5 mrad it is not flat: the deepest corner comes first.
        let tilted = cap(5e-3, 3.0 * std::f32::consts::FRAC_PI_4);
        assert_eq!(spread_points(&tilted, Vec3::Z).0[0], 3);
    }
}
