//! The first 16 vertices of a convex hull in SIMD lanes (structure of arrays, `wide::f32x4`),
//! for the support function: GJK and EPA ask a hull for its farthest vertex tens of times per
//! pair, and a small hull (all of it in the lanes) answers with 12 multiply–adds and one
//! reduction instead of a dot product and a compare per vertex (Jolt and parry keep hull
//! vertices for the same scan; Box2D v3's `b2FloatW` lanes are the same idea for contacts).
//! A larger hull starts its hill climb from the lanes' answer.

use glam::Vec3;
use wide::f32x4;

/// Vertices held in lanes.
pub(crate) const LANE_VERTICES: usize = 16;

/// Up to [`LANE_VERTICES`] vertices, lane `j` of chunk `c` holding vertex `4c + j`; the unused
/// lanes repeat vertex 0 (so they tie with it and never win: the lowest index wins a tie).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct HullLanes {
    x: [f32x4; 4],
    y: [f32x4; 4],
    z: [f32x4; 4],
    /// Chunks in use.
    chunks: usize,
}

impl HullLanes {
    /// The first [`LANE_VERTICES`] of `vertices` (at least one).
    pub fn new(vertices: &[Vec3]) -> Self {
        let first = vertices.first().copied().unwrap_or(Vec3::ZERO);
        let at = |i: usize| vertices.get(i).copied().unwrap_or(first);
        let lanes = |c: usize, axis: usize| f32x4::new([0, 1, 2, 3].map(|j| at(4 * c + j)[axis]));
        Self {
            x: [0, 1, 2, 3].map(|c| lanes(c, 0)),
            y: [0, 1, 2, 3].map(|c| lanes(c, 1)),
            z: [0, 1, 2, 3].map(|c| lanes(c, 2)),
            chunks: vertices.len().clamp(1, LANE_VERTICES).div_ceil(4),
        }
    }

    /// Index of the held vertex farthest along `dir`, the lowest on a tie: what a scalar scan
    /// with a strict `>` finds, bit for bit (each dot product is summed in the same order).
    pub fn farthest(&self, dir: Vec3) -> usize {
        let (dx, dy, dz) = (
            f32x4::splat(dir.x),
            f32x4::splat(dir.y),
            f32x4::splat(dir.z),
        );
        let mut best = f32x4::splat(f32::MIN);
        let mut index = f32x4::splat(0.0);
        for c in 0..self.chunks {
            let height = self.x[c] * dx + self.y[c] * dy + self.z[c] * dz;
            let higher = height.simd_gt(best);
            best = higher.select(height, best);
            let ids = f32x4::new([0.0, 1.0, 2.0, 3.0]) + f32x4::splat(4.0 * c as f32);
            index = higher.select(ids, index);
        }
        let (best, index) = (best.to_array(), index.to_array());
        let mut winner = 0;
        for j in 1..4 {
            let better = best[j] > best[winner];
            let tie_lower = best[j] == best[winner] && index[j] < index[winner];
            if better || tie_lower {
                winner = j;
            }
        }
        index[winner] as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    /// The scalar rule the lanes replace: the first vertex with the largest dot product.
    fn scan(v: &[Vec3], dir: Vec3) -> usize {
        let mut best = (0, f32::MIN);
        for (i, p) in v.iter().take(LANE_VERTICES).enumerate() {
            if p.dot(dir) > best.1 {
                best = (i, p.dot(dir));
            }
        }
        best.0
    }

    #[test]
    fn the_lanes_find_the_scalar_scans_vertex_on_every_count_and_ties_on_2000_draws() {
        let mut rng = TestRng::new(16);
        for k in 0..2000 {
            let n = 1 + k % 20;
            let mut v: Vec<Vec3> = (0..n).map(|_| rng.vec3(-1.0, 1.0)).collect();
            if k % 3 == 0 && n > 2 {
                v[n - 1] = v[1]; // a repeated vertex: a tie the lower index wins
            }
            let dir = if k % 7 == 0 {
                Vec3::ZERO
            } else {
                rng.vec3(-1.0, 1.0)
            };
            assert_eq!(
                HullLanes::new(&v).farthest(dir),
                scan(&v, dir),
                "{n} vertices"
            );
        }
    }
}
