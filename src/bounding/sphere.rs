//! Bounding sphere: the slides' first bounding volume, whose overlap test is one distance
//! comparison and is indifferent to rotation.
//!
//! Fit: Ritter's (1990, "An efficient bounding sphere", Graphics Gems) two-pass approximation —
//! a sphere on the diameter between two far-apart points, grown to take in every point outside —
//! compared with the sphere centred on the points' AABB; the smaller of the two is kept. Both are
//! O(n) and deterministic; neither is the minimal sphere (Welzl 1991), which costs more to build
//! and gains little for the hierarchy's inner nodes.

use super::{Aabb, Bv, RelativePose, overlap_ratio, rounding_pad};
use crate::geometry::Isometry;
use glam::{Vec3, Vec3A};

/// A ball `|x - center| <= radius`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    /// Centre, in the object's frame.
    pub center: Vec3,
    /// Radius, `>= 0`.
    pub radius: f32,
}

impl BoundingSphere {
    /// A sphere from its parts.
    pub const fn new(center: Vec3, radius: f32) -> Self {
        Self { center, radius }
    }

    /// Ritter's sphere of a non-empty point set.
    fn ritter<I: Iterator<Item = Vec3> + Clone>(points: I, first: Vec3) -> Self {
        let farthest_from = |q: Vec3| {
            points.clone().fold((q, 0.0f32), |(best, d), p| {
                let dp = p.distance_squared(q);
                if dp > d { (p, dp) } else { (best, d) }
            })
        };
        let (y, _) = farthest_from(first);
        let (z, _) = farthest_from(y);
        let mut center = (y + z) * 0.5;
        let mut radius = y.distance(z) * 0.5;
        for p in points {
            let d = p.distance(center);
            if d > radius {
                // Grow to hold both the old sphere and p: the new diameter runs from the far side
                // of the old sphere through p.
                let new_radius = (radius + d) * 0.5;
                center += (p - center) * ((new_radius - radius) / d);
                radius = new_radius;
            }
        }
        Self::new(center, radius)
    }

    /// The sphere centred on the points' AABB.
    fn aabb_centred<I: Iterator<Item = Vec3> + Clone>(points: I) -> Self {
        let center = Aabb::from_points(points.clone()).center();
        let radius_sq = points.fold(0.0f32, |r, p| r.max(p.distance_squared(center)));
        Self::new(center, radius_sq.sqrt())
    }

    /// The sphere grown by its rounding pad.
    fn padded(self) -> Self {
        let pad = rounding_pad(self.center.abs().max_element() + self.radius);
        Self::new(self.center, self.radius + pad)
    }
}

impl Bv for BoundingSphere {
    type Relative = RelativePose;

    fn relative(pose_b_in_a: &Isometry) -> RelativePose {
        RelativePose::new(pose_b_in_a)
    }

    fn fit_points<I>(points: I) -> Self
    where
        I: Iterator<Item = Vec3> + Clone,
    {
        let Some(first) = points.clone().next() else {
            return Self::new(Vec3::ZERO, 0.0);
        };
        let ritter = Self::ritter(points.clone(), first);
        let boxed = Self::aabb_centred(points.clone());
        let best = if ritter.radius <= boxed.radius {
            ritter
        } else {
            boxed
        };
        // Ritter's incremental growth rounds; make sure no point was lost to it.
        let reach = points.fold(best.radius, |r, p| r.max(p.distance(best.center)));
        Self::new(best.center, reach).padded()
    }

    fn merged(&self, other: &Self) -> Self {
        let offset = other.center - self.center;
        let d = offset.length();
        if d + other.radius <= self.radius {
            return *self;
        }
        if d + self.radius <= other.radius {
            return *other;
        }
        // d > 0 here: otherwise one sphere holds the other.
        let radius = (d + self.radius + other.radius) * 0.5;
        let center = self.center + offset * ((radius - self.radius) / d);
        Self::new(center, radius).padded()
    }

    fn grown(&self, margin: f32) -> Self {
        Self::new(self.center, self.radius + margin)
    }

    #[inline]
    fn overlaps(&self, other: &Self, rel: &RelativePose) -> bool {
        let reach = self.radius + other.radius + rel.slack;
        rel.transform_point(other.center)
            .distance_squared(Vec3A::from(self.center))
            <= reach * reach
    }

    #[inline]
    fn overlap_estimate(&self, other: &Self, rel: &RelativePose) -> Option<f32> {
        let reach = self.radius + other.radius + rel.slack;
        let d_sq = rel
            .transform_point(other.center)
            .distance_squared(Vec3A::from(self.center));
        (d_sq <= reach * reach)
            .then(|| overlap_ratio(self.radius + rel.slack, other.radius, d_sq.sqrt()))
    }

    fn size(&self) -> f32 {
        self.radius
    }

    fn local_aabb(&self) -> Aabb {
        Aabb::from_center_half_extents(self.center, Vec3::splat(self.radius))
    }

    fn contains_point(&self, p: Vec3, tolerance: f32) -> bool {
        p.distance(self.center) <= self.radius + tolerance
    }
}
