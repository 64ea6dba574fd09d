//! Merging the contacts of many triangles into one manifold.
//!
//! A mesh touches another shape through many triangles at once, each with its own normal (a
//! sphere in a crease, a box across a ridge of a terrain). urto's response works with one normal
//! per pair, so the triangle contacts are merged:
//! - **normal**: the depth-weighted average of the triangle normals, so the deepest triangles
//!   dominate and a body in a crease is pushed along the bisector. When every depth is zero
//!   (touching) the plain average; when the average cancels (normals from opposite sides, as for
//!   a thin plate squeezed from both faces) the normal of the deepest triangle.
//! - **points**: all triangle contact points are pooled, and at most
//!   [`MAX_MANIFOLD_POINTS`](crate::geometry::MAX_MANIFOLD_POINTS) kept: the deepest, then the
//!   ones spanning the widest area (`manifold_reduction.rs`). Each keeps its own depth, so the
//!   manifold's depth is the deepest triangle's.
//!
//! This is an approximation: a depth measured along one triangle's normal is kept as is under the
//! averaged normal. It is exact for a flat contact region and errs on the deep side in a crease
//! (the solver then corrects a little more than needed rather than less).

use super::manifold_reduction::spread_points;
use crate::geometry::{ContactManifold, ContactPoint, Isometry};
use glam::Vec3;

/// A weighted sum cancelling below this fraction of the summed weights counts as cancelled.
const CANCELLED_FRACTION: f32 = 1e-3;

/// Running sums of the triangle normals, for the merged normal of the module notes.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct NormalMerge {
    weighted: Vec3,
    weight: f32,
    plain: Vec3,
    count: u32,
    /// The deepest contribution's depth and normal (the first one on ties).
    deepest: Option<(f32, Vec3)>,
}

impl NormalMerge {
    /// Adds one triangle's unit normal with its depth (`>= 0`).
    #[inline]
    pub(crate) fn add(&mut self, normal: Vec3, depth: f32) {
        self.weighted += normal * depth;
        self.weight += depth;
        self.plain += normal;
        self.count += 1;
        if self.deepest.is_none_or(|(d, _)| depth > d) {
            self.deepest = Some((depth, normal));
        }
    }

    /// The merged unit normal, or `None` when nothing was added.
    pub(crate) fn normal(&self) -> Option<Vec3> {
        let (_, deepest) = self.deepest?;
        let (sum, total) = if self.weight > 0.0 {
            (self.weighted, self.weight)
        } else {
            (self.plain, self.count as f32)
        };
        if sum.length() > CANCELLED_FRACTION * total {
            sum.try_normalize().or(Some(deepest))
        } else {
            Some(deepest)
        }
    }
}

/// The manifold of the merged `normal` and the pooled `points` (both in a local frame), reduced
/// to the deepest and widest few and carried to the world by `pose`. `None` without points.
pub(crate) fn reduce_to_manifold(
    normal: Vec3,
    points: &[ContactPoint],
    pose: &Isometry,
) -> Option<ContactManifold> {
    let (chosen, count) = spread_points(points, normal);
    if count == 0 {
        return None;
    }
    let mut manifold = ContactManifold::new(pose.transform_vector(normal));
    for &k in &chosen[..count] {
        let p = points[k];
        manifold.push(ContactPoint {
            point: pose.transform_point(p.point),
            depth: p.depth,
        });
    }
    Some(manifold)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deeper_normals_weigh_more_and_cancellation_falls_back_on_the_deepest() {
        let mut m = NormalMerge::default();
        assert!(m.normal().is_none());
        m.add(Vec3::Z, 0.3);
        m.add(Vec3::X, 0.1);
        let n = m.normal().unwrap();
        assert!((n - Vec3::new(0.1, 0.0, 0.3).normalize()).length() < 1e-6);

        let mut touching = NormalMerge::default();
        touching.add(Vec3::Z, 0.0);
        touching.add(Vec3::Y, 0.0);
        let n = touching.normal().unwrap();
        assert!((n - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);

        let mut squeezed = NormalMerge::default();
        squeezed.add(Vec3::Z, 0.2);
        squeezed.add(-Vec3::Z, 0.2);
        squeezed.add(-Vec3::Z, 0.1);
        squeezed.add(Vec3::Z, 0.1);
        assert_eq!(squeezed.normal(), Some(Vec3::Z), "first of the deepest");
    }
}
