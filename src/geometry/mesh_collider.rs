//! A triangle mesh ready to collide: the validated [`TriMesh`] and its OBB hierarchy, built
//! once and shared.
//!
//! The slides' polygon-mesh objects are tested pairwise through a bounding-volume hierarchy
//! ("Gerarchie di bounding volumes"); the hierarchy lives in the mesh's own frame and is never
//! rebuilt when the body moves (the pose comes with every query). OBBs (Gottschalk, Lin and
//! Manocha 1996, "OBBTree") are the BV kind: `examples/bvh_costs.rs` measured them fastest for
//! mesh–mesh queries in this crate, their tighter fit outweighing the dearer 15-axis test.
//!
//! A [`MeshCollider`] is a handle (`Arc`): cloning it is cheap, so many bodies can share one mesh,
//! and two handles compare equal only when they share the same data (comparing thousands of
//! vertices to detect a change would cost more than it saves).

use crate::bounding::{Aabb, Obb};
use crate::bvh::{BuildOptions, Bvh, BvhError};
use crate::geometry::mesh_io::MeshLoadError;
use crate::geometry::{Isometry, MeshError, TriMesh};
use glam::{Mat3, Vec3};
use std::fmt;
use std::sync::Arc;

/// Why a mesh collider could not be made.
#[derive(Debug)]
pub enum MeshColliderError {
    /// The file could not be read or parsed (see [`MeshLoadError`]).
    Load(MeshLoadError),
    /// The vertex and index arrays do not make a valid mesh: empty, non-finite, indices out of
    /// range, every triangle degenerate (see [`MeshError`]).
    Mesh(MeshError),
    /// The hierarchy could not be built (see [`BvhError`]; a validated mesh only fails here
    /// with more than `u32::MAX` triangles).
    Hierarchy(BvhError),
}

impl fmt::Display for MeshColliderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Load(e) => write!(f, "cannot load the mesh collider: {e}"),
            Self::Mesh(e) => write!(f, "invalid mesh collider: {e}"),
            Self::Hierarchy(e) => write!(f, "cannot build the mesh collider's hierarchy: {e}"),
        }
    }
}

impl std::error::Error for MeshColliderError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Load(e) => Some(e),
            Self::Mesh(e) => Some(e),
            Self::Hierarchy(e) => Some(e),
        }
    }
}

impl From<MeshLoadError> for MeshColliderError {
    fn from(e: MeshLoadError) -> Self {
        Self::Load(e)
    }
}

impl From<MeshError> for MeshColliderError {
    fn from(e: MeshError) -> Self {
        Self::Mesh(e)
    }
}

impl From<BvhError> for MeshColliderError {
    fn from(e: BvhError) -> Self {
        Self::Hierarchy(e)
    }
}

/// The shared data behind a [`MeshCollider`].
struct MeshData {
    name: String,
    mesh: TriMesh,
    bvh: Bvh<Obb>,
    /// For each triangle, the index of the leaf node holding it (for debug output).
    leaf_of_triangle: Vec<u32>,
    /// Farthest vertex from the local origin.
    bounding_radius: f32,
    /// Per triangle, its active edges (see [`active_edges`](crate::geometry::active_edges)).
    active_edges: Vec<u8>,
}

/// A triangle mesh with its OBB hierarchy, in the mesh's local frame; a cheap, shareable handle.
#[derive(Clone)]
pub struct MeshCollider {
    data: Arc<MeshData>,
}

impl fmt::Debug for MeshCollider {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MeshCollider")
            .field("name", &self.data.name)
            .field("triangles", &self.data.mesh.triangle_count())
            .field("vertices", &self.data.mesh.vertex_count())
            .field("bvh_nodes", &self.data.bvh.nodes().len())
            .finish()
    }
}

/// Equal when both handles share the same data (see the module notes).
impl PartialEq for MeshCollider {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.data, &other.data)
    }
}

impl MeshCollider {
    /// Builds the hierarchy of `mesh` (binned SAH, default leaf size), named `"mesh"`.
    ///
    /// A mesh of a few thousand triangles or more is built on scoped threads, as many as the
    /// machine has ([`BuildOptions::threads`] `0`), joined before this returns; the tree is
    /// the same as a one-thread build's. A game that wants the build off its main thread calls
    /// this from a task of its own.
    pub fn new(mesh: TriMesh) -> Result<Self, MeshColliderError> {
        Self::named("mesh", mesh)
    }

    /// Like [`MeshCollider::new`], with a name shown by debug output (the rerun recording).
    pub fn named(name: impl Into<String>, mesh: TriMesh) -> Result<Self, MeshColliderError> {
        let bvh = Bvh::<Obb>::build(mesh.vertices(), mesh.triangles(), &BuildOptions::default())?;
        let mut leaf_of_triangle = vec![0u32; mesh.triangle_count()];
        for (index, node) in bvh.nodes().iter().enumerate() {
            for &t in bvh.leaf_triangles(node) {
                // Node indices fit in u32: the hierarchy stores its child links as u32.
                leaf_of_triangle[t as usize] = index as u32;
            }
        }
        let bounding_radius = mesh
            .triangles()
            .iter()
            .flatten()
            .fold(0.0f32, |r, &i| r.max(mesh.vertices()[i as usize].length()));
        let active_edges = crate::geometry::active_edges::active_edges(&mesh);
        Ok(Self {
            data: Arc::new(MeshData {
                name: name.into(),
                mesh,
                bvh,
                leaf_of_triangle,
                bounding_radius,
                active_edges,
            }),
        })
    }

    /// Validates the arrays into a [`TriMesh`] (see its rules) and builds the collider.
    pub fn from_arrays(
        vertices: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self, MeshColliderError> {
        Self::new(TriMesh::new(vertices, triangles)?)
    }

    /// Loads an OBJ, STL or PLY file (by extension, see [`load`](crate::geometry::mesh_io::load)) and builds the
    /// collider, named after the file's stem.
    #[cfg(feature = "mesh-io")]
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<Self, MeshColliderError> {
        let path = path.as_ref();
        let mesh = crate::geometry::mesh_io::load(path)?;
        let name = path
            .file_stem()
            .map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned());
        Self::named(name, mesh)
    }

    /// The name given at construction.
    pub fn name(&self) -> &str {
        &self.data.name
    }

    /// The triangles, in the local frame.
    pub fn mesh(&self) -> &TriMesh {
        &self.data.mesh
    }

    /// The hierarchy over [`MeshCollider::mesh`]'s triangles.
    pub fn bvh(&self) -> &Bvh<Obb> {
        &self.data.bvh
    }

    /// Index (in [`Bvh::nodes`]) of the leaf holding triangle `t`, or `None` past the end.
    pub fn leaf_of_triangle(&self, t: u32) -> Option<u32> {
        self.data.leaf_of_triangle.get(t as usize).copied()
    }

    /// Triangle `t`'s active edges: bit `k` for its edge from corner `k` to corner `k + 1`
    /// (see [`active_edges`](crate::geometry::active_edges)); all three past the end.
    pub fn active_edges(&self, t: u32) -> u8 {
        use crate::geometry::active_edges::ALL_EDGES_ACTIVE;
        self.data
            .active_edges
            .get(t as usize)
            .copied()
            .unwrap_or(ALL_EDGES_ACTIVE)
    }

    /// Radius of the smallest origin-centred ball holding the triangles.
    pub fn bounding_radius(&self) -> f32 {
        self.data.bounding_radius
    }

    /// The box of the triangles in the local frame.
    pub fn local_aabb(&self) -> Aabb {
        self.data.mesh.local_aabb()
    }

    /// The world AABB of the mesh at `pose`: the intersection of the transformed local AABB and
    /// the transformed root OBB, which both hold the mesh (the OBB is the tighter one when the
    /// mesh is turned away from its local axes, the AABB when it is not).
    pub fn world_aabb(&self, pose: &Isometry) -> Aabb {
        let by_aabb = self.local_aabb().transformed(pose);
        let root = self.data.bvh.root().bv;
        let axes = pose.rotation_matrix() * root.axes;
        let abs = Mat3::from_cols(axes.x_axis.abs(), axes.y_axis.abs(), axes.z_axis.abs());
        let by_obb = Aabb::from_center_half_extents(
            pose.transform_point(root.center),
            abs * root.half_extents,
        );
        let meet = Aabb::new(by_aabb.min.max(by_obb.min), by_aabb.max.min(by_obb.max));
        // Both hold the mesh, so they meet; rounding could still cross a flat side.
        if meet.is_valid() {
            meet
        } else {
            by_aabb.union(&by_obb)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::Bv;
    use glam::Quat;

    #[test]
    fn world_box_holds_every_vertex_and_beats_the_rotated_local_box() {
        let mesh = TriMesh::cuboid(Vec3::new(2.0, 0.5, 0.25)).unwrap();
        let collider = MeshCollider::new(mesh).unwrap();
        let pose = Isometry::new(
            Vec3::new(1.0, -2.0, 3.0),
            Quat::from_euler(glam::EulerRot::XYZ, 0.4, 0.9, -0.3),
        );
        let world = collider.world_aabb(&pose);
        for v in collider.mesh().vertices() {
            assert!(
                world
                    .expanded(1e-5)
                    .contains_point(pose.transform_point(*v))
            );
        }
        assert!(world.volume() <= collider.local_aabb().transformed(&pose).volume() + 1e-4);
        assert!((collider.bounding_radius() - Vec3::new(2.0, 0.5, 0.25).length()).abs() < 1e-6);
    }

    #[test]
    fn handles_compare_by_identity_and_map_triangles_to_leaves() {
        let mesh = TriMesh::uv_sphere(1.0, 16, 8).unwrap();
        let a = MeshCollider::new(mesh.clone()).unwrap();
        let b = MeshCollider::new(mesh).unwrap();
        assert_eq!(a, a.clone());
        assert_ne!(a, b);
        for t in 0..a.mesh().triangle_count() as u32 {
            let leaf = a.leaf_of_triangle(t).unwrap();
            let node = &a.bvh().nodes()[leaf as usize];
            assert!(a.bvh().leaf_triangles(node).contains(&t));
            let tri = a.mesh().triangle(t as usize).unwrap();
            assert!(
                tri.vertices()
                    .iter()
                    .all(|&p| node.bv.contains_point(p, 1e-6))
            );
        }
        assert_eq!(a.leaf_of_triangle(u32::MAX), None);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            MeshCollider::from_arrays(vec![], vec![]),
            Err(MeshColliderError::Mesh(MeshError::NoVertices))
        ));
        let flat = vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        assert!(matches!(
            MeshCollider::from_arrays(flat, vec![[0, 1, 2]]),
            Err(MeshColliderError::Mesh(
                MeshError::AllTrianglesDegenerate { .. }
            ))
        ));
        let nan = vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, f32::NAN, 0.0)];
        assert!(MeshCollider::from_arrays(nan, vec![[0, 1, 2]]).is_err());
    }

    #[cfg(feature = "mesh-io")]
    #[test]
    fn a_missing_or_unknown_file_is_an_error() {
        let missing = MeshCollider::from_file("no/such/file.ply").unwrap_err();
        assert!(missing.to_string().contains("cannot load"), "{missing}");
        assert!(matches!(
            MeshCollider::from_file("mesh.xyz"),
            Err(MeshColliderError::Load(MeshLoadError::UnknownFormat(_)))
        ));
    }
}
