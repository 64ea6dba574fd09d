//! The pose of B's frame seen from A's frame, prepared once per query.
//!
//! A hierarchy query between two objects runs in A's frame (the slides' "AABB in the object's
//! reference frame": no BV is ever rebuilt when an object moves). Every BV pair test then needs
//! B's rotation as a matrix and, for the separating-axis tests, the absolute value of that matrix;
//! computing them once per query instead of once per node pair is the trick of Gottschalk, Lin
//! and Manocha (1996, "OBBTree").

use crate::geometry::Isometry;
use glam::{Mat3A, Quat, Vec3, Vec3A};

/// Added to every entry of `|R|` so that near-parallel axes, whose cross products are nearly zero,
/// cannot turn rounding noise into a false "separated" (Gottschalk et al. 1996, §4 of RAPID).
pub const ABS_ROTATION_EPSILON: f32 = 1e-6;

/// Relative error allowed for rounding in the transformed comparisons: the translation's length
/// times this is added to every interval test, so a BV test never disagrees with an exact test
/// about contents that touch to within rounding.
pub const RELATIVE_SLACK: f32 = 4.0 * f32::EPSILON;

/// `x_A = rotation * x_B + translation`, with what the BV tests derive from it. Stored in the
/// SIMD-aligned `Mat3A`/`Vec3A`, the form the tests compute in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RelativePose {
    /// Columns: B's axes expressed in A's frame.
    pub rotation: Mat3A,
    /// `|rotation|` entry-wise, plus [`ABS_ROTATION_EPSILON`].
    pub abs_rotation: Mat3A,
    /// B's origin in A's frame.
    pub translation: Vec3A,
    /// True when the rotation is exactly the identity: axis-aligned tests then stay exact.
    pub rotation_free: bool,
    /// Absolute tolerance added to each interval comparison (see [`RELATIVE_SLACK`]).
    pub slack: f32,
}

impl RelativePose {
    /// Prepares `pose_b_in_a` (usually `pose_a.inv_mul(&pose_b)`).
    pub fn new(pose_b_in_a: &Isometry) -> Self {
        let q = pose_b_in_a.rotation;
        let rotation_free = q == Quat::IDENTITY || q == -Quat::IDENTITY;
        let rotation = if rotation_free {
            Mat3A::IDENTITY
        } else {
            Mat3A::from_quat(q)
        };
        let eps = Vec3A::splat(ABS_ROTATION_EPSILON);
        let abs_rotation = Mat3A::from_cols(
            rotation.x_axis.abs() + eps,
            rotation.y_axis.abs() + eps,
            rotation.z_axis.abs() + eps,
        );
        let translation = Vec3A::from(pose_b_in_a.translation);
        Self {
            rotation,
            abs_rotation,
            translation,
            rotation_free,
            slack: RELATIVE_SLACK * translation.abs().max_element(),
        }
    }

    /// Maps a point of B's frame into A's frame.
    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3A {
        self.rotation * Vec3A::from(p) + self.translation
    }
}
