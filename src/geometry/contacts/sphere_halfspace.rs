//! Sphere–half-space: the ball on the ground of the slides' bouncing example.

use crate::geometry::{ContactManifold, HalfSpace, Isometry, Sphere};
use glam::Vec3;

/// Contact between a sphere centred at `c` (shape A) and a half-space at `pose` (shape B).
///
/// The normal from A to B is the plane's inward normal `-n`; the depth is `r - signed distance`.
pub fn contact_sphere_halfspace(
    c: Vec3,
    s: &Sphere,
    pose: &Isometry,
    h: &HalfSpace,
) -> Option<ContactManifold> {
    let n = pose.transform_vector(h.normal);
    let signed_distance = n.dot(c - pose.translation);
    let depth = s.radius - signed_distance;
    if depth < 0.0 {
        return None;
    }
    let on_sphere = c - n * s.radius;
    let on_plane = c - n * signed_distance;
    Some(ContactManifold::single(
        -n,
        (on_sphere + on_plane) * 0.5,
        depth,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn ball_resting_on_a_tilted_ground() {
        let pose = Isometry::new(Vec3::new(0.0, 0.0, 1.0), Quat::from_rotation_x(0.3));
        let h = HalfSpace { normal: Vec3::Z };
        let n = pose.transform_vector(Vec3::Z);
        let s = Sphere { radius: 0.5 };
        let c = pose.translation + n * 0.4;
        let m = contact_sphere_halfspace(c, &s, &pose, &h).unwrap();
        assert!((m.normal + n).length() < 1e-6);
        assert!((m.max_depth() - 0.1).abs() < 1e-5);
        assert!(contact_sphere_halfspace(pose.translation + n * 0.6, &s, &pose, &h).is_none());
    }
}
