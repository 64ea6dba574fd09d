//! Sort and sweep from scratch every commit (Ericson, *Real-Time Collision Detection* 2005,
//! §7.5.2): sort the boxes by their min on the axis where the centres spread most, then sweep
//! forward from each box over the boxes starting before it ends, testing the other two axes.
//!
//! No state survives a commit except the previous pair list (to report changes), so its cost
//! does not depend on how far bodies moved: O(n log n + overlaps on the sweep axis). A commit
//! in which no body came, went or moved keeps the pairs it had and rebuilds nothing. It is the
//! yardstick the incremental version must beat under coherence, and the winner when motion is
//! large.

use super::body_store::BodyStore;
use super::pair_diff::PairHistory;
use super::{BodyKind, BroadPhase, BroadPhaseError, Pair, ProxyId, StepStats, float_order_key};
use crate::bounding::Aabb;
use std::mem::size_of;
use wide::f32x4;

/// The boxes of one commit in sweep order (struct of arrays).
#[derive(Debug, Default)]
struct SweepArrays {
    /// `float_order_key(min) << 32 | position in the body store`, sorted.
    order: Vec<u64>,
    /// Min on the sweep axis.
    lo: Vec<f32>,
    /// Max on the sweep axis.
    hi: Vec<f32>,
    /// `[min_u, max_u, min_v, max_v]` on the other two axes.
    cross: Vec<[f32; 4]>,
    /// `id << 1 | is_static`.
    owner: Vec<u32>,
}

impl SweepArrays {
    fn memory_bytes(&self) -> usize {
        self.order.capacity() * size_of::<u64>()
            + (self.lo.capacity() + self.hi.capacity() + self.owner.capacity()) * size_of::<f32>()
            + self.cross.capacity() * size_of::<[f32; 4]>()
    }
}

/// Sort-and-sweep broad phase, rebuilt at every commit that changed something.
#[derive(Debug, Default)]
pub struct SortAndSweep {
    bodies: BodyStore,
    history: PairHistory,
    stats: StepStats,
    arrays: SweepArrays,
}

impl SortAndSweep {
    /// An empty broad phase.
    pub fn new() -> Self {
        Self::default()
    }
}

/// The axis along which the box centres have the largest variance.
pub(super) fn sweep_axis(aabbs: &[Aabb]) -> usize {
    let (mut sum, mut sum_sq) = ([0.0f64; 3], [0.0f64; 3]);
    for aabb in aabbs {
        let c = aabb.center();
        for axis in 0..3 {
            let x = f64::from(c[axis]);
            sum[axis] += x;
            sum_sq[axis] += x * x;
        }
    }
    let n = aabbs.len().max(1) as f64;
    let variance = |axis: usize| sum_sq[axis] / n - (sum[axis] / n).powi(2);
    (0..3).fold(0, |best, axis| {
        if variance(axis) > variance(best) {
            axis
        } else {
            best
        }
    })
}

/// Lays the bodies out in sweep order along `axis`.
fn fill_arrays(arrays: &mut SweepArrays, bodies: &BodyStore, axis: usize) {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let aabbs = bodies.aabbs();
    arrays.order.clear();
    arrays.order.extend(
        aabbs
            .iter()
            .enumerate()
            .map(|(at, b)| u64::from(float_order_key(b.min[axis])) << 32 | at as u64),
    );
    arrays.order.sort_unstable();
    arrays.lo.clear();
    arrays.hi.clear();
    arrays.cross.clear();
    arrays.owner.clear();
    for &key in &arrays.order {
        // The low half of the key is the position.
        let at = key as u32 as usize;
        let b = &aabbs[at];
        arrays.lo.push(b.min[axis]);
        arrays.hi.push(b.max[axis]);
        arrays.cross.push([b.min[u], b.max[u], b.min[v], b.max[v]]);
        let is_static = bodies.kinds()[at] == BodyKind::Static;
        arrays
            .owner
            .push(bodies.ids()[at] << 1 | u32::from(is_static));
    }
}

/// The forward sweep: every pair overlapping on all axes, found from its earlier-starting box;
/// returns the number of cross-axis tests.
fn sweep(arrays: &SweepArrays, out: &mut Vec<Pair>) -> u64 {
    let SweepArrays {
        lo,
        hi,
        cross,
        owner,
        ..
    } = arrays;
    let mut tests = 0;
    for i in 0..lo.len() {
        let (end, c, o) = (hi[i], cross[i], owner[i]);
        let mut j = i + 1;
        // Whole groups of four that start before box `i` ends, tested at once in SIMD lanes
        // (their bounds transposed into `wide::f32x4`s: eight compares and a bit mask,
        // Terdiman's "box pruning revisited"); a run too short for one (a row of boxes along
        // the sweep axis) pays one compare for the check.
        if lo.get(j + 3).is_some_and(|&l| l <= end) {
            let lanes = c.map(f32x4::splat);
            let groups = lo[j..].as_chunks::<4>().0.iter();
            for (starts, four) in groups.zip(cross[j..].as_chunks::<4>().0) {
                if starts[3] > end {
                    break;
                }
                let [lo_u, hi_u, lo_v, hi_v] = f32x4::transpose(four.map(f32x4::from));
                let overlap = lanes[0].simd_le(hi_u)
                    & lo_u.simd_le(lanes[1])
                    & lanes[2].simd_le(hi_v)
                    & lo_v.simd_le(lanes[3]);
                let mut hits = overlap.to_bitmask();
                while hits != 0 {
                    let k = j + hits.trailing_zeros() as usize;
                    if o & owner[k] & 1 == 0 {
                        out.push(Pair::ordered(o >> 1, owner[k] >> 1));
                    }
                    hits &= hits - 1;
                }
                j += 4;
            }
        }
        while j < lo.len() && lo[j] <= end {
            let d = cross[j];
            // `&`, not `&&`: four compares without branches beat unpredictable early exits.
            let overlap = (c[0] <= d[1]) & (d[0] <= c[1]) & (c[2] <= d[3]) & (d[2] <= c[3]);
            if overlap && o & owner[j] & 1 == 0 {
                out.push(Pair::ordered(o >> 1, owner[j] >> 1));
            }
            j += 1;
        }
        tests += (j - i - 1) as u64;
    }
    tests
}

impl BroadPhase for SortAndSweep {
    fn insert(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) -> Result<(), BroadPhaseError> {
        self.bodies.insert(id, aabb, kind)
    }

    fn insert_bulk(&mut self, bodies: &[(ProxyId, Aabb, BodyKind)]) -> Result<(), BroadPhaseError> {
        self.bodies.insert_bulk(bodies)
    }

    fn update(&mut self, id: ProxyId, aabb: Aabb) -> Result<(), BroadPhaseError> {
        self.bodies.update(id, aabb)
    }

    fn remove(&mut self, id: ProxyId) -> Result<(), BroadPhaseError> {
        self.bodies.remove(id)
    }

    fn commit(&mut self) {
        if !self.bodies.take_changed() {
            // The same boxes find the same pairs: a game re-sending unchanged boxes, or
            // committing with none moved (the ECS commits twice a step), pays nothing.
            self.history.keep();
            self.stats = StepStats::default();
            return;
        }
        let axis = sweep_axis(self.bodies.aabbs());
        fill_arrays(&mut self.arrays, &self.bodies, axis);
        let tests = sweep(&self.arrays, self.history.begin());
        self.history.finish();
        self.stats = StepStats {
            rebuilt: true,
            endpoint_swaps: 0,
            pair_tests: tests,
            changed: true,
        };
    }

    fn pairs(&self) -> &[Pair] {
        self.history.current()
    }

    fn added(&self) -> &[Pair] {
        self.history.added()
    }

    fn removed(&self) -> &[Pair] {
        self.history.removed()
    }

    fn stats(&self) -> StepStats {
        self.stats
    }

    fn memory_bytes(&self) -> usize {
        self.bodies.memory_bytes() + self.history.memory_bytes() + self.arrays.memory_bytes()
    }

    fn len(&self) -> usize {
        self.bodies.len()
    }

    fn contains(&self, id: ProxyId) -> bool {
        self.bodies.contains(id)
    }

    fn aabb(&self, id: ProxyId) -> Option<Aabb> {
        self.bodies.aabb(id)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweep_axis_follows_the_spread() {
        let boxes: Vec<Aabb> = (0..10)
            .map(|i| {
                Aabb::from_center_half_extents(
                    glam::Vec3::new(0.1 * i as f32, 0.0, i as f32),
                    glam::Vec3::ONE,
                )
            })
            .collect();
        assert_eq!(sweep_axis(&boxes), 2);
    }

    /// A commit with the same boxes keeps the pairs, reports no change and rebuilds nothing;
    /// one moved box brings the rebuild back.
    #[test]
    fn a_commit_with_the_same_boxes_rebuilds_nothing_and_reports_no_change() {
        let at = |x: f32| Aabb::from_center_half_extents(glam::Vec3::X * x, glam::Vec3::ONE);
        let mut sweep = SortAndSweep::new();
        for (id, x) in [(0, 0.0), (1, 1.5), (2, 5.0)] {
            sweep.insert(id, at(x), BodyKind::Dynamic).unwrap();
        }
        sweep.commit();
        assert_eq!(sweep.added(), &[Pair::ordered(0, 1)]);
        sweep.update(2, at(5.0)).unwrap();
        sweep.commit();
        assert!(sweep.added().is_empty() && sweep.removed().is_empty());
        assert_eq!(sweep.pairs(), &[Pair::ordered(0, 1)]);
        assert!(!sweep.stats().rebuilt);
        sweep.update(2, at(3.0)).unwrap();
        sweep.commit();
        assert!(sweep.stats().rebuilt);
        assert_eq!(sweep.added(), &[Pair::ordered(1, 2)]);
        assert!(sweep.removed().is_empty());
    }

    #[test]
    fn crowded_runs_tested_four_at_a_time_find_exactly_the_brute_force_pairs_and_test_counts() {
        use crate::broad_phase::BruteForce;
        use glam::Vec3;
        // Columns of boxes sharing their interval on both spread axes (every run far longer
        // than four), boxes straddling two columns, statics among them, and runs that end in
        // the middle of a group of four.
        let mut rng = crate::test_rng::TestRng::new(7);
        let (mut sweep, mut brute) = (SortAndSweep::new(), BruteForce::default());
        let mut expected_tests = 0u64;
        let mut boxes = Vec::new();
        for k in 0..37u32 {
            let column = (k % 3) as f32;
            let half = Vec3::new(0.3 + 0.4 * rng.unit(), 0.3, 0.3 + 0.2 * rng.unit());
            let centre = Vec3::new(column + 0.2 * rng.unit(), rng.unit(), k as f32 * 0.1);
            let kind = if k % 5 == 0 {
                BodyKind::Static
            } else {
                BodyKind::Dynamic
            };
            boxes.push(Aabb::from_center_half_extents(centre, half));
            for bp in [&mut sweep as &mut dyn BroadPhase, &mut brute] {
                bp.insert(k, boxes[k as usize], kind).expect("fresh id");
            }
        }
        sweep.commit();
        brute.commit();
        let sorted = |bp: &dyn BroadPhase| {
            let mut pairs = bp.pairs().to_vec();
            pairs.sort_unstable();
            pairs
        };
        assert_eq!(sorted(&sweep), sorted(&brute));
        assert!(sweep.pairs().len() > 50, "{} pairs", sweep.pairs().len());
        // The tests are counted per run, as one at a time.
        let arrays = &sweep.arrays;
        for i in 0..arrays.lo.len() {
            expected_tests += arrays.lo[i + 1..]
                .iter()
                .take_while(|&&l| l <= arrays.hi[i])
                .count() as u64;
        }
        let mut again = Vec::new();
        assert_eq!(super::sweep(arrays, &mut again), expected_tests);
        assert!(expected_tests > 4 * arrays.lo.len() as u64);
    }
}
