//! Shape-pair contact tests (the narrow phase for primitives), one file per pair as in parry's
//! `query/contact/contact_<shape1>_<shape2>.rs`, and [`contact`], which dispatches on the pair.
//!
//! Every test follows the conventions of [`ContactManifold`]: normal from A to B, touching counts
//! (depth 0), and degenerate input (coincident centres, zero-size shapes) gives a finite normal
//! chosen by a documented rule, never NaN.
//!
//! # The pairs
//!
//! | A \ B         | `Sphere`                      | `Cuboid`                          | `HalfSpace`                   |
//! |---------------|-------------------------------|-----------------------------------|-------------------------------|
//! | **Sphere**    | [`contact_sphere_sphere`]     | [`contact_sphere_cuboid`]         | [`contact_sphere_halfspace`]  |
//! | **Cuboid**    | sphere–cuboid, flipped        | [`contact_cuboid_cuboid`] (SAT)   | [`contact_cuboid_halfspace`]  |
//! | **HalfSpace** | sphere–half-space, flipped    | cuboid–half-space, flipped        | `None` (both static, infinite) |
//!
//! "Flipped" means the test runs with the arguments swapped and the manifold is turned around
//! with [`ContactManifold::flipped`] (normal negated, points unchanged). Box–box puts its two
//! boxes in a canonical order the same way, so for every pair `contact(a, b)` and
//! `contact(b, a)` report opposite normals and equal depths (but for the one exception below).
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

mod closest_segment_points;
mod cuboid_cuboid;
mod cuboid_halfspace;
mod manifold_reduction;
mod polygon_clip;
mod sphere_cuboid;
mod sphere_halfspace;
mod sphere_sphere;

pub use cuboid_cuboid::contact_cuboid_cuboid;
pub use cuboid_halfspace::contact_cuboid_halfspace;
pub use sphere_cuboid::contact_sphere_cuboid;
pub use sphere_halfspace::contact_sphere_halfspace;
pub use sphere_sphere::contact_sphere_sphere;

use crate::geometry::{ContactManifold, Isometry, Shape};
use glam::Vec3;

/// The normal used when the geometry defines none (coincident centres): world up, +Z, the
/// slides' vertical. Deterministic, so a stack of coincident bodies separates the same way on
/// every run.
pub const FALLBACK_NORMAL: Vec3 = Vec3::Z;

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
pub fn contact(
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
        (Cuboid(_), Sphere(_)) | (HalfSpace(_), Sphere(_)) | (HalfSpace(_), Cuboid(_)) => {
            contact(b, pose_b, a, pose_a).map(ContactManifold::flipped)
        }
        (HalfSpace(_), HalfSpace(_)) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn shapes() -> [Shape; 3] {
        [
            Shape::sphere(0.7),
            Shape::cuboid(Vec3::new(0.5, 0.8, 0.3)),
            Shape::half_space(Vec3::new(0.1, 0.2, 1.0)),
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
            ];
            for a in shapes().iter().chain(&bad_shapes) {
                for b in shapes().iter().chain(&bad_shapes) {
                    for pose in &poses {
                        let _ = contact(a, pose, b, &good);
                        let _ = contact(a, &good, b, pose);
                    }
                    let _ = contact(a, &good, b, &good);
                }
            }
        }
    }

    #[test]
    fn far_apart_pairs_give_none() {
        let pa = Isometry::IDENTITY;
        let pb = Isometry::from_translation(Vec3::new(0.0, 0.0, 10.0));
        let [sphere, cuboid, half_space] = shapes();
        for (a, b) in [
            (&sphere, &sphere),
            (&sphere, &cuboid),
            (&cuboid, &sphere),
            (&cuboid, &cuboid),
        ] {
            assert!(contact(a, &pa, b, &pb).is_none());
        }
        // A body 10 above a ground through the origin is apart; the ground above it is not.
        assert!(contact(&cuboid, &pb, &half_space, &pa).is_none());
        assert!(contact(&half_space, &pa, &sphere, &pb).is_none());
        assert!(contact(&cuboid, &pa, &half_space, &pb).is_some());
    }
}
