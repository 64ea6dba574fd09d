//! A ray or a sphere cast against one shape: closed forms along the unit direction for balls,
//! half-spaces and rays against boxes; otherwise the exact time of impact of [`crate::ccd`] (a
//! ray is a sweep of radius 0), given a finite sweep long enough to reach the shape.
//!
//! CCD sweeps a body over one step, a segment of known length; a query ray may be unbounded
//! (`max_distance = f32::INFINITY`). A cast through a sweep therefore sweeps only as far as the
//! shape can be (to the far side of its box), and the answer is the sweep's, scaled back to a
//! distance along the unit direction.

use super::ray_convex::ray_at_convex;
use crate::bounding::Aabb;
use crate::bvh::QueryScratch;
use crate::ccd::{SphereSweep, toi_sphere_shape};
use crate::geometry::{Isometry, Shape};
use glam::Vec3;
use std::fmt;

/// A half-line from `origin` along a unit `direction`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    origin: Vec3,
    direction: Vec3,
}

/// Why a query was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QueryError {
    /// An origin or point with a NaN or infinite coordinate.
    NonFiniteOrigin(Vec3),
    /// A direction that is zero or not finite (it has no unit direction).
    BadDirection(Vec3),
    /// A cast radius that is negative or not finite.
    BadRadius(f32),
    /// A maximum distance that is negative or NaN.
    BadMaxDistance(f32),
    /// A cast shape's size that is negative, not finite or above the largest supported: a box's
    /// half extents, a capsule's `(half_length, radius, 0)`, a ball's `(radius, 0, 0)`, a
    /// cylinder's or a cone's `(half_height, radius, 0)`, an ellipsoid's radii, a hull's
    /// bounding radius on every axis.
    BadSize(Vec3),
    /// A shape that cannot be cast: a half-space (unbounded) or a mesh (not convex; cast its
    /// convex pieces).
    NotCastable,
}

impl fmt::Display for QueryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFiniteOrigin(p) => write!(f, "query origin {p} is not finite"),
            Self::BadDirection(d) => write!(f, "query direction {d} is zero or not finite"),
            Self::BadRadius(r) => write!(f, "cast radius {r} is negative or not finite"),
            Self::BadMaxDistance(m) => write!(f, "maximum distance {m} is negative or NaN"),
            Self::BadSize(s) => write!(
                f,
                "cast shape size {s} is negative, not finite or too large"
            ),
            Self::NotCastable => write!(f, "a half-space or a mesh cannot be cast"),
        }
    }
}

impl std::error::Error for QueryError {}

impl Ray {
    /// The ray from `origin` along `direction` (normalised here).
    pub fn new(origin: Vec3, direction: Vec3) -> Result<Self, QueryError> {
        if !origin.is_finite() {
            return Err(QueryError::NonFiniteOrigin(origin));
        }
        // Scaled first, so a finite direction too long to square still has a unit direction.
        let unit = (direction / direction.abs().max_element())
            .try_normalize()
            .ok_or(QueryError::BadDirection(direction))?;
        Ok(Self {
            origin,
            direction: unit,
        })
    }

    /// Where the ray starts.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// Its unit direction.
    pub fn direction(&self) -> Vec3 {
        self.direction
    }

    /// The point `distance` along it.
    pub fn at(&self, distance: f32) -> Vec3 {
        self.origin + self.direction * distance
    }
}

/// Refuses a maximum distance that is negative or NaN (infinity is fine: no limit).
pub(crate) fn check_max_distance(max_distance: f32) -> Result<f32, QueryError> {
    if max_distance >= 0.0 {
        Ok(max_distance)
    } else {
        Err(QueryError::BadMaxDistance(max_distance))
    }
}

/// Where a cast first meets a shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CastHit {
    /// Distance travelled along the unit direction (0 when the cast starts touching or inside).
    pub distance: f32,
    /// The point where the surfaces meet (for a cast starting inside, the static contact's).
    pub point: Vec3,
    /// Unit surface normal at the hit, pointing back toward the cast (out of the shape).
    pub normal: Vec3,
}

/// The first contact of a sphere of `radius` (0: a ray) moving from `ray.origin` along
/// `ray.direction` for at most `max_distance` with `shape` at `pose` (whose world box is
/// `aabb`). Solid shapes: a cast starting inside or touching hits at distance 0; meshes are
/// surfaces (two-sided triangles), as everywhere in urto.
///
/// Balls, half-spaces and rays against boxes, cylinders, cones, ellipsoids and hulls are solved
/// in closed form along the unit direction (a sweep's quadratic over a 100 m segment lost
/// millimetres to rounding, and a sweep stops short by its tolerance: `ray_convex.rs`); a
/// sphere against a box (a rounded box) or those shapes, and anything against a mesh, go
/// through the CCD sweeps.
pub fn cast_sphere(
    ray: &Ray,
    radius: f32,
    max_distance: f32,
    (shape, pose, aabb): (&Shape, &Isometry, &Aabb),
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    match shape {
        Shape::Sphere(s) => cast_at_ball(ray, radius, max_distance, pose.translation, s.radius),
        Shape::HalfSpace(h) => {
            let normal = pose.transform_vector(h.normal);
            cast_at_plane(ray, radius, max_distance, pose.translation, normal)
        }
        _ => {
            let exact = (radius == 0.0).then(|| ray_at_convex(ray, max_distance, shape, pose));
            match exact.flatten() {
                Some(hit) => hit,
                None => cast_by_sweep(ray, radius, max_distance, (shape, pose, aabb), scratch),
            }
        }
    }
}

/// A ball of `radius` cast at a ball of `other` centred at `centre`: the ray against the ball
/// of radius `radius + other`, the chord measured from the closest approach (Ericson 2005,
/// §5.3.2, in the form that keeps its precision far from the ball).
fn cast_at_ball(ray: &Ray, radius: f32, max: f32, centre: Vec3, other: f32) -> Option<CastHit> {
    let reach = radius + other;
    let m = ray.origin - centre;
    let surface = |normal: Vec3, distance: f32| CastHit {
        distance,
        point: centre + normal * other,
        normal,
    };
    if m.length_squared() <= reach * reach {
        let normal = m.try_normalize().unwrap_or(-ray.direction);
        return Some(surface(normal, 0.0));
    }
    // In f64: a ray grazing a ball 100 m away has a chord of nearly zero, and the f32 rounding
    // of the offset and of the closest approach (~1e-5 m at 100 m) moved its hit by millimetres.
    let m64 = ray.origin.as_dvec3() - centre.as_dvec3();
    let d64 = ray.direction.as_dvec3();
    let along = m64.dot(d64);
    if along >= 0.0 {
        return None; // starting outside and moving away
    }
    let closest = m64 - d64 * along;
    let half_chord = f64::from(reach).powi(2) - closest.length_squared();
    if half_chord < 0.0 {
        return None;
    }
    let distance = (-along - half_chord.sqrt()) as f32;
    if distance > max {
        return None;
    }
    let normal = (m + ray.direction * distance)
        .try_normalize()
        .unwrap_or(-ray.direction);
    Some(surface(normal, distance))
}

/// A ball of `radius` cast at the half-space below the plane through `at` with unit `normal`.
pub(crate) fn cast_at_plane(
    ray: &Ray,
    radius: f32,
    max: f32,
    at: Vec3,
    normal: Vec3,
) -> Option<CastHit> {
    let above = normal.dot(ray.origin - at);
    let gap = above - radius;
    if gap <= 0.0 {
        let point = ray.origin - normal * above;
        return Some(CastHit {
            distance: 0.0,
            point,
            normal,
        });
    }
    let closing = -normal.dot(ray.direction);
    if closing.is_nan() || closing <= 0.0 {
        return None;
    }
    let distance = gap / closing;
    (distance <= max).then(|| CastHit {
        distance,
        point: ray.at(distance) - normal * radius,
        normal,
    })
}

/// Any cast through the CCD sweep of [`crate::ccd`], swept only as far as the shape can be.
fn cast_by_sweep(
    ray: &Ray,
    radius: f32,
    max_distance: f32,
    (shape, pose, aabb): (&Shape, &Isometry, &Aabb),
    scratch: &mut QueryScratch,
) -> Option<CastHit> {
    let reach = (ray.origin - aabb.center()).length() + aabb.half_extents().length() + radius;
    let length = reach.min(max_distance);
    let sweep = SphereSweep::new(ray.origin, radius, ray.direction * length).ok()?;
    let toi = toi_sphere_shape(&sweep, shape, pose, scratch)?;
    let distance = toi.t * length;
    (distance <= max_distance).then_some(CastHit {
        distance,
        point: toi.point,
        normal: toi.normal,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn hit(ray: &Ray, radius: f32, max: f32, shape: &Shape, pose: &Isometry) -> Option<CastHit> {
        let aabb = shape.world_aabb(pose);
        cast_sphere(
            ray,
            radius,
            max,
            (shape, pose, &aabb),
            &mut QueryScratch::new(),
        )
    }

    #[test]
    fn unbounded_rays_hit_a_far_plane_and_box_at_the_analytic_distance_within_1e_6_relative() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 1000.0), Vec3::new(0.0, 0.6, -0.8)).unwrap();
        let ground = Shape::half_space(Vec3::Z);
        let h = hit(&ray, 0.0, f32::INFINITY, &ground, &Isometry::default()).unwrap();
        assert!((h.distance - 1250.0).abs() < 1250.0 * 1e-6, "{h:?}");
        assert!((h.normal - Vec3::Z).length() < 1e-6);
        let pose = Isometry::new(Vec3::new(0.0, 600.0, 200.0), Quat::from_rotation_z(0.4));
        let cube = Shape::cuboid(Vec3::splat(1.0));
        // The ray passes the cube's centre height at y = 600 (z = 200): 1000 along it.
        let h = hit(&ray, 0.0, f32::INFINITY, &cube, &pose).unwrap();
        assert!(h.distance > 997.0 && h.distance < 1000.0, "{h:?}");
        assert!(hit(&ray, 0.0, 990.0, &cube, &pose).is_none());
        // A sphere cast meets the plane `radius` earlier along the normal.
        let h = hit(&ray, 2.0, f32::INFINITY, &ground, &Isometry::default()).unwrap();
        assert!((h.distance - 1247.5).abs() < 1247.5 * 1e-6, "{h:?}");
    }

    #[test]
    fn a_ray_leaving_a_plane_or_starting_inside_a_box_is_refused_or_hits_at_0() {
        let up = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::Z).unwrap();
        let ground = Shape::half_space(Vec3::Z);
        assert!(hit(&up, 0.0, f32::INFINITY, &ground, &Isometry::default()).is_none());
        let inside = Ray::new(Vec3::new(0.1, 0.0, 0.0), Vec3::X).unwrap();
        let cube = Shape::cuboid(Vec3::ONE);
        let h = hit(&inside, 0.0, 5.0, &cube, &Isometry::default()).unwrap();
        assert_eq!(h.distance, 0.0);
    }

    #[test]
    fn bad_rays_and_distances_are_refused() {
        assert!(Ray::new(Vec3::NAN, Vec3::X).is_err());
        assert!(Ray::new(Vec3::ZERO, Vec3::ZERO).is_err());
        assert!(Ray::new(Vec3::ZERO, Vec3::splat(f32::INFINITY)).is_err());
        let long = Ray::new(Vec3::ZERO, Vec3::new(3e30, 4e30, 0.0)).unwrap();
        assert!((long.direction() - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6);
        assert!(check_max_distance(f32::NAN).is_err());
        assert!(check_max_distance(-1.0).is_err());
        assert_eq!(check_max_distance(f32::INFINITY), Ok(f32::INFINITY));
    }
}
