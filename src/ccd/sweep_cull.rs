//! Culling a hierarchy's nodes against a swept sphere: may the sphere, moving over the first
//! `t_max` of its displacement, touch what the node's bounding volume holds?
//!
//! The swept sphere is a capsule; testing it against each BV kind in the BV's own shape is
//! tighter than testing the swept AABB against the BV's box, because a long diagonal sweep has a
//! huge AABB but a thin capsule. Each test inflates the BV by the radius (a superset of the
//! Minkowski sum of the BV and the ball) and clips the centre's segment against it, slab by slab
//! (Kay and Kajiya 1986): conservative, never "no" for a node whose contents the sphere touches.

use crate::bounding::{Aabb, BoundingSphere, Kdop, Obb};
use glam::Vec3;

/// A bounding volume that can be culled against a swept sphere.
pub trait SweepCull {
    /// Where along `[0, t_max]` the sphere of `radius` whose centre moves along
    /// `origin + t·displacement` may first touch anything inside the BV (a lower bound; all in
    /// the BV's frame), or `None` only if it cannot touch it at all: what a walk that visits the
    /// nearest nodes first orders them by. Boxes give their slab entry; other kinds say 0.
    fn sweep_entry(&self, origin: Vec3, displacement: Vec3, radius: f32, t_max: f32)
    -> Option<f32>;

    /// False only if that sphere, over `t ∈ [0, t_max]`, cannot touch anything inside the BV.
    #[inline]
    fn may_touch_sweep(&self, origin: Vec3, displacement: Vec3, radius: f32, t_max: f32) -> bool {
        self.sweep_entry(origin, displacement, radius, t_max)
            .is_some()
    }
}

/// Narrows `[t0, t1]` to the times when `start + t·rate` lies in `[low, high]`; false when
/// nothing is left. Divides rather than multiplying by an inverse, so no `0 × ∞`.
#[inline]
fn clip_slab(start: f32, rate: f32, low: f32, high: f32, t0: &mut f32, t1: &mut f32) -> bool {
    if rate == 0.0 {
        return low <= start && start <= high;
    }
    let (a, b) = ((low - start) / rate, (high - start) / rate);
    let (near, far) = if rate > 0.0 { (a, b) } else { (b, a) };
    *t0 = t0.max(near);
    *t1 = t1.min(far);
    *t0 <= *t1
}

/// Where the segment enters the box `[low, high]` of the given frame coordinates, if it does.
#[inline]
fn segment_box_entry(
    origin: Vec3,
    displacement: Vec3,
    low: Vec3,
    high: Vec3,
    t_max: f32,
) -> Option<f32> {
    let (mut t0, mut t1) = (0.0f32, t_max);
    let meets = (0..3).all(|i| {
        clip_slab(
            origin[i],
            displacement[i],
            low[i],
            high[i],
            &mut t0,
            &mut t1,
        )
    });
    meets.then_some(t0)
}

impl SweepCull for Aabb {
    #[inline]
    fn sweep_entry(
        &self,
        origin: Vec3,
        displacement: Vec3,
        radius: f32,
        t_max: f32,
    ) -> Option<f32> {
        let grow = Vec3::splat(radius);
        segment_box_entry(
            origin,
            displacement,
            self.min - grow,
            self.max + grow,
            t_max,
        )
    }
}

impl SweepCull for Obb {
    #[inline]
    fn sweep_entry(
        &self,
        origin: Vec3,
        displacement: Vec3,
        radius: f32,
        t_max: f32,
    ) -> Option<f32> {
        let to_box = self.axes.transpose();
        let o = to_box * (origin - self.center);
        let d = to_box * displacement;
        let half = self.half_extents + Vec3::splat(radius);
        segment_box_entry(o, d, -half, half, t_max)
    }
}

impl SweepCull for BoundingSphere {
    #[inline]
    fn sweep_entry(
        &self,
        origin: Vec3,
        displacement: Vec3,
        radius: f32,
        t_max: f32,
    ) -> Option<f32> {
        // Closest point of the segment to the centre, then one distance comparison.
        let m = origin - self.center;
        let along = displacement.length_squared();
        let t = if along > 0.0 {
            (-m.dot(displacement) / along).clamp(0.0, t_max)
        } else {
            0.0
        };
        let reach = self.radius + radius;
        ((m + displacement * t).length_squared() <= reach * reach).then_some(0.0)
    }
}

impl<const AXES: usize> SweepCull for Kdop<AXES> {
    #[inline]
    fn sweep_entry(
        &self,
        origin: Vec3,
        displacement: Vec3,
        radius: f32,
        t_max: f32,
    ) -> Option<f32> {
        // Slab i holds `min ≤ dir·x ≤ max` with an unnormalised `dir`: a ball of radius r
        // widens it by r·|dir| on each side.
        let (mut t0, mut t1) = (0.0f32, t_max);
        let meets = Self::DIRECTIONS.iter().enumerate().all(|(i, dir)| {
            let grow = radius * dir.length();
            clip_slab(
                dir.dot(origin),
                dir.dot(displacement),
                self.min[i] - grow,
                self.max[i] + grow,
                &mut t0,
                &mut t1,
            )
        });
        // Entry 0, as the trait says of kinds other than boxes.
        meets.then_some(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::{Bv, Kdop14, Kdop26};
    use glam::Quat;

    /// Points of a small rotated box cloud, and sweeps around it: every BV kind fitted to the
    /// points must say "may touch" whenever a sampled sphere along the sweep reaches a point.
    #[test]
    fn never_culls_a_sweep_that_reaches_a_contained_point() {
        let q = Quat::from_euler(glam::EulerRot::XYZ, 0.4, -0.9, 0.2);
        let points: Vec<Vec3> = (0..8)
            .map(|i| {
                let s = Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -0.5 } else { 0.5 },
                    if i & 4 == 0 { -0.2 } else { 0.2 },
                );
                q * s + Vec3::new(0.5, -0.3, 0.2)
            })
            .collect();
        let bvs: [&dyn SweepCull; 5] = [
            &Aabb::fit_points(points.iter().copied()),
            &Obb::fit_points(points.iter().copied()),
            &BoundingSphere::fit_points(points.iter().copied()),
            &Kdop14::fit_points(points.iter().copied()),
            &Kdop26::fit_points(points.iter().copied()),
        ];
        let mut culled = [0usize; 5];
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        for _ in 0..2000 {
            let origin = Vec3::new(next(), next(), next()) * 4.0;
            let displacement = Vec3::new(next(), next(), next()) * 6.0;
            let radius = (next() + 1.0) * 0.5;
            let t_max = (next() + 1.0) * 0.5;
            let reaches = (0..=200).any(|k| {
                let c = origin + displacement * (t_max * k as f32 / 200.0);
                points.iter().any(|p| p.distance(c) <= radius)
            });
            for (n, bv) in bvs.iter().enumerate() {
                let may = bv.may_touch_sweep(origin, displacement, radius, t_max);
                assert!(may || !reaches, "kind {n} culled a reaching sweep");
                culled[n] += usize::from(!may);
            }
        }
        // The tests do cull (they are not trivially true).
        assert!(culled.iter().all(|&c| c > 200), "{culled:?}");
    }
}
