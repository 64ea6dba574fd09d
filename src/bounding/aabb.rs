//! Axis-aligned bounding box: the slides' AABB, and the currency of the broad phase.
//!
//! Two AABBs intersect iff their projections on x, y and z all overlap (the observation sweep
//! and prune rests on). Boxes are closed: boxes that only touch do intersect, which is the same
//! convention as the contact tests (a contact at distance exactly zero is reported with depth 0).

use crate::geometry::Isometry;
use glam::{Mat3A, Vec3};

/// A box `[min, max]` with faces parallel to the axes of its frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lowest corner.
    pub min: Vec3,
    /// Highest corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// Holds nothing; the identity of [`Aabb::union`].
    pub const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// A box from its corners (not checked: `min <= max` is the caller's promise).
    pub const fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    /// A box from its centre and half extents.
    pub fn from_center_half_extents(center: Vec3, half_extents: Vec3) -> Self {
        Self::new(center - half_extents, center + half_extents)
    }

    /// The smallest box holding every point (`EMPTY` for none).
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points
            .into_iter()
            .fold(Self::EMPTY, |b, p| Self::new(b.min.min(p), b.max.max(p)))
    }

    /// Midpoint.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the size along each axis.
    pub fn half_extents(&self) -> Vec3 {
        (self.max - self.min) * 0.5
    }

    /// Size along each axis.
    pub fn extents(&self) -> Vec3 {
        self.max - self.min
    }

    /// Volume (0 for an empty or flat box).
    pub fn volume(&self) -> f32 {
        let e = self.extents().max(Vec3::ZERO);
        e.x * e.y * e.z
    }

    /// Surface area, the measure of the surface-area heuristic.
    pub fn surface_area(&self) -> f32 {
        let e = self.extents().max(Vec3::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Index (0, 1, 2) of the longest side.
    pub fn longest_axis(&self) -> usize {
        let e = self.extents();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// True when `min <= max` on every axis.
    pub fn is_valid(&self) -> bool {
        self.min.cmple(self.max).all()
    }

    /// True when no coordinate is NaN or infinite.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// Closed-box overlap test: touching boxes intersect.
    #[inline]
    pub fn intersects(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// True when `p` is inside or on the boundary.
    pub fn contains_point(&self, p: Vec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
    }

    /// True when `other` lies inside this box (boundaries may touch).
    pub fn contains(&self, other: &Aabb) -> bool {
        self.min.cmple(other.min).all() && other.max.cmple(self.max).all()
    }

    /// The smallest box holding both.
    #[must_use]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb::new(self.min.min(other.min), self.max.max(other.max))
    }

    /// The box grown to hold `p`.
    #[must_use]
    pub fn including(&self, p: Vec3) -> Aabb {
        Aabb::new(self.min.min(p), self.max.max(p))
    }

    /// The box grown by `margin` on every side.
    #[must_use]
    pub fn expanded(&self, margin: f32) -> Aabb {
        Aabb::new(
            self.min - Vec3::splat(margin),
            self.max + Vec3::splat(margin),
        )
    }

    /// The box of this box's image under `pose` (Arvo 1990: project the rotated half extents).
    #[must_use]
    pub fn transformed(&self, pose: &Isometry) -> Aabb {
        let center = pose.transform_point(self.center());
        Aabb::from_center_half_extents(center, rotated_half_extents(pose, self.half_extents()))
    }

    /// The box of a box of `half_extents` centred on `pose`'s origin (a cuboid collider):
    /// [`Self::transformed`] without moving a centre at the origin.
    #[must_use]
    pub fn of_centred_box(half_extents: Vec3, pose: &Isometry) -> Aabb {
        Aabb::from_center_half_extents(pose.translation, rotated_half_extents(pose, half_extents))
    }
}

/// `|R| h`, the half extents of a turned box's bounding box, in SIMD lanes (the arithmetic of
/// `Mat3 * Vec3`, column by column: the same bits, a third of the instructions).
#[inline]
fn rotated_half_extents(pose: &Isometry, h: Vec3) -> Vec3 {
    let m = Mat3A::from_quat(pose.rotation);
    (m.x_axis.abs() * h.x + m.y_axis.abs() * h.y + m.z_axis.abs() * h.z).into()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn touching_boxes_intersect_and_separated_ones_do_not() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let touching = Aabb::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 1.0));
        let apart = Aabb::new(Vec3::new(1.0 + 1e-6, 0.0, 0.0), Vec3::new(2.0, 1.0, 1.0));
        assert!(a.intersects(&touching) && touching.intersects(&a));
        assert!(!a.intersects(&apart) && !apart.intersects(&a));
    }

    #[test]
    fn transformed_box_holds_every_transformed_corner() {
        let b = Aabb::new(Vec3::new(-1.0, -2.0, 0.5), Vec3::new(3.0, 1.0, 2.0));
        let pose = Isometry::new(
            Vec3::new(5.0, -1.0, 2.0),
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.8, 1.9),
        );
        let t = b.transformed(&pose);
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            assert!(
                t.expanded(1e-4)
                    .contains_point(pose.transform_point(corner))
            );
        }
    }

    #[test]
    fn turned_boxes_are_bit_identical_to_the_scalar_matrix_product_on_10000_poses() {
        let mut rng = crate::test_rng::TestRng::new(21);
        for _ in 0..10_000 {
            let pose = Isometry::new(rng.vec3(-50.0, 50.0), rng.rotation());
            let h = rng.vec3(0.01, 3.0);
            let scalar = Aabb::from_center_half_extents(
                pose.transform_point(Vec3::ZERO),
                pose.rotation_matrix().abs() * h,
            );
            let centred = Aabb::of_centred_box(h, &pose);
            let moved = Aabb::from_center_half_extents(Vec3::ZERO, h).transformed(&pose);
            assert_eq!(centred, scalar);
            assert_eq!(moved, scalar);
        }
    }

    #[test]
    fn empty_is_the_identity_of_union() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(2.0));
        assert_eq!(Aabb::EMPTY.union(&b), b);
        assert_eq!(Aabb::from_points([]), Aabb::EMPTY);
        assert!(!Aabb::EMPTY.is_valid());
    }
}
