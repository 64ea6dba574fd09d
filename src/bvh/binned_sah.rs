//! Binned surface-area-heuristic split (Wald 2007, "On fast construction of SAH-based bounding
//! volume hierarchies").
//!
//! The SAH estimates the cost of a split as `A_L·N_L + A_R·N_R`: the chance that a query reaching
//! the parent reaches a child grows with the child's surface area, and the work below it with its
//! triangle count. Instead of sorting, the centroids are dropped into a few equal bins along each
//! axis, and only the planes between bins are evaluated: two sweeps over the bins give every
//! plane's cost. The areas are those of the triangles' AABBs, whatever BV the tree stores — the
//! heuristic only ranks splits, and AABBs make it cheap.
//!
//! Unlike Wald's single longest axis we bin all three axes and keep the cheapest plane (as
//! Embree does): the bins are cheap next to fitting the nodes' BVs.

use super::build::MAX_SAH_BINS;
use crate::bounding::Aabb;
use glam::Vec3;

/// What the builder needs of a triangle: its box and the box's centre.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Primitive {
    pub aabb: Aabb,
    pub centroid: Vec3,
}

impl Primitive {
    pub fn of_triangle(corners: [Vec3; 3]) -> Self {
        let aabb = Aabb::from_points(corners);
        Self {
            aabb,
            centroid: aabb.center(),
        }
    }
}

#[derive(Clone, Copy)]
struct Bin {
    aabb: Aabb,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    aabb: Aabb::EMPTY,
    count: 0,
};

/// Surface area of a possibly empty box (0 when empty).
fn area(b: &Aabb) -> f32 {
    if b.is_valid() { b.surface_area() } else { 0.0 }
}

/// The best plane on one axis: `(cost, bins left of the plane)`, or `None` when the centroids
/// do not spread along it.
fn best_plane(
    run: &[u32],
    primitives: &[Primitive],
    bins: &mut [Bin],
    axis: usize,
    lo: f32,
    extent: f32,
) -> Option<(f32, usize)> {
    if extent.is_nan() || extent <= 0.0 {
        return None;
    }
    let n = bins.len();
    bins.fill(EMPTY_BIN);
    let scale = n as f32 * (1.0 - 1e-6) / extent;
    for &t in run {
        let p = &primitives[t as usize];
        let bin = &mut bins[bin_of(p.centroid[axis], lo, scale, n)];
        bin.aabb = bin.aabb.union(&p.aabb);
        bin.count += 1;
    }
    // right_cost[i] = area·count of bins i.. (the right side of plane i).
    let mut right_cost = [0.0f32; MAX_SAH_BINS];
    let mut acc = EMPTY_BIN;
    for i in (1..n).rev() {
        acc.aabb = acc.aabb.union(&bins[i].aabb);
        acc.count += bins[i].count;
        right_cost[i] = area(&acc.aabb) * acc.count as f32;
    }
    let mut best: Option<(f32, usize)> = None;
    let mut left = EMPTY_BIN;
    for i in 1..n {
        left.aabb = left.aabb.union(&bins[i - 1].aabb);
        left.count += bins[i - 1].count;
        if left.count == 0 || left.count as usize == run.len() {
            continue;
        }
        let cost = area(&left.aabb) * left.count as f32 + right_cost[i];
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, i));
        }
    }
    best
}

#[inline]
fn bin_of(x: f32, lo: f32, scale: f32, bins: usize) -> usize {
    // `as usize` saturates (negative and NaN give 0), and the min clamps the top.
    (((x - lo) * scale) as usize).min(bins - 1)
}

/// Partitions `run` at the cheapest SAH plane over the three axes and returns the size of the
/// left part, or `None` when no plane separates the centroids (the caller then splits at the
/// median).
pub(crate) fn binned_sah_split(
    run: &mut [u32],
    primitives: &[Primitive],
    bin_count: usize,
) -> Option<usize> {
    let n = bin_count.clamp(2, MAX_SAH_BINS);
    let mut bins = [EMPTY_BIN; MAX_SAH_BINS];
    let bins = &mut bins[..n];
    let bounds = Aabb::from_points(run.iter().map(|&t| primitives[t as usize].centroid));
    let extents = bounds.extents();
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        let plane = best_plane(run, primitives, bins, axis, bounds.min[axis], extents[axis]);
        if let Some((cost, plane)) = plane
            && best.is_none_or(|(c, _, _)| cost < c)
        {
            best = Some((cost, axis, plane));
        }
    }
    let (_, axis, plane) = best?;
    let (lo, scale) = (bounds.min[axis], n as f32 * (1.0 - 1e-6) / extents[axis]);
    let goes_left = |t: u32| bin_of(primitives[t as usize].centroid[axis], lo, scale, n) < plane;
    let mid = partition(run, goes_left);
    (mid > 0 && mid < run.len()).then_some(mid)
}

/// Moves the items satisfying `left` to the front (deterministic, not stable); returns how many.
fn partition(run: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..run.len() {
        if left(run[i]) {
            run.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny_triangle_at(c: Vec3) -> Primitive {
        Primitive::of_triangle([c, c + Vec3::X * 0.01, c + Vec3::Y * 0.01])
    }

    /// Two clusters far apart along y: the SAH must cut between them, whatever the order.
    #[test]
    fn cuts_between_two_clusters() {
        let mut prims = Vec::new();
        for i in 0..10 {
            prims.push(tiny_triangle_at(Vec3::new(i as f32 * 0.1, 0.0, 0.0)));
            prims.push(tiny_triangle_at(Vec3::new(i as f32 * 0.1, 50.0, 0.0)));
        }
        let mut run: Vec<u32> = (0..prims.len() as u32).collect();
        let mid = binned_sah_split(&mut run, &prims, 12).unwrap();
        assert_eq!(mid, 10);
        let left_y: Vec<f32> = run[..mid]
            .iter()
            .map(|&t| prims[t as usize].centroid.y)
            .collect();
        let right_y: Vec<f32> = run[mid..]
            .iter()
            .map(|&t| prims[t as usize].centroid.y)
            .collect();
        let (l, r) = if left_y[0] < 1.0 {
            (left_y, right_y)
        } else {
            (right_y, left_y)
        };
        assert!(l.iter().all(|y| *y < 1.0) && r.iter().all(|y| *y > 49.0));
    }

    #[test]
    fn coincident_centroids_are_refused() {
        let prims = vec![tiny_triangle_at(Vec3::ONE); 8];
        let mut run: Vec<u32> = (0..8).collect();
        assert!(binned_sah_split(&mut run, &prims, 12).is_none());
    }
}
