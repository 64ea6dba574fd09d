//! Shape-pair contact tests (the narrow phase), one file per pair as in parry's
//! `query/contact/contact_<shape1>_<shape2>.rs`, and [`contact`] / [`contact_with_scratch`], which
//! dispatch on the pair.
//!
//! Every test follows the conventions of [`ContactManifold`]: normal from A to B, touching counts
//! (depth 0), and degenerate input (coincident centres, zero-size shapes) gives a finite normal
//! chosen by a documented rule, never NaN.
//!
//! # The pairs
//!
//! | A \ B         | `Sphere`                      | `Cuboid`                          | `HalfSpace`                   | `Capsule`                      | `TriMesh`                     |
//! |---------------|-------------------------------|-----------------------------------|-------------------------------|--------------------------------|-------------------------------|
//! | **Sphere**    | [`contact_sphere_sphere`]     | [`contact_sphere_cuboid`]         | [`contact_sphere_halfspace`]  | capsule–sphere, flipped        | mesh–sphere, flipped          |
//! | **Cuboid**    | sphere–cuboid, flipped        | [`contact_cuboid_cuboid`] (SAT)   | [`contact_cuboid_halfspace`]  | capsule–cuboid, flipped        | mesh–box, flipped             |
//! | **HalfSpace** | sphere–half-space, flipped    | cuboid–half-space, flipped        | `None` (both static, infinite) | capsule–half-space, flipped   | mesh–half-space, flipped      |
//! | **Capsule**   | [`contact_capsule_sphere`]    | [`contact_capsule_cuboid`]        | [`contact_capsule_halfspace`] | [`contact_capsule_capsule`]    | mesh–capsule, flipped         |
//! | **TriMesh**   | [`contact_trimesh_sphere`]    | [`contact_trimesh_cuboid`]        | [`contact_trimesh_halfspace`] | [`contact_trimesh_capsule`]    | [`contact_trimesh_trimesh`]   |
//!
//! Any pair with a **cylinder, ellipsoid or convex hull** (no closed form) goes through GJK/EPA
//! and a manifold clipped from the supporting features (`convex_convex.rs`), against a
//! half-space through its supporting feature below the plane, and against a mesh triangle by
//! triangle (`trimesh_convex.rs`); see `general_convex_contact`.
//!
//! "Flipped" means the test runs with the arguments swapped and the manifold is turned around
//! with [`ContactManifold::flipped`] (normal negated, points unchanged). Box–box and mesh–mesh put
//! their two shapes in a canonical order the same way, so for every pair `contact(a, b)` and
//! `contact(b, a)` report opposite normals and equal depths (but for the one exception below).
//!
//! # Meshes
//!
//! Mesh tests descend the mesh's OBB hierarchy ([`MeshCollider`](crate::geometry::MeshCollider))
//! with the other shape, test the triangles of the leaves they reach exactly, and merge the
//! triangle contacts into one manifold (`mesh_manifold.rs`: depth-weighted normal, deepest and
//! widest points). Triangles are two-sided surfaces, so a shape entirely inside a closed mesh
//! touches nothing. They need buffers: [`contact_with_scratch`] takes a [`ContactScratch`] that
//! a caller keeps from query to query (so a warm query allocates nothing) and that sums the
//! hierarchy work (`Nv`, `Nn`, `Ns`); [`contact`] makes a fresh one per mesh query.
//!
//! # Degenerate geometry
//!
//! When the geometry leaves the normal undefined, the tests fall back on [`FALLBACK_NORMAL`]
//! (world up): coincident sphere centres push the smaller ball up (the normal is
//! `FALLBACK_NORMAL` when A is at least as big as B, its opposite otherwise), and a choice between
//! equally deep axes (a sphere at a box's centre, two coincident boxes) goes to the candidate
//! normal closest to `FALLBACK_NORMAL`. Only two identical shapes at the same place cannot be
//! told apart; both orders then report the same normal.
//!
//! Non-finite poses or shapes are refused upstream ([`Shape::validate`],
//! [`Isometry::is_finite`]); given them anyway, the tests do not panic but their output is
//! unspecified.

mod capsule_capsule;
mod capsule_cuboid;
mod capsule_halfspace;
mod capsule_sphere;
mod closest_segment_points;
mod convex_convex;
mod cuboid_axes;
mod cuboid_cuboid;
mod cuboid_halfspace;
#[cfg(test)]
mod feature_id_tests;
mod manifold_cache;
mod manifold_reduction;
mod mesh_manifold;
mod mesh_scratch;
mod polygon_clip;
mod speculative;
mod sphere_cuboid;
mod sphere_halfspace;
mod sphere_sphere;
mod triangle_capsule;
mod triangle_cuboid;
mod triangle_distance;
mod trimesh_capsule;
mod trimesh_convex;
mod trimesh_cuboid;
mod trimesh_halfspace;
mod trimesh_sphere;
mod trimesh_trimesh;

pub use capsule_capsule::contact_capsule_capsule;
pub(crate) use capsule_cuboid::closest_segment_box;
pub use capsule_cuboid::contact_capsule_cuboid;
pub use capsule_halfspace::contact_capsule_halfspace;
pub use capsule_sphere::contact_capsule_sphere;
pub(crate) use closest_segment_points::{
    Segment, closest_point_on_segment, closest_segment_points,
};
pub(crate) use convex_convex::{contact_convex_convex, contact_convex_halfspace};
pub use cuboid_cuboid::contact_cuboid_cuboid;
pub use cuboid_halfspace::contact_cuboid_halfspace;
pub use manifold_cache::{MAX_SHIFT, ManifoldCache, RoundSide};
pub use mesh_scratch::{ContactScratch, NO_TRIANGLE};
pub use speculative::{
    motion_bound, raw_motion_bound, speculative_contact, speculative_contact_with_scratch,
};
pub use sphere_cuboid::contact_sphere_cuboid;
pub use sphere_halfspace::contact_sphere_halfspace;
pub use sphere_sphere::{contact_sphere_sphere, sphere_sphere_on_approach};
pub use triangle_capsule::contact_triangle_capsule;
pub use triangle_cuboid::{contact_triangle_cuboid, contact_triangle_cuboid_with_edges};
pub use triangle_distance::closest_points_triangle_triangle;
pub use trimesh_capsule::contact_trimesh_capsule;
pub(crate) use trimesh_convex::contact_trimesh_convex;
pub use trimesh_cuboid::contact_trimesh_cuboid;
pub use trimesh_halfspace::contact_trimesh_halfspace;
pub use trimesh_sphere::contact_trimesh_sphere;
pub(crate) use trimesh_sphere::obb_distance_squared;
pub use trimesh_trimesh::{
    contact_triangle_triangle, contact_trimesh_trimesh, contact_trimesh_trimesh_within,
};

use crate::geometry::{ContactManifold, Isometry, Shape};
use glam::Vec3;

/// The normal used when the geometry defines none (coincident centres): world up, +Z, the
/// slides' vertical. Deterministic, so a stack of coincident bodies separates the same way on
/// every run.
pub const FALLBACK_NORMAL: Vec3 = Vec3::Z;

/// Lexicographic total order of two equally long float keys (a shape's size and pose): pair
/// queries use it to pick one argument order for a symmetric pair, so swapping the arguments
/// gives the same contact.
pub(crate) fn total_order(a: &[f32], b: &[f32]) -> std::cmp::Ordering {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.total_cmp(y))
        .find(|o| o.is_ne())
        .unwrap_or(std::cmp::Ordering::Equal)
}

/// Tie-break between two candidate normals of *equal* depth: true when the candidate whose
/// normal has component `candidate_up` along [`FALLBACK_NORMAL`] beats the incumbent's
/// `best_up`.
///
/// Why: with coincident sphere centres the normal is [`FALLBACK_NORMAL`] ("B above A"); this
/// rule extends the same choice to boxes, so two coincident bodies of any kind separate along
/// the axis closest to world up, the same way on every run.
#[inline]
pub(crate) fn prefer_towards_fallback(candidate_up: f32, best_up: f32) -> bool {
    candidate_up > best_up
}

/// Contact between shape `a` at `pose_a` and shape `b` at `pose_b`, or `None` when they are
/// apart. `None` is also returned for pairs no test covers (two half-spaces). See the module
/// docs for the table of pairs.
///
/// A convenience: a pair involving a mesh gets fresh buffers, which allocates. Code that runs
/// many queries (the narrow phase) keeps a [`ContactScratch`] and calls [`contact_with_scratch`].
pub fn contact(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
) -> Option<ContactManifold> {
    let needs_scratch = |s: &Shape| matches!(s, Shape::TriMesh(_)) || is_general_convex(s);
    if needs_scratch(a) || needs_scratch(b) {
        contact_with_scratch(a, pose_a, b, pose_b, &mut ContactScratch::new())
    } else {
        primitive_contact(a, pose_a, b, pose_b)
    }
}

/// [`contact`] with caller-owned buffers: mesh queries reuse `scratch` (no allocation once it
/// has grown), add their hierarchy work to its counters, and leave their triangle hits in it
/// ([`ContactScratch::hits`], in this call's A/B order). Pairs of primitives only clear the hits.
pub fn contact_with_scratch(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    if let Some(m) = general_convex_contact(a, pose_a, b, pose_b, 0.0, scratch) {
        return m;
    }
    use Shape::*;
    match (a, b) {
        (TriMesh(m), Sphere(s)) => {
            contact_trimesh_sphere(pose_a, m, pose_b.translation, s, scratch)
        }
        (TriMesh(m), Cuboid(c)) => contact_trimesh_cuboid(pose_a, m, pose_b, c, scratch),
        (TriMesh(m), HalfSpace(h)) => contact_trimesh_halfspace(pose_a, m, pose_b, h, scratch),
        (TriMesh(m), Capsule(c)) => contact_trimesh_capsule(pose_a, m, pose_b, c, scratch),
        (TriMesh(ma), TriMesh(mb)) => contact_trimesh_trimesh(pose_a, ma, pose_b, mb, scratch),
        (Sphere(_) | Cuboid(_) | HalfSpace(_) | Capsule(_), TriMesh(_)) => {
            let m = contact_with_scratch(b, pose_b, a, pose_a, scratch);
            scratch.flip_hits();
            m.map(ContactManifold::flipped)
        }
        _ => {
            scratch.begin_query();
            primitive_contact(a, pose_a, b, pose_b)
        }
    }
}

/// The pairs of primitives (no mesh): closed-form tests, no buffers.
fn primitive_contact(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
) -> Option<ContactManifold> {
    use Shape::*;
    match (a, b) {
        (Sphere(sa), Sphere(sb)) => {
            contact_sphere_sphere(pose_a.translation, sa, pose_b.translation, sb)
        }
        (Sphere(s), Cuboid(c)) => contact_sphere_cuboid(pose_a.translation, s, pose_b, c),
        (Sphere(s), HalfSpace(h)) => contact_sphere_halfspace(pose_a.translation, s, pose_b, h),
        (Cuboid(ca), Cuboid(cb)) => contact_cuboid_cuboid(pose_a, ca, pose_b, cb),
        (Cuboid(c), HalfSpace(h)) => contact_cuboid_halfspace(pose_a, c, pose_b, h),
        (Capsule(c), Sphere(s)) => contact_capsule_sphere(pose_a, c, pose_b.translation, s),
        (Capsule(c), Cuboid(k)) => contact_capsule_cuboid(pose_a, c, pose_b, k),
        (Capsule(c), HalfSpace(h)) => contact_capsule_halfspace(pose_a, c, pose_b, h),
        (Capsule(ca), Capsule(cb)) => contact_capsule_capsule(pose_a, ca, pose_b, cb),
        (Cuboid(_), Sphere(_))
        | (HalfSpace(_), Sphere(_) | Cuboid(_) | Capsule(_))
        | (Sphere(_) | Cuboid(_), Capsule(_)) => {
            primitive_contact(b, pose_b, a, pose_a).map(ContactManifold::flipped)
        }
        (HalfSpace(_), HalfSpace(_)) | (TriMesh(_), _) | (_, TriMesh(_)) => None,
        (Cylinder(_) | Cone(_) | Ellipsoid(_) | ConvexHull(_), _)
        | (_, Cylinder(_) | Cone(_) | Ellipsoid(_) | ConvexHull(_)) => None,
    }
}

/// Shapes that collide only through GJK/EPA (no closed form).
pub(crate) fn is_general_convex(shape: &Shape) -> bool {
    matches!(
        shape,
        Shape::Cylinder(_) | Shape::Cone(_) | Shape::Ellipsoid(_) | Shape::ConvexHull(_)
    )
}

/// The contact of a pair involving a cylinder, ellipsoid or hull, with a speculative `margin`
/// (0: touching or overlapping only); `None` (the outer one) for the other pairs, which have
/// closed forms. Two convex shapes are taken in a canonical order (kind, then pose), so that
/// swapping the arguments flips the normal and keeps the depths bit for bit.
pub(crate) fn general_convex_contact(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    margin: f32,
    scratch: &mut ContactScratch,
) -> Option<Option<ContactManifold>> {
    if !(is_general_convex(a) || is_general_convex(b)) {
        return None;
    }
    Some(match (a, b) {
        (Shape::TriMesh(m), _) => contact_trimesh_convex((pose_a, m), (pose_b, b), margin, scratch),
        (_, Shape::TriMesh(m)) => {
            let found = contact_trimesh_convex((pose_b, m), (pose_a, a), margin, scratch);
            scratch.flip_hits();
            found.map(ContactManifold::flipped)
        }
        (_, Shape::HalfSpace(h)) => {
            scratch.begin_query();
            contact_convex_halfspace(a, pose_a, h, pose_b, margin)
        }
        (Shape::HalfSpace(h), _) => {
            scratch.begin_query();
            contact_convex_halfspace(b, pose_b, h, pose_a, margin).map(ContactManifold::flipped)
        }
        _ => {
            scratch.begin_query();
            if canonical_swap(a, pose_a, b, pose_b) {
                contact_convex_convex(b, pose_b, a, pose_a, margin).map(ContactManifold::flipped)
            } else {
                contact_convex_convex(a, pose_a, b, pose_b, margin)
            }
        }
    })
}

/// True when `(b, a)` comes first in the canonical order of convex pairs: by kind, then by pose.
fn canonical_swap(a: &Shape, pose_a: &Isometry, b: &Shape, pose_b: &Isometry) -> bool {
    let rank = |s: &Shape| match s {
        Shape::Sphere(_) => 0,
        Shape::Capsule(_) => 1,
        Shape::Cuboid(_) => 2,
        Shape::Cylinder(_) => 3,
        Shape::Ellipsoid(_) => 4,
        Shape::Cone(_) => 5,
        _ => 6,
    };
    let key = |p: &Isometry| {
        let (t, r) = (p.translation, p.rotation);
        [t.x, t.y, t.z, r.x, r.y, r.z, r.w]
    };
    match rank(a).cmp(&rank(b)) {
        std::cmp::Ordering::Equal => total_order(&key(pose_a), &key(pose_b)).is_gt(),
        other => other.is_gt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn shapes() -> [Shape; 9] {
        let ball = crate::geometry::TriMesh::uv_sphere(0.7, 24, 12).unwrap();
        let gem = [
            Vec3::new(0.6, 0.1, 0.0),
            Vec3::new(-0.5, 0.2, 0.1),
            Vec3::new(0.0, 0.6, -0.2),
            Vec3::new(0.1, -0.5, 0.3),
            Vec3::new(0.0, 0.0, 0.6),
            Vec3::new(0.1, 0.1, -0.5),
        ];
        [
            Shape::sphere(0.7),
            Shape::cuboid(Vec3::new(0.5, 0.8, 0.3)),
            Shape::half_space(Vec3::new(0.1, 0.2, 1.0)),
            Shape::capsule(0.4, 0.3),
            Shape::TriMesh(crate::geometry::MeshCollider::new(ball).unwrap()),
            Shape::cylinder(0.4, 0.5),
            Shape::ellipsoid(Vec3::new(0.6, 0.4, 0.3)),
            Shape::convex_hull(&gem).unwrap(),
            Shape::cone(0.5, 0.5),
        ]
    }

    #[test]
    fn every_ordered_pair_is_dispatched_and_swapping_flips_the_normal() {
        let pa = Isometry::new(Vec3::new(0.1, 0.2, 0.3), Quat::from_rotation_x(0.4));
        let pb = Isometry::new(Vec3::new(0.3, -0.1, 0.6), Quat::from_rotation_y(-0.9));
        for a in &shapes() {
            for b in &shapes() {
                let ab = contact(a, &pa, b, &pb);
                let ba = contact(b, &pb, a, &pa);
                if a.is_unbounded() && b.is_unbounded() {
                    assert!(ab.is_none() && ba.is_none());
                    continue;
                }
                let (ab, ba) = (ab.expect("overlapping pair"), ba.expect("overlapping pair"));
                assert!(ab.normal.is_normalized(), "{a:?} {b:?}");
                assert_eq!(ab.normal, -ba.normal, "{a:?} {b:?}");
                assert_eq!(ab.max_depth(), ba.max_depth(), "{a:?} {b:?}");
                assert!(!ab.is_empty() && ab.max_depth() > 0.0);
            }
        }
    }

    #[test]
    fn non_finite_input_does_not_panic() {
        let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
        let good = Isometry::IDENTITY;
        for &x in &bad {
            let poses = [
                Isometry::from_translation(Vec3::new(x, 0.0, 0.0)),
                Isometry::new(Vec3::ZERO, Quat::from_xyzw(x, 0.0, 0.0, 1.0)),
            ];
            let bad_shapes = [
                Shape::sphere(x),
                Shape::cuboid(Vec3::new(1.0, x, 1.0)),
                Shape::half_space(Vec3::new(0.0, x, 1.0)),
                Shape::capsule(x, 0.5),
                Shape::capsule(0.5, x),
                Shape::cylinder(x, 0.5),
                Shape::cylinder(0.5, x),
                Shape::cone(x, 0.5),
                Shape::cone(0.5, x),
                Shape::ellipsoid(Vec3::new(0.5, x, 0.5)),
            ];
            for a in shapes().iter().chain(&bad_shapes) {
                for b in shapes().iter().chain(&bad_shapes) {
                    for pose in &poses {
                        let _ = contact(a, pose, b, &good);
                        let _ = contact(a, &good, b, pose);
                        let _ = speculative_contact(a, pose, b, &good, 0.05);
                        let _ = crate::geometry::convex::signed_distance(a, pose, b, &good);
                    }
                    let _ = contact(a, &good, b, &good);
                }
            }
        }
    }

    #[test]
    fn zero_size_convex_shapes_give_finite_contacts_or_none() {
        let degenerate = [
            Shape::cylinder(0.0, 0.5),
            Shape::cylinder(0.5, 0.0),
            Shape::cylinder(0.0, 0.0),
            Shape::cone(0.0, 0.5),
            Shape::cone(0.5, 0.0),
            Shape::ellipsoid(Vec3::new(0.5, 0.0, 0.5)),
            Shape::ellipsoid(Vec3::ZERO),
            Shape::cuboid(Vec3::new(0.5, 0.0, 0.5)),
        ];
        let poses = [
            Isometry::IDENTITY,
            Isometry::new(Vec3::new(0.1, 0.2, 0.3), Quat::from_rotation_x(0.4)),
            Isometry::from_translation(Vec3::new(0.0, 0.0, 0.5)),
        ];
        for a in degenerate.iter().chain(&shapes()) {
            for b in &degenerate {
                for pa in &poses {
                    for pb in &poses {
                        for m in [contact(a, pa, b, pb), contact(b, pb, a, pa)]
                            .into_iter()
                            .flatten()
                        {
                            assert!(
                                m.normal.is_finite() && m.normal.is_normalized(),
                                "{a:?} {b:?}"
                            );
                            assert!(
                                m.points()
                                    .iter()
                                    .all(|p| p.point.is_finite() && p.depth.is_finite())
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn far_apart_pairs_give_none() {
        let pa = Isometry::IDENTITY;
        let pb = Isometry::from_translation(Vec3::new(0.0, 0.0, 10.0));
        let [
            sphere,
            cuboid,
            half_space,
            capsule,
            mesh,
            cylinder,
            ellipsoid,
            hull,
            cone,
        ] = shapes();
        for (a, b) in [
            (&cylinder, &hull),
            (&cone, &cylinder),
            (&mesh, &cone),
            (&hull, &ellipsoid),
            (&mesh, &cylinder),
            (&ellipsoid, &sphere),
            (&capsule, &capsule),
            (&capsule, &cuboid),
            (&sphere, &capsule),
            (&mesh, &capsule),
            (&sphere, &sphere),
            (&sphere, &cuboid),
            (&cuboid, &sphere),
            (&cuboid, &cuboid),
            (&mesh, &sphere),
            (&cuboid, &mesh),
            (&mesh, &mesh),
        ] {
            assert!(contact(a, &pa, b, &pb).is_none());
        }
        // A body 10 above a ground through the origin is apart; the ground above it is not.
        assert!(contact(&cuboid, &pb, &half_space, &pa).is_none());
        assert!(contact(&half_space, &pa, &sphere, &pb).is_none());
        assert!(contact(&cuboid, &pa, &half_space, &pb).is_some());
        assert!(contact(&half_space, &pa, &mesh, &pb).is_none());
        assert!(contact(&half_space, &pa, &capsule, &pb).is_none());
        assert!(contact(&mesh, &pa, &half_space, &pb).is_some());
        assert!(contact(&half_space, &pa, &hull, &pb).is_none());
        assert!(contact(&cylinder, &pa, &half_space, &pb).is_some());
        assert!(contact(&half_space, &pa, &cone, &pb).is_none());
    }
}
