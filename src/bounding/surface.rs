//! What a hierarchy node's bounding volume is fitted to: its triangles' corners, contiguous, and
//! the moments of their surface, summed once for the whole tree.
//!
//! An OBB is oriented by the covariance of its node's surface (Gottschalk, Lin and Manocha 1996,
//! "OBBTree", §3). Integrating it afresh at every node costs a pass over the node's triangles per
//! level, with a square root per triangle. The moments (area, first and second moments) are sums,
//! so the builder integrates each triangle once and gives every inner node the sum of its two
//! children's, and the covariance follows in O(1) per node.
//!
//! A tree's moments are taken about one origin near the mesh (in f64), so a node far smaller than
//! the mesh loses about `(mesh size / node size)²` ulps of f64 to cancellation: 8 of 16 digits for
//! a node 10⁴ times smaller, ample for a box's axes. The axes only orient the box; its extents are
//! the exact projections of the corners, so a box stays a bound whatever rounding did to them.

use super::Aabb;
use glam::{DMat3, DVec3, Vec3};

/// Total area below which a surface counts as degenerate (relative to its squared extent): its
/// covariance is then the corners' (see [`SurfaceMoments::covariance`]).
const DEGENERATE_AREA: f64 = 1e-12;

pub(crate) fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Area, first and second area moments of a set of triangles about an origin, and the box of
/// their corners: enough to give the set's surface covariance, and closed under addition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceMoments {
    origin: DVec3,
    area: f64,
    first: DVec3,
    second: DMat3,
    bounds: Aabb,
}

impl SurfaceMoments {
    /// No triangle, moments about `origin`.
    pub(crate) fn empty(origin: Vec3) -> Self {
        Self {
            origin: origin.as_dvec3(),
            area: 0.0,
            first: DVec3::ZERO,
            second: DMat3::ZERO,
            bounds: Aabb::EMPTY,
        }
    }

    /// One triangle's moments about `origin`: area `A`, first moment `A m` and the exact second
    /// moment `A/12 · (9 m mᵀ + p pᵀ + q qᵀ + r rᵀ)` (m the centroid, p, q, r the corners, all
    /// relative to `origin`).
    #[inline]
    pub(crate) fn of_triangle(corners: [Vec3; 3], origin: Vec3) -> Self {
        let o = origin.as_dvec3();
        let [p, q, r] = corners.map(|c| c.as_dvec3() - o);
        let area = 0.5 * (q - p).cross(r - p).length();
        let m = (p + q + r) / 3.0;
        Self {
            origin: o,
            area,
            first: m * area,
            second: (outer(m, m) * 9.0 + outer(p, p) + outer(q, q) + outer(r, r)) * (area / 12.0),
            bounds: Aabb::from_points(corners),
        }
    }

    /// The moments of `triangles`, about their first corner (so that large coordinates do not
    /// cancel away the spread).
    pub fn of_triangles(triangles: &[[Vec3; 3]]) -> Self {
        let origin = triangles.first().map_or(Vec3::ZERO, |t| t[0]);
        let mut sum = Self::empty(origin);
        for &t in triangles {
            sum.add(&Self::of_triangle(t, origin));
        }
        sum
    }

    /// Adds the moments of other triangles, taken about the same origin (the builder's sums).
    #[inline]
    pub(crate) fn add(&mut self, other: &Self) {
        debug_assert_eq!(self.origin, other.origin, "moments about different origins");
        self.area += other.area;
        self.first += other.first;
        self.second += other.second;
        self.bounds = self.bounds.union(&other.bounds);
    }

    /// The sum of two sets' moments.
    #[must_use]
    #[inline]
    pub(crate) fn plus(mut self, other: &Self) -> Self {
        self.add(other);
        self
    }

    /// Total area.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// The box of every corner (empty for no triangle).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The area-weighted covariance of the surface, or `None` when its area is negligible next to
    /// its extent (slivers, coincident corners, no triangle): then only the corners' point
    /// covariance can orient a box.
    pub fn covariance(&self) -> Option<DMat3> {
        let extent_sq = if self.bounds.is_valid() {
            (self.bounds.max - self.bounds.min)
                .as_dvec3()
                .length_squared()
        } else {
            0.0
        };
        if self.area.is_nan() || self.area <= DEGENERATE_AREA * extent_sq {
            return None;
        }
        let mean = self.first / self.area;
        Some(self.second * (1.0 / self.area) - outer(mean, mean))
    }
}

/// A run of triangles to fit a bounding volume to: their corners and their summed moments.
#[derive(Clone, Copy, Debug)]
pub struct TriangleSet<'a> {
    corners: &'a [[Vec3; 3]],
    surface: SurfaceMoments,
}

impl<'a> TriangleSet<'a> {
    /// The triangles `corners`, their moments integrated here.
    pub fn new(corners: &'a [[Vec3; 3]]) -> Self {
        Self::with_surface(corners, SurfaceMoments::of_triangles(corners))
    }

    /// The triangles `corners`, whose moments summed are `surface` (the builder's promise: it
    /// sums them bottom-up; a mismatch would give boxes that miss triangles).
    pub(crate) fn with_surface(corners: &'a [[Vec3; 3]], surface: SurfaceMoments) -> Self {
        Self { corners, surface }
    }

    /// The triangles' corners.
    pub fn corners(&self) -> &'a [[Vec3; 3]] {
        self.corners
    }

    /// Every corner, triangle by triangle (shared vertices repeat).
    pub fn points(&self) -> impl Iterator<Item = Vec3> + Clone + 'a {
        self.corners.iter().flatten().copied()
    }

    /// The triangles' summed moments.
    pub fn surface(&self) -> &SurfaceMoments {
        &self.surface
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corners(seed: u32, n: usize) -> Vec<[Vec3; 3]> {
        let mut rng = crate::test_rng::TestRng::new(u64::from(seed));
        (0..n)
            .map(|_| std::array::from_fn(|_| rng.vec3(-1.0, 1.0)))
            .collect()
    }

    /// The builder's bottom-up sums (about a shared far origin) give the covariance of the
    /// whole surface integrated afresh about its own first corner, to 1e-9 of its size.
    #[test]
    fn summed_halves_give_the_whole_surface_covariance_within_1e_9() {
        let tris = corners(7, 40);
        let origin = Vec3::new(30.0, -20.0, 10.0);
        let sum = |part: &[[Vec3; 3]]| {
            part.iter().fold(SurfaceMoments::empty(origin), |s, &t| {
                s.plus(&SurfaceMoments::of_triangle(t, origin))
            })
        };
        let summed = sum(&tris[..17]).plus(&sum(&tris[17..]));
        let direct = SurfaceMoments::of_triangles(&tris);
        let (a, b) = (summed.covariance().unwrap(), direct.covariance().unwrap());
        let scale = b
            .abs()
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, x| m.max(*x));
        let worst = (a - b)
            .abs()
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, x| m.max(*x));
        assert!(worst <= 1e-9 * scale, "{worst} of {scale}");
        assert!((summed.area() - direct.area()).abs() <= 1e-9 * direct.area());
        assert_eq!(summed.bounds(), direct.bounds());
    }

    #[test]
    fn slivers_and_empty_sets_have_no_surface_covariance() {
        let p = Vec3::new(1.0, 2.0, 3.0);
        let sliver = [p, p + Vec3::X, p + Vec3::X * 2.0];
        assert!(
            SurfaceMoments::of_triangles(&[sliver])
                .covariance()
                .is_none()
        );
        assert!(SurfaceMoments::of_triangles(&[]).covariance().is_none());
        assert!(!SurfaceMoments::of_triangles(&[]).bounds().is_valid());
    }
}
