//! Capsule–box, in the box's frame, in two regimes:
//!
//! - **Core outside the box** (the usual case: a capsule resting on or against a box). The exact
//!   closest points of the inner segment and the box decide, as for a sphere: the squared
//!   distance from a point moving along the segment to the box is a convex, piecewise quadratic
//!   function of the parameter, whose pieces change where the point crosses a face plane (at
//!   most six crossings). Each piece's minimum is found in closed form, so the distance is exact
//!   (no iteration, unlike GJK).
//! - **Core inside the box** (deep penetration). The separating-axis test of a segment against a
//!   box: the box's three face normals and the three cross products of the segment with the
//!   box's edges (Ericson 2005, §5.2.1 and §4.4); the depth is the least penetration plus the
//!   radius. Face axes win ties and near-ties (5%), as in `cuboid_cuboid.rs`, so resting
//!   contacts keep a face normal.
//!
//! When the normal is a face normal, the segment is clipped to that face's rectangle and each
//! end of the clipped part becomes a point with its own depth (Box2D v3's capsule–polygon
//! manifold in 3D): a capsule lying on a box rests on two points instead of seesawing on one.

use super::closest_segment_points::{Segment, closest_segment_points};
use crate::ccd::segment_in_box;
use crate::geometry::{Capsule, ContactManifold, ContactPoint, Cuboid, Isometry};
use glam::Vec3;

/// A face normal counts as the contact normal when their cosine is at least this (the
/// closest-points normal of a face region is exactly a face normal; this only absorbs rounding).
const FACE_COSINE: f32 = 1.0 - 1e-5;
/// An edge axis must beat the best face axis by this factor to be chosen.
const FACE_BIAS: f32 = 0.95;

/// Contact between a capsule at `pose_a` (shape A) and a box at `pose_b` (shape B), normal from
/// the capsule to the box.
pub fn contact_capsule_cuboid(
    pose_a: &Isometry,
    capsule: &Capsule,
    pose_b: &Isometry,
    cuboid: &Cuboid,
) -> Option<ContactManifold> {
    let h = cuboid.half_extents;
    let r = capsule.radius;
    let (p0, p1) = capsule.segment(&pose_b.inv_mul(pose_a));
    let (on_segment, on_box) = closest_segment_box(p0, p1, h);
    let gap = on_box - on_segment;
    let dist2 = gap.length_squared();
    if dist2 > r * r {
        return None;
    }
    // A core within rounding of the box counts as inside: the offset is noise, not a direction.
    let rounding = 4.0 * f32::EPSILON * (p0.abs().max(p1.abs()).max_element() + h.max_element());
    let (normal, depth, feature) = if dist2 > rounding * rounding && dist2 >= f32::MIN_POSITIVE {
        let dist = dist2.sqrt();
        (gap / dist, r - dist, Feature::Closest(on_segment))
    } else {
        let (normal, penetration, feature) = deepest_axis(p0, p1, h);
        (normal, penetration + r, feature)
    };
    let mut local = ContactManifold::new(normal);
    let midway = |x: Vec3, depth: f32| ContactPoint::new(x + normal * (r - 0.5 * depth), depth);
    for (x, d) in face_points(p0, p1, h, normal, r).into_iter().flatten() {
        local.push(midway(x, d.min(depth)));
    }
    if local.is_empty() {
        let x = match feature {
            Feature::Closest(x) => x,
            Feature::Edge(axis) => point_near_edge(p0, p1, h, normal, axis),
        };
        local.push(midway(x, depth.max(0.0)));
    }
    Some(local.transformed(pose_b))
}

/// Where the single point of a manifold comes from.
#[derive(Clone, Copy, Debug)]
enum Feature {
    /// The segment's point closest to the box (or deepest along a face axis).
    Closest(Vec3),
    /// An edge axis: the box edge along this local axis.
    Edge(usize),
}

/// The closest points `(on the segment, on the box [-h, h])` of the segment from `p0` to `p1`
/// (see the module notes: the exact minimum of a convex piecewise quadratic). Ties keep the
/// smallest parameter.
pub(crate) fn closest_segment_box(p0: Vec3, p1: Vec3, h: Vec3) -> (Vec3, Vec3) {
    let d = p1 - p0;
    let mut breaks = [0.0f32; 8];
    let mut count = 0;
    for k in 0..3 {
        if d[k] != 0.0 {
            for plane in [-h[k], h[k]] {
                let t = (plane - p0[k]) / d[k];
                if t > 0.0 && t < 1.0 {
                    breaks[count] = t;
                    count += 1;
                }
            }
        }
    }
    breaks[count] = 1.0;
    let breaks = &mut breaks[..=count];
    breaks.sort_unstable_by(f32::total_cmp);
    let at = |t: f32| p0 + d * t;
    let outside2 = |p: Vec3| (p - p.clamp(-h, h)).length_squared();
    let (mut best_t, mut best) = (0.0, outside2(p0));
    let mut lo = 0.0;
    for &hi in breaks.iter() {
        let t = piece_minimum(p0, d, h, lo, hi);
        let value = outside2(at(t));
        if value < best {
            (best_t, best) = (t, value);
        }
        lo = hi;
    }
    let p = at(best_t);
    (p, p.clamp(-h, h))
}

/// The minimum over `[lo, hi]` of the squared distance to the box, on a piece where each axis
/// stays below, inside or above the box's slab (as at the piece's midpoint): a sum of squares of
/// linear functions, whose minimum is at `-b / 2a`, clamped.
fn piece_minimum(p0: Vec3, d: Vec3, h: Vec3, lo: f32, hi: f32) -> f32 {
    let mid = p0 + d * (0.5 * (lo + hi));
    let (mut a, mut b) = (0.0f32, 0.0f32);
    for k in 0..3 {
        let face = if mid[k] > h[k] {
            h[k]
        } else if mid[k] < -h[k] {
            -h[k]
        } else {
            continue;
        };
        a += d[k] * d[k];
        b += 2.0 * d[k] * (p0[k] - face);
    }
    if a > 0.0 {
        (-b / (2.0 * a)).clamp(lo, hi)
    } else {
        // Inside every slab: the whole piece is in the box, and its midpoint (unlike its ends,
        // computed on the faces) is inside after rounding too.
        0.5 * (lo + hi)
    }
}

/// The separating axis of least penetration of the segment into the box (module notes):
/// `(normal from the capsule to the box, penetration of the segment, feature)`.
fn deepest_axis(p0: Vec3, p1: Vec3, h: Vec3) -> (Vec3, f32, Feature) {
    // Along `axis`, the segment leaves through +axis after moving `radius - min`, or through
    // -axis after `max + radius`; the normal points from the capsule to the box.
    let exit = |axis: Vec3| {
        let radius = (axis.abs() * h).element_sum();
        let (s0, s1) = (p0.dot(axis), p1.dot(axis));
        let (up, down) = (radius - s0.min(s1), s0.max(s1) + radius);
        if up <= down {
            (-axis, up)
        } else {
            (axis, down)
        }
    };
    let mut best = (Vec3::Z, f32::INFINITY, Feature::Closest(p0));
    for k in 0..3 {
        let (normal, penetration) = exit(Vec3::AXES[k]);
        if penetration < best.1 {
            let lead = (p0 - p1).dot(normal);
            let deepest = match lead.partial_cmp(&0.0) {
                Some(std::cmp::Ordering::Greater) => p0,
                Some(std::cmp::Ordering::Less) => p1,
                _ => (p0 + p1) * 0.5,
            };
            best = (normal, penetration, Feature::Closest(deepest));
        }
    }
    let u = p1 - p0;
    for k in 0..3 {
        let Some(axis) = u.cross(Vec3::AXES[k]).try_normalize() else {
            continue;
        };
        let (normal, penetration) = exit(axis);
        if penetration < FACE_BIAS * best.1 {
            best = (normal, penetration, Feature::Edge(k));
        }
    }
    best
}

/// The segment's point nearest the box edge along local axis `k` that faces the capsule (the
/// box's extreme edge against `normal`).
fn point_near_edge(p0: Vec3, p1: Vec3, h: Vec3, normal: Vec3, k: usize) -> Vec3 {
    let mut centre = -normal.signum() * h;
    centre[k] = 0.0;
    let along = Vec3::AXES[k] * h[k];
    let edge = Segment {
        start: centre - along,
        end: centre + along,
    };
    closest_segment_points(Segment { start: p0, end: p1 }, edge).0
}

/// For a face normal: the ends of the segment's part over the box face facing the capsule, with
/// their depths (`radius` minus the height above the face), those with depth `>= 0`. None
/// for a normal that is not a face normal.
fn face_points(p0: Vec3, p1: Vec3, h: Vec3, normal: Vec3, radius: f32) -> [Option<(Vec3, f32)>; 2] {
    const NONE: [Option<(Vec3, f32)>; 2] = [None, None];
    let k = normal.abs().max_position();
    if normal[k].abs() < FACE_COSINE {
        return NONE;
    }
    // The face the capsule touches is the box's side facing it, at -sign(n_k) h_k.
    let face = -normal[k].signum() * h[k];
    // The segment's part over the face: clipped by the box's side slabs, not by its own axis.
    let mut sides = h;
    sides[k] = f32::INFINITY;
    let d = p1 - p0;
    let Some(span) = segment_in_box(p0, d, sides) else {
        return NONE;
    };
    let (lo, hi) = (span.t_in, span.t_out);
    let end = |t: f32| {
        let x = p0 + d * t;
        let depth = radius + normal[k].signum() * (x[k] - face);
        (depth >= 0.0).then_some((x, depth))
    };
    // A clipped part shorter than this is one point.
    let single = hi - lo <= 1e-6;
    [end(lo), if single { None } else { end(hi) }]
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    /// Brute force: the smallest distance over a fine sampling of the segment.
    fn sampled_distance(p0: Vec3, p1: Vec3, h: Vec3) -> f32 {
        (0..=20_000)
            .map(|i| {
                let p = p0.lerp(p1, i as f32 / 20_000.0);
                (p - p.clamp(-h, h)).length()
            })
            .fold(f32::INFINITY, f32::min)
    }

    #[test]
    fn segment_box_distance_matches_sampling_within_1e_4() {
        let mut rng = crate::test_rng::TestRng::new(1);
        let h = Vec3::new(0.5, 1.0, 0.25);
        for _ in 0..500 {
            let p0 = rng.vec3(-3.0, 3.0);
            let p1 = rng.vec3(-3.0, 3.0);
            let (p, q) = closest_segment_box(p0, p1, h);
            let exact = (p - q).length();
            assert!(
                (exact - sampled_distance(p0, p1, h)).abs() < 1e-4,
                "{p0} {p1}"
            );
        }
    }

    #[test]
    fn a_capsule_lying_on_a_box_rests_on_two_points() {
        let capsule = Capsule {
            half_length: 0.5,
            radius: 0.2,
        };
        let table = Cuboid {
            half_extents: Vec3::new(2.0, 2.0, 0.5),
        };
        let lying = Isometry::new(
            Vec3::new(0.3, 0.0, 0.69),
            Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        );
        let m = contact_capsule_cuboid(&lying, &capsule, &Isometry::IDENTITY, &table).unwrap();
        assert_eq!(m.len(), 2, "{m:?}");
        assert!((m.normal + Vec3::Z).length() < 1e-6);
        for p in m.points() {
            assert!(
                (p.depth - 0.01).abs() < 1e-5 && (p.point.z - 0.495).abs() < 1e-5,
                "{p:?}"
            );
        }
        // Hanging over the edge: clipped at x = 2.
        let over = Isometry::new(Vec3::new(1.9, 0.0, 0.69), lying.rotation);
        let m = contact_capsule_cuboid(&over, &capsule, &Isometry::IDENTITY, &table).unwrap();
        let xs: Vec<f32> = m.points().iter().map(|p| p.point.x).collect();
        assert!(xs.iter().any(|x| (x - 2.0).abs() < 1e-5), "{xs:?}");
    }

    #[test]
    fn a_core_deep_inside_leaves_through_the_nearest_face() {
        let capsule = Capsule {
            half_length: 0.3,
            radius: 0.1,
        };
        let block = Cuboid {
            half_extents: Vec3::splat(1.0),
        };
        let inside = Isometry::from_translation(Vec3::new(0.0, 0.0, 0.5));
        let m = contact_capsule_cuboid(&inside, &capsule, &Isometry::IDENTITY, &block).unwrap();
        // Standing along z at z = 0.5: its lower end is 0.2 above the bottom... the top face is
        // nearest: the segment's lowest point (z = 0.2) must rise 0.8, plus the radius.
        assert!((m.normal + Vec3::Z).length() < 1e-6, "{m:?}");
        assert!((m.max_depth() - 0.9).abs() < 1e-5, "{m:?}");
    }
}
