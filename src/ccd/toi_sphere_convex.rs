//! Time of impact of a swept sphere against a cylinder, ellipsoid or hull: conservative
//! advancement (`advancement.rs`) on the GJK distance between the ball and the shape, which a
//! ball moving by `|d|` per unit of `t` cannot close faster than `|d|`. Never late: the answer
//! is the first contact from below.

use super::advancement::{
    Advancement, DEFAULT_MAX_ADVANCEMENT_ITERATIONS, conservative_advancement,
};
use super::{InitialOverlap, SphereSweep, Toi};
use crate::geometry::convex::signed_distance;
use crate::geometry::{Isometry, Shape};

/// Time of impact of `sweep` against the convex `shape` at `pose` (static); `None` when it is
/// missed, or `shape` is not convex.
pub fn toi_sphere_convex(sweep: &SphereSweep, shape: &Shape, pose: &Isometry) -> Option<Toi> {
    let ball = Shape::sphere(sweep.radius());
    let gap = |t: f32| {
        let at = Isometry::from_translation(sweep.position_at(t));
        signed_distance(shape, pose, &ball, &at)
    };
    gap(0.0)?;
    let outcome = conservative_advancement(
        |t| gap(t).map_or(0.0, |d| d.distance),
        sweep.displacement().length(),
        sweep.tolerance(),
        DEFAULT_MAX_ADVANCEMENT_ITERATIONS,
    );
    let t = match outcome {
        Advancement::Contact { t, .. } | Advancement::Unresolved { t } => t,
        Advancement::NoContact { .. } => return None,
    };
    let d = gap(t)?;
    let skip = t == 0.0
        && sweep.initial_overlap() == InitialOverlap::ApproachingOnly
        && sweep.displacement().dot(d.normal) >= 0.0;
    // At an impact the surfaces meet (on_a is on both); a contact already at the start takes
    // the midpoint between the surfaces, as the static tests do.
    let point = if t > 0.0 {
        d.on_a
    } else {
        (d.on_a + d.on_b) * 0.5
    };
    (!skip).then_some(Toi {
        t,
        normal: d.normal,
        point,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn ball_dropped_on_a_cylinder_hits_its_cap_within_1e_4() {
        let cylinder = Shape::cylinder(0.5, 1.0);
        let sweep = SphereSweep::new(Vec3::new(0.3, 0.0, 3.0), 0.25, Vec3::new(0.0, 0.0, -4.0));
        let toi = toi_sphere_convex(&sweep.unwrap(), &cylinder, &Isometry::IDENTITY).unwrap();
        // The ball's bottom meets the cap at z = 0.5: its centre at 0.75, t = 2.25 / 4.
        assert!((toi.t - 2.25 / 4.0).abs() < 1e-4, "{toi:?}");
        assert!(toi.normal.dot(Vec3::Z) > 0.9999);
        let miss = SphereSweep::new(Vec3::new(3.0, 0.0, 3.0), 0.25, Vec3::new(0.0, 0.0, -4.0));
        assert!(toi_sphere_convex(&miss.unwrap(), &cylinder, &Isometry::IDENTITY).is_none());
    }
}
