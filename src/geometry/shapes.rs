//! Collision shapes in their local frames: the slides' closed-form shapes (sphere, plane),
//! the box that OBB tests and games both need, the capsule that game characters and limbs are
//! made of (a sphere swept along a segment: every closed-form sphere test becomes a segment
//! test), the cylinder and ellipsoid of props and wheels, convex hulls, and triangle meshes with
//! their hierarchy. Cylinders, ellipsoids and hulls collide through their support functions
//! (GJK and EPA, [`crate::geometry::convex`]); the others keep their closed forms.
//!
//! A shape never stores its pose: the pose comes with every query (see [`Isometry`]).

use crate::bounding::Aabb;
use crate::geometry::convex::support::LINE_FEATURE_SINE;
use crate::geometry::{ConvexHull, Isometry, MeshCollider, length_or_zero};
use glam::{Quat, Vec3};
use std::fmt;
use std::sync::Arc;

/// A ball of `radius` centred on the local origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Radius, `>= 0` (zero is a point).
    pub radius: f32,
}

/// A box centred on the local origin, faces along the local axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cuboid {
    /// Half the size along local x, y, z; each `>= 0`.
    pub half_extents: Vec3,
}

/// A capsule: the points within `radius` of the segment from `-half_length` to `+half_length`
/// along the local **z** axis (urto's vertical, so a standing character is unrotated; Bevy's
/// and parry's `Capsule3d` run along y). Zero length is a sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    /// Half the length of the inner segment (between the caps' centres), `>= 0`.
    pub half_length: f32,
    /// Radius of the caps and of the cylinder, `>= 0`.
    pub radius: f32,
}

impl Capsule {
    /// The inner segment's two ends, `(bottom, top)`, placed at `pose`.
    #[inline]
    pub fn segment(&self, pose: &Isometry) -> (Vec3, Vec3) {
        let half = pose.rotation * Vec3::new(0.0, 0.0, self.half_length);
        (pose.translation - half, pose.translation + half)
    }
}

/// A solid cylinder along the local **z** axis (as [`Capsule`]): its flat caps at
/// `z = ±half_height`, its side at `radius` from the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// Half the height, from the centre to each cap, `>= 0`.
    pub half_height: f32,
    /// Radius of the caps, `>= 0`.
    pub radius: f32,
}

/// A solid cone along the local **z** axis (as [`Cylinder`]): its flat base at `z = −half_height`
/// of `radius`, its apex at `z = +half_height` (parry's and rapier's convention, turned to z). Its
/// centre of mass is a quarter of the height above the base, at `z = −half_height / 2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Half the height, from the centre to the apex and to the base, `>= 0`.
    pub half_height: f32,
    /// Radius of the base, `>= 0`.
    pub radius: f32,
}

/// A solid ellipsoid centred on the local origin with semi-axes `radii` along the local axes:
/// the slides' closed-form quadric `(x/a)² + (y/b)² + (z/c)² <= 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid {
    /// Semi-axes along local x, y, z; each `>= 0`.
    pub radii: Vec3,
}

/// The solid half-space below a plane through the local origin: points `x` with `normal·x <= 0`.
///
/// Used for grounds and walls: the body is unbounded, so it is always static and never enters the
/// broad phase's sort (its AABB is infinite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSpace {
    /// Outward unit normal in the local frame: it points out of the solid.
    pub normal: Vec3,
}

/// Every shape urto collides.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// See [`Sphere`].
    Sphere(Sphere),
    /// See [`Cuboid`].
    Cuboid(Cuboid),
    /// See [`HalfSpace`].
    HalfSpace(HalfSpace),
    /// See [`Capsule`].
    Capsule(Capsule),
    /// See [`Cylinder`].
    Cylinder(Cylinder),
    /// See [`Ellipsoid`].
    Ellipsoid(Ellipsoid),
    /// See [`Cone`].
    Cone(Cone),
    /// A convex polyhedron; see [`ConvexHull`]. Cheap to clone (shared).
    ConvexHull(Arc<ConvexHull>),
    /// A triangle mesh (a surface: open meshes are fine) with its hierarchy; see
    /// [`MeshCollider`]. Cheap to clone (shared).
    TriMesh(MeshCollider),
}

/// Largest radius or half extent of a shape (m): 1,000 km. Sizes are kept in a band around 1 so
/// that squared distances, volumes and inertias stay finite in f32 (a sphere of radius
/// `f32::MAX` turned the body it touched NaN); a larger ground is a half-space.
pub const MAX_SHAPE_EXTENT: f32 = 1.0e6;

/// Why a shape cannot be simulated.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeError {
    /// A radius or half extent above `MAX_SHAPE_EXTENT` (1,000 km).
    TooLarge(f32),
    /// A radius that is negative, NaN or infinite.
    BadRadius(f32),
    /// Half extents with a negative, NaN or infinite component.
    BadHalfExtents(Vec3),
    /// A plane normal that is zero, NaN or infinite.
    BadNormal(Vec3),
    /// A capsule's half length or a cylinder's half height that is negative, NaN or infinite.
    BadLength(f32),
    /// Ellipsoid semi-axes with a negative, NaN or infinite component.
    BadRadii(Vec3),
}

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadRadius(r) => write!(f, "sphere radius must be finite and >= 0, got {r}"),
            Self::BadHalfExtents(h) => {
                write!(f, "box half extents must be finite and >= 0, got {h}")
            }
            Self::BadNormal(n) => write!(f, "plane normal must be finite and non-zero, got {n}"),
            Self::BadLength(l) => write!(
                f,
                "capsule half length and cylinder half height must be finite and >= 0, got {l}"
            ),
            Self::BadRadii(r) => write!(f, "ellipsoid radii must be finite and >= 0, got {r}"),
            Self::TooLarge(x) => write!(
                f,
                "shape size {x} m is above the largest supported, {MAX_SHAPE_EXTENT} m (use a \
                 half-space for a ground)"
            ),
        }
    }
}

impl std::error::Error for ShapeError {}

impl Shape {
    /// A sphere of `radius`.
    pub fn sphere(radius: f32) -> Self {
        Self::Sphere(Sphere { radius })
    }

    /// A box of the given half extents.
    pub fn cuboid(half_extents: Vec3) -> Self {
        Self::Cuboid(Cuboid { half_extents })
    }

    /// A capsule along local z: `half_length` from its centre to each cap's centre, and
    /// `radius`.
    pub fn capsule(half_length: f32, radius: f32) -> Self {
        Self::Capsule(Capsule {
            half_length,
            radius,
        })
    }

    /// A cylinder along local z: `half_height` from its centre to each cap, and `radius`.
    pub fn cylinder(half_height: f32, radius: f32) -> Self {
        Self::Cylinder(Cylinder {
            half_height,
            radius,
        })
    }

    /// A cone along local z: its base `half_height` below the centre, of `radius`, its apex
    /// `half_height` above.
    pub fn cone(half_height: f32, radius: f32) -> Self {
        Self::Cone(Cone {
            half_height,
            radius,
        })
    }

    /// An ellipsoid of semi-axes `radii` along the local axes.
    pub fn ellipsoid(radii: Vec3) -> Self {
        Self::Ellipsoid(Ellipsoid { radii })
    }

    /// The convex hull of `points` (see [`ConvexHull::from_points`] for what is refused).
    pub fn convex_hull(points: &[Vec3]) -> Result<Self, crate::geometry::HullError> {
        Ok(Self::ConvexHull(Arc::new(ConvexHull::from_points(points)?)))
    }

    /// The half-space below the plane of outward `normal` (normalised here, after scaling by
    /// its largest component so that huge or tiny finite normals normalise too; a zero or
    /// non-finite normal is kept as is and refused by [`Shape::validate`]).
    pub fn half_space(normal: Vec3) -> Self {
        let scale = normal.abs().max_element();
        let unit = (scale > 0.0 && scale.is_finite())
            .then(|| (normal / scale).try_normalize())
            .flatten();
        Self::HalfSpace(HalfSpace {
            normal: unit.unwrap_or(normal),
        })
    }

    /// Checks that the shape's numbers describe a real shape. Meshes and hulls are validated
    /// when they are built, so they always pass.
    pub fn validate(&self) -> Result<(), ShapeError> {
        match self {
            Self::Sphere(Sphere { radius }) if !(radius.is_finite() && *radius >= 0.0) => {
                Err(ShapeError::BadRadius(*radius))
            }
            Self::Capsule(c) => check_axial(c.half_length, c.radius),
            Self::Cylinder(c) => check_axial(c.half_height, c.radius),
            Self::Cone(c) => check_axial(c.half_height, c.radius),
            Self::Ellipsoid(e) if !(e.radii.is_finite() && e.radii.cmpge(Vec3::ZERO).all()) => {
                Err(ShapeError::BadRadii(e.radii))
            }
            Self::Ellipsoid(e) if e.radii.max_element() > MAX_SHAPE_EXTENT => {
                Err(ShapeError::TooLarge(e.radii.max_element()))
            }
            Self::Cuboid(c)
                if !(c.half_extents.is_finite() && c.half_extents.cmpge(Vec3::ZERO).all()) =>
            {
                Err(ShapeError::BadHalfExtents(c.half_extents))
            }
            Self::HalfSpace(h)
                if !(h.normal.is_finite() && (h.normal.length_squared() - 1.0).abs() < 1e-3) =>
            {
                Err(ShapeError::BadNormal(h.normal))
            }
            Self::Sphere(s) if s.radius > MAX_SHAPE_EXTENT => Err(ShapeError::TooLarge(s.radius)),
            Self::Cuboid(c) if c.half_extents.max_element() > MAX_SHAPE_EXTENT => {
                Err(ShapeError::TooLarge(c.half_extents.max_element()))
            }
            _ => Ok(()),
        }
    }

    /// True for shapes with an infinite extent (they are static scenery by construction).
    pub fn is_unbounded(&self) -> bool {
        matches!(self, Self::HalfSpace(_))
    }

    /// The world-space AABB of the shape placed at `pose` (infinite for unbounded shapes).
    pub fn world_aabb(&self, pose: &Isometry) -> Aabb {
        match self {
            Self::Sphere(s) => {
                Aabb::from_center_half_extents(pose.translation, Vec3::splat(s.radius))
            }
            Self::Cuboid(c) => Aabb::of_centred_box(c.half_extents, pose),
            Self::HalfSpace(_) => Aabb::new(Vec3::NEG_INFINITY, Vec3::INFINITY),
            Self::Capsule(c) => {
                let (bottom, top) = c.segment(pose);
                Aabb::new(bottom.min(top), bottom.max(top)).expanded(c.radius)
            }
            Self::Cylinder(c) => {
                // The caps' circles: along world axis i a circle of radius r around the axis `a`
                // reaches r·sqrt(1 - a_i²).
                let axis = pose.rotation * Vec3::Z;
                let rim = (Vec3::ONE - axis * axis).max(Vec3::ZERO).sqrt() * c.radius;
                let half = axis.abs() * c.half_height + rim;
                Aabb::from_center_half_extents(pose.translation, half)
            }
            Self::Cone(c) => {
                // The apex, and the base's circle (as a cylinder's cap).
                let axis = pose.rotation * Vec3::Z;
                let rim = (Vec3::ONE - axis * axis).max(Vec3::ZERO).sqrt() * c.radius;
                let (apex, base) = (axis * c.half_height, -axis * c.half_height);
                let lo = apex.min(base - rim) + pose.translation;
                let hi = apex.max(base + rim) + pose.translation;
                Aabb::new(lo, hi)
            }
            Self::Ellipsoid(e) => {
                // Row i of R·diag(radii) has length sqrt(Σ_j (R_ij r_j)²): the support along
                // world axis i.
                let m = pose.rotation_matrix();
                let scaled = [
                    m.x_axis * e.radii.x,
                    m.y_axis * e.radii.y,
                    m.z_axis * e.radii.z,
                ];
                let half =
                    (scaled[0] * scaled[0] + scaled[1] * scaled[1] + scaled[2] * scaled[2]).sqrt();
                Aabb::from_center_half_extents(pose.translation, half)
            }
            Self::ConvexHull(h) => {
                let m = pose.rotation_matrix();
                let (lo, hi) = h
                    .vertices()
                    .iter()
                    .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &v| {
                        (lo.min(m * v), hi.max(m * v))
                    });
                Aabb::new(lo + pose.translation, hi + pose.translation)
            }
            Self::TriMesh(m) => m.world_aabb(pose),
        }
    }

    /// How far the surface lies outside the shape's core: a sphere's radius (its core a point)
    /// and a capsule's (a segment); 0 for shapes with faces, edges or corners. A rounded shape
    /// rolls on its core: the contact under it stays the core's point plus this radius along
    /// the normal however it turns, which the solver follows (`dynamics/solver/contact.rs`).
    pub fn rounding(&self) -> f32 {
        match self {
            Self::Sphere(s) => s.radius,
            Self::Capsule(c) => c.radius,
            _ => 0.0,
        }
    }

    /// [`Self::rounding`] for a contact of normal `normal` (world) with the shape turned by
    /// `rotation`: also a cylinder's radius where it lies on its side (the normal square to its
    /// axis within the tolerance that makes its side line the contact feature). Rolling, it
    /// turns about its axis, which keeps its axis at its radius from the contact as a ball's
    /// centre is kept: read as a material point instead, its contact rose `r (1 − cos θ)` a
    /// step and the solver let it sink that far, 1.8 mm at 3 m/s for a 0.3 m radius (`∝ v²`).
    /// On its cap or its rim it has corners: 0.
    pub fn rounding_along(&self, rotation: Quat, normal: Vec3) -> f32 {
        match self {
            Self::Cylinder(c) => {
                let axis = rotation * Vec3::Z;
                let square = axis.dot(normal).abs() <= LINE_FEATURE_SINE * normal.length();
                if square { c.radius } else { 0.0 }
            }
            _ => self.rounding(),
        }
    }

    /// Radius of the smallest origin-centred ball holding the shape (infinite if unbounded).
    pub fn bounding_radius(&self) -> f32 {
        match self {
            Self::Sphere(s) => s.radius,
            Self::Cuboid(c) => c.half_extents.length(),
            Self::HalfSpace(_) => f32::INFINITY,
            Self::Capsule(c) => c.half_length + c.radius,
            Self::Cylinder(c) => c.half_height.hypot(c.radius),
            // The base's rim is farther than the apex.
            Self::Cone(c) => c.half_height.hypot(c.radius),
            Self::Ellipsoid(e) => e.radii.max_element(),
            Self::ConvexHull(h) => h.bounding_radius(),
            Self::TriMesh(m) => m.bounding_radius(),
        }
    }

    /// Radius of the largest origin-centred ball inside the shape (a lower bound for a cone;
    /// 0 for a half-space, whose boundary holds the origin, and for a triangle mesh, whose
    /// inside is not known). What a body's turning cannot move: continuous collision reads a
    /// thin body (a plank, a bat, a stick) turning by more than its thickness a substep as
    /// fast, whatever its speed.
    pub fn inner_radius(&self) -> f32 {
        match self {
            Self::Sphere(s) => s.radius,
            Self::Cuboid(c) => c.half_extents.min_element(),
            Self::HalfSpace(_) | Self::TriMesh(_) => 0.0,
            Self::Capsule(c) => c.radius,
            Self::Cylinder(c) => c.radius.min(c.half_height),
            // The base at `half_height`, the side `r h / √(r² + 4h²)` from the centre.
            Self::Cone(c) => {
                let (r, h) = (c.radius, c.half_height);
                length_or_zero(r * h / (r * r + 4.0 * h * h).sqrt()).min(h)
            }
            Self::Ellipsoid(e) => e.radii.min_element(),
            Self::ConvexHull(h) => h.inner_radius(),
        }
    }
}

/// The two numbers of a capsule, cylinder or cone: a radius and a half length, each finite and
/// `>= 0` (radius first), neither above [`MAX_SHAPE_EXTENT`].
fn check_axial(half_length: f32, radius: f32) -> Result<(), ShapeError> {
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(ShapeError::BadRadius(radius));
    }
    if !(half_length.is_finite() && half_length >= 0.0) {
        return Err(ShapeError::BadLength(half_length));
    }
    let largest = half_length.max(radius);
    if largest > MAX_SHAPE_EXTENT {
        return Err(ShapeError::TooLarge(largest));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cylinder_is_rounded_only_on_its_side_and_a_bad_normal_or_turn_gives_no_rounding() {
        let c = Shape::cylinder(0.4, 0.3);
        let lying = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
        // Lying (axis along y): rounded against the ground, not against a wall at its cap.
        assert_eq!(c.rounding_along(lying, Vec3::Z), 0.3);
        assert_eq!(c.rounding_along(lying, Vec3::Y), 0.0);
        // Standing on its cap, or tilted past the side line's 3°: corners.
        assert_eq!(c.rounding_along(Quat::IDENTITY, Vec3::Z), 0.0);
        let tilted = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2 - 0.1);
        assert_eq!(c.rounding_along(tilted, Vec3::Z), 0.0);
        // Bad input reads as no rounding, never NaN.
        let nan = Vec3::splat(f32::NAN);
        assert_eq!(c.rounding_along(lying, nan), 0.0);
        assert_eq!(
            c.rounding_along(Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0), Vec3::Z),
            0.0
        );
        let inf = c.rounding_along(lying, Vec3::splat(f32::INFINITY));
        assert!(inf == 0.0 || inf == 0.3, "{inf}");
        // Other shapes keep their rounding whatever the normal.
        assert_eq!(Shape::sphere(0.5).rounding_along(lying, nan), 0.5);
        assert_eq!(Shape::cuboid(Vec3::ONE).rounding_along(lying, Vec3::Z), 0.0);
    }

    #[test]
    fn validation_refuses_nan_negative_and_zero_normals() {
        assert!(Shape::sphere(0.0).validate().is_ok());
        assert!(Shape::sphere(-1.0).validate().is_err());
        assert!(Shape::sphere(f32::NAN).validate().is_err());
        assert!(Shape::cuboid(Vec3::new(1.0, -0.1, 1.0)).validate().is_err());
        assert!(Shape::half_space(Vec3::ZERO).validate().is_err());
        assert!(Shape::capsule(0.0, 0.0).validate().is_ok());
        assert!(Shape::capsule(-0.1, 0.5).validate().is_err());
        assert!(Shape::capsule(0.5, f32::NAN).validate().is_err());
        assert!(Shape::capsule(f32::INFINITY, 0.5).validate().is_err());
        assert!(Shape::capsule(2e6, 0.5).validate().is_err());
        assert!(Shape::cone(0.0, 0.0).validate().is_ok());
        for (h, r) in [
            (-0.1, 0.5),
            (0.5, -0.1),
            (f32::NAN, 0.5),
            (0.5, f32::INFINITY),
            (2e6, 1.0),
        ] {
            assert!(Shape::cone(h, r).validate().is_err(), "{h} {r}");
        }
        assert!(
            Shape::half_space(Vec3::new(0.0, 0.0, 3.0))
                .validate()
                .is_ok()
        );
    }

    #[test]
    fn a_turned_cones_aabb_is_its_support_along_each_world_axis_within_1e_5() {
        use crate::geometry::convex::support::ConvexPart;
        use glam::Quat;
        let cone = Shape::cone(0.7, 0.4);
        for k in 0..50 {
            let t = k as f32 * 0.37;
            let turn = Quat::from_euler(glam::EulerRot::XYZ, t, 1.3 * t, 0.7 * t);
            let pose = Isometry::new(Vec3::new(t, -1.0, 2.0), turn);
            let aabb = cone.world_aabb(&pose);
            let Some(part) = ConvexPart::of_shape(&cone, pose) else {
                panic!("a cone is convex");
            };
            for axis in Vec3::AXES {
                let (hi, lo) = (part.support(axis).dot(axis), part.support(-axis).dot(axis));
                assert!((aabb.max.dot(axis) - hi).abs() < 1e-5, "{k}: {aabb:?} {hi}");
                assert!((aabb.min.dot(axis) - lo).abs() < 1e-5, "{k}: {aabb:?} {lo}");
            }
        }
    }

    /// Every convex shape's inner radius against its support function `h(d) = max x·d`
    /// sampled over the axes, a hull's face normals and 4,000 directions: never above `min h`
    /// (the ball is inside), and within 1 % of it (the largest such ball; the cone's side is
    /// exact as well).
    #[test]
    fn inner_radii_are_the_least_support_distance_within_1_percent() {
        use crate::geometry::convex::support::ConvexPart;
        let hull = Shape::convex_hull(&[
            Vec3::new(0.5, 0.2, 0.1),
            Vec3::new(-0.4, 0.3, 0.2),
            Vec3::new(0.1, -0.5, 0.15),
            Vec3::new(0.0, 0.1, -0.3),
            Vec3::new(-0.1, -0.2, 0.4),
        ])
        .unwrap();
        let shapes = [
            Shape::sphere(0.3),
            Shape::cuboid(Vec3::new(0.5, 0.1, 0.3)),
            Shape::capsule(0.5, 0.02),
            Shape::cylinder(0.05, 0.4),
            Shape::cone(0.5, 0.2),
            Shape::cone(0.1, 0.6),
            Shape::ellipsoid(Vec3::new(0.3, 0.08, 0.2)),
            hull,
        ];
        let mut rng = crate::test_rng::TestRng::new(5);
        for shape in &shapes {
            let part = ConvexPart::of_shape(shape, Isometry::IDENTITY).unwrap();
            let mut axes: Vec<Vec3> = [Vec3::X, Vec3::Y, Vec3::Z]
                .into_iter()
                .flat_map(|a| [a, -a])
                .collect();
            if let Shape::ConvexHull(h) = shape {
                axes.extend(h.faces().iter().map(|f| f.normal));
            }
            let random = (0..4000).map(|_| rng.vec3(-1.0, 1.0).normalize_or(Vec3::Z));
            let least = axes
                .into_iter()
                .chain(random)
                .map(|d| part.support(d).dot(d) + part.rounding)
                .fold(f32::INFINITY, f32::min);
            let inner = shape.inner_radius();
            assert!(inner <= least + 1e-6, "{shape:?}: {inner} > {least}");
            assert!(inner >= 0.99 * least, "{shape:?}: {inner} < {least}");
        }
        assert_eq!(Shape::half_space(Vec3::Z).inner_radius(), 0.0);
        assert_eq!(Shape::cone(0.0, 0.0).inner_radius(), 0.0);
    }
}
