//! Discrete oriented polytopes: the intersection of slabs along `k/2` fixed directions (the
//! slides' k-DOP, Klosowski, Held, Mitchell, Sowizral and Zikan 1998, "Efficient collision
//! detection using bounding volume hierarchies of k-DOPs").
//!
//! The directions are the 3 coordinate axes, then the 4 cube diagonals `(±1, ±1, ±1)` (the 14-DOP)
//! or the 6 edge diagonals `(±1, ±1, 0)…` (the 18-DOP), or both (the 26-DOP). They are left
//! unnormalised, as in the paper: a slab is `min ≤ d·x ≤ max` in units of `|d|`, and fitting is
//! additions only.
//!
//! **k-DOPs are not rotation invariant.** Rotated, a k-DOP's slabs no longer lie along the fixed
//! directions, and the paper's answer — refit a k-DOP around the rotated one — is approximate. We
//! keep the hierarchy in the object's frame and use a conservative test instead: each of A's slabs
//! is compared with the exact projection of B's *enclosing box* (its three axis slabs, mapped into
//! A's frame), and symmetrically each of B's slabs with A's enclosing box mapped into B's frame.
//! The box holds the k-DOP, so a separation found this way is real: no false negatives. Without
//! rotation the test is the exact slab-by-slab comparison. The per-query precomputation
//! ([`KdopRelative`]) holds every direction rotated into the other frame, so a node pair costs
//! `2k` dot-product pairs and no matrix product.

use super::{Aabb, Bv, RelativePose, overlap_ratio, rounding_pad};
use crate::geometry::Isometry;
use glam::{Mat3, Vec3};

/// All 13 directions: axes (0..3), cube diagonals (3..7), edge diagonals (7..13).
const ALL_DIRECTIONS: [Vec3; 13] = [
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(0.0, 1.0, 0.0),
    Vec3::new(0.0, 0.0, 1.0),
    Vec3::new(1.0, 1.0, 1.0),
    Vec3::new(1.0, -1.0, 1.0),
    Vec3::new(1.0, 1.0, -1.0),
    Vec3::new(1.0, -1.0, -1.0),
    Vec3::new(1.0, 1.0, 0.0),
    Vec3::new(1.0, 0.0, 1.0),
    Vec3::new(0.0, 1.0, 1.0),
    Vec3::new(1.0, -1.0, 0.0),
    Vec3::new(1.0, 0.0, -1.0),
    Vec3::new(0.0, 1.0, -1.0),
];

/// The directions of a k-DOP with `AXES` slabs; only 7, 9 and 13 exist (a compile error
/// otherwise). The first three are always the coordinate axes.
const fn directions<const AXES: usize>() -> [Vec3; AXES] {
    let picks: &[usize] = match AXES {
        7 => &[0, 1, 2, 3, 4, 5, 6],
        9 => &[0, 1, 2, 7, 8, 9, 10, 11, 12],
        13 => &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12],
        _ => panic!("a k-DOP has 7 (k = 14), 9 (k = 18) or 13 (k = 26) directions"),
    };
    let mut out = [Vec3::ZERO; AXES];
    let mut i = 0;
    while i < AXES {
        out[i] = ALL_DIRECTIONS[picks[i]];
        i += 1;
    }
    out
}

/// A k-DOP with `AXES = k/2` slabs `min[i] ≤ d_i·x ≤ max[i]` along [`Kdop::DIRECTIONS`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kdop<const AXES: usize> {
    /// Lower end of each slab.
    pub min: [f32; AXES],
    /// Upper end of each slab.
    pub max: [f32; AXES],
}

/// The 14-DOP: axes and cube diagonals.
pub type Kdop14 = Kdop<7>;
/// The 18-DOP: axes and edge diagonals.
pub type Kdop18 = Kdop<9>;
/// The 26-DOP: axes, cube and edge diagonals.
pub type Kdop26 = Kdop<13>;

/// The slab directions of one frame carried into the other, stored as separate coordinate
/// arrays (struct of arrays, each contiguous): direction `i` is
/// `(x[i], y[i], z[i])`, its absolute value (plus ε) `(abs_x[i], abs_y[i], abs_z[i])`, and a box
/// centre `c` projects to `dot(direction_i, c) + offset[i]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CarriedDirections<const AXES: usize> {
    x: [f32; AXES],
    y: [f32; AXES],
    z: [f32; AXES],
    abs_x: [f32; AXES],
    abs_y: [f32; AXES],
    abs_z: [f32; AXES],
    offset: [f32; AXES],
}

impl<const AXES: usize> CarriedDirections<AXES> {
    fn new(dirs: [Vec3; AXES], offset: [f32; AXES]) -> Self {
        let eps = super::ABS_ROTATION_EPSILON;
        Self {
            x: dirs.map(|d| d.x),
            y: dirs.map(|d| d.y),
            z: dirs.map(|d| d.z),
            abs_x: dirs.map(|d| d.x.abs() + eps),
            abs_y: dirs.map(|d| d.y.abs() + eps),
            abs_z: dirs.map(|d| d.z.abs() + eps),
            offset,
        }
    }

    /// Centre and radius of the projection of the box `(c, h)` on direction `i`.
    #[inline(always)]
    fn project(&self, i: usize, c: Vec3, h: Vec3) -> (f32, f32) {
        let centre = self.x[i] * c.x + self.y[i] * c.y + self.z[i] * c.z + self.offset[i];
        let radius = self.abs_x[i] * h.x + self.abs_y[i] * h.y + self.abs_z[i] * h.z;
        (centre, radius)
    }
}

/// The relative pose prepared for k-DOP tests: every direction of each frame carried into the
/// other.
#[derive(Clone, Copy, Debug)]
pub struct KdopRelative<const AXES: usize> {
    /// The pose itself.
    pub pose: RelativePose,
    /// A's directions in B's frame, `Rᵀ d_i`, offset `d_i · t` (B's box centre is in B's frame).
    a_in_b: CarriedDirections<AXES>,
    /// B's directions in A's frame, `R d_j`, offset `−(R d_j) · t` (A's box centre is in A's
    /// frame, and `d_j · Rᵀ(c − t) = (R d_j)·c − (R d_j)·t`).
    b_in_a: CarriedDirections<AXES>,
    /// `d_i · t`, for the rotation-free test.
    shift: [f32; AXES],
}

impl<const AXES: usize> Kdop<AXES> {
    /// The slab directions (unnormalised).
    pub const DIRECTIONS: [Vec3; AXES] = directions::<AXES>();

    /// The enclosing box (the three axis slabs) as centre and half extents.
    #[inline(always)]
    fn box_center_half(&self) -> (Vec3, Vec3) {
        let lo = Vec3::new(self.min[0], self.min[1], self.min[2]);
        let hi = Vec3::new(self.max[0], self.max[1], self.max[2]);
        ((lo + hi) * 0.5, (hi - lo) * 0.5)
    }

    /// Exact slab comparison when B is only translated.
    #[inline(always)]
    fn translated_overlap<const ESTIMATE: bool>(
        &self,
        other: &Self,
        rel: &KdopRelative<AXES>,
    ) -> Option<f32> {
        let slack = rel.pose.slack;
        let mut best = 1.0f32;
        for i in 0..AXES {
            let (b_min, b_max) = (other.min[i] + rel.shift[i], other.max[i] + rel.shift[i]);
            if b_min > self.max[i] + slack || b_max < self.min[i] - slack {
                return None;
            }
            if ESTIMATE {
                let ra = (self.max[i] - self.min[i]) * 0.5 + slack;
                let rb = (b_max - b_min) * 0.5;
                let d = (b_max + b_min - self.max[i] - self.min[i]) * 0.5;
                best = best.min(overlap_ratio(ra, rb, d));
            }
        }
        Some(best)
    }

    /// Each slab of `slabs` against the projection of the box `(center, half)` given in the other
    /// frame, through the slab directions carried into that frame; exits at the first slab that
    /// separates (most rejected pairs are rejected by the first few).
    #[inline(always)]
    fn slabs_against_box<const ESTIMATE: bool>(
        slabs: &Self,
        (center, half): (Vec3, Vec3),
        dirs: &CarriedDirections<AXES>,
        which: std::ops::Range<usize>,
        slack: f32,
        mut best: f32,
    ) -> Option<f32> {
        for i in which {
            let (c, r) = dirs.project(i, center, half);
            if c - r > slabs.max[i] + slack || c + r < slabs.min[i] - slack {
                return None;
            }
            if !ESTIMATE {
                continue;
            }
            let ra = (slabs.max[i] - slabs.min[i]) * 0.5 + slack;
            let d = c - (slabs.max[i] + slabs.min[i]) * 0.5;
            best = best.min(overlap_ratio(ra, r, d));
        }
        Some(best)
    }

    #[inline(always)]
    fn overlap_in<const ESTIMATE: bool>(
        &self,
        other: &Self,
        rel: &KdopRelative<AXES>,
    ) -> Option<f32> {
        if rel.pose.rotation_free {
            return self.translated_overlap::<ESTIMATE>(other, rel);
        }
        let slack = rel.pose.slack;
        let (box_a, box_b) = (self.box_center_half(), other.box_center_half());
        // A's slabs against B's box carried into A, and B's slabs against A's box: the three
        // axis slabs of each first (the boxes' face axes, which reject most disjoint pairs),
        // then the diagonal slabs.
        let mut best = 1.0;
        for which in [0..3, 3..AXES] {
            best = Self::slabs_against_box::<ESTIMATE>(
                self,
                box_b,
                &rel.a_in_b,
                which.clone(),
                slack,
                best,
            )?;
            best =
                Self::slabs_against_box::<ESTIMATE>(other, box_a, &rel.b_in_a, which, slack, best)?;
        }
        Some(best)
    }
}

impl<const AXES: usize> Bv for Kdop<AXES> {
    type Relative = KdopRelative<AXES>;

    fn relative(pose_b_in_a: &Isometry) -> KdopRelative<AXES> {
        let pose = RelativePose::new(pose_b_in_a);
        let r = Mat3::from(pose.rotation);
        let rt = r.transpose();
        let t = Vec3::from(pose.translation);
        let shift = Self::DIRECTIONS.map(|d| d.dot(t));
        let b_dirs = Self::DIRECTIONS.map(|d| r * d);
        KdopRelative {
            pose,
            a_in_b: CarriedDirections::new(Self::DIRECTIONS.map(|d| rt * d), shift),
            b_in_a: CarriedDirections::new(b_dirs, b_dirs.map(|v| -v.dot(t))),
            shift,
        }
    }

    fn fit_points<I>(points: I) -> Self
    where
        I: Iterator<Item = Vec3> + Clone,
    {
        let mut min = [f32::INFINITY; AXES];
        let mut max = [f32::NEG_INFINITY; AXES];
        for p in points {
            for (i, d) in Self::DIRECTIONS.iter().enumerate() {
                let s = d.dot(p);
                min[i] = min[i].min(s);
                max[i] = max[i].max(s);
            }
        }
        // No point (or only NaN ones, which `min`/`max` skip): the documented zero k-DOP.
        if min[0] > max[0] {
            return Self {
                min: [0.0; AXES],
                max: [0.0; AXES],
            };
        }
        let (c, h) = Self { min, max }.box_center_half();
        let pad = rounding_pad(c.abs().max_element() + h.max_element());
        for (i, d) in Self::DIRECTIONS.iter().enumerate() {
            let slab_pad = pad * d.length();
            min[i] -= slab_pad;
            max[i] += slab_pad;
        }
        Self { min, max }
    }

    fn merged(&self, other: &Self) -> Self {
        Self {
            min: std::array::from_fn(|i| self.min[i].min(other.min[i])),
            max: std::array::from_fn(|i| self.max[i].max(other.max[i])),
        }
    }

    fn grown(&self, margin: f32) -> Self {
        // Slab `i` measures `d_i · x`, so a point `margin` away moves it by up to `margin |d_i|`.
        let pad = Self::DIRECTIONS.map(|d| margin * d.length());
        Self {
            min: std::array::from_fn(|i| self.min[i] - pad[i]),
            max: std::array::from_fn(|i| self.max[i] + pad[i]),
        }
    }

    #[inline]
    fn overlaps(&self, other: &Self, rel: &KdopRelative<AXES>) -> bool {
        self.overlap_in::<false>(other, rel).is_some()
    }

    #[inline]
    fn overlap_estimate(&self, other: &Self, rel: &KdopRelative<AXES>) -> Option<f32> {
        self.overlap_in::<true>(other, rel)
    }

    fn size(&self) -> f32 {
        self.box_center_half().1.length()
    }

    fn local_aabb(&self) -> Aabb {
        let (c, h) = self.box_center_half();
        Aabb::from_center_half_extents(c, h)
    }

    fn contains_point(&self, p: Vec3, tolerance: f32) -> bool {
        Self::DIRECTIONS.iter().enumerate().all(|(i, d)| {
            let s = d.dot(p);
            let tol = tolerance * d.length();
            self.min[i] - tol <= s && s <= self.max[i] + tol
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_sets_are_distinct_and_start_with_the_axes() {
        fn check<const N: usize>() {
            let d = Kdop::<N>::DIRECTIONS;
            assert_eq!(&d[..3], &[Vec3::X, Vec3::Y, Vec3::Z]);
            for i in 0..N {
                for j in 0..i {
                    // No direction repeats, up to sign.
                    assert!(d[i].normalize().dot(d[j].normalize()).abs() < 0.99);
                }
            }
        }
        check::<7>();
        check::<9>();
        check::<13>();
    }

    /// A cube-corner cut: the 14-DOP of a tetrahedron corner rejects a point the box accepts.
    #[test]
    fn diagonal_slabs_are_tighter_than_the_box() {
        let pts = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let k = Kdop14::fit_points(pts.iter().copied());
        assert!(k.local_aabb().contains_point(Vec3::splat(0.9)));
        assert!(!k.contains_point(Vec3::splat(0.9), 0.0));
        assert!(pts.iter().all(|p| k.contains_point(*p, 0.0)));
    }
}
