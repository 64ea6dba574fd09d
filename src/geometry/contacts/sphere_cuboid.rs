//! Sphere–cuboid: the closest point of an oriented box to the sphere's centre (Arvo 1990,
//! "A simple method for box-sphere intersection testing"; Ericson 2005, *Real-Time Collision
//! Detection* §5.1.4), computed in the box's frame where the box is an AABB and the closest point
//! is a per-axis clamp.
//!
//! When the centre is inside the box the closest point is the centre itself and defines no
//! normal, so the sphere is pushed out through the face of least penetration instead.
//!
//! The centre is brought into the box's frame in double precision. In single precision its
//! coordinates there are rounded to the spacing of the box's own size (a ball resting on a 20 m
//! thick ground, 10 m above the ground's centre, read its height to 1 µm, sixteen times
//! coarser than its position), and a resting body answered that rounding by creeping one ulp
//! a step and jumping back, never at rest; world coordinates would instead lose what a scene
//! far from the origin has (the centre and the box there differ by a short, exact vector).
//! The difference of two `f32` vectors is exact in `f64`, so the distance comes out as
//! precise as the separation itself, whatever the box's size or the scene's place.

use super::{FALLBACK_NORMAL, prefer_towards_fallback};
use crate::geometry::{ContactManifold, Cuboid, Isometry, Sphere};
use glam::Vec3;

/// Contact between a sphere centred at `c` (shape A) and a box at `pose` (shape B).
///
/// - Centre outside the box: the normal runs from the centre to its closest point on the box,
///   and the depth is `radius - distance`.
/// - Centre inside (or on) the box: the normal is the inward normal of the nearest face (the
///   sphere leaves through it), and the depth is `radius + distance to that face`. Equally near
///   faces (the centre at the box's centre, a zero-size box) go to the face whose normal is
///   closest to [`FALLBACK_NORMAL`], then to the first in the order +x, −x, +y, −y, +z, −z.
pub fn contact_sphere_cuboid(
    c: Vec3,
    s: &Sphere,
    pose: &Isometry,
    b: &Cuboid,
) -> Option<ContactManifold> {
    let to_box = pose.rotation.inverse().as_dquat();
    let local = to_box * (c.as_dvec3() - pose.translation.as_dvec3());
    let h = b.half_extents.as_dvec3();
    let offset = local - local.clamp(-h, h);
    let dist2 = offset.length_squared();
    let radius = f64::from(s.radius);
    if dist2 > radius * radius {
        return None;
    }
    // Below the smallest normal float the offset cannot be normalised reliably: such a centre
    // is on the surface for every practical purpose, and the face rule gives it a clean normal.
    if dist2 >= f64::from(f32::MIN_POSITIVE) {
        let dist = dist2.sqrt();
        let normal = pose.transform_vector((-offset / dist).as_vec3());
        Some(sphere_contact(c, s.radius, normal, dist as f32))
    } else {
        let (local_normal, gap) = nearest_face_push(local.as_vec3(), b.half_extents, pose);
        let normal = pose.transform_vector(local_normal);
        Some(sphere_contact(c, s.radius, normal, -gap))
    }
}

/// For a centre `p` inside the box of half extents `h`: the normal from the sphere to the box
/// (the inward normal of the nearest face, in the box frame) and the distance to that face.
fn nearest_face_push(p: Vec3, h: Vec3, pose: &Isometry) -> (Vec3, f32) {
    let up = pose.inverse_transform_vector(FALLBACK_NORMAL);
    // Starts on the first face's normal so that even NaN input leaves a unit normal.
    let mut best = (-Vec3::X, f32::INFINITY, f32::NEG_INFINITY);
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            // The sphere leaves through the face of outward normal `sign * e_axis`, so the box
            // lies the other way: the normal from A (sphere) to B (box) is `-sign * e_axis`.
            let gap = (h[axis] - sign * p[axis]).max(0.0);
            let up_component = -sign * up[axis];
            let better =
                gap < best.1 || (gap == best.1 && prefer_towards_fallback(up_component, best.2));
            if better {
                best = (-sign * Vec3::AXES[axis], gap, up_component);
            }
        }
    }
    (best.0, best.1)
}

/// The one-point manifold of a sphere (centre `c`, radius `r`) whose surface along `normal`
/// lies at signed distance `surface_distance` from the centre of the other shape's surface
/// (positive: outside, negative: the centre is inside the other shape).
fn sphere_contact(c: Vec3, r: f32, normal: Vec3, surface_distance: f32) -> ContactManifold {
    let on_sphere = c + normal * r;
    let on_box = c + normal * surface_distance;
    ContactManifold::single(
        normal,
        (on_sphere + on_box) * 0.5,
        (r - surface_distance).max(0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn unit_box() -> Cuboid {
        Cuboid {
            half_extents: Vec3::ONE,
        }
    }

    #[test]
    fn face_edge_and_corner_regions_match_analytic_distances() {
        let s = Sphere { radius: 1.0 };
        let pose = Isometry::IDENTITY;
        let face = contact_sphere_cuboid(Vec3::new(1.5, 0.2, -0.3), &s, &pose, &unit_box());
        let face = face.unwrap();
        assert_eq!(face.normal, -Vec3::X);
        assert!((face.max_depth() - 0.5).abs() < 1e-6);
        assert!((face.points()[0].point - Vec3::new(0.75, 0.2, -0.3)).length() < 1e-6);

        let c = Vec3::new(1.3, 1.4, 0.0);
        let edge = contact_sphere_cuboid(c, &s, &pose, &unit_box()).unwrap();
        let d = Vec3::new(0.3, 0.4, 0.0);
        assert!((edge.normal + d / 0.5).length() < 1e-6);
        assert!((edge.max_depth() - 0.5).abs() < 1e-6);

        let corner = Vec3::ONE + Vec3::splat(0.5);
        let m = contact_sphere_cuboid(corner, &s, &pose, &unit_box()).unwrap();
        assert!((m.normal + Vec3::ONE.normalize()).length() < 1e-6);
        assert!((m.max_depth() - (1.0 - 0.75f32.sqrt())).abs() < 1e-6);
    }

    #[test]
    fn touching_counts_and_one_ulp_apart_does_not() {
        let s = Sphere { radius: 1.0 };
        let pose = Isometry::IDENTITY;
        let touching = contact_sphere_cuboid(Vec3::new(2.0, 0.5, 0.0), &s, &pose, &unit_box());
        assert_eq!(touching.unwrap().max_depth(), 0.0);
        let gap = Vec3::new(2.0f32.next_up(), 0.5, 0.0);
        assert!(contact_sphere_cuboid(gap, &s, &pose, &unit_box()).is_none());
        // A point (zero-radius sphere) on the surface touches; a point just off it does not.
        let point = Sphere { radius: 0.0 };
        let on_face = contact_sphere_cuboid(Vec3::new(0.2, 1.0, 0.3), &point, &pose, &unit_box());
        let on_face = on_face.unwrap();
        assert_eq!((on_face.normal, on_face.max_depth()), (-Vec3::Y, 0.0));
        let off = Vec3::new(0.2, 1.0f32.next_up(), 0.3);
        assert!(contact_sphere_cuboid(off, &point, &pose, &unit_box()).is_none());
    }

    #[test]
    fn the_gap_to_a_face_of_a_box_up_to_80_m_is_within_1e_7_m_of_the_f64_plane_distance() {
        // Spheres over a face of large, turned boxes anywhere within 1 km of the origin (centres
        // outside, in front of the face): the gap is read to the sphere's own precision, not
        // to the box's size. An independent oracle: the face plane's distance `n·(c − t) − h`
        // in f64. Single precision in the box's frame erred by up to 5.9e-6 m here.
        let mut rng = crate::test_rng::TestRng::new(5);
        let mut worst = 0.0f64;
        for _ in 0..2000 {
            let h = rng.vec3(0.5, 40.0);
            let pose = Isometry::new(rng.vec3(-1000.0, 1000.0), rng.rotation());
            let axis = rng.below(3) as usize;
            let sign = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
            // A point on the face, inside its rim, then out along its normal.
            let mut on_face = rng.vec3(-1.0, 1.0) * h * 0.9;
            on_face[axis] = sign * h[axis];
            let radius = rng.range(0.05, 1.0);
            let gap = rng.range(0.0, 1.0) * radius;
            let outward = pose.transform_vector(Vec3::AXES[axis] * sign);
            let c = pose.transform_point(on_face) + outward * gap;
            let Some(m) =
                contact_sphere_cuboid(c, &Sphere { radius }, &pose, &Cuboid { half_extents: h })
            else {
                continue;
            };
            let n = pose.rotation.as_dquat() * (Vec3::AXES[axis] * sign).as_dvec3();
            let plane = n.dot(c.as_dvec3() - pose.translation.as_dvec3()) - f64::from(h[axis]);
            let depth = f64::from(radius) - plane;
            worst = worst.max((f64::from(m.max_depth()) - depth).abs());
        }
        assert!(worst < 1e-7, "worst depth error {worst} m");
    }

    #[test]
    fn centre_inside_leaves_through_the_nearest_face() {
        let s = Sphere { radius: 0.25 };
        let b = Cuboid {
            half_extents: Vec3::new(2.0, 1.0, 3.0),
        };
        let pose = Isometry::new(Vec3::new(1.0, 2.0, 3.0), Quat::from_rotation_z(0.5));
        // 0.25 inside the box's local -y face: nearest face is -y (gap 0.25 < every other).
        let c = pose.transform_point(Vec3::new(0.5, -0.75, 1.0));
        let m = contact_sphere_cuboid(c, &s, &pose, &b).unwrap();
        let inward = pose.transform_vector(Vec3::Y);
        assert!((m.normal - inward).length() < 1e-5);
        assert!((m.max_depth() - 0.5).abs() < 1e-5);
    }

    #[test]
    fn centre_at_box_centre_and_zero_size_box_are_deterministic_and_finite() {
        let s = Sphere { radius: 0.5 };
        // A cube centred on the sphere: six faces tie; the one whose push is up wins.
        let m = contact_sphere_cuboid(Vec3::ZERO, &s, &Isometry::IDENTITY, &unit_box()).unwrap();
        assert_eq!(m.normal, FALLBACK_NORMAL);
        assert_eq!(m.max_depth(), 1.5);
        // Rotated box: still the face closest to up, i.e. the largest normal.z among the six.
        let pose = Isometry::new(Vec3::ZERO, Quat::from_rotation_x(0.3));
        let m = contact_sphere_cuboid(Vec3::ZERO, &s, &pose, &unit_box()).unwrap();
        let best_up = (0..3)
            .map(|i| pose.transform_vector(Vec3::AXES[i]).z.abs())
            .fold(0.0, f32::max);
        assert!((m.normal.z - best_up).abs() < 1e-6);
        // A zero-size box at the centre of a zero-size sphere: a point on a point.
        let point_box = Cuboid {
            half_extents: Vec3::ZERO,
        };
        let point = Sphere { radius: 0.0 };
        let m = contact_sphere_cuboid(
            Vec3::ONE,
            &point,
            &Isometry::from_translation(Vec3::ONE),
            &point_box,
        )
        .unwrap();
        assert!(m.normal.is_finite() && m.normal.is_normalized());
        assert_eq!(m.max_depth(), 0.0);
        assert!(m.points()[0].point.is_finite());
    }
}
