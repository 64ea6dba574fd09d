//! Which test a pair of colliders takes beyond the speculative contact: two balls closing take
//! their contact where they will meet, and a pair worth it is answered from the manifold cache
//! when it has not moved.

use crate::geometry::contacts::sphere_sphere_on_approach;
use crate::geometry::{ContactManifold, Isometry, Shape};
use glam::Vec3;

/// Two balls within `margin` of each other and closing, B moving by `motion` relative to A:
/// their contact where they will meet, not where they are (`sphere_sphere_on_approach`);
/// `None` for any other pair, and for balls that do not meet that soon (their closest
/// points' contact stands).
pub(super) fn balls_meeting(
    (sa, pa): (&Shape, &Isometry),
    (sb, pb): (&Shape, &Isometry),
    margin: f32,
    motion: Vec3,
) -> Option<ContactManifold> {
    let (Shape::Sphere(ra), Shape::Sphere(rb)) = (sa, sb) else {
        return None;
    };
    let (ca, cb) = (pa.translation, pb.translation);
    let reach = ra.radius + rb.radius + margin;
    if !(margin > 0.0 && (cb - ca).length_squared() <= reach * reach) {
        return None;
    }
    sphere_sphere_on_approach(ca, ra, cb, rb, motion)
}

pub(super) fn is_mesh(shape: &Shape) -> bool {
    matches!(shape, Shape::TriMesh(_))
}

/// Whether a pair's test costs more than a cache lookup: a mesh against anything, else two
/// shapes neither of which is a sphere or a half-space (closed forms of a few dozen operations)
/// and not two capsules (closest points of two segments). Two boxes take about 4,600
/// instructions (axes, clipping, four points chosen), the GJK/EPA shapes 12,000–25,000; a
/// lookup a few hundred. Never with an ellipsoid: where it touches depends on how it is turned
/// (a point under an ellipsoid rocking on its flattest side runs `(a² − c²)/c` per radian, 1.6
/// m for one of 0.6 × 0.4 × 0.2 m), which a kept contact cannot follow: it lagged by up to
/// 2.7 mm, and the push there rocked such an ellipsoid lying on a box harder and harder (26 mm
/// of drift in 20 s with sleeping off, 0.06 mm tested each step).
pub(super) fn worth_caching(a: &Shape, b: &Shape) -> bool {
    let closed_form = |s: &Shape| matches!(s, Shape::Sphere(_) | Shape::HalfSpace(_));
    let capsules = matches!((a, b), (Shape::Capsule(_), Shape::Capsule(_)));
    let ellipsoid = |s: &Shape| matches!(s, Shape::Ellipsoid(_));
    if ellipsoid(a) || ellipsoid(b) {
        return false;
    }
    is_mesh(a) || is_mesh(b) || !(closed_form(a) || closed_form(b) || capsules)
}
