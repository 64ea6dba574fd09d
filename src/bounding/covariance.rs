//! Covariance of a point set and of a triangle surface, the input of the OBB's principal axes
//! (Gottschalk, Lin and Manocha 1996, "OBBTree", §3).
//!
//! The point covariance depends on how densely the mesh is sampled: a cluster of small triangles
//! pulls the axes towards itself. The paper's remedy, used by [`triangles_covariance`], integrates
//! over the *surface*: each triangle weighs by its area, with its exact second moment
//! `A/12 · (9 m mᵀ + p pᵀ + q qᵀ + r rᵀ)` (m its centroid, p, q, r its corners).
//!
//! Sums run in f64 about a reference point near the data, so large coordinates (a mesh far from
//! its origin) do not cancel away the spread.

use glam::{DMat3, DVec3, Vec3};

/// Total area below which a surface counts as degenerate (relative to its squared extent); the
/// corners' point covariance is used instead.
const DEGENERATE_AREA: f64 = 1e-12;

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

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

/// Area-weighted covariance of the triangles' surface, or `None` when their total area is
/// negligible (the caller then falls back to [`points_covariance`]).
pub(crate) fn triangles_covariance<I>(triangles: I) -> Option<DMat3>
where
    I: Iterator<Item = [Vec3; 3]> + Clone,
{
    let reference = triangles.clone().next()?[0].as_dvec3();
    let mut area_sum = 0.0;
    let mut first_moment = DVec3::ZERO;
    let mut second_moment = DMat3::ZERO;
    let mut extent_sq: f64 = 0.0;
    for [p, q, r] in triangles {
        let (p, q, r) = (
            p.as_dvec3() - reference,
            q.as_dvec3() - reference,
            r.as_dvec3() - reference,
        );
        extent_sq = extent_sq.max(
            p.length_squared()
                .max(q.length_squared())
                .max(r.length_squared()),
        );
        let area = 0.5 * (q - p).cross(r - p).length();
        let m = (p + q + r) / 3.0;
        area_sum += area;
        first_moment += m * area;
        second_moment +=
            (outer(m, m) * 9.0 + outer(p, p) + outer(q, q) + outer(r, r)) * (area / 12.0);
    }
    if area_sum.is_nan() || area_sum <= DEGENERATE_AREA * extent_sq {
        return None;
    }
    let mean = first_moment / area_sum;
    Some(second_moment * (1.0 / area_sum) - outer(mean, mean))
}

#[cfg(test)]
mod tests {
    use super::*;

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
            let cov = triangles_covariance(tris.iter().copied()).unwrap();
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
        assert!(triangles_covariance([[p, p, p]].into_iter()).is_none());
        assert!(triangles_covariance(std::iter::empty()).is_none());
        assert_eq!(points_covariance([p, p].into_iter()), DMat3::ZERO);
        let c = points_covariance([Vec3::ZERO, Vec3::X * 2.0].into_iter());
        assert!((c.x_axis.x - 1.0).abs() < 1e-12 && c.y_axis.y == 0.0);
    }
}
