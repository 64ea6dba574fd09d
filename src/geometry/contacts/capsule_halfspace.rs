//! Capsule–half-space: the deepest points of a capsule against a plane are on its two cap
//! spheres, so the pair is two sphere–half-space tests sharing the plane's normal. A capsule
//! lying on the ground gets both points and rests on them (one point would let it seesaw).

use super::contact_sphere_halfspace;
use crate::geometry::{Capsule, ContactManifold, HalfSpace, Isometry, Sphere};

/// Contact between a capsule at `pose_a` (shape A) and a half-space at `pose_b` (shape B): one
/// point per cap that reaches the plane, with the plane's inward normal.
pub fn contact_capsule_halfspace(
    pose_a: &Isometry,
    capsule: &Capsule,
    pose_b: &Isometry,
    half_space: &HalfSpace,
) -> Option<ContactManifold> {
    let (bottom, top) = capsule.segment(pose_a);
    let cap = Sphere {
        radius: capsule.radius,
    };
    let ends = [bottom, top].map(|end| contact_sphere_halfspace(end, &cap, pose_b, half_space));
    let mut out: Option<ContactManifold> = None;
    for m in ends.into_iter().flatten() {
        let manifold = out.get_or_insert(ContactManifold::new(m.normal));
        manifold.push(m.points()[0]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec3};

    #[test]
    fn a_lying_capsule_rests_on_two_points_and_a_tilted_one_on_its_lower_cap() {
        let capsule = Capsule {
            half_length: 1.0,
            radius: 0.5,
        };
        let ground = HalfSpace { normal: Vec3::Z };
        let lying = Isometry::new(
            Vec3::new(0.0, 0.0, 0.49),
            Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
        );
        let m = contact_capsule_halfspace(&lying, &capsule, &Isometry::IDENTITY, &ground).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m.normal, -Vec3::Z);
        for p in m.points() {
            assert!((p.depth - 0.01).abs() < 1e-6, "{p:?}");
        }
        let tilted = Isometry::new(Vec3::new(0.0, 0.0, 1.2), Quat::from_rotation_x(0.5));
        let m = contact_capsule_halfspace(&tilted, &capsule, &Isometry::IDENTITY, &ground).unwrap();
        assert_eq!(m.len(), 1);
        let expected = 0.5 - (1.2 - 0.5f32.cos());
        assert!((m.max_depth() - expected).abs() < 1e-6, "{m:?}");
    }
}
