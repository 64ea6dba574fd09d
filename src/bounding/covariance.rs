//! Covariance of a point set and of a triangle surface, the input of the OBB's principal axes
//! (Gottschalk, Lin and Manocha 1996, "OBBTree", §3).
//!
//! The point covariance depends on how densely the mesh is sampled: a cluster of small triangles
//! pulls the axes towards itself. The paper's remedy integrates
//! over the *surface*: each triangle weighs by its area, with its exact second moment
//! `A/12 · (9 m mᵀ + p pᵀ + q qᵀ + r rᵀ)` (m its centroid, p, q, r its corners); those sums are
//! [`SurfaceMoments`](super::SurfaceMoments), summed once per hierarchy, and this file keeps the
//! point covariance, the fallback for surfaces without area.
//!
//! Sums run in f64 about a reference point near the data, so large coordinates (a mesh far from
//! its origin) do not cancel away the spread.

use glam::{DMat3, DVec3, Vec3};

use super::surface::outer;

/// Covariance matrix of the points (zero for fewer than two distinct points).
pub(crate) fn points_covariance<I: Iterator<Item = Vec3> + Clone>(points: I) -> DMat3 {
    let Some(reference) = points.clone().next().map(|p| p.as_dvec3()) else {
        return DMat3::ZERO;
    };
    let (sum, sum_sq, n) = points.fold((DVec3::ZERO, DMat3::ZERO, 0usize), |(s, ss, n), p| {
        let d = p.as_dvec3() - reference;
        (s + d, ss + outer(d, d), n + 1)
    });
    let n = n as f64;
    let mean = sum / n;
    sum_sq * (1.0 / n) - outer(mean, mean)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::SurfaceMoments;
    use glam::DVec3;

    /// A unit square in the xy plane split into two triangles, and the same square far from the
    /// origin: the surface covariance of a uniform unit square is diag(1/12, 1/12, 0).
    #[test]
    fn square_surface_has_the_uniform_square_covariance() {
        for offset in [Vec3::ZERO, Vec3::new(1000.0, -2000.0, 500.0)] {
            let [a, b, c, d] = [
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ]
            .map(|v| v + offset);
            let tris = [[a, b, c], [a, c, d]];
            let cov = SurfaceMoments::of_triangles(&tris).covariance().unwrap();
            let expected = DMat3::from_diagonal(DVec3::new(1.0 / 12.0, 1.0 / 12.0, 0.0));
            assert!(
                (cov - expected)
                    .abs()
                    .to_cols_array()
                    .iter()
                    .all(|x| *x < 1e-9),
                "{cov}"
            );
        }
    }

    #[test]
    fn degenerate_surfaces_are_refused_and_points_still_work() {
        let p = Vec3::new(1.0, 2.0, 3.0);
        assert!(
            SurfaceMoments::of_triangles(&[[p, p, p]])
                .covariance()
                .is_none()
        );
        assert!(SurfaceMoments::of_triangles(&[]).covariance().is_none());
        assert_eq!(points_covariance([p, p].into_iter()), DMat3::ZERO);
        let c = points_covariance([Vec3::ZERO, Vec3::X * 2.0].into_iter());
        assert!((c.x_axis.x - 1.0).abs() < 1e-12 && c.y_axis.y == 0.0);
    }
}
