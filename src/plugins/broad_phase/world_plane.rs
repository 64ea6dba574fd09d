//! The world plane of an unbounded static half-space, so the broad phase pairs a half-space only
//! with the bodies whose volume reaches below it.

use crate::bounding::Aabb;
use crate::geometry::{Isometry, Shape};
use glam::Vec3;

/// An unbounded static half-space (a ground, a wall) in world space: the points `x` with
/// `normal·x <= offset` are inside it.
#[derive(Clone, Copy, Debug)]
pub(super) struct WorldPlane {
    normal: Vec3,
    offset: f32,
}

impl WorldPlane {
    /// The plane of a half-space collider at `pose`; `None` for any other shape.
    pub(super) fn of(shape: &Shape, pose: &Isometry) -> Option<Self> {
        let Shape::HalfSpace(h) = shape else {
            return None;
        };
        let normal = pose.rotation * h.normal;
        Some(Self {
            normal,
            offset: normal.dot(pose.translation),
        })
    }

    /// Whether some point of `aabb` lies inside the half-space (its lowest corner along the
    /// normal is at or below the plane). A NaN plane or box reaches (the pair is left to the
    /// narrow phase, as before).
    pub(super) fn reaches(&self, aabb: &Aabb) -> bool {
        let lowest = self.normal.dot(aabb.center()) - self.normal.abs().dot(aabb.half_extents());
        lowest.partial_cmp(&self.offset) != Some(std::cmp::Ordering::Greater)
    }
}
