//! The output of the narrow phase: a contact manifold between two shapes.
//!
//! Convention used by every shape-pair test: the `normal` is a unit vector pointing **from shape
//! A towards shape B**, `depth >= 0` is how far they interpenetrate along it, and a pair at
//! distance exactly zero (touching) *is* in contact with depth 0 — the same closed-set convention
//! as [`Aabb::intersects`](crate::bounding::Aabb::intersects). Points are in world space, midway
//! between the two surfaces. A speculative contact (found with a margin, for a solver that
//! detects once per step) also holds points still apart, with negative depth.

use crate::geometry::Isometry;
use glam::Vec3;

/// Most points a manifold keeps: four span a face-face contact, enough for a box to rest flat.
pub const MAX_MANIFOLD_POINTS: usize = 4;

/// Which features of the two shapes made a contact point: the same number from step to step
/// while the same features touch (a box's corner on a face, an edge crossing a side of the
/// reference face), whatever has moved, so that a warm start follows the point (Box2D's
/// `b2ManifoldPoint::id`, parry's `PackedFeatureId` under rapier and Avian). Where a shape
/// test has none to give, [`FeatureId::NONE`], and the point is matched by place.
///
/// The number is a name, not a ranking: only equality means something, and two different
/// features of one pair may rarely share one (mesh triangles' numbers are mixed into 32 bits);
/// a warm start taken from the wrong point is a worse first guess, nothing more.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct FeatureId(pub u32);

/// The bit of a [`FeatureId`] that marks a feature of the shape a mesh part meets, alone.
const OTHER_ALONE: u32 = 1 << 30;

impl FeatureId {
    /// No feature known.
    pub const NONE: Self = Self(0);

    /// The vertex where two lines of a face contact cross (`tag`, the clipping's name for
    /// the pair of lines), within `context` (which features met; for box–box also whose face
    /// is the reference).
    #[inline]
    pub(crate) fn clipped(context: u32, tag: u16) -> Self {
        Self(((context & 0x3FFF) << 16 | tag as u32) | 1 << 31)
    }

    /// A point named by `context` alone (a corner, an end, the deepest point).
    #[inline]
    pub(crate) fn single(context: u32) -> Self {
        Self::clipped(context, 0)
    }

    /// This feature of part `part` of a shape (a mesh's triangle or vertex), mixed in so that
    /// neighbouring parts' points do not share numbers; a feature of the other shape alone
    /// ([`Self::of_other_alone`]) keeps its number.
    #[inline]
    pub(crate) fn of_part(self, part: u32) -> Self {
        if self.is_other_alone() {
            return self;
        }
        let mixed = (self.0 ^ part.wrapping_mul(0x9E37_79B1)).rotate_left(5);
        Self((mixed | 1) & !OTHER_ALONE)
    }

    /// The same feature marked as one of the shape a mesh part meets, whichever part it meets
    /// (a box's corner): it keeps its number as it slides from triangle to triangle of a
    /// floor, so its warm start follows it.
    #[inline]
    pub(crate) fn of_other_alone(self) -> Self {
        Self(self.0 | OTHER_ALONE)
    }

    /// Whether this is a feature of the shape a mesh part meets, alone
    /// ([`Self::of_other_alone`]).
    #[inline]
    pub(crate) fn is_other_alone(self) -> bool {
        self.0 & OTHER_ALONE != 0
    }

    /// Whether a feature is named.
    #[inline]
    pub fn is_some(self) -> bool {
        self != Self::NONE
    }
}

/// One point of contact.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ContactPoint {
    /// World-space point midway between the two surfaces.
    pub point: Vec3,
    /// Penetration along the manifold normal: `>= 0` from the exact tests, negative (the gap)
    /// for the points of a speculative contact
    /// ([`speculative_contact`](crate::geometry::contacts::speculative_contact)) still apart.
    pub depth: f32,
    /// The features that made it ([`FeatureId::NONE`] where the test names none).
    pub feature: FeatureId,
}

impl ContactPoint {
    /// A point no feature names.
    #[inline]
    pub fn new(point: Vec3, depth: f32) -> Self {
        Self {
            point,
            depth,
            feature: FeatureId::NONE,
        }
    }

    /// The same point named by `feature`.
    #[inline]
    #[must_use]
    pub fn with_feature(self, feature: FeatureId) -> Self {
        Self { feature, ..self }
    }
}

/// Up to [`MAX_MANIFOLD_POINTS`] contact points sharing one normal, stored inline (the narrow
/// phase allocates nothing per pair).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactManifold {
    /// Unit normal from A to B.
    pub normal: Vec3,
    points: [ContactPoint; MAX_MANIFOLD_POINTS],
    len: u8,
}

impl ContactManifold {
    /// An empty manifold with the given normal.
    pub fn new(normal: Vec3) -> Self {
        Self {
            normal,
            points: [ContactPoint::default(); MAX_MANIFOLD_POINTS],
            len: 0,
        }
    }

    /// A manifold of a single point.
    pub fn single(normal: Vec3, point: Vec3, depth: f32) -> Self {
        let mut m = Self::new(normal);
        m.push(ContactPoint::new(point, depth));
        m
    }

    /// Adds a point; returns `false` (and drops it) when the manifold is full.
    pub fn push(&mut self, p: ContactPoint) -> bool {
        if (self.len as usize) < MAX_MANIFOLD_POINTS {
            self.points[self.len as usize] = p;
            self.len += 1;
            true
        } else {
            false
        }
    }

    /// The points held.
    pub fn points(&self) -> &[ContactPoint] {
        &self.points[..self.len as usize]
    }

    /// Number of points held.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// True when no point is held.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The deepest penetration over the points (0 when empty).
    pub fn max_depth(&self) -> f32 {
        self.points().iter().fold(0.0, |d, p| d.max(p.depth))
    }

    /// True when some point is closer than `tolerance` (a speculative contact whose points
    /// are all farther apart is not touching yet).
    pub fn touching(&self, tolerance: f32) -> bool {
        self.points().iter().any(|p| p.depth >= -tolerance)
    }

    /// The points closer than `tolerance` (where the shapes touch), or every point when none
    /// is that close (a speculative contact the solver stopped at the surface: its points
    /// are where the bodies met).
    #[must_use]
    pub fn touching_points(&self, tolerance: f32) -> Self {
        if !self.touching(tolerance) {
            return *self;
        }
        let mut out = Self::new(self.normal);
        for &p in self.points().iter().filter(|p| p.depth >= -tolerance) {
            out.push(p);
        }
        out
    }

    /// The manifold of a local frame carried to the frame `pose` places it in (normal turned,
    /// points moved, depths kept).
    #[must_use]
    pub fn transformed(&self, pose: &Isometry) -> Self {
        self.mapped(|n| pose.transform_vector(n), |p| pose.transform_point(p))
    }

    /// The manifold of the frame `pose` places in world carried back into that frame (the
    /// inverse of [`transformed`](Self::transformed)).
    #[must_use]
    pub fn to_local(&self, pose: &Isometry) -> Self {
        self.mapped(
            |n| pose.inverse_transform_vector(n),
            |p| pose.inverse_transform_point(p),
        )
    }

    /// The same normal and depths, each point moved by `point`.
    #[must_use]
    pub(crate) fn with_points_moved(&self, point: impl Fn(Vec3) -> Vec3) -> Self {
        self.mapped(|n| n, point)
    }

    /// The normal and the points mapped, depths kept.
    fn mapped(&self, normal: impl Fn(Vec3) -> Vec3, point: impl Fn(Vec3) -> Vec3) -> Self {
        let mut out = Self::new(normal(self.normal));
        for p in self.points() {
            out.push(ContactPoint {
                point: point(p.point),
                ..*p
            });
        }
        out
    }

    /// The same contact seen from B: the normal flips, the points stay.
    #[must_use]
    pub fn flipped(mut self) -> Self {
        self.normal = -self.normal;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifold(depths: &[f32]) -> ContactManifold {
        let mut m = ContactManifold::new(Vec3::Z);
        for (i, &depth) in depths.iter().enumerate() {
            let point = Vec3::new(i as f32, 0.0, 0.0);
            m.push(ContactPoint::new(point, depth));
        }
        m
    }

    #[test]
    fn touching_points_drop_points_apart_beyond_the_tolerance_unless_none_is_within_it() {
        let tipping = manifold(&[0.01, -0.004, -0.2, -0.5]).touching_points(0.005);
        let depths: Vec<f32> = tipping.points().iter().map(|p| p.depth).collect();
        assert_eq!(depths, [0.01, -0.004]);
        assert_eq!(tipping.normal, Vec3::Z);
        let approaching = manifold(&[-0.2, -0.3]);
        assert_eq!(approaching.touching_points(0.005), approaching);
    }
}
