//! Triangle meshes: validated vertex and index arrays in the mesh's local frame.
//!
//! The slides' polygon-mesh objects. The data stay flat (`Vec<Vec3>` and `Vec<[u32; 3]>`, what
//! loaders produce and what a BVH indexes) and never move: a mesh is placed by an
//! [`Isometry`] given with every query.
//!
//! Validation at construction, so that every later query can trust the data:
//! - no vertices or no triangles, a NaN or infinite coordinate, an index out of range: errors;
//! - **degenerate triangles** (a repeated index, or exactly collinear corners: zero area) are
//!   dropped and counted in the [`MeshReport`]. They have no surface, and as segments they could
//!   only add contacts along edges the proper triangles already cover, so a mesh collides as if
//!   they were never there;
//! - duplicate vertices are kept (indices stay as given); [`TriMesh::weld`] merges them on
//!   request;
//! - **open and non-manifold meshes are accepted**: urto collides surfaces, not volumes, so a
//!   mesh needs no inside (an open terrain, a single quad, edges shared by three faces are all
//!   fine). Consequently nothing inside a closed mesh is "in contact" with it until it reaches
//!   the surface.

use crate::bounding::Aabb;
use crate::geometry::{Isometry, Triangle, tri_tri_intersect};
use glam::{DVec3, Vec3};
use std::fmt;

/// What validation (and welding) changed in the data they were given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshReport {
    /// Zero-area triangles (a repeated index or collinear corners) that were dropped.
    pub degenerate_triangles_dropped: usize,
    /// Vertices merged into an earlier one by [`TriMesh::weld`] (0 for a mesh never welded).
    pub vertices_welded: usize,
}

/// Why a mesh cannot be built.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshError {
    /// The vertex list is empty.
    NoVertices,
    /// The triangle list is empty.
    NoTriangles,
    /// More vertices than `u32` indices can address.
    TooManyVertices(usize),
    /// A vertex with a NaN or infinite coordinate.
    NonFiniteVertex {
        /// Position of the vertex in the list.
        index: usize,
        /// Its coordinates.
        position: Vec3,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Position of the triangle in the list.
        triangle: usize,
        /// The offending index.
        index: u32,
        /// How many vertices there are.
        vertex_count: usize,
    },
    /// Every triangle has zero area: nothing is left to collide.
    AllTrianglesDegenerate {
        /// How many triangles were given.
        count: usize,
    },
    /// A construction parameter (weld distance, procedural mesh size…) is out of its domain.
    InvalidParameter(String),
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoVertices => write!(f, "mesh has no vertices"),
            Self::NoTriangles => write!(f, "mesh has no triangles"),
            Self::TooManyVertices(n) => write!(f, "mesh has {n} vertices, more than u32 indexes"),
            Self::NonFiniteVertex { index, position } => {
                write!(f, "vertex {index} is not finite: {position}")
            }
            Self::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "triangle {triangle} refers to vertex {index}, but there are {vertex_count}"
            ),
            Self::AllTrianglesDegenerate { count } => {
                write!(f, "all {count} triangles have zero area")
            }
            Self::InvalidParameter(why) => write!(f, "invalid mesh parameter: {why}"),
        }
    }
}

impl std::error::Error for MeshError {}

/// A validated triangle mesh in its local frame.
#[derive(Clone, Debug, PartialEq)]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    aabb: Aabb,
    report: MeshReport,
}

impl TriMesh {
    /// One id per distinct vertex position, for every vertex: vertices at exactly the same
    /// position share an id (so unwelded meshes, one vertex per triangle corner as STL gives,
    /// have their shared edges recognised), ids numbered in order of first appearance.
    pub(crate) fn position_ids(&self) -> Vec<u32> {
        let mut ids: std::collections::HashMap<[u32; 3], u32> =
            std::collections::HashMap::with_capacity(self.vertex_count());
        // `+ 0.0` turns -0.0 into +0.0, so both zeros are one position.
        let key = |v: &Vec3| (*v + Vec3::ZERO).to_array().map(f32::to_bits);
        self.vertices()
            .iter()
            .map(|v| {
                let next = ids.len() as u32;
                *ids.entry(key(v)).or_insert(next)
            })
            .collect()
    }

    /// Validates and builds a mesh (see the module notes for what is refused, dropped, kept).
    ///
    /// The kept triangles keep their relative order; vertices are kept as given.
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        if vertices.is_empty() {
            return Err(MeshError::NoVertices);
        }
        if triangles.is_empty() {
            return Err(MeshError::NoTriangles);
        }
        if u32::try_from(vertices.len()).is_err() {
            return Err(MeshError::TooManyVertices(vertices.len()));
        }
        if let Some(index) = vertices.iter().position(|v| !v.is_finite()) {
            let position = vertices[index];
            return Err(MeshError::NonFiniteVertex { index, position });
        }
        check_indices(&triangles, vertices.len())?;
        let given = triangles.len();
        let mut triangles = triangles;
        triangles.retain(|&t| !is_degenerate(&vertices, t));
        if triangles.is_empty() {
            return Err(MeshError::AllTrianglesDegenerate { count: given });
        }
        let aabb = Aabb::from_points(triangles.iter().flatten().map(|&i| vertices[i as usize]));
        let report = MeshReport {
            degenerate_triangles_dropped: given - triangles.len(),
            vertices_welded: 0,
        };
        Ok(Self {
            vertices,
            triangles,
            aabb,
            report,
        })
    }

    /// The vertices, as given.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The kept triangles, as vertex indices (every index is in range).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Number of kept triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    /// Triangle `i` with its corner positions, or `None` past the end.
    pub fn triangle(&self, i: usize) -> Option<Triangle> {
        self.triangles.get(i).map(|&t| self.corners(t))
    }

    /// Every triangle with its corner positions, in order.
    pub fn iter_triangles(&self) -> impl ExactSizeIterator<Item = Triangle> + '_ {
        self.triangles.iter().map(|&t| self.corners(t))
    }

    #[inline]
    fn corners(&self, t: [u32; 3]) -> Triangle {
        // Indices were checked against the vertex count at construction. Written out, not
        // `t.map(..)`: the array map stayed out of line, a call per triangle that took 9 % of
        // a ball's query on a terrain.
        let v = &self.vertices;
        Triangle {
            a: v[t[0] as usize],
            b: v[t[1] as usize],
            c: v[t[2] as usize],
        }
    }

    /// The box of the triangles (unreferenced vertices do not widen it), in the local frame.
    pub fn local_aabb(&self) -> Aabb {
        self.aabb
    }

    /// What validation and welding changed.
    pub fn report(&self) -> MeshReport {
        self.report
    }

    /// Total surface area.
    pub fn area(&self) -> f32 {
        self.iter_triangles().map(|t| t.area() as f64).sum::<f64>() as f32
    }

    /// The area-weighted centroid of the surface (not of an enclosed volume: meshes may be
    /// open). Accumulated in `f64`; if the total area underflows, the mean of the corners.
    pub fn centroid(&self) -> Vec3 {
        let (mut weighted, mut total) = (DVec3::ZERO, 0.0);
        for t in self.iter_triangles() {
            let area = t.area() as f64;
            weighted += t.centroid().as_dvec3() * area;
            total += area;
        }
        if total > 0.0 {
            (weighted / total).as_vec3()
        } else {
            let corners = self.iter_triangles().flat_map(|t| t.vertices());
            let sum: DVec3 = corners.map(Vec3::as_dvec3).sum();
            (sum / (3 * self.triangles.len()) as f64).as_vec3()
        }
    }

    pub(crate) fn with_report(mut self, report: MeshReport) -> Self {
        self.report = report;
        self
    }

    /// Every pair `(i, j)` of a triangle `i` of this mesh and `j` of `other` that intersect, with
    /// `other` placed by `pose` in this mesh's frame, in lexicographic order.
    ///
    /// Brute force over all pairs — `n1 * n2` exact triangle tests (only a per-pair box check in
    /// front, which is exact too): the reference that hierarchies are tested against.
    pub fn intersecting_pairs_brute_force(
        &self,
        other: &TriMesh,
        pose: &Isometry,
    ) -> Vec<(u32, u32)> {
        let placed = other.placed_triangles(pose);
        let mut pairs = Vec::new();
        for (i, a) in self.iter_triangles().enumerate() {
            let box_a = a.aabb();
            for (j, (b, box_b)) in placed.iter().enumerate() {
                if box_a.intersects(box_b) && tri_tri_intersect(&a, b) {
                    pairs.push((i as u32, j as u32));
                }
            }
        }
        pairs
    }

    /// True when any triangle of this mesh meets any of `other` placed by `pose` (brute force,
    /// stops at the first hit).
    pub fn intersects_brute_force(&self, other: &TriMesh, pose: &Isometry) -> bool {
        let placed = other.placed_triangles(pose);
        self.iter_triangles().any(|a| {
            let box_a = a.aabb();
            placed
                .iter()
                .any(|(b, box_b)| box_a.intersects(box_b) && tri_tri_intersect(&a, b))
        })
    }

    fn placed_triangles(&self, pose: &Isometry) -> Vec<(Triangle, Aabb)> {
        self.iter_triangles()
            .map(|t| {
                let t = t.transformed(pose);
                (t, t.aabb())
            })
            .collect()
    }
}

fn check_indices(triangles: &[[u32; 3]], vertex_count: usize) -> Result<(), MeshError> {
    for (triangle, t) in triangles.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(MeshError::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            });
        }
    }
    Ok(())
}

/// Zero area: a repeated index, or corners that are exactly collinear.
fn is_degenerate(vertices: &[Vec3], t: [u32; 3]) -> bool {
    t[0] == t[1]
        || t[1] == t[2]
        || t[2] == t[0]
        || Triangle::from(t.map(|i| vertices[i as usize])).is_degenerate()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        (v, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn validation_errors() {
        let (v, t) = quad();
        assert_eq!(TriMesh::new(vec![], t.clone()), Err(MeshError::NoVertices));
        assert_eq!(TriMesh::new(v.clone(), vec![]), Err(MeshError::NoTriangles));
        let mut nan = v.clone();
        nan[2].y = f32::NAN;
        assert!(matches!(
            TriMesh::new(nan, t.clone()),
            Err(MeshError::NonFiniteVertex { index: 2, .. })
        ));
        let mut inf = v.clone();
        inf[3].z = f32::NEG_INFINITY;
        assert!(matches!(
            TriMesh::new(inf, t.clone()),
            Err(MeshError::NonFiniteVertex { index: 3, .. })
        ));
        assert_eq!(
            TriMesh::new(v.clone(), vec![[0, 1, 2], [0, 2, 4]]),
            Err(MeshError::IndexOutOfRange {
                triangle: 1,
                index: 4,
                vertex_count: 4
            })
        );
        let all_flat = vec![[0, 0, 1], [0, 1, 1]];
        assert_eq!(
            TriMesh::new(v, all_flat),
            Err(MeshError::AllTrianglesDegenerate { count: 2 })
        );
    }

    #[test]
    fn degenerate_triangles_are_dropped_and_counted() {
        let (mut v, mut t) = quad();
        v.push(Vec3::new(2.0, 2.0, 0.0)); // collinear with 0 and 2
        t.insert(1, [0, 2, 4]);
        t.push([3, 3, 1]);
        let m = TriMesh::new(v, t).unwrap();
        assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.report().degenerate_triangles_dropped, 2);
        // The unreferenced far vertex does not widen the box.
        assert_eq!(
            m.local_aabb(),
            Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0))
        );
    }

    #[test]
    fn area_and_centroid_weigh_by_area() {
        // A unit square at the origin and a 2×2 square around (3, 0): centroid at
        // (1·0.5 + 4·3) / 5 along x.
        let v = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::Y,
            Vec3::new(2.0, -1.0, 0.0),
            Vec3::new(4.0, -1.0, 0.0),
            Vec3::new(4.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        let m = TriMesh::new(v, t).unwrap();
        assert!((m.area() - 5.0).abs() < 1e-6);
        let expected = Vec3::new((0.5 + 4.0 * 3.0) / 5.0, (0.5 + 0.0) / 5.0, 0.0);
        assert!(
            (m.centroid() - expected).length() < 1e-6,
            "{}",
            m.centroid()
        );
    }

    #[test]
    fn accessors_do_not_panic_past_the_end() {
        let (v, t) = quad();
        let m = TriMesh::new(v, t).unwrap();
        assert_eq!(
            m.triangle(1),
            Some(Triangle::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y))
        );
        assert_eq!(m.triangle(2), None);
        assert_eq!(m.iter_triangles().len(), 2);
    }
}
