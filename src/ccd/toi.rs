//! The answer of a time-of-impact query, and the dispatch of a sweep against any [`Shape`].

use super::{
    SphereSweep, toi_sphere_capsule, toi_sphere_convex, toi_sphere_cuboid, toi_sphere_halfspace,
    toi_sphere_sphere, toi_sphere_trimesh,
};
use crate::bvh::QueryScratch;
use crate::geometry::{Isometry, Shape};
use glam::Vec3;

/// The first contact of a sweep with an obstacle (see the [module conventions](super)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Toi {
    /// Fraction of the displacement travelled at impact, in `[0, 1]`.
    pub t: f32,
    /// Unit normal from the obstacle toward the sphere at impact: the direction that separates
    /// them, about which a response reflects the velocity.
    pub normal: Vec3,
    /// World-space contact point at time `t` (on both surfaces for an impact at `t > 0`; for a
    /// contact already at `t = 0`, the static test's point midway between the surfaces).
    pub point: Vec3,
}

/// A [`Toi`] against a triangle mesh, with the triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshToi {
    /// The impact, in world space.
    pub toi: Toi,
    /// Index of the triangle hit, into [`TriMesh::triangles`](crate::geometry::TriMesh::triangles).
    pub triangle: u32,
}

/// Time of impact of the sweep against `shape` placed at `pose` (static), dispatching to the
/// pair's query; a mesh is swept through its BVH with the reusable `scratch`.
pub fn toi_sphere_shape(
    sweep: &SphereSweep,
    shape: &Shape,
    pose: &Isometry,
    scratch: &mut QueryScratch,
) -> Option<Toi> {
    match shape {
        Shape::Sphere(s) => toi_sphere_sphere(sweep, pose.translation, s),
        Shape::Cuboid(c) => toi_sphere_cuboid(sweep, pose, c),
        Shape::HalfSpace(h) => toi_sphere_halfspace(sweep, pose, h),
        Shape::Capsule(c) => toi_sphere_capsule(sweep, pose, c),
        Shape::Cylinder(_) | Shape::Cone(_) | Shape::Ellipsoid(_) | Shape::ConvexHull(_) => {
            toi_sphere_convex(sweep, shape, pose)
        }
        Shape::TriMesh(m) => toi_sphere_trimesh(sweep, m.mesh(), m.bvh(), pose, scratch)
            .0
            .map(|hit| hit.toi),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn dispatch_reaches_every_shape() {
        let sweep = SphereSweep::new(Vec3::new(0.0, 0.0, 5.0), 0.5, Vec3::new(0.0, 0.0, -10.0));
        let sweep = sweep.unwrap();
        let pose = Isometry::new(Vec3::ZERO, Quat::from_rotation_z(0.3));
        // Each obstacle's top is at z = 1 (the half-space through z = 1), so impact at z = 1.5.
        let cases = [
            (Shape::sphere(1.0), 0.35),
            (Shape::cuboid(Vec3::ONE), 0.35),
            (Shape::capsule(0.5, 0.5), 0.35),
            (
                Shape::half_space(Vec3::Z),
                (5.0 - 0.5) / 10.0, // plane through the origin
            ),
        ];
        for (shape, expected_t) in cases {
            let mut scratch = QueryScratch::new();
            let toi = toi_sphere_shape(&sweep, &shape, &pose, &mut scratch).expect("head-on hit");
            assert!((toi.t - expected_t).abs() < 1e-6, "{shape:?}: {toi:?}");
            assert!((toi.normal - Vec3::Z).length() < 1e-6);
        }
    }
}
