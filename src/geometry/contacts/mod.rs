//! Shape-pair contact tests (the narrow phase for primitives), one file per pair as in parry's
//! `query/contact/contact_<shape1>_<shape2>.rs`, and [`contact`], which dispatches on the pair.
//!
//! Every test follows the conventions of [`ContactManifold`]: normal from A to B, touching counts
//! (depth 0), and degenerate input (coincident centres, zero-size shapes) gives a finite normal
//! chosen by a documented rule, never NaN.

mod sphere_halfspace;
mod sphere_sphere;

pub use sphere_halfspace::contact_sphere_halfspace;
pub use sphere_sphere::contact_sphere_sphere;

use crate::geometry::{ContactManifold, Isometry, Shape};
use glam::Vec3;

/// The normal used when the geometry defines none (coincident centres): world up, +Z, the
/// slides' vertical. Deterministic, so a stack of coincident bodies separates the same way on
/// every run.
pub const FALLBACK_NORMAL: Vec3 = Vec3::Z;

/// Contact between shape `a` at `pose_a` and shape `b` at `pose_b`, or `None` when they are
/// apart. `None` is also returned for pairs no test covers (two half-spaces).
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
        (Sphere(s), HalfSpace(h)) => contact_sphere_halfspace(pose_a.translation, s, pose_b, h),
        (HalfSpace(_), Sphere(_)) => contact(b, pose_b, a, pose_a).map(ContactManifold::flipped),
        _ => None,
    }
}
