//! [`Aabb`] as a hierarchy bounding volume: a box with faces parallel to the axes of the
//! *object's own* frame (the slides' AABB), so the hierarchy survives rigid motion untouched.
//!
//! Under a relative rotation two such boxes are no longer aligned, and the test becomes a
//! box–box separating-axis test. We use the 6 face axes only (van den Bergen 1997, "SAT lite"):
//! conservative, about half the cost of the full 15 axes, and in an AABB tree the 9 edge axes
//! rarely separate what the face axes do not. Without rotation the test is the exact
//! three-interval comparison.

use super::box_sat::face_axes;
use super::{Aabb, Bv, RelativePose, TriangleSet, overlap_ratio, rounding_pad};
use crate::geometry::Isometry;
use glam::{Vec3, Vec3A};

impl Aabb {
    /// The fitted box widened by its rounding pad.
    fn padded(self) -> Aabb {
        let magnitude = self.min.abs().max(self.max.abs()).max_element();
        self.expanded(rounding_pad(magnitude))
    }

    #[inline(always)]
    fn overlap_in<const ESTIMATE: bool>(&self, other: &Aabb, rel: &RelativePose) -> Option<f32> {
        if rel.rotation_free {
            return self.translated_overlap::<ESTIMATE>(other, rel);
        }
        let ha = Vec3A::from(self.half_extents());
        let hb = Vec3A::from(other.half_extents());
        let t = rel.transform_point(other.center()) - Vec3A::from(self.center());
        face_axes::<ESTIMATE>(ha, hb, t, &rel.rotation, &rel.abs_rotation, rel.slack)
    }
}

impl Aabb {
    /// The exact three-interval test when B is only translated.
    #[inline(always)]
    fn translated_overlap<const ESTIMATE: bool>(
        &self,
        other: &Aabb,
        rel: &RelativePose,
    ) -> Option<f32> {
        let s = Vec3::splat(rel.slack);
        let shift = Vec3::from(rel.translation);
        let (b_min, b_max) = (other.min + shift, other.max + shift);
        if !(self.min.cmple(b_max + s).all() && b_min.cmple(self.max + s).all()) {
            return None;
        }
        if !ESTIMATE {
            return Some(1.0);
        }
        let ha = self.half_extents() + s;
        let hb = other.half_extents();
        let d = (b_min + b_max - self.min - self.max) * 0.5;
        let ratio = |i: usize| overlap_ratio(ha[i], hb[i], d[i]);
        Some(ratio(0).min(ratio(1)).min(ratio(2)))
    }
}

impl Bv for Aabb {
    type Relative = RelativePose;

    fn relative(pose_b_in_a: &Isometry) -> RelativePose {
        RelativePose::new(pose_b_in_a)
    }

    fn fit_points<I>(points: I) -> Self
    where
        I: Iterator<Item = Vec3> + Clone,
    {
        let b = Aabb::from_points(points);
        if b.is_valid() {
            b.padded()
        } else {
            Aabb::new(Vec3::ZERO, Vec3::ZERO)
        }
    }

    /// The box of the corners is already in the summed moments.
    fn fit_triangles(set: &TriangleSet) -> Self {
        let b = set.surface().bounds();
        if b.is_valid() {
            b.padded()
        } else {
            Self::fit_points(set.points())
        }
    }

    fn merged(&self, other: &Self) -> Self {
        self.union(other)
    }

    fn grown(&self, margin: f32) -> Self {
        self.expanded(margin)
    }

    #[inline]
    fn overlaps(&self, other: &Self, rel: &RelativePose) -> bool {
        self.overlap_in::<false>(other, rel).is_some()
    }

    #[inline]
    fn overlap_estimate(&self, other: &Self, rel: &RelativePose) -> Option<f32> {
        self.overlap_in::<true>(other, rel)
    }

    fn size(&self) -> f32 {
        self.half_extents().length()
    }

    fn local_aabb(&self) -> Aabb {
        *self
    }

    fn contains_point(&self, p: Vec3, tolerance: f32) -> bool {
        self.expanded(tolerance).contains_point(p)
    }
}
