//! Capsule–capsule: the closest points of the two inner segments (Ericson 2005, §5.1.9) decide
//! the contact as two spheres would. Nearly parallel capsules lying on each other touch along a
//! line, so, as Box2D v3's `b2CollideCapsules` does, the second segment is clipped to the span
//! of the first and each end of the overlap becomes a point with its own depth along the shared
//! normal: two points, so a log on a log does not seesaw.
//!
//! When the segments cross (the cores intersect) no closest-point direction exists; the normal
//! is then the segments' common perpendicular, the shortest way out (the Minkowski difference of
//! two segments is a flat parallelogram, so leaving through its plane costs only the radii).

use super::closest_segment_points::{Segment, closest_segment_points};
use super::{FALLBACK_NORMAL, total_order};
use crate::geometry::{Capsule, ContactManifold, ContactPoint, Isometry};
use glam::Vec3;
use std::cmp::Ordering;

/// Segments within this sine of parallel get the two-point manifold (about 3°, the angle at
/// which a 2 m log resting on another lifts one end by ~5 cm: beyond it the single closest point
/// is the contact).
const PARALLEL_SINE: f32 = 0.05;

/// Contact between capsules `a` at `pose_a` and `b` at `pose_b`, normal from A to B.
///
/// Symmetric: the pair is put in a fixed order first, so `contact(b, a)` is exactly
/// `contact(a, b)` flipped.
pub fn contact_capsule_capsule(
    pose_a: &Isometry,
    a: &Capsule,
    pose_b: &Isometry,
    b: &Capsule,
) -> Option<ContactManifold> {
    if canonical_order(pose_a, a, pose_b, b) == Ordering::Less {
        contact_in_order(pose_b, b, pose_a, a).map(ContactManifold::flipped)
    } else {
        contact_in_order(pose_a, a, pose_b, b)
    }
}

fn canonical_order(pose_a: &Isometry, a: &Capsule, pose_b: &Isometry, b: &Capsule) -> Ordering {
    let key = |pose: &Isometry, c: &Capsule| {
        let (t, q) = (pose.translation, pose.rotation);
        [c.radius, c.half_length, t.x, t.y, t.z, q.x, q.y, q.z, q.w]
    };
    total_order(&key(pose_a, a), &key(pose_b, b))
}

fn contact_in_order(
    pose_a: &Isometry,
    a: &Capsule,
    pose_b: &Isometry,
    b: &Capsule,
) -> Option<ContactManifold> {
    let (a0, a1) = a.segment(pose_a);
    let (b0, b1) = b.segment(pose_b);
    let sa = Segment { start: a0, end: a1 };
    let sb = Segment { start: b0, end: b1 };
    let (pa, pb) = closest_segment_points(sa, sb);
    let reach = a.radius + b.radius;
    let gap = pb - pa;
    let dist2 = gap.length_squared();
    if dist2 > reach * reach {
        return None;
    }
    let dist = dist2.sqrt();
    // Crossing segments meet only up to the rounding of their coordinates: below it the
    // closest points' offset is noise, not a direction.
    let rounding = 4.0 * f32::EPSILON * (a0.abs().max(a1.abs()).max_element() + a.half_length);
    let normal = if dist > rounding && dist2 >= f32::MIN_POSITIVE {
        gap / dist
    } else {
        crossing_normal(sa, sb, pose_b.translation - pose_a.translation)
    };
    let midway = |on_a: Vec3, on_b: Vec3, depth: f32| {
        ContactPoint::new(
            (on_a + normal * a.radius + on_b - normal * b.radius) * 0.5,
            depth,
        )
    };
    let closest = midway(pa, pb, (reach - dist).max(0.0));
    let mut out = ContactManifold::new(normal);
    match parallel_overlap(sa, sb) {
        Some(ends) => {
            for (on_a, on_b) in ends {
                let depth = reach - (on_b - on_a).dot(normal);
                if depth >= 0.0 {
                    out.push(midway(on_a, on_b, depth.min(closest.depth)));
                }
            }
            if out.len() < 2 {
                out = ContactManifold::new(normal);
                out.push(closest);
            }
        }
        None => {
            out.push(closest);
        }
    }
    Some(out)
}

/// For nearly parallel segments whose spans overlap along `a`: the two ends of the overlap, each
/// as (point on `a`, point on `b` with the same projection on `a`).
fn parallel_overlap(a: Segment, b: Segment) -> Option<[(Vec3, Vec3); 2]> {
    let (da, db) = (a.end - a.start, b.end - b.start);
    let (la, lb) = (da.length(), db.length());
    if la <= f32::EPSILON * (1.0 + a.start.abs().max_element()) || lb <= f32::EPSILON * la {
        return None;
    }
    let (ua, ub) = (da / la, db / lb);
    if ua.cross(ub).length() > PARALLEL_SINE {
        return None;
    }
    let (t0, t1) = ((b.start - a.start).dot(ua), (b.end - a.start).dot(ua));
    let (lo, hi) = (t0.min(t1).max(0.0), t0.max(t1).min(la));
    if hi - lo <= 1e-4 * la {
        return None;
    }
    // The point of b whose projection on a's line is t (t0 != t1: the segments are parallel).
    let on_b = |t: f32| b.start + db * ((t - t0) / (t1 - t0));
    Some([lo, hi].map(|t| (a.start + ua * t, on_b(t))))
}

/// The normal of two crossing segments: their common perpendicular, else (parallel and
/// overlapping) the direction across `a` towards B's centre, else any direction across `a`;
/// oriented towards B's centre (`centres`, from A's centre to B's), ties towards
/// [`FALLBACK_NORMAL`].
fn crossing_normal(a: Segment, b: Segment, centres: Vec3) -> Vec3 {
    let (da, db) = (a.end - a.start, b.end - b.start);
    let across = |v: Vec3| match da.try_normalize() {
        Some(u) => v - u * v.dot(u),
        None => v,
    };
    let n = da
        .cross(db)
        .try_normalize()
        .or_else(|| across(centres).try_normalize())
        .or_else(|| da.try_normalize().map(|u| u.any_orthonormal_vector()))
        .unwrap_or(FALLBACK_NORMAL);
    let side = n.dot(centres);
    let flip = side < 0.0 || (side == 0.0 && n.dot(FALLBACK_NORMAL) < 0.0);
    if flip { -n } else { n }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn lying(at: Vec3, yaw: f32) -> Isometry {
        Isometry::new(
            at,
            Quat::from_rotation_z(yaw) * Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        )
    }

    #[test]
    fn a_log_on_a_log_touches_at_two_points_and_crossed_logs_at_one() {
        let log = Capsule {
            half_length: 1.0,
            radius: 0.25,
        };
        let below = lying(Vec3::ZERO, 0.0);
        let above = lying(Vec3::new(0.5, 0.0, 0.49), 0.0);
        let m = contact_capsule_capsule(&below, &log, &above, &log).unwrap();
        assert_eq!(m.len(), 2, "{m:?}");
        assert!((m.normal - Vec3::Z).length() < 1e-6);
        // The overlap runs from x = -0.5 to x = 1.
        let xs: Vec<f32> = m.points().iter().map(|p| p.point.x).collect();
        assert!(xs.iter().any(|x| (x + 0.5).abs() < 1e-5), "{xs:?}");
        assert!(xs.iter().any(|x| (x - 1.0).abs() < 1e-5), "{xs:?}");
        assert!(m.points().iter().all(|p| (p.depth - 0.01).abs() < 1e-5));
        let crossed = lying(Vec3::new(0.0, 0.0, 0.49), 1.0);
        let m = contact_capsule_capsule(&below, &log, &crossed, &log).unwrap();
        assert_eq!(m.len(), 1);
        assert!((m.max_depth() - 0.01).abs() < 1e-5);
    }

    #[test]
    fn crossing_cores_separate_along_the_common_perpendicular() {
        let log = Capsule {
            half_length: 1.0,
            radius: 0.25,
        };
        let below = lying(Vec3::ZERO, 0.0);
        let crossed = lying(Vec3::ZERO, 1.0);
        let m = contact_capsule_capsule(&below, &log, &crossed, &log).unwrap();
        assert!((m.normal.abs() - Vec3::Z).length() < 1e-6, "{m:?}");
        assert!((m.max_depth() - 0.5).abs() < 1e-6);
        let flipped = contact_capsule_capsule(&crossed, &log, &below, &log).unwrap();
        assert_eq!(flipped.normal, -m.normal);
        // Coincident, parallel: across the axis, never NaN.
        let m = contact_capsule_capsule(&below, &log, &below, &log).unwrap();
        assert!(m.normal.is_normalized() && m.normal.dot(Vec3::X).abs() < 1e-6);
    }
}
