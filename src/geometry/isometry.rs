//! A rigid pose: rotation followed by translation.
//!
//! Every narrow-phase query takes the poses of its two shapes as `Isometry`s, so that shapes
//! stay in their own local frames (a mesh's vertices and BVH are never rewritten when it moves:
//! the slides' "AABB in the object's reference frame").

use glam::{Mat3, Quat, Vec3};
use std::ops::Mul;

/// A proper rigid motion `x ↦ rotation * x + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isometry {
    /// Where the local origin lands.
    pub translation: Vec3,
    /// Orientation of the local axes; expected to be normalised.
    pub rotation: Quat,
}

impl Default for Isometry {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Isometry {
    /// No motion.
    pub const IDENTITY: Self = Self {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };

    /// A pose from its two parts.
    pub fn new(translation: Vec3, rotation: Quat) -> Self {
        Self {
            translation,
            rotation,
        }
    }

    /// A pure translation.
    pub fn from_translation(translation: Vec3) -> Self {
        Self::new(translation, Quat::IDENTITY)
    }

    /// Maps a point of the local frame to the parent frame.
    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }

    /// Rotates a direction (translation does not apply to vectors).
    #[inline]
    pub fn transform_vector(&self, v: Vec3) -> Vec3 {
        self.rotation * v
    }

    /// Maps a point of the parent frame into the local frame.
    #[inline]
    pub fn inverse_transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation.inverse() * (p - self.translation)
    }

    /// Rotates a parent-frame direction into the local frame.
    #[inline]
    pub fn inverse_transform_vector(&self, v: Vec3) -> Vec3 {
        self.rotation.inverse() * v
    }

    /// The motion that undoes this one.
    pub fn inverse(&self) -> Self {
        let inv = self.rotation.inverse();
        Self::new(inv * -self.translation, inv)
    }

    /// The pose of `other`'s frame seen from this frame: `self⁻¹ ∘ other`.
    ///
    /// Pair queries run in the first shape's frame, so they only ever need this relative pose.
    pub fn inv_mul(&self, other: &Self) -> Self {
        self.inverse() * *other
    }

    /// The rotation as a matrix, whose columns are the local axes in the parent frame.
    pub fn rotation_matrix(&self) -> Mat3 {
        Mat3::from_quat(self.rotation)
    }

    /// True when neither part holds a NaN or an infinity.
    pub fn is_finite(&self) -> bool {
        self.translation.is_finite() && self.rotation.is_finite()
    }
}

impl Mul for Isometry {
    type Output = Isometry;

    /// Composition: `(a * b).transform_point(p) == a.transform_point(b.transform_point(p))`.
    fn mul(self, rhs: Isometry) -> Isometry {
        Isometry::new(
            self.transform_point(rhs.translation),
            self.rotation * rhs.rotation,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn composition_and_inverse_agree_with_pointwise_maps() {
        let a = Isometry::new(Vec3::new(1.0, -2.0, 3.0), Quat::from_rotation_z(0.7));
        let b = Isometry::new(Vec3::new(-4.0, 0.5, 2.0), Quat::from_rotation_x(-1.1));
        let p = Vec3::new(0.3, 0.2, -0.9);
        let composed = (a * b).transform_point(p);
        assert!((composed - a.transform_point(b.transform_point(p))).length() < 1e-5);
        let back = a.inverse().transform_point(a.transform_point(p));
        assert!((back - p).length() < 1e-5);
        let rel = a.inv_mul(&b).transform_point(p);
        assert!((rel - a.inverse_transform_point(b.transform_point(p))).length() < 1e-5);
    }
}
