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
use crate::geometry::active_edges::ALL_EDGES_ACTIVE;
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
    /// Per triangle, its active edges (bits 0–2) and flat edges (bits 3–5; see
    /// [`active_edges`](crate::geometry::active_edges)).
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
        Self::with_hierarchy(name, mesh, &BuildOptions::default())
    }

    /// Like [`MeshCollider::named`], with the hierarchy built by `options`: the split rule, the
    /// leaf size and the build's threads. The leaf size trades memory and build time for query
    /// time; on two 20k-triangle tori (`examples/bvh_costs.rs`, binned SAH, OBBs), against the
    /// default 4: leaves of 1 took 2.3× the build time and 3.1× the memory for all-pairs
    /// queries 19 % faster; leaves of 16 built in 0.58× the time and 0.35× the memory and
    /// queried 2.7–3.3× slower. The median split was no faster to build than binned SAH there
    /// (12.9 against 10.3 ms) and 1.3× slower to query. To measure a mesh of your own:
    /// `URTO_BVH_MESH=your.obj cargo run --release --example bvh_costs` prints build time,
    /// memory and query times per BV kind, rule and traversal order (`URTO_BVH_LEAF_SIZE` sets
    /// the leaf size). The BV kind stays the OBB, measured fastest there for the mesh pair
    /// queries this crate makes.
    ///
    /// Options the hierarchy cannot be built with (a leaf size of 0, a bin count outside
    /// `2..=`[`MAX_SAH_BINS`](crate::bvh::MAX_SAH_BINS)) are [`MeshColliderError::Hierarchy`].
    pub fn with_hierarchy(
        name: impl Into<String>,
        mesh: TriMesh,
        options: &BuildOptions,
    ) -> Result<Self, MeshColliderError> {
        let bvh = Bvh::<Obb>::build(mesh.vertices(), mesh.triangles(), options)?;
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
        self.edge_marks(t) & ALL_EDGES_ACTIVE
    }

    /// Triangle `t`'s flat edges, bit `k` as in [`Self::active_edges`]: inactive edges whose
    /// neighbours are coplanar within
    /// [`FLAT_DEGREES`](crate::geometry::active_edges::FLAT_DEGREES); none past the end.
    pub fn flat_edges(&self, t: u32) -> u8 {
        self.edge_marks(t) >> 3
    }

    fn edge_marks(&self, t: u32) -> u8 {
        let marks = self.data.active_edges.get(t as usize).copied();
        marks.unwrap_or(ALL_EDGES_ACTIVE)
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

    #[test]
    fn every_leaf_size_and_rule_gives_the_same_contacts_within_1e_5_and_bad_options_are_errors() {
        use crate::bvh::BuildRule;
        use crate::geometry::Shape;
        use crate::geometry::contacts::contact;
        let torus = || TriMesh::torus(1.2, 0.4, 48, 24).unwrap();
        let ball = Shape::sphere(0.5);
        let poses: Vec<Isometry> = (0..40)
            .map(|k| {
                let t = k as f32 * 0.37;
                let at = Vec3::new(1.2 * t.cos(), 1.2 * t.sin(), 0.6 * (2.0 * t).sin());
                Isometry::new(at, Quat::IDENTITY)
            })
            .collect();
        let contacts = |options: &BuildOptions| {
            let mesh = MeshCollider::with_hierarchy("torus", torus(), options).unwrap();
            let shape = Shape::TriMesh(mesh);
            poses
                .iter()
                .map(|p| contact(&shape, &Isometry::default(), &ball, p))
                .map(|m| m.map(|m| (m.max_depth(), m.normal)))
                .collect::<Vec<_>>()
        };
        let reference = contacts(&BuildOptions::default());
        assert!(reference.iter().filter(|c| c.is_some()).count() > 10);
        for (rule, leaf_size) in [
            (BuildRule::BinnedSah, 1),
            (BuildRule::BinnedSah, 16),
            (BuildRule::Median, 4),
        ] {
            let options = BuildOptions {
                leaf_size,
                ..BuildOptions::with_rule(rule)
            };
            for (got, want) in contacts(&options).iter().zip(&reference) {
                match (got, want) {
                    (Some((d, n)), Some((dw, nw))) => {
                        assert!((d - dw).abs() < 1e-5 && (*n - *nw).length() < 1e-5)
                    }
                    (None, None) => {}
                    _ => panic!("{rule:?} leaves of {leaf_size}: {got:?} against {want:?}"),
                }
            }
        }
        for (options, error) in [
            (
                BuildOptions {
                    leaf_size: 0,
                    ..BuildOptions::default()
                },
                BvhError::BadLeafSize(0),
            ),
            (
                BuildOptions {
                    sah_bins: 1,
                    ..BuildOptions::default()
                },
                BvhError::BadBinCount(1),
            ),
        ] {
            match MeshCollider::with_hierarchy("torus", torus(), &options) {
                Err(MeshColliderError::Hierarchy(e)) => assert_eq!(e, error),
                other => panic!("{options:?} gave {other:?}"),
            }
        }
    }
}
