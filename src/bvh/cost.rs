//! The slides' cost model of a hierarchy query, `Tc = Nv*Cv + Nn*Cn + Ns*Cs`: counters of the
//! three kinds of work, and a measurement of their unit costs.
//!
//! - `Nv`, nodes visited: node pairs taken from the queue (for a single-volume descent, nodes).
//! - `Nn`, BV tests: node pairs whose BVs were tested (pairs are tested before they are queued,
//!   so a visited pair always overlaps).
//! - `Ns`, leaf tests: triangle pairs handed to the caller's leaf test.
//!
//! Tighter BVs (OBB, k-DOP) lower `Nv` and `Ns` and raise `Cn`; [`measure_unit_costs`] gives the
//! `C`s for one pair of hierarchies, so that [`UnitCosts::predict_ns`] can be set against measured
//! query times per BV kind.

use super::query::{TraversalOrder, children_to_visit};
use super::scratch::{NodePair, PairQueue, RankedQueue};
use super::{Bvh, QueryScratch};
use crate::bounding::Bv;
use crate::geometry::Isometry;
use std::hint::black_box;
use std::ops::{Add, AddAssign};
use std::time::{Duration, Instant};

/// Work done by one query (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct QueryStats {
    /// `Nv`: node pairs (or nodes) visited.
    pub nodes_visited: u64,
    /// `Nn`: BV pairs (or node predicates) tested.
    pub bv_tests: u64,
    /// `Ns`: leaf tests (triangle pairs, or triangles handed to the callback).
    pub leaf_tests: u64,
}

impl Add for QueryStats {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            nodes_visited: self.nodes_visited + o.nodes_visited,
            bv_tests: self.bv_tests + o.bv_tests,
            leaf_tests: self.leaf_tests + o.leaf_tests,
        }
    }
}

impl AddAssign for QueryStats {
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

/// Measured unit costs, in nanoseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UnitCosts {
    /// `Cv`: one visit (queue pop, node fetch, size comparison, pushes), excluding the tests.
    pub visit_ns: f64,
    /// `Cn`: one BV pair test.
    pub bv_test_ns: f64,
    /// `Cs`: one leaf test.
    pub leaf_test_ns: f64,
}

impl UnitCosts {
    /// The model's prediction `Nv*Cv + Nn*Cn + Ns*Cs` for a query's counters, in nanoseconds.
    pub fn predict_ns(&self, stats: &QueryStats) -> f64 {
        stats.nodes_visited as f64 * self.visit_ns
            + stats.bv_tests as f64 * self.bv_test_ns
            + stats.leaf_tests as f64 * self.leaf_test_ns
    }
}

/// Most samples of each kind replayed by [`measure_unit_costs`].
const MAX_SAMPLES: usize = 4096;

/// Measures `Cv`, `Cn` and `Cs` on the work a real query between `a` and `b` does.
///
/// The node pairs and triangle pairs that a depth-first enumerate-all traversal tests (up to
/// 4096 of each, padded to 256 with pseudo-random pairs when the query tests fewer) are recorded
/// once, then each kind of work is replayed in a loop for about `budget / 3`: the BV tests with
/// the query's prepared relative pose, the leaf tests through `leaf_test`, and the visits as
/// pops and pushes on `order`'s queue with the node fetches and the split rule. Timings are means
/// over the loop, so they include the cache behaviour of that replay, not of the interleaved real
/// query.
pub fn measure_unit_costs<B: Bv>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_b_in_a: &Isometry,
    order: TraversalOrder,
    mut leaf_test: impl FnMut(u32, u32) -> bool,
    budget: Duration,
) -> UnitCosts {
    let rel = B::relative(pose_b_in_a);
    let (bv_pairs, leaf_pairs) = record_work(a, b, &rel);
    let slice = budget / 3;
    let bv_test_ns = time_per_item(slice, bv_pairs.len(), || {
        bv_pairs
            .iter()
            .filter(|p| {
                let (na, nb) = (&a.nodes[p.a as usize], &b.nodes[p.b as usize]);
                black_box(na.bv.overlaps(&nb.bv, &rel))
            })
            .count()
    });
    let leaf_test_ns = time_per_item(slice, leaf_pairs.len(), || {
        leaf_pairs
            .iter()
            .filter(|&&(ta, tb)| black_box(leaf_test(ta, tb)))
            .count()
    });
    let mut scratch = QueryScratch::new();
    let visit_ns = match order {
        TraversalOrder::DepthFirst => time_visits(a, b, &bv_pairs, &mut scratch.stack, slice),
        TraversalOrder::BreadthFirst => time_visits(a, b, &bv_pairs, &mut scratch.fifo, slice),
        TraversalOrder::Priority => {
            let mut q = RankedQueue::default();
            time_visits(a, b, &bv_pairs, &mut q, slice)
        }
    };
    UnitCosts {
        visit_ns,
        bv_test_ns,
        leaf_test_ns,
    }
}

/// The node pairs and triangle pairs a depth-first, enumerate-all traversal tests, up to
/// [`MAX_SAMPLES`] each, padded with deterministic pseudo-random pairs when there are few.
fn record_work<B: Bv>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    rel: &B::Relative,
) -> (Vec<NodePair>, Vec<(u32, u32)>) {
    let mut bv_pairs = vec![NodePair { a: 0, b: 0 }];
    let mut leaf_pairs = Vec::new();
    let mut stack = vec![NodePair { a: 0, b: 0 }];
    while let Some(p) = stack.pop() {
        let (na, nb) = (&a.nodes[p.a as usize], &b.nodes[p.b as usize]);
        if !na.bv.overlaps(&nb.bv, rel) {
            continue;
        }
        if let (Some(ra), Some(rb)) = (na.triangle_range(), nb.triangle_range()) {
            for &ta in &a.order[ra] {
                for &tb in &b.order[rb.clone()] {
                    if leaf_pairs.len() < MAX_SAMPLES {
                        leaf_pairs.push((ta, tb));
                    }
                }
            }
            continue;
        }
        for child in children_to_visit(a, b, p) {
            if bv_pairs.len() < MAX_SAMPLES {
                bv_pairs.push(child);
            }
            stack.push(child);
        }
        if bv_pairs.len() >= MAX_SAMPLES && leaf_pairs.len() >= MAX_SAMPLES {
            break;
        }
    }
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = |n: usize| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % n as u64) as u32
    };
    while bv_pairs.len() < 256 {
        bv_pairs.push(NodePair {
            a: next(a.nodes.len()),
            b: next(b.nodes.len()),
        });
    }
    while leaf_pairs.len() < 256 {
        leaf_pairs.push((next(a.order.len()), next(b.order.len())));
    }
    (bv_pairs, leaf_pairs)
}

/// Replays one visit per recorded pair through queue `Q`: pop a pair, fetch its nodes, apply the
/// split rule, push both children (an upper bound: a real visit pushes only the children whose
/// BVs overlap).
fn time_visits<B: Bv, Q: PairQueue>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pairs: &[NodePair],
    queue: &mut Q,
    slice: Duration,
) -> f64 {
    time_per_item(slice, pairs.len(), || {
        queue.clear();
        queue.push(pairs[0], 1.0);
        for (i, &p) in pairs.iter().enumerate() {
            let q = queue.pop().unwrap_or(p);
            let (na, nb) = (&a.nodes[q.a as usize], &b.nodes[q.b as usize]);
            if !(na.is_leaf() && nb.is_leaf()) {
                // Varied ranks, so a heap does real sifting.
                let rank = (i.wrapping_mul(2_654_435_761) % 1024) as f32 / 1024.0;
                let [c0, c1] = children_to_visit(a, b, q);
                queue.push(c0, rank);
                queue.push(c1, 1.0 - rank);
            }
        }
        queue.pop()
    })
}

/// Mean time of one item of `run` (which does `items` items per call) over about `slice`.
fn time_per_item<R>(slice: Duration, items: usize, mut run: impl FnMut() -> R) -> f64 {
    black_box(run());
    let start = Instant::now();
    let mut calls = 0u64;
    loop {
        black_box(run());
        calls += 1;
        if start.elapsed() >= slice {
            break;
        }
    }
    start.elapsed().as_nanos() as f64 / (calls as f64 * items.max(1) as f64)
}
