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
use crate::bounding::WideBox;
use glam::{Vec3, Vec3A};
use wide::f32x4;

/// What the builder needs of a triangle: its box and which triangle it is. The builder
/// partitions these in place, so each node's primitives are contiguous.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Primitive {
    pub bounds: WideBox,
    pub triangle: u32,
}

impl Primitive {
    pub fn of_triangle(triangle: u32, corners: [Vec3; 3]) -> Self {
        let [a, b, c] = corners.map(Vec3A::from);
        Self {
            bounds: WideBox {
                min: a.min(b).min(c),
                max: a.max(b).max(c),
            },
            triangle,
        }
    }

    /// The centre of the triangle's box, the point the split rules sort and bin.
    #[inline]
    pub fn centroid(&self) -> Vec3A {
        // Past 1.7e38 the sum overflows to infinity; binning and partitioning both go through
        // `Binning::position`, which clamps it to the top bin, so they still agree.
        (self.bounds.min + self.bounds.max) * 0.5
    }
}

/// The centroids' box.
pub(crate) fn centroid_bounds(run: &[Primitive]) -> WideBox {
    run.iter()
        .fold(WideBox::EMPTY, |b, p| b.including(p.centroid()))
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: WideBox,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    bounds: WideBox::EMPTY,
    count: 0,
};

/// How centroids map to bins along the three axes: bin `i` of axis `a` holds the centroids
/// with `i <= (c[a] - lo[a]) * scale[a] < i + 1`. An axis the centroids do not spread along
/// gets scale 0: all its centroids fall in bin 0, and no plane of it separates anything.
#[derive(Clone, Copy)]
struct Binning {
    lo: Vec3A,
    scale: Vec3A,
    top: Vec3A,
}

impl Binning {
    fn new(bounds: &WideBox, bins: usize) -> Self {
        let extents = bounds.max - bounds.min;
        let scale = finite_positive_or_zero(Vec3A::splat(bins as f32 * (1.0 - 1e-6)) / extents);
        Self {
            lo: bounds.min,
            scale,
            top: Vec3A::splat((bins - 1) as f32),
        }
    }

    /// Where `centroid` falls along each axis, in bins (fractional), clamped to the bins.
    #[inline]
    fn position(&self, centroid: Vec3A) -> Vec3A {
        ((centroid - self.lo) * self.scale).clamp(Vec3A::ZERO, self.top)
    }

    /// The centroid's bin along each axis.
    #[inline]
    fn bins_of(&self, centroid: Vec3A) -> [usize; 3] {
        // In [0, top] by the clamp, so one truncating conversion of the lanes is exact (glam's
        // per-lane `as` casts check for overflow lane by lane).
        let p = self.position(centroid);
        let [x, y, z, _] = f32x4::new([p.x, p.y, p.z, 0.0]).fast_trunc_int().to_array();
        [x, y, z].map(|b| b as usize)
    }

    /// True when the centroid's bin along `axis` is below `plane` (≥ 1): `floor(x) < plane`
    /// exactly when `x < plane`, so this is the bin test without the truncation.
    #[inline]
    fn left_of(&self, centroid: Vec3A, axis: usize, plane: usize) -> bool {
        self.position(centroid)[axis] < plane as f32
    }
}

/// Zero in the lanes that are not finite and positive (an axis of no spread: its extent was 0,
/// or so small that the scale overflowed).
fn finite_positive_or_zero(v: Vec3A) -> Vec3A {
    let keep = v.is_finite_mask() & v.cmpgt(Vec3A::ZERO);
    Vec3A::select(keep, v, Vec3A::ZERO)
}

/// The best plane on one axis's filled bins: `(cost, bins left of the plane)`, or `None` when
/// every centroid fell on one side of every plane.
fn best_plane(bins: &[Bin], total: usize) -> Option<(f32, usize)> {
    let n = bins.len();
    // right_cost[i] = area·count of bins i.. (the right side of plane i).
    let mut right_cost = [0.0f32; MAX_SAH_BINS];
    let mut acc = EMPTY_BIN;
    for i in (1..n).rev() {
        acc.bounds = acc.bounds.union(&bins[i].bounds);
        acc.count += bins[i].count;
        right_cost[i] = acc.bounds.surface_area() * acc.count as f32;
    }
    let mut best: Option<(f32, usize)> = None;
    let mut left = EMPTY_BIN;
    for i in 1..n {
        left.bounds = left.bounds.union(&bins[i - 1].bounds);
        left.count += bins[i - 1].count;
        if left.count == 0 || left.count as usize == total {
            continue;
        }
        let cost = left.bounds.surface_area() * left.count as f32 + right_cost[i];
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, i));
        }
    }
    best
}

/// The bins of the three axes, allocated once per build (clearing a fixed array of the most bins
/// at every node cost more than binning the many small nodes).
pub(crate) struct SahBins {
    bins: Vec<Bin>,
    per_axis: usize,
}

impl SahBins {
    pub fn new(bin_count: usize) -> Self {
        let per_axis = bin_count.clamp(2, MAX_SAH_BINS);
        Self {
            bins: vec![EMPTY_BIN; 3 * per_axis],
            per_axis,
        }
    }
}

/// Partitions `run` at the cheapest SAH plane over the three axes and returns the size of the
/// left part, or `None` when no plane separates the centroids (the caller then splits at the
/// median). One pass fills the bins of all three axes.
pub(crate) fn binned_sah_split(run: &mut [Primitive], scratch: &mut SahBins) -> Option<usize> {
    // No more bins than primitives: a small node's planes are few anyway, and evaluating empty
    // bins is most of its cost.
    let bins_per_axis = scratch.per_axis.min(run.len()).max(2);
    let binning = Binning::new(&centroid_bounds(run), bins_per_axis);
    let bins = &mut scratch.bins[..3 * bins_per_axis];
    bins.fill(EMPTY_BIN);
    let (x, yz) = bins.split_at_mut(bins_per_axis);
    let (y, z) = yz.split_at_mut(bins_per_axis);
    let mut bins = [x, y, z];
    for p in run.iter() {
        for (axis_bins, bin) in bins.iter_mut().zip(binning.bins_of(p.centroid())) {
            let bin = &mut axis_bins[bin];
            bin.bounds = bin.bounds.union(&p.bounds);
            bin.count += 1;
        }
    }
    let mut best: Option<(f32, usize, usize)> = None;
    for (axis, axis_bins) in bins.iter().enumerate() {
        if let Some((cost, plane)) = best_plane(axis_bins, run.len())
            && best.is_none_or(|(c, _, _)| cost < c)
        {
            best = Some((cost, axis, plane));
        }
    }
    let (_, axis, plane) = best?;
    let mid = partition(run, |p| binning.left_of(p.centroid(), axis, plane));
    (mid > 0 && mid < run.len()).then_some(mid)
}

/// Moves the items satisfying `left` to the front (deterministic, not stable); returns how many.
fn partition(run: &mut [Primitive], left: impl Fn(&Primitive) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..run.len() {
        if left(&run[i]) {
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
        Primitive::of_triangle(0, [c, c + Vec3::X * 0.01, c + Vec3::Y * 0.01])
    }

    /// Two clusters far apart along y: the SAH must cut between them, whatever the order.
    #[test]
    fn cuts_between_two_clusters() {
        let mut prims = Vec::new();
        for i in 0..10 {
            prims.push(tiny_triangle_at(Vec3::new(i as f32 * 0.1, 0.0, 0.0)));
            prims.push(tiny_triangle_at(Vec3::new(i as f32 * 0.1, 50.0, 0.0)));
        }
        let mid = binned_sah_split(&mut prims, &mut SahBins::new(12)).unwrap();
        assert_eq!(mid, 10);
        let left_y: Vec<f32> = prims[..mid].iter().map(|p| p.centroid().y).collect();
        let right_y: Vec<f32> = prims[mid..].iter().map(|p| p.centroid().y).collect();
        let (l, r) = if left_y[0] < 1.0 {
            (left_y, right_y)
        } else {
            (right_y, left_y)
        };
        assert!(l.iter().all(|y| *y < 1.0) && r.iter().all(|y| *y > 49.0));
    }

    #[test]
    fn coincident_centroids_are_refused() {
        let mut prims = vec![tiny_triangle_at(Vec3::ONE); 8];
        assert!(binned_sah_split(&mut prims, &mut SahBins::new(12)).is_none());
    }
}
