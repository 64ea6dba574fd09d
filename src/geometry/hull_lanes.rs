//! A small hull's support scan four vertices at a time (`wide::f32x4`, the structure-of-arrays
//! layout Box2D v3 and rapier use for their wide solvers): GJK and EPA ask a hull for its
//! support point several dozen times per pair, and for the random 16-point hulls of the contact
//! bench the scalar scan over the vertices was the largest single cost (15 % of a hull–hull
//! manifold, by callgrind).
//!
//! The answer is the scalar scan's, bit for bit: each dot product is `(x·dx + y·dy) + z·dz` in
//! that order (glam's `Vec3::dot`), a lane takes a new vertex only when it is strictly higher,
//! and the lanes are merged by value, then by the smaller index, so a tie still goes to the
//! first vertex. Padding lanes repeat vertex 0, which can never win over it.

use glam::Vec3;
use wide::f32x4;

/// How many of a hull's vertices are scanned (all of a hull this small; a larger hull climbs
/// its vertex graph from the best of these).
pub(crate) const SCANNED_VERTICES: usize = 16;

/// Groups of four vertices scanned.
const GROUPS: usize = SCANNED_VERTICES / 4;

/// The first [`SCANNED_VERTICES`] vertices of a hull, four to a group, coordinate by
/// coordinate.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SupportLanes {
    /// Per group: the x, y and z of its four vertices.
    groups: [[[f32; 4]; 3]; GROUPS],
    /// Groups holding at least one vertex.
    used: usize,
}

impl SupportLanes {
    /// The lanes of `vertices`' first [`SCANNED_VERTICES`].
    pub(crate) fn new(vertices: &[Vec3]) -> Self {
        let scanned = &vertices[..vertices.len().min(SCANNED_VERTICES)];
        let pad = scanned.first().copied().unwrap_or(Vec3::ZERO);
        let mut groups = [[[0.0; 4]; 3]; GROUPS];
        for (g, group) in groups.iter_mut().enumerate() {
            for lane in 0..4 {
                let v = scanned.get(4 * g + lane).copied().unwrap_or(pad);
                for (axis, coordinate) in group.iter_mut().enumerate() {
                    coordinate[lane] = v[axis];
                }
            }
        }
        Self {
            groups,
            used: scanned.len().div_ceil(4),
        }
    }

    /// The index of the scanned vertex farthest along `dir`, the first on a tie; 0 when there is
    /// none or no dot product is above `f32::MIN` (a NaN direction).
    pub(crate) fn farthest(&self, dir: Vec3) -> usize {
        let [dx, dy, dz] = [dir.x, dir.y, dir.z].map(f32x4::splat);
        let mut best = f32x4::splat(f32::MIN);
        let mut index = f32x4::ZERO;
        for (g, [x, y, z]) in self.groups[..self.used].iter().enumerate() {
            let dot = f32x4::from(*x) * dx + f32x4::from(*y) * dy + f32x4::from(*z) * dz;
            let higher = dot.simd_gt(best);
            best = higher.select(dot, best);
            let ids = f32x4::from([0.0, 1.0, 2.0, 3.0]) + f32x4::splat(4.0 * g as f32);
            index = higher.select(ids, index);
        }
        // The lanes merged without branches (a branch per lane on which one is ahead depends
        // on the data, and the scalar merge took most of this function's samples): the highest
        // value, then the smallest index holding it. No lane holds a NaN (`simd_gt` never
        // takes one), so `max` is exact.
        let (best, index) = (best.to_array(), index.to_array());
        let top = best[0].max(best[1]).max(best[2].max(best[3]));
        let at = |lane: usize| {
            if best[lane] == top {
                index[lane]
            } else {
                f32::MAX
            }
        };
        let winner = at(0).min(at(1)).min(at(2).min(at(3)));
        // Indices are small whole numbers, exact in f32; converted through `i32`, whose
        // saturating conversion is shorter than `usize`'s (no branch-free fix-up above 2^63).
        winner as i32 as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    /// The scalar scan: the first index with the largest dot product (0 if none).
    fn scalar(vertices: &[Vec3], dir: Vec3) -> usize {
        let n = vertices.len().min(SCANNED_VERTICES);
        let better = |b: (usize, f32), x: (usize, f32)| if x.1 > b.1 { x } else { b };
        (0..n)
            .map(|i| (i, vertices[i].dot(dir)))
            .fold((0, f32::MIN), better)
            .0
    }

    #[test]
    fn the_lanes_pick_the_scalar_scan_s_vertex_on_20_000_directions_ties_and_nan_included() {
        let mut rng = TestRng::new(31);
        for k in 0..20_000 {
            let n = 1 + k % 20;
            let mut vertices: Vec<Vec3> = (0..n).map(|_| rng.vec3(-1.0, 1.0)).collect();
            // Ties: repeated vertices, a face of equal heights, a zero or NaN direction.
            if k % 3 == 0 && n > 2 {
                vertices[n - 1] = vertices[0];
                vertices[n / 2] = vertices[1];
            }
            let dir = match k % 50 {
                0 => Vec3::ZERO,
                1 => Vec3::new(f32::NAN, 0.0, 1.0),
                2 => Vec3::Z,
                _ => rng.vec3(-1.0, 1.0),
            };
            let lanes = SupportLanes::new(&vertices);
            assert_eq!(lanes.farthest(dir), scalar(&vertices, dir), "{k}: {dir}");
        }
        assert_eq!(SupportLanes::new(&[]).farthest(Vec3::X), 0);
    }
}
