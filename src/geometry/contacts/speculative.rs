//! Speculative contacts: pairs found while still apart by up to a margin, with their
//! separations, so that a solver that detects once per step can stop a body at the surface
//! before it gets there (Catto, "Speculative Contacts", 2013; Box2D's 2 cm speculative
//! distance).
//!
//! The closed-form tests report only touching or penetrating pairs, so one of the two shapes is
//! tested grown by the margin — a ball's radius, a box's half extents — and each point's
//! separation is the margin minus its depth against the grown shape. For a ball this is exact;
//! for a box it is exact across faces and errs on the early side near edges and corners (a
//! grown box is not a rounded one), which only makes a contact speculative sooner. Half-spaces
//! and meshes are not grown: a pair of them reports penetration only.

use super::contact;
use crate::geometry::{ContactManifold, Cuboid, Isometry, MAX_MANIFOLD_POINTS, Shape, Sphere};
use glam::Vec3;

/// The shape grown by `margin`, or `None` if it cannot be grown.
fn grown(shape: &Shape, margin: f32) -> Option<Shape> {
    match shape {
        Shape::Sphere(s) => Some(Shape::Sphere(Sphere {
            radius: s.radius + margin,
        })),
        Shape::Cuboid(c) => Some(Shape::Cuboid(Cuboid {
            half_extents: c.half_extents + margin,
        })),
        Shape::HalfSpace(_) | Shape::TriMesh(_) => None,
    }
}

/// A point of a speculative contact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpeculativePoint {
    /// World point midway between the true surfaces.
    pub point: Vec3,
    /// Distance between the surfaces along the normal: negative in penetration.
    pub separation: f32,
}

/// A contact found with a speculative margin: points that may still be apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeculativeContact {
    /// Unit normal from A to B.
    pub normal: Vec3,
    points: [SpeculativePoint; MAX_MANIFOLD_POINTS],
    len: u8,
}

impl SpeculativeContact {
    /// The points.
    pub fn points(&self) -> &[SpeculativePoint] {
        &self.points[..self.len as usize]
    }

    /// The manifold of the grown shape brought back to the true surfaces: the grown surface of
    /// A lies `added` further along the normal (of B, `added` back), so the midpoint moved by
    /// half of it; and a point on a grown box's rim (a corner of the grown face) is pulled in
    /// across the normal to the true box, or the lever arms would be `added` too long.
    fn from_grown(
        m: ContactManifold,
        added: f32,
        grown: Option<(&Cuboid, &Isometry)>,
        grown_a: bool,
    ) -> Self {
        let shift = m.normal * (if grown_a { -0.5 } else { 0.5 } * added);
        let mut points = [SpeculativePoint::default(); MAX_MANIFOLD_POINTS];
        for (out, p) in points.iter_mut().zip(m.points()) {
            let mut point = p.point + shift;
            if let Some((c, pose)) = grown {
                let local = pose.inverse_transform_point(point);
                let inside = local.clamp(-c.half_extents, c.half_extents);
                let pulled = pose.transform_point(inside);
                // Keep the offset along the normal; remove only the part across it.
                let off = point - pulled;
                point = pulled + m.normal * off.dot(m.normal);
            }
            *out = SpeculativePoint {
                point,
                separation: added - p.depth,
            };
        }
        Self {
            normal: m.normal,
            points,
            len: m.len() as u8,
        }
    }
}

/// The contact of `a` and `b` with a speculative `margin` (see the module doc), or `None` when
/// they are farther apart than the margin.
pub fn speculative_contact(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    margin: f32,
) -> Option<SpeculativeContact> {
    if margin > 0.0 {
        if let Some(ga) = grown(a, margin) {
            let m = contact(&ga, pose_a, b, pose_b)?;
            let rim = cuboid_of(a).map(|c| (c, pose_a));
            return Some(SpeculativeContact::from_grown(m, margin, rim, true));
        }
        if let Some(gb) = grown(b, margin) {
            let m = contact(a, pose_a, &gb, pose_b)?;
            let rim = cuboid_of(b).map(|c| (c, pose_b));
            return Some(SpeculativeContact::from_grown(m, margin, rim, false));
        }
    }
    contact(a, pose_a, b, pose_b).map(|m| SpeculativeContact::from_grown(m, 0.0, None, true))
}

fn cuboid_of(shape: &Shape) -> Option<&Cuboid> {
    match shape {
        Shape::Cuboid(c) => Some(c),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ball_above_the_ground_reports_its_exact_gap() {
        let ground = Shape::half_space(Vec3::Z);
        let ball = Shape::sphere(0.5);
        let at = Isometry::from_translation(Vec3::new(0.0, 0.0, 0.51));
        let c = speculative_contact(&ground, &Isometry::default(), &ball, &at, 0.02).unwrap();
        let p = c.points()[0];
        assert!((p.separation - 0.01).abs() < 1e-6, "{}", p.separation);
        // Midway between the true surfaces (z = 0 and z = 0.01), not the grown ones.
        assert!((p.point.z - 0.005).abs() < 1e-6, "{}", p.point);
        assert!(speculative_contact(&ground, &Isometry::default(), &ball, &at, 0.005).is_none());
    }

    #[test]
    fn a_box_above_the_ground_has_its_points_at_its_true_corners() {
        let ground = Shape::half_space(Vec3::Z);
        let b = Shape::cuboid(Vec3::splat(0.5));
        let at = Isometry::from_translation(Vec3::new(0.0, 0.0, 0.51));
        let c = speculative_contact(&ground, &Isometry::default(), &b, &at, 0.02).unwrap();
        assert_eq!(c.points().len(), 4);
        for p in c.points() {
            assert!((p.point.x.abs() - 0.5).abs() < 1e-5 && (p.point.y.abs() - 0.5).abs() < 1e-5);
            assert!((p.separation - 0.01).abs() < 1e-5);
        }
    }

    #[test]
    fn a_box_over_a_box_reports_the_face_gap_at_every_point() {
        let a = Shape::cuboid(Vec3::splat(0.5));
        let b = Shape::cuboid(Vec3::new(0.3, 0.3, 0.2));
        let above = Isometry::from_translation(Vec3::new(0.1, 0.0, 0.5 + 0.2 + 0.015));
        let c = speculative_contact(&a, &Isometry::default(), &b, &above, 0.02).unwrap();
        assert!(c.normal.abs_diff_eq(Vec3::Z, 1e-6));
        assert_eq!(c.points().len(), 4);
        for p in c.points() {
            assert!((p.separation - 0.015).abs() < 1e-5);
            assert!((p.point.z - (0.5 + 0.0075)).abs() < 1e-5, "{}", p.point);
        }
    }
}
