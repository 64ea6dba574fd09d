//! The yes/no mesh–mesh query in the public API: do two mesh colliders touch at a pose?
//!
//! It is the lecture's early-out query ("Gerarchie di bounding volumes": descend both OBB
//! hierarchies, splitting the larger volume first, and stop at the first pair of triangles that
//! meet), so a user need not assemble it from [`Bvh::first_intersecting_pair`] and a triangle
//! closure. Exact: the leaves are decided by the triangle–triangle test
//! ([`tri_tri_intersect`], Möller's interval test with exact predicates), never by the boxes.
//!
//! [`Bvh::first_intersecting_pair`]: crate::bvh::Bvh::first_intersecting_pair

use crate::bvh::{QueryScratch, TraversalOrder};
use crate::geometry::{Isometry, MeshCollider, tri_tri_intersect};
use std::fmt;

/// A pose a query cannot use: a NaN or infinite part, or a rotation that is not a unit
/// quaternion (within 1e-3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BadPose(pub Isometry);

impl fmt::Display for BadPose {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "pose ({}, {}) is not finite or its rotation is not a unit quaternion",
            self.0.translation, self.0.rotation
        )
    }
}

impl std::error::Error for BadPose {}

impl MeshCollider {
    /// Whether this mesh and `other`, placed by `pose` (`other`'s frame in this one's), touch:
    /// some triangle of one meets some triangle of the other. Stops at the first such pair.
    /// Two meshes one inside the other without their surfaces meeting do not touch.
    pub fn intersects(&self, other: &MeshCollider, pose: &Isometry) -> Result<bool, BadPose> {
        self.intersects_with(other, pose, &mut QueryScratch::new())
    }

    /// [`intersects`](Self::intersects) with the caller's buffers, for many queries in a row
    /// without allocating.
    pub fn intersects_with(
        &self,
        other: &MeshCollider,
        pose: &Isometry,
        scratch: &mut QueryScratch,
    ) -> Result<bool, BadPose> {
        if !pose.is_finite() || (pose.rotation.length() - 1.0).abs() > 1e-3 {
            return Err(BadPose(*pose));
        }
        let pose = Isometry::new(pose.translation, pose.rotation.normalize());
        let (mine, theirs) = (self.mesh(), other.mesh());
        let (found, _) = self.bvh().first_intersecting_pair(
            other.bvh(),
            &pose,
            TraversalOrder::DepthFirst,
            scratch,
            |a, b| match (mine.triangle(a as usize), theirs.triangle(b as usize)) {
                (Some(a), Some(b)) => tri_tri_intersect(&a, &b.transformed(&pose)),
                _ => false,
            },
        );
        Ok(found.is_some())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::TriMesh;
    use glam::{Quat, Vec3};

    /// A deterministic spread of poses around the origin within `reach`, turned every way.
    fn poses(count: usize, reach: f32) -> impl Iterator<Item = Isometry> {
        (0..count).map(move |i| {
            let t = i as f32;
            let at = Vec3::new((t * 0.73).sin(), (t * 1.31).cos(), (t * 0.37).sin()) * reach;
            let turn = Quat::from_euler(glam::EulerRot::XYZ, t * 0.9, t * 0.41, t * 1.7);
            Isometry::new(at, turn)
        })
    }

    #[test]
    fn intersects_agrees_with_brute_force_on_400_poses_of_a_sphere_and_a_torus() {
        let sphere = MeshCollider::new(TriMesh::uv_sphere(1.0, 24, 12).unwrap()).unwrap();
        let torus = MeshCollider::new(TriMesh::torus(1.0, 0.3, 24, 12).unwrap()).unwrap();
        let mut scratch = QueryScratch::new();
        let (mut hits, mut misses) = (0, 0);
        for pose in poses(400, 2.2) {
            let fast = sphere.intersects_with(&torus, &pose, &mut scratch).unwrap();
            let slow = sphere.mesh().intersects_brute_force(torus.mesh(), &pose);
            assert_eq!(fast, slow, "{pose:?}");
            if fast {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        // Both answers occur, so the agreement means something.
        assert!(hits > 50 && misses > 50, "{hits} hits, {misses} misses");
    }

    #[test]
    fn a_small_sphere_inside_a_big_one_does_not_touch_it_and_a_bad_pose_is_an_error() {
        let big = MeshCollider::new(TriMesh::uv_sphere(2.0, 16, 8).unwrap()).unwrap();
        let small = MeshCollider::new(TriMesh::uv_sphere(0.5, 16, 8).unwrap()).unwrap();
        assert_eq!(big.intersects(&small, &Isometry::default()), Ok(false));
        let touching = Isometry::new(Vec3::X * 1.8, Quat::IDENTITY);
        assert_eq!(big.intersects(&small, &touching), Ok(true));
        for bad in [
            Isometry::new(Vec3::NAN, Quat::IDENTITY),
            Isometry::new(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 2.0)),
            Isometry::new(Vec3::ZERO, Quat::from_xyzw(f32::INFINITY, 0.0, 0.0, 1.0)),
        ] {
            let err = big.intersects(&small, &bad).unwrap_err();
            assert!(err.to_string().contains("not finite"), "{err}");
        }
    }
}
