//! Sweep against an oriented box, **exactly**: the centre's segment against the box inflated by
//! the radius, a rounded box (Ericson 2005, §5.5.7, "Intersecting moving sphere against AABB").
//!
//! In the box's frame the rounded box is the union of three face slabs (the box grown by `r`
//! along one axis), twelve edge cylinders and eight corner balls, and it lies inside the box
//! grown by `r` along every axis (the *outer box*). The query:
//!
//! 1. Clip the segment to the outer box (slabs). No overlap: no hit.
//! 2. If it enters through a face of the outer box at a point whose other two coordinates lie
//!    within the box (the face's Voronoi region), that point is on the rounded box: the hit.
//! 3. Otherwise the entry is in an edge or corner region, where the outer box sticks out of the
//!    rounded one. Inside the outer box every point of a face region is in the rounded box, so the
//!    segment, if it enters at all, enters through a cylinder or a ball: the earliest entry over
//!    the edges and corners whose regions the clipped segment reaches. (Ericson tests only the
//!    edges at the entry point; a segment can leave that edge's region through a corner region
//!    into another edge's, so all reachable ones are tested here.)
//!
//! Exact up to rounding, so the brute-force and conservative-advancement tests can hold it to
//! tight tolerances.

use super::swept_point::{Earliest, Piece, PieceHit, ball_entry, cylinder_entry, segment_in_box};
use super::{SphereSweep, Toi};
use crate::geometry::contacts::contact_sphere_cuboid;
use crate::geometry::{Cuboid, Isometry, Sphere};
use glam::Vec3;

/// Time of impact of the sweep against the box `cuboid` placed at `pose`.
pub fn toi_sphere_cuboid(sweep: &SphereSweep, pose: &Isometry, cuboid: &Cuboid) -> Option<Toi> {
    let sphere = Sphere {
        radius: sweep.radius(),
    };
    if let Some(m) = contact_sphere_cuboid(sweep.center(), &sphere, pose, cuboid) {
        return sweep.initial_contact(-m.normal, m.points()[0].point);
    }
    let local = sweep.in_frame(pose);
    let hit = rounded_box_entry(&local, cuboid.half_extents)?;
    Some(sweep.impact(hit.t, pose.transform_vector(hit.normal)))
}

/// First entry of the local sweep's centre into the box `[-h, h]` inflated by the radius.
fn rounded_box_entry(sweep: &SphereSweep, h: Vec3) -> Option<PieceHit> {
    let (o, d, r) = (sweep.center(), sweep.displacement(), sweep.radius());
    let span = segment_in_box(o, d, h + Vec3::splat(r))?;
    if let Some((axis, sign)) = span.entry {
        let q = o + d * span.t_in;
        let slack = sweep.slack();
        let (i, j) = other_axes(axis);
        if q[i].abs() <= h[i] + slack && q[j].abs() <= h[j] + slack {
            let mut normal = Vec3::ZERO;
            normal[axis] = sign;
            return Some(PieceHit {
                t: span.t_in,
                normal,
                on_face: true,
            });
        }
    }
    let (q_in, q_out) = (o + d * span.t_in, o + d * span.t_out);
    let reach = Reach {
        high: q_in.max(q_out).cmpge(h),
        low: q_in.min(q_out).cmple(-h),
    };
    let mut earliest = Earliest::before(1.0);
    edges_entry(sweep, h, &reach, &mut earliest);
    corners_entry(sweep, h, &reach, &mut earliest);
    earliest.hit(o, d, || sweep.fallback_normal())
}

/// On which axes the clipped segment reaches beyond the box's high and low faces: an edge or
/// corner matters only if the segment reaches its region.
struct Reach {
    high: glam::BVec3,
    low: glam::BVec3,
}

impl Reach {
    /// True when the segment reaches the side `sign` (±1) of axis `i`.
    fn side(&self, i: usize, sign: f32) -> bool {
        if sign > 0.0 {
            self.high.test(i)
        } else {
            self.low.test(i)
        }
    }
}

/// The two axes other than `axis`, in increasing order.
fn other_axes(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

const SIGNS: [f32; 2] = [1.0, -1.0];

/// Entries through the sides of the edge cylinders. Edges in the order: axis x, y, z; for
/// each, signs of the other two axes (+,+), (+,−), (−,+), (−,−). Edges of zero length (a flat
/// box) have no side: their end balls cover them.
fn edges_entry(sweep: &SphereSweep, h: Vec3, reach: &Reach, earliest: &mut Earliest) {
    let (o, d, r) = (sweep.center(), sweep.displacement(), sweep.radius());
    for k in 0..3 {
        if h[k] <= 0.0 {
            continue;
        }
        let (i, j) = other_axes(k);
        for si in SIGNS {
            for sj in SIGNS {
                if !(reach.side(i, si) && reach.side(j, sj)) {
                    continue;
                }
                let mut start = Vec3::ZERO;
                start[i] = si * h[i];
                start[j] = sj * h[j];
                start[k] = -h[k];
                let edge = Vec3::AXES[k] * (2.0 * h[k]);
                let t = cylinder_entry(o - start, d, edge, r);
                earliest.consider(t, Piece::Edge { start, edge });
            }
        }
    }
}

/// Entries into the corner balls, corners in the order of their sign bits (x, y, z).
fn corners_entry(sweep: &SphereSweep, h: Vec3, reach: &Reach, earliest: &mut Earliest) {
    let (o, d, r) = (sweep.center(), sweep.displacement(), sweep.radius());
    for bits in 0..8 {
        let signs = Vec3::new(
            SIGNS[bits & 1],
            SIGNS[(bits >> 1) & 1],
            SIGNS[(bits >> 2) & 1],
        );
        if !(0..3).all(|i| reach.side(i, signs[i])) {
            continue;
        }
        let corner = signs * h;
        earliest.consider(ball_entry(o - corner, d, r), Piece::Vertex(corner));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ccd::InitialOverlap;
    use glam::Quat;

    fn unit() -> Cuboid {
        Cuboid {
            half_extents: Vec3::ONE,
        }
    }

    fn sweep(c: Vec3, r: f32, d: Vec3) -> SphereSweep {
        SphereSweep::new(c, r, d).unwrap()
    }

    #[test]
    fn face_edge_and_corner_hits_match_analytic_times() {
        let pose = Isometry::IDENTITY;
        // Face: from x = 5 toward the +x face, touching when x = 1.5.
        let face = toi_sphere_cuboid(
            &sweep(Vec3::new(5.0, 0.3, -0.2), 0.5, -Vec3::X * 7.0),
            &pose,
            &unit(),
        );
        let face = face.unwrap();
        assert!((face.t - 0.5).abs() < 1e-6 && face.normal == Vec3::X);
        // Edge: moving along -x at y = 1.3 (above the +y face), z = 0, with r = 0.5: the sphere
        // touches the edge (x, y) = (1, 1) when (x − 1)² + 0.3² = 0.25, x = 1.4.
        let edge = toi_sphere_cuboid(
            &sweep(Vec3::new(5.0, 1.3, 0.0), 0.5, -Vec3::X * 8.0),
            &pose,
            &unit(),
        );
        let edge = edge.unwrap();
        assert!((edge.t - 3.6 / 8.0).abs() < 1e-6, "{edge:?}");
        assert!((edge.normal - Vec3::new(0.4, 0.3, 0.0) / 0.5).length() < 1e-6);
        // Corner: along the diagonal toward (1, 1, 1).
        let dir = -Vec3::ONE.normalize();
        let start = Vec3::ONE + Vec3::ONE.normalize() * 3.0;
        let corner = toi_sphere_cuboid(&sweep(start, 0.5, dir * 5.0), &pose, &unit()).unwrap();
        assert!((corner.t - 2.5 / 5.0).abs() < 1e-6, "{corner:?}");
        assert!((corner.normal + dir).length() < 1e-6);
        assert!((corner.point - Vec3::ONE).length() < 1e-5);
    }

    #[test]
    fn segment_leaving_one_edge_region_for_another_through_a_corner_region() {
        // Enters the outer box in the region of the edge (x = 1, y = 1) and travels through the
        // corner region into the region of the edge (x = 1, z = 1), where it touches first.
        let pose = Isometry::IDENTITY;
        let r = 0.5;
        let start = Vec3::new(1.4, 1.45, 0.3);
        let d = Vec3::new(0.0, -0.6, 1.2);
        let toi = toi_sphere_cuboid(&sweep(start, r, d), &pose, &unit());
        // Reference: the distance to the box first drops to r along the segment.
        let dist = |t: f32| {
            let c = start + d * t;
            (c - c.clamp(-Vec3::ONE, Vec3::ONE)).length()
        };
        let first = (0..=100_000)
            .map(|i| i as f32 / 100_000.0)
            .find(|&t| dist(t) <= r);
        match (toi, first) {
            (Some(toi), Some(reference)) => assert!((toi.t - reference).abs() < 1e-4),
            (None, None) => {}
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn rotated_box_zero_radius_and_parallel_motion() {
        let pose = Isometry::new(Vec3::new(1.0, 2.0, 3.0), Quat::from_rotation_z(0.7));
        let normal = pose.transform_vector(Vec3::X);
        let c0 = pose.transform_point(Vec3::new(4.0, 0.2, 0.1));
        let ray = toi_sphere_cuboid(&sweep(c0, 0.0, -normal * 6.0), &pose, &unit()).unwrap();
        assert!((ray.t - 0.5).abs() < 1e-6 && (ray.normal - normal).length() < 1e-6);
        // Parallel to the +y face, just above it: never touches.
        let above = pose.transform_point(Vec3::new(-4.0, 1.5 + 1e-3, 0.0));
        let along = pose.transform_vector(Vec3::X * 8.0);
        assert!(toi_sphere_cuboid(&sweep(above, 0.5, along), &pose, &unit()).is_none());
        // At exactly r above it: grazes from the moment it reaches the edge (x = -1), t = 3/8.
        let graze = sweep(Vec3::new(-4.0, 1.5, 0.0), 0.5, Vec3::X * 8.0);
        let toi = toi_sphere_cuboid(&graze, &Isometry::IDENTITY, &unit()).unwrap();
        assert_eq!((toi.t, toi.normal), (0.375, Vec3::Y));
        // Already on it (touching): a contact at t = 0.
        let on = Vec3::new(-0.5, 1.5, 0.0);
        let toi = toi_sphere_cuboid(&sweep(on, 0.5, Vec3::X * 8.0), &Isometry::IDENTITY, &unit());
        let toi = toi.unwrap();
        assert_eq!((toi.t, toi.normal), (0.0, Vec3::Y));
    }

    #[test]
    fn starting_inside_and_zero_size_box() {
        let inside = sweep(Vec3::new(0.5, 0.0, 0.0), 0.25, Vec3::X);
        let toi = toi_sphere_cuboid(&inside, &Isometry::IDENTITY, &unit()).unwrap();
        assert_eq!((toi.t, toi.normal), (0.0, Vec3::X));
        let leaving = inside.with_initial_overlap(InitialOverlap::ApproachingOnly);
        assert!(toi_sphere_cuboid(&leaving, &Isometry::IDENTITY, &unit()).is_none());
        let point_box = Cuboid {
            half_extents: Vec3::ZERO,
        };
        let toi = toi_sphere_cuboid(
            &sweep(Vec3::new(-3.0, 0.0, 0.0), 1.0, Vec3::X * 4.0),
            &Isometry::IDENTITY,
            &point_box,
        );
        let toi = toi.unwrap();
        assert!(
            (toi.t - 0.5).abs() < 1e-6 && toi.normal == -Vec3::X,
            "{toi:?}"
        );
    }
}
