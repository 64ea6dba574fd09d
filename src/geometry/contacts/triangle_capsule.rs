//! Triangle–capsule, the leaf test of mesh–capsule: the closest points of the capsule's inner
//! segment and the triangle (Ericson 2005, §5.1.10: the segment crosses the triangle, or the
//! closest pair involves an end of the segment or an edge of the triangle) decide the contact as
//! for a sphere. A capsule lying on a triangle also gets its other end as a point when that end
//! lies over the face, so it rests on two points, as on a box.
//!
//! A segment that pierces the triangle has no closest-point direction: it is pushed out along
//! the triangle's normal, to the side holding most of it, by the radius plus the depth of its
//! end on the other side. Triangles are two-sided surfaces, as everywhere in urto.

use super::FALLBACK_NORMAL;
use super::closest_segment_points::{Segment, closest_segment_points};
use crate::geometry::active_edges::face_normal_at_inactive_edge;
use crate::geometry::{ContactManifold, ContactPoint, Triangle};
use glam::Vec3;

/// An end of the segment counts as resting on the face when the direction to it from its
/// closest triangle point is this close to the contact normal (cosine).
const OVER_FACE_COSINE: f32 = 0.999;

/// Contact between a triangle (shape A) and the capsule of `radius` around the segment from
/// `p0` to `p1` (shape B), all in one frame; the normal points from the triangle to the capsule.
/// `active` holds the triangle's active edges (bit `k`: edge from corner `k` to `k + 1`; all
/// three for a lone triangle): a closest point only on inactive edges takes the face normal
/// (see [`active_edges`](crate::geometry::active_edges)).
pub fn contact_triangle_capsule(
    tri: &Triangle,
    active: u8,
    p0: Vec3,
    p1: Vec3,
    radius: f32,
) -> Option<ContactManifold> {
    if let Some(m) = pierced(tri, p0, p1, radius) {
        return Some(m);
    }
    // The ends' nearest triangle points serve both the closest pair and the resting points.
    let feet = [p0, p1].map(|p| tri.closest_point(p));
    let (on_segment, on_triangle) = closest_segment_triangle(tri, p0, p1, feet);
    let gap = on_segment - on_triangle;
    let dist2 = gap.length_squared();
    if dist2.is_nan() || dist2 > radius * radius {
        return None;
    }
    let normal = gap
        .try_normalize()
        .or_else(|| tri.normal())
        .unwrap_or(FALLBACK_NORMAL);
    let (normal, on_triangle) = match face_normal_at_inactive_edge(tri, active, on_triangle, normal)
    {
        // The flat surface continues past the inactive edge: it supports the capsule right
        // under its axis, not at the edge (a point off to the side would roll it).
        Some(face) => (face, on_segment - face * gap.dot(face)),
        None => (normal, on_triangle),
    };
    let depth = (radius - gap.dot(normal)).max(0.0);
    let midway = |on_tri: Vec3, on_axis: Vec3, depth: f32| {
        ContactPoint::new((on_tri + on_axis - normal * radius) * 0.5, depth)
    };
    let mut out = ContactManifold::new(normal);
    for (end, foot) in [p0, p1].into_iter().zip(feet) {
        let up = end - foot;
        let height = up.dot(normal);
        if height >= OVER_FACE_COSINE * up.length() && height <= radius {
            out.push(midway(foot, end, (radius - height).min(depth)));
        }
    }
    if out.len() < 2 {
        out = ContactManifold::new(normal);
        out.push(midway(on_triangle, on_segment, depth));
    }
    Some(out)
}

/// The contact of a segment crossing the triangle (module notes), or `None` when it does not.
fn pierced(tri: &Triangle, p0: Vec3, p1: Vec3, radius: f32) -> Option<ContactManifold> {
    let (n, h0, h1) = crossing(tri, p0, p1)?;
    // Out towards the side holding the longer part of the segment.
    let (normal, below, end) = if h0.abs() >= h1.abs() {
        (n * h0.signum(), h1.abs(), p1)
    } else {
        (n * h1.signum(), h0.abs(), p0)
    };
    let depth = radius + below;
    // Midway between the capsule's surface under `end` and the plane.
    let point = end + normal * (below - 0.5 * depth);
    Some(ContactManifold::single(normal, point, depth))
}

/// Where the segment crosses the triangle: the triangle's unit normal and the ends' heights
/// along it (of opposite signs), or `None` when it does not cross.
fn crossing(tri: &Triangle, p0: Vec3, p1: Vec3) -> Option<(Vec3, f32, f32)> {
    let n = tri.normal()?;
    let [a, _, _] = tri.vertices();
    let (h0, h1) = (n.dot(p0 - a), n.dot(p1 - a));
    let product = h0 * h1;
    if product.is_nan() || product >= 0.0 {
        return None;
    }
    let at = p0 + (p1 - p0) * (h0 / (h0 - h1));
    let slack = 1e-6 * (1.0 + at.abs().max_element());
    ((tri.closest_point(at) - at).length_squared() <= slack * slack).then_some((n, h0, h1))
}

/// The closest points `(on the segment, on the triangle)` of a segment that does not cross the
/// triangle: the nearer of the segment's ends to the triangle (`feet`, their nearest triangle
/// points) and the segment against each edge.
fn closest_segment_triangle(tri: &Triangle, p0: Vec3, p1: Vec3, feet: [Vec3; 2]) -> (Vec3, Vec3) {
    let segment = Segment { start: p0, end: p1 };
    let [a, b, c] = tri.vertices();
    let ends = [(p0, feet[0]), (p1, feet[1])];
    let edges = [(a, b), (b, c), (c, a)]
        .map(|(start, end)| closest_segment_points(segment, Segment { start, end }));
    ends.into_iter()
        .chain(edges)
        .min_by(|x, y| {
            (x.0 - x.1)
                .length_squared()
                .total_cmp(&(y.0 - y.1).length_squared())
        })
        .unwrap_or((p0, a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::active_edges::ALL_EDGES_ACTIVE as ALL;

    fn floor() -> Triangle {
        Triangle::new(
            Vec3::new(-5.0, -5.0, 0.0),
            Vec3::new(5.0, -5.0, 0.0),
            Vec3::new(0.0, 5.0, 0.0),
        )
    }

    #[test]
    fn a_capsule_lying_on_a_triangle_rests_on_both_ends() {
        let m = contact_triangle_capsule(
            &floor(),
            ALL,
            Vec3::new(-1.0, 0.0, 0.49),
            Vec3::new(1.0, 0.0, 0.49),
            0.5,
        )
        .unwrap();
        assert_eq!(m.len(), 2, "{m:?}");
        assert!((m.normal - Vec3::Z).length() < 1e-6);
        for p in m.points() {
            assert!(
                (p.depth - 0.01).abs() < 1e-6 && (p.point.z + 0.005).abs() < 1e-6,
                "{p:?}"
            );
        }
        let tilted =
            contact_triangle_capsule(&floor(), ALL, Vec3::new(-1.0, 0.0, 0.4), Vec3::Z, 0.5);
        let tilted = tilted.unwrap();
        assert_eq!(tilted.len(), 1);
        assert!((tilted.max_depth() - 0.1).abs() < 1e-6);
    }

    #[test]
    fn a_piercing_capsule_leaves_to_the_side_holding_most_of_it() {
        let m = contact_triangle_capsule(
            &floor(),
            ALL,
            Vec3::new(0.0, 0.0, -0.2),
            Vec3::new(0.0, 0.0, 1.0),
            0.1,
        )
        .unwrap();
        assert!((m.normal - Vec3::Z).length() < 1e-6);
        assert!((m.max_depth() - 0.3).abs() < 1e-6, "{m:?}");
    }
}
