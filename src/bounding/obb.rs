//! Oriented bounding box: a box whose axes follow the shape (the slides' OBB, "faces parallel to
//! an optimal frame"), after Gottschalk, Lin and Manocha (1996, "OBBTree").
//!
//! Fit: the axes are the eigenvectors of the covariance of the surface (area-weighted over the
//! triangles, summed once per hierarchy: `surface.rs`; of the points when there is no surface), the extents the
//! points' projections on them. Degenerate sets still get a stable basis: the Jacobi
//! decomposition returns orthonormal vectors for repeated or zero eigenvalues, the axes are sorted
//! by decreasing variance with a fixed sign convention, and the third is the cross product of the
//! first two, so the basis is always right-handed and deterministic.
//!
//! Overlap: the 15-axis separating-axis test (face normals of both boxes and the 9 cross
//! products of their edges) with ε added to the absolute rotation matrix.

use super::box_sat::all_axes;
use super::covariance::points_covariance;
use super::symmetric_eigen::symmetric_eigen_within;
use super::{Aabb, Bv, RelativePose, TriangleSet, WideBox, rounding_pad};
use crate::geometry::Isometry;
use glam::{BVec3A, DMat3, Mat3, Mat3A, Vec3, Vec3A};

/// A box with centre `center`, unit axes the columns of `axes`, and `half_extents` along them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obb {
    /// Centre, in the object's frame.
    pub center: Vec3,
    /// Orthonormal, right-handed: column `i` is the box's `i`-th axis in the object's frame.
    pub axes: Mat3,
    /// Half the size along each axis, `>= 0`.
    pub half_extents: Vec3,
}

impl Obb {
    /// The tightest box with the given (orthonormal) axes holding every point, padded against
    /// rounding; a zero box at the origin when there is no point (or a non-finite one).
    pub fn fit_with_axes<I: Iterator<Item = Vec3>>(points: I, axes: Mat3) -> Self {
        // In SIMD lanes: the projections are most of a hierarchy's build.
        let to_box = Mat3A::from(axes.transpose());
        let mut interval = Interval::EMPTY;
        for p in points {
            interval.include(to_box * Vec3A::from(p));
        }
        interval.into_box(axes)
    }

    /// [`Obb::fit_with_axes`] over triangles' corners, a triangle per step (the loop a
    /// hierarchy build spends its time in).
    fn fit_triangles_with_axes(corners: &[[Vec3; 3]], axes: Mat3) -> Self {
        let to_box = Mat3A::from(axes.transpose());
        let mut interval = Interval::EMPTY;
        for triangle in corners {
            for p in triangle {
                interval.include(to_box * Vec3A::from(*p));
            }
        }
        interval.into_box(axes)
    }

    /// The eight corners.
    pub fn corners(&self) -> [Vec3; 8] {
        let h = self.half_extents;
        std::array::from_fn(|i| {
            let sign = Vec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            self.center + self.axes * (sign * h)
        })
    }

    #[inline(always)]
    fn overlap_in<const ESTIMATE: bool>(&self, other: &Obb, rel: &RelativePose) -> Option<f32> {
        let to_a_box = Mat3A::from(self.axes).transpose();
        // B's box axes, then B's centre offset, both in A's box frame.
        let c = to_a_box * (rel.rotation * Mat3A::from(other.axes));
        let t = to_a_box * (rel.transform_point(other.center) - Vec3A::from(self.center));
        let eps = Vec3A::splat(super::ABS_ROTATION_EPSILON);
        let abs_c = Mat3A::from_cols(
            c.x_axis.abs() + eps,
            c.y_axis.abs() + eps,
            c.z_axis.abs() + eps,
        );
        let (ha, hb) = (
            Vec3A::from(self.half_extents),
            Vec3A::from(other.half_extents),
        );
        all_axes::<ESTIMATE>(ha, hb, t, &c, &abs_c, rel.slack)
    }
}

/// The projections of points on a box's axes: their box in SIMD lanes ([`WideBox`]), and the
/// lanes in which a NaN came by (SIMD `min` forgets a NaN at the next finite value, where the
/// scalar one ignores it: either way the box would not hold that point).
struct Interval {
    bounds: WideBox,
    nan: BVec3A,
}

impl Interval {
    const EMPTY: Self = Self {
        bounds: WideBox::EMPTY,
        nan: BVec3A::FALSE,
    };

    #[inline]
    fn include(&mut self, q: Vec3A) {
        self.bounds = self.bounds.including(q);
        self.nan |= q.is_nan_mask();
    }

    /// The box over the interval in the frame `axes`, padded against rounding; a zero box at
    /// the origin when the interval is empty or saw a non-finite point.
    fn into_box(self, axes: Mat3) -> Obb {
        let (lo, hi) = (Vec3::from(self.bounds.min), Vec3::from(self.bounds.max));
        // An infinite point leaves an infinite bound; a NaN one only its mark.
        if self.nan.any() || !(lo.is_finite() && hi.is_finite() && lo.cmple(hi).all()) {
            return Obb {
                center: Vec3::ZERO,
                axes,
                half_extents: Vec3::ZERO,
            };
        }
        let pad = rounding_pad(lo.abs().max(hi.abs()).max_element());
        Obb {
            center: axes * ((lo + hi) * 0.5),
            axes,
            half_extents: (hi - lo) * 0.5 + Vec3::splat(pad),
        }
    }
}

/// Principal axes of a covariance matrix as an orthonormal right-handed `Mat3` (see the module
/// doc for the conventions that make it stable on degenerate input).
fn principal_axes(covariance: DMat3) -> Mat3 {
    // A box's axes need no more than f32 precision.
    let eigen = symmetric_eigen_within(covariance, 1e-12);
    let mut order = [0usize, 1, 2];
    // Decreasing variance; ties keep Jacobi's order, which is deterministic.
    order.sort_by(|&i, &j| eigen.values[j].total_cmp(&eigen.values[i]));
    let canonical = |i: usize| {
        let v = eigen.vectors.col(order[i]).as_vec3();
        // Sign convention: the component of largest magnitude is positive.
        let a = v.abs();
        let lead = if a.x >= a.y && a.x >= a.z {
            v.x
        } else if a.y >= a.z {
            v.y
        } else {
            v.z
        };
        if lead < 0.0 { -v } else { v }
    };
    let Some(x) = canonical(0).try_normalize() else {
        return Mat3::IDENTITY;
    };
    let y = canonical(1);
    let Some(y) = (y - x * x.dot(y)).try_normalize() else {
        return Mat3::IDENTITY;
    };
    Mat3::from_cols(x, y, x.cross(y))
}

impl Bv for Obb {
    type Relative = RelativePose;

    fn relative(pose_b_in_a: &Isometry) -> RelativePose {
        RelativePose::new(pose_b_in_a)
    }

    fn fit_points<I>(points: I) -> Self
    where
        I: Iterator<Item = Vec3> + Clone,
    {
        let axes = principal_axes(points_covariance(points.clone()));
        Self::fit_with_axes(points, axes)
    }

    fn fit_triangles(set: &TriangleSet) -> Self {
        let covariance = set
            .surface()
            .covariance()
            .unwrap_or_else(|| points_covariance(set.points()));
        Self::fit_triangles_with_axes(set.corners(), principal_axes(covariance))
    }

    fn merged(&self, other: &Self) -> Self {
        let corners = self.corners().into_iter().chain(other.corners());
        Self::fit_points(corners)
    }

    fn grown(&self, margin: f32) -> Self {
        // The box of the grown box's faces holds the rounded box (the Minkowski sum).
        Self {
            half_extents: self.half_extents + Vec3::splat(margin),
            ..*self
        }
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
        self.half_extents.length()
    }

    fn local_aabb(&self) -> Aabb {
        let abs = Mat3::from_cols(
            self.axes.x_axis.abs(),
            self.axes.y_axis.abs(),
            self.axes.z_axis.abs(),
        );
        Aabb::from_center_half_extents(self.center, abs * self.half_extents)
    }

    fn contains_point(&self, p: Vec3, tolerance: f32) -> bool {
        let q = self.axes.transpose() * (p - self.center);
        q.abs()
            .cmple(self.half_extents + Vec3::splat(tolerance))
            .all()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    /// Points on a rotated thin slab: the fitted box must follow the slab, not the world axes.
    #[test]
    fn fit_recovers_the_orientation_of_a_rotated_box() {
        let q = Quat::from_euler(glam::EulerRot::XYZ, 0.5, -0.3, 1.1);
        let h = Vec3::new(4.0, 1.0, 0.25);
        let corners: Vec<Vec3> = (0..8)
            .map(|i| {
                let s = Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                );
                q * (s * h) + Vec3::new(3.0, 2.0, 1.0)
            })
            .collect();
        let obb = Obb::fit_points(corners.iter().copied());
        assert!((obb.half_extents - h).abs().max_element() < 1e-3, "{obb:?}");
        assert!((obb.center - Vec3::new(3.0, 2.0, 1.0)).length() < 1e-4);
        assert!((obb.axes.x_axis.dot(q * Vec3::X)).abs() > 0.9999);
    }

    #[test]
    fn degenerate_sets_get_an_orthonormal_right_handed_basis() {
        let p = Vec3::new(1.0, -2.0, 3.0);
        let sets: [Vec<Vec3>; 4] = [
            vec![p; 5],
            vec![
                p,
                p + Vec3::new(1.0, 1.0, 0.0),
                p + Vec3::new(2.0, 2.0, 0.0),
            ],
            vec![p, p + Vec3::X, p + Vec3::Y, p + Vec3::X + Vec3::Y],
            vec![],
        ];
        for set in sets {
            let obb = Obb::fit_points(set.iter().copied());
            let a = obb.axes;
            assert!((a.transpose() * a - Mat3::IDENTITY).abs_diff_eq(Mat3::ZERO, 1e-5));
            assert!((a.determinant() - 1.0).abs() < 1e-5);
            assert!(obb.half_extents.is_finite() && obb.center.is_finite());
            for q in &set {
                assert!(obb.contains_point(*q, 0.0), "{obb:?} misses {q}");
            }
        }
    }
}
