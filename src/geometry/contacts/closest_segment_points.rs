//! Closest points of two segments (Ericson 2005, *Real-Time Collision Detection* §5.1.9): the
//! edge–edge case of box–box contact.

use glam::Vec3;

/// A segment from `start` to `end`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Segment {
    /// First endpoint.
    pub start: Vec3,
    /// Second endpoint.
    pub end: Vec3,
}

/// The point of the segment from `start` to `end` closest to `p` (`start` for a segment of zero
/// length).
#[inline]
pub(crate) fn closest_point_on_segment(start: Vec3, end: Vec3, p: Vec3) -> Vec3 {
    let d = end - start;
    let len2 = d.length_squared();
    if len2 <= f32::MIN_POSITIVE {
        return start;
    }
    start + d * ((p - start).dot(d) / len2).clamp(0.0, 1.0)
}

/// The closest points `(on a, on b)` of segments `a` and `b`.
///
/// Degenerate segments (zero length) act as points; parallel segments return the pair found
/// from `a.start`'s projection, so the answer is always finite and deterministic.
pub(crate) fn closest_segment_points(a: Segment, b: Segment) -> (Vec3, Vec3) {
    let da = a.end - a.start;
    let db = b.end - b.start;
    let r = a.start - b.start;
    let len2_a = da.length_squared();
    let len2_b = db.length_squared();
    let f = db.dot(r);
    // Below this squared length a segment is a point: dividing by it would amplify rounding
    // without bound.
    let tiny = f32::MIN_POSITIVE;

    let (s, t) = if len2_a <= tiny && len2_b <= tiny {
        (0.0, 0.0)
    } else if len2_a <= tiny {
        (0.0, (f / len2_b).clamp(0.0, 1.0))
    } else {
        let c = da.dot(r);
        if len2_b <= tiny {
            ((-c / len2_a).clamp(0.0, 1.0), 0.0)
        } else {
            let b_dot = da.dot(db);
            let denom = len2_a * len2_b - b_dot * b_dot;
            let s = if denom > 0.0 {
                ((b_dot * f - c * len2_b) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = (b_dot * s + f) / len2_b;
            if t < 0.0 {
                ((-c / len2_a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b_dot - c) / len2_a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    (a.start + da * s, b.start + db * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(a: [f32; 3], b: [f32; 3]) -> Segment {
        Segment {
            start: Vec3::from_array(a),
            end: Vec3::from_array(b),
        }
    }

    /// Brute force: the smallest distance over a fine grid of parameters.
    fn brute_distance(a: Segment, b: Segment) -> f32 {
        let n = 400;
        let mut best = f32::INFINITY;
        for i in 0..=n {
            let p = a.start.lerp(a.end, i as f32 / n as f32);
            for j in 0..=n {
                let q = b.start.lerp(b.end, j as f32 / n as f32);
                best = best.min((p - q).length());
            }
        }
        best
    }

    #[test]
    fn crossing_skew_clamped_parallel_and_degenerate_segments() {
        let cases = [
            (
                seg([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
                seg([0.0, -1.0, 1.0], [0.0, 1.0, 1.0]),
            ),
            (
                seg([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
                seg([2.0, -1.0, 0.5], [3.0, 1.0, -0.5]),
            ),
            (
                seg([0.0, 0.0, 0.0], [2.0, 0.0, 0.0]),
                seg([1.0, 1.0, 0.0], [3.0, 1.0, 0.0]),
            ),
            (
                seg([0.3, 0.2, 0.1], [0.3, 0.2, 0.1]),
                seg([-1.0, 0.0, 0.0], [1.0, 0.5, 0.0]),
            ),
            (
                seg([0.3, 0.2, 0.1], [0.3, 0.2, 0.1]),
                seg([1.0, 1.0, 1.0], [1.0, 1.0, 1.0]),
            ),
        ];
        for (a, b) in cases {
            let (p, q) = closest_segment_points(a, b);
            assert!(p.is_finite() && q.is_finite());
            assert!(
                ((p - q).length() - brute_distance(a, b)).abs() < 1e-2,
                "{a:?} {b:?}"
            );
        }
        let (p, q) = closest_segment_points(cases[0].0, cases[0].1);
        assert!(p.length() < 1e-6 && (q - Vec3::Z).length() < 1e-6);
    }
}
