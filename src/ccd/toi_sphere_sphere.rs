//! Sweep against a sphere, static or moving: the centres' distance `|m + t·d|` reaches `r_a + r_b`
//! at the smaller root of a quadratic (Ericson 2005, §5.5.5). Two moving spheres are one moving
//! against the other at rest, with the relative displacement `d_a − d_b` (Galilean invariance:
//! the gap depends only on the relative motion).

use super::swept_point::{ball_entry, unit_or};
use super::{SphereSweep, Toi};
use crate::geometry::Sphere;
use crate::geometry::contacts::contact_sphere_sphere;
use glam::Vec3;

/// Time of impact of the sweep against a static sphere centred at `center`.
pub fn toi_sphere_sphere(sweep: &SphereSweep, center: Vec3, other: &Sphere) -> Option<Toi> {
    let me = Sphere {
        radius: sweep.radius(),
    };
    // The obstacle as shape A: the manifold's normal then runs from it to the sweep, like ours.
    if let Some(m) = contact_sphere_sphere(center, other, sweep.center(), &me) {
        return sweep.initial_contact(m.normal, m.points()[0].point);
    }
    let m = sweep.center() - center;
    let d = sweep.displacement();
    let t = ball_entry(m, d, sweep.radius() + other.radius)?;
    Some(sweep.impact(t, unit_or(m + d * t, || sweep.fallback_normal())))
}

/// Time of impact of two spheres both moving during the step: `a` and `b` are their sweeps
/// (each with its own displacement over the same step). The result is seen from `a`: the normal
/// points from `b` toward `a` at impact, the point is where they touch at time `t` (with both
/// at their positions of time `t`), and `a`'s [`InitialOverlap`](super::InitialOverlap) policy
/// applies, judged on the relative displacement.
pub fn toi_spheres_moving(a: &SphereSweep, b: &SphereSweep) -> Option<Toi> {
    let relative = a.with_displacement(a.displacement() - b.displacement());
    let b_sphere = Sphere { radius: b.radius() };
    let toi = toi_sphere_sphere(&relative, b.center(), &b_sphere)?;
    // `relative` saw b at rest; at time t it has moved by t·d_b, and so has the contact.
    Some(Toi {
        point: toi.point + b.displacement() * toi.t,
        ..toi
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ccd::InitialOverlap;
    use crate::geometry::contacts::FALLBACK_NORMAL;

    #[test]
    fn head_on_and_exactly_tangent() {
        let sweep = SphereSweep::new(Vec3::new(-5.0, 0.0, 0.0), 1.0, Vec3::X * 10.0).unwrap();
        let toi = toi_sphere_sphere(&sweep, Vec3::ZERO, &Sphere { radius: 1.0 }).unwrap();
        assert!((toi.t - 0.3).abs() < 1e-7);
        assert_eq!(toi.normal, -Vec3::X);
        assert!((toi.point - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-6);
        // Passing at exactly r_a + r_b = 2 from the centre touches at the closest approach.
        let graze = SphereSweep::new(Vec3::new(-5.0, 2.0, 0.0), 0.5, Vec3::X * 10.0).unwrap();
        let toi = toi_sphere_sphere(&graze, Vec3::ZERO, &Sphere { radius: 1.5 }).unwrap();
        assert_eq!((toi.t, toi.normal), (0.5, Vec3::Y));
        assert_eq!(toi.point, Vec3::new(0.0, 1.5, 0.0));
        let gap = SphereSweep::new(Vec3::new(-5.0, 2.0f32.next_up(), 0.0), 0.5, Vec3::X * 10.0);
        assert!(toi_sphere_sphere(&gap.unwrap(), Vec3::ZERO, &Sphere { radius: 1.5 }).is_none());
    }

    #[test]
    fn starting_in_contact_and_coincident_centres() {
        let other = Sphere { radius: 1.0 };
        let touching = SphereSweep::new(Vec3::new(0.0, 2.0, 0.0), 1.0, Vec3::X).unwrap();
        let toi = toi_sphere_sphere(&touching, Vec3::ZERO, &other).unwrap();
        assert_eq!((toi.t, toi.normal), (0.0, Vec3::Y));
        let leaving = touching.with_initial_overlap(InitialOverlap::ApproachingOnly);
        assert!(toi_sphere_sphere(&leaving, Vec3::ZERO, &other).is_none());
        let coincident = SphereSweep::new(Vec3::ZERO, 0.5, Vec3::X).unwrap();
        let toi = toi_sphere_sphere(&coincident, Vec3::ZERO, &other).unwrap();
        assert_eq!(toi.t, 0.0);
        assert!(toi.normal.is_normalized() && toi.normal.abs() == FALLBACK_NORMAL);
    }

    #[test]
    fn zero_radii_and_zero_motion() {
        let point = Sphere { radius: 0.0 };
        let dead_on = SphereSweep::new(Vec3::new(-1.0, 0.0, 0.0), 0.0, Vec3::X * 2.0).unwrap();
        let toi = toi_sphere_sphere(&dead_on, Vec3::ZERO, &point).unwrap();
        assert_eq!((toi.t, toi.normal), (0.5, -Vec3::X));
        let still = SphereSweep::new(Vec3::X * 3.0, 1.0, Vec3::ZERO).unwrap();
        assert!(toi_sphere_sphere(&still, Vec3::ZERO, &Sphere { radius: 1.0 }).is_none());
    }

    #[test]
    fn two_moving_spheres_meet_where_relative_motion_says() {
        // a from x = -4 moving +4, b from x = 4 moving -4: they close 8 in a step, gap 6.
        let a = SphereSweep::new(Vec3::new(-4.0, 0.0, 0.0), 1.0, Vec3::X * 4.0).unwrap();
        let b = SphereSweep::new(Vec3::new(4.0, 0.0, 0.0), 1.0, -Vec3::X * 4.0).unwrap();
        let toi = toi_spheres_moving(&a, &b).unwrap();
        assert!((toi.t - 0.75).abs() < 1e-7);
        assert_eq!(toi.normal, -Vec3::X);
        assert!(
            toi.point.length() < 1e-6,
            "they touch at the origin: {toi:?}"
        );
        // Same velocity: they never close.
        let b_same = SphereSweep::new(Vec3::new(4.0, 0.0, 0.0), 1.0, Vec3::X * 4.0).unwrap();
        assert!(toi_spheres_moving(&a, &b_same).is_none());
        // Seen from b, the same impact with the normal flipped.
        let from_b = toi_spheres_moving(&b, &a).unwrap();
        assert_eq!(from_b.t, toi.t);
        assert_eq!(from_b.normal, -toi.normal);
        assert!((from_b.point - toi.point).length() < 1e-6);
    }
}
