//! Welding: merging a mesh's duplicate vertices, so that triangles cut apart by a file format
//! (STL stores every triangle's corners separately; OBJ and PLY exports often split vertices
//! along seams) share their corners again.
//!
//! Deterministic by construction: vertices are visited in index order and each is merged into
//! the **lowest-indexed kept vertex** within the distance, or kept. A uniform hash grid with
//! cells as wide as the distance finds the candidates (the 27 cells around a vertex); it is
//! only looked up, never iterated, and its hasher is fixed, so no hash order reaches the output.

use crate::geometry::{MeshError, MeshReport, TriMesh};
use glam::Vec3;
use std::collections::HashMap;
use std::collections::hash_map::DefaultHasher;
use std::hash::BuildHasherDefault;

type FixedHashMap<K, V> = HashMap<K, V, BuildHasherDefault<DefaultHasher>>;

impl TriMesh {
    /// A copy where every vertex within `epsilon` (Euclidean, inclusive) of an earlier kept
    /// vertex is replaced by it; `epsilon = 0` merges exact duplicates only. Kept vertices keep
    /// their positions and relative order. Triangles that collapse are dropped as at
    /// construction; the [`MeshReport`] adds up both counts.
    ///
    /// Errors: `epsilon` negative, NaN or infinite; every triangle collapsed.
    pub fn weld(&self, epsilon: f32) -> Result<TriMesh, MeshError> {
        if !(epsilon.is_finite() && epsilon >= 0.0) {
            return Err(MeshError::InvalidParameter(format!(
                "weld distance must be finite and >= 0, got {epsilon}"
            )));
        }
        let (vertices, remap) = merge_vertices(self.vertices(), epsilon);
        let triangles = self
            .triangles()
            .iter()
            .map(|t| t.map(|i| remap[i as usize]))
            .collect();
        let welded = TriMesh::new(vertices, triangles)?;
        let report = MeshReport {
            degenerate_triangles_dropped: self.report().degenerate_triangles_dropped
                + welded.report().degenerate_triangles_dropped,
            vertices_welded: self.report().vertices_welded + self.vertex_count()
                - welded.vertex_count(),
        };
        Ok(welded.with_report(report))
    }
}

/// The kept vertices, and for every input vertex the index of its kept representative.
fn merge_vertices(vertices: &[Vec3], epsilon: f32) -> (Vec<Vec3>, Vec<u32>) {
    let mut grid: FixedHashMap<[i64; 3], Vec<u32>> = FixedHashMap::default();
    let mut kept: Vec<Vec3> = Vec::new();
    let mut remap = Vec::with_capacity(vertices.len());
    for &v in vertices {
        let cell = cell_of(v, epsilon);
        let representative = neighbour_cells(cell, epsilon)
            .filter_map(|c| grid.get(&c))
            .flatten()
            .copied()
            .filter(|&k| kept[k as usize].distance(v) <= epsilon)
            .min();
        let index = match representative {
            Some(k) => k,
            None => {
                // `TriMesh::new` checked that vertex indices fit in u32.
                let k = kept.len() as u32;
                kept.push(v);
                grid.entry(cell).or_default().push(k);
                k
            }
        };
        remap.push(index);
    }
    (kept, remap)
}

/// The grid cell of `v`. With `epsilon = 0` the cell is the exact position (`-0.0` and `0.0`
/// share it); float-to-int casts saturate, so far-out coordinates only crowd a cell.
fn cell_of(v: Vec3, epsilon: f32) -> [i64; 3] {
    if epsilon > 0.0 {
        (v / epsilon).floor().to_array().map(|c| c as i64)
    } else {
        (v + Vec3::ZERO).to_array().map(|c| c.to_bits() as i64)
    }
}

/// The cells that can hold a point within `epsilon` of one in `cell` (just `cell` when welding
/// exact duplicates).
fn neighbour_cells(cell: [i64; 3], epsilon: f32) -> impl Iterator<Item = [i64; 3]> {
    let reach: i64 = if epsilon > 0.0 { 1 } else { 0 };
    (-reach..=reach).flat_map(move |dx| {
        (-reach..=reach).flat_map(move |dy| {
            (-reach..=reach).map(move |dz| {
                [
                    cell[0].saturating_add(dx),
                    cell[1].saturating_add(dy),
                    cell[2].saturating_add(dz),
                ]
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles of a unit square stored STL-style: six corners, two pairs duplicated, one
    /// corner of the second copy nudged by 1e-4.
    fn split_square() -> TriMesh {
        let v = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 1e-4),
            Vec3::Y,
        ];
        TriMesh::new(v, vec![[0, 1, 2], [3, 4, 5]]).unwrap()
    }

    #[test]
    fn exact_and_tolerant_welds() {
        let m = split_square();
        let exact = m.weld(0.0).unwrap();
        assert_eq!(exact.vertex_count(), 5);
        assert_eq!(exact.triangles(), &[[0, 1, 2], [0, 3, 4]]);
        assert_eq!(exact.report().vertices_welded, 1);
        let tolerant = m.weld(1e-3).unwrap();
        assert_eq!(tolerant.vertex_count(), 4);
        assert_eq!(tolerant.triangles(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(
            tolerant.vertices()[2],
            Vec3::new(1.0, 1.0, 0.0),
            "the first one is kept"
        );
    }

    #[test]
    fn welding_picks_the_lowest_kept_index_whatever_the_grid() {
        // a, b, c on a line 0.6 apart: with epsilon 1, b merges into a; c is 1.2 from a, so it
        // stays (merging is not transitive through a dropped vertex).
        let v = vec![
            Vec3::ZERO,
            Vec3::X * 0.6,
            Vec3::X * 1.2,
            Vec3::Y * 2.0,
            Vec3::Z * 5.0,
        ];
        let m = TriMesh::new(v, vec![[0, 3, 4], [1, 3, 4], [2, 3, 4]]).unwrap();
        let w = m.weld(1.0).unwrap();
        assert_eq!(
            w.vertices(),
            &[Vec3::ZERO, Vec3::X * 1.2, Vec3::Y * 2.0, Vec3::Z * 5.0]
        );
        assert_eq!(w.triangles(), &[[0, 2, 3], [0, 2, 3], [1, 2, 3]]);
    }

    #[test]
    fn collapsing_triangles_are_dropped_and_bad_distances_refused() {
        let m = split_square();
        assert!(m.weld(-1.0).is_err() && m.weld(f32::NAN).is_err());
        assert!(matches!(
            m.weld(10.0),
            Err(MeshError::AllTrianglesDegenerate { .. })
        ));
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X * 1e-6];
        let m = TriMesh::new(v, vec![[0, 1, 2], [0, 3, 2]]).unwrap();
        let w = m.weld(1e-5).unwrap();
        assert_eq!(w.triangle_count(), 1);
        assert_eq!(w.report().degenerate_triangles_dropped, 1);
    }

    #[test]
    fn negative_zero_is_zero() {
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(-0.0, 0.0, -0.0)];
        let m = TriMesh::new(v, vec![[0, 1, 2], [3, 1, 2]]).unwrap();
        assert_eq!(m.weld(0.0).unwrap().vertex_count(), 3);
    }
}
