//! Sweep against a capsule, exactly: the centre's segment against the capsule inflated by the
//! sweep's radius, which is again a capsule — the side of a cylinder around the inner segment
//! and a ball at each end (Ericson 2005, §5.3.7, "Intersecting ray or segment against
//! cylinder", with the end discs left to the balls that contain them).

use super::swept_point::{Earliest, Piece, ball_entry, cylinder_entry};
use super::{SphereSweep, Toi};
use crate::geometry::contacts::contact_capsule_sphere;
use crate::geometry::{Capsule, Isometry, Sphere};

/// Time of impact of the sweep against the capsule placed at `pose`.
pub fn toi_sphere_capsule(sweep: &SphereSweep, pose: &Isometry, capsule: &Capsule) -> Option<Toi> {
    let sphere = Sphere {
        radius: sweep.radius(),
    };
    // The capsule as shape A: the manifold's normal then runs from it to the sweep, like ours.
    if let Some(m) = contact_capsule_sphere(pose, capsule, sweep.center(), &sphere) {
        return sweep.initial_contact(m.normal, m.points()[0].point);
    }
    let (bottom, top) = capsule.segment(pose);
    let (o, d) = (sweep.center(), sweep.displacement());
    let reach = sweep.radius() + capsule.radius;
    let mut earliest = Earliest::before(1.0);
    let edge = top - bottom;
    if edge.length_squared() > 0.0 {
        let entry = cylinder_entry(o - bottom, d, edge, reach);
        earliest.consider(
            entry,
            Piece::Edge {
                start: bottom,
                edge,
            },
        );
    }
    for end in [bottom, top] {
        earliest.consider(ball_entry(o - end, d, reach), Piece::Vertex(end));
    }
    let hit = earliest.hit(o, d, || sweep.fallback_normal())?;
    Some(sweep.impact(hit.t, hit.normal))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ccd::{DEFAULT_MAX_ADVANCEMENT_ITERATIONS, toi_sphere_by_advancement};
    use glam::{Quat, Vec3};

    #[test]
    fn side_and_cap_hits_agree_with_conservative_advancement_within_1e_4() {
        let capsule = Capsule {
            half_length: 0.8,
            radius: 0.3,
        };
        let pose = Isometry::new(Vec3::new(0.2, -0.1, 0.4), Quat::from_rotation_x(0.7));
        let (bottom, top) = capsule.segment(&pose);
        // The solid capsule's closest point (a point inside is its own).
        let closest = |p: Vec3| {
            let d = top - bottom;
            let axis = bottom + d * ((p - bottom).dot(d) / d.length_squared()).clamp(0.0, 1.0);
            let out = p - axis;
            if out.length() <= capsule.radius {
                p
            } else {
                axis + out.normalize() * capsule.radius
            }
        };
        let (mut hits, mut misses) = (0, 0);
        for k in 0..300 {
            let a = k as f32 * 0.37;
            let start = Vec3::new(3.0 * a.cos(), 3.0 * a.sin(), (k % 7) as f32 * 0.5 - 1.5);
            let aim = Vec3::new(0.0, (k % 5) as f32 * 0.3 - 0.6, (k % 3) as f32 * 0.6 - 0.6);
            let sweep = SphereSweep::new(start, 0.2, (pose.translation + aim - start) * 2.0);
            let sweep = sweep.unwrap();
            let exact = toi_sphere_capsule(&sweep, &pose, &capsule);
            let reference =
                toi_sphere_by_advancement(&sweep, closest, DEFAULT_MAX_ADVANCEMENT_ITERATIONS);
            assert_eq!(exact.is_some(), reference.is_some(), "#{k}");
            match (exact, reference) {
                (Some(e), Some(r)) => {
                    assert!((e.t - r.t).abs() < 1e-4, "#{k}: {e:?} {r:?}");
                    assert!(e.normal.dot(r.normal) > 0.999, "#{k}: {e:?} {r:?}");
                    hits += 1;
                }
                _ => misses += 1,
            }
        }
        assert!(hits > 100 && misses > 10, "{hits} {misses}");
    }
}
