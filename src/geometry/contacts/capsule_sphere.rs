//! Capsule–sphere: a capsule is a sphere swept along a segment, so the pair is the slides'
//! sphere–sphere test from the segment's point closest to the ball's centre (Ericson 2005,
//! *Real-Time Collision Detection* §5.1.2 for the closest point).

use super::closest_segment_points::closest_point_on_segment;
use super::contact_sphere_sphere;
use crate::geometry::{Capsule, ContactManifold, Isometry, Sphere};
use glam::Vec3;

/// Contact between a capsule at `pose` (shape A) and a sphere centred at `center` (shape B).
///
/// A centre on the capsule's segment gives the sphere–sphere fallback (see
/// [`contact_sphere_sphere`]).
pub fn contact_capsule_sphere(
    pose: &Isometry,
    capsule: &Capsule,
    center: Vec3,
    sphere: &Sphere,
) -> Option<ContactManifold> {
    let (bottom, top) = capsule.segment(pose);
    let nearest = closest_point_on_segment(bottom, top, center);
    let cap = Sphere {
        radius: capsule.radius,
    };
    contact_sphere_sphere(nearest, &cap, center, sphere)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn side_and_cap_contacts_are_exact_to_1e_6() {
        let capsule = Capsule {
            half_length: 1.0,
            radius: 0.5,
        };
        // Lying along x (z turned onto x), a ball beside its middle and one past its end.
        let pose = Isometry::new(
            Vec3::ZERO,
            Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        );
        let ball = Sphere { radius: 0.25 };
        let side = contact_capsule_sphere(&pose, &capsule, Vec3::new(0.3, 0.7, 0.0), &ball);
        let side = side.unwrap();
        assert!((side.normal - Vec3::Y).length() < 1e-6);
        assert!((side.max_depth() - 0.05).abs() < 1e-6);
        let end = contact_capsule_sphere(&pose, &capsule, Vec3::new(1.7, 0.0, 0.0), &ball);
        assert!((end.unwrap().normal - Vec3::X).length() < 1e-6);
        assert!(
            contact_capsule_sphere(&pose, &capsule, Vec3::new(1.76, 0.0, 0.0), &ball).is_none()
        );
    }
}
