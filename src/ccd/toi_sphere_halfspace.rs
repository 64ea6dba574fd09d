//! Sweep against a half-space (grounds, walls): the signed distance of the centre to the plane is
//! linear in `t`, so the impact is one division (Ericson 2005, §5.5.3).

use super::{SphereSweep, Toi};
use crate::geometry::contacts::contact_sphere_halfspace;
use crate::geometry::{HalfSpace, Isometry, Sphere};

/// Time of impact of the sweep against the half-space `h` placed at `pose`.
///
/// The centre's height above the plane is `s(t) = s0 + t·(n·d)`; the sphere touches when
/// `s(t) = r`. Moving parallel to the plane or away from it (`n·d >= 0`) never hits.
pub fn toi_sphere_halfspace(sweep: &SphereSweep, pose: &Isometry, h: &HalfSpace) -> Option<Toi> {
    let sphere = Sphere {
        radius: sweep.radius(),
    };
    if let Some(m) = contact_sphere_halfspace(sweep.center(), &sphere, pose, h) {
        // The manifold's normal runs from the sphere to the plane; ours the other way.
        return sweep.initial_contact(-m.normal, m.points()[0].point);
    }
    let n = pose.transform_vector(h.normal);
    let height = n.dot(sweep.center() - pose.translation) - sweep.radius();
    let closing = -n.dot(sweep.displacement());
    if closing.is_nan() || closing <= 0.0 {
        return None;
    }
    // height > 0 (no contact at the start) and closing > 0, so t > 0.
    let t = height / closing;
    (t <= 1.0).then(|| sweep.impact(t, n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ccd::InitialOverlap;
    use glam::{Quat, Vec3};

    fn ground() -> HalfSpace {
        HalfSpace {
            normal: glam::Vec3::Z,
        }
    }

    #[test]
    fn falling_ball_hits_at_its_radius_above_a_tilted_plane() {
        let pose = Isometry::new(Vec3::new(0.0, 0.0, 1.0), Quat::from_rotation_x(0.4));
        let n = pose.transform_vector(Vec3::Z);
        let c0 = pose.translation + n * 3.0 + Vec3::X * 2.0;
        let sweep = SphereSweep::new(c0, 0.5, -n * 5.0).unwrap();
        let toi = toi_sphere_halfspace(&sweep, &pose, &ground()).unwrap();
        assert!((toi.t - 0.5).abs() < 1e-6, "{toi:?}");
        assert!((toi.normal - n).length() < 1e-6);
        let on_plane = n.dot(toi.point - pose.translation);
        assert!(on_plane.abs() < 1e-5);
    }

    #[test]
    fn parallel_away_short_and_exactly_at_the_end() {
        let pose = Isometry::IDENTITY;
        let above = Vec3::new(0.0, 0.0, 2.0);
        let parallel = SphereSweep::new(above, 1.0, Vec3::X * 100.0).unwrap();
        assert!(toi_sphere_halfspace(&parallel, &pose, &ground()).is_none());
        let away = SphereSweep::new(above, 1.0, Vec3::Z).unwrap();
        assert!(toi_sphere_halfspace(&away, &pose, &ground()).is_none());
        let short = SphereSweep::new(above, 1.0, -Vec3::Z * 0.99).unwrap();
        assert!(toi_sphere_halfspace(&short, &pose, &ground()).is_none());
        let exact = SphereSweep::new(above, 1.0, -Vec3::Z).unwrap();
        assert_eq!(
            toi_sphere_halfspace(&exact, &pose, &ground()).unwrap().t,
            1.0
        );
        let still = SphereSweep::new(above, 1.0, Vec3::ZERO).unwrap();
        assert!(toi_sphere_halfspace(&still, &pose, &ground()).is_none());
    }

    #[test]
    fn starting_in_contact_follows_the_policy() {
        let pose = Isometry::IDENTITY;
        let resting = Vec3::new(0.0, 0.0, 1.0);
        let sliding = SphereSweep::new(resting, 1.0, Vec3::X).unwrap();
        let toi = toi_sphere_halfspace(&sliding, &pose, &ground()).unwrap();
        assert_eq!((toi.t, toi.normal, toi.point), (0.0, Vec3::Z, Vec3::ZERO));
        let approaching_only = sliding.with_initial_overlap(InitialOverlap::ApproachingOnly);
        assert!(toi_sphere_halfspace(&approaching_only, &pose, &ground()).is_none());
        let sinking = SphereSweep::new(resting, 1.0, -Vec3::Z)
            .unwrap()
            .with_initial_overlap(InitialOverlap::ApproachingOnly);
        assert_eq!(
            toi_sphere_halfspace(&sinking, &pose, &ground()).unwrap().t,
            0.0
        );
    }
}
