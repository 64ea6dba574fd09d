//! Pair queries between two hierarchies: the slides' "Uso della gerarchia".
//!
//! A queue of node pairs starts with the two roots. A pair is taken out; if both nodes are
//! leaves, their triangles are tested pairwise with the caller's leaf test; otherwise the node
//! with the larger BV is split (a leaf never is) and each child is paired with the other node.
//! Pairs are BV-tested *before* they are queued, so the queue only ever holds overlapping pairs.
//!
//! The queue decides the visiting order ([`TraversalOrder`]): a stack gives depth-first, a FIFO
//! breadth-first, a max-heap on [`Bv::overlap_estimate`] a priority order that reaches the
//! deepest overlaps first. Two modes: [`Bvh::first_intersecting_pair`] stops at the first leaf
//! test that returns true (the slides' `return` — which in the slides returns the first leaf
//! pair's result even when it is false; here the search continues), and
//! [`Bvh::intersecting_pairs`] enumerates every intersecting triangle pair.
//!
//! The query runs in A's frame: B is placed by `pose_b_in_a = pose_a.inv_mul(&pose_b)`, which
//! each BV kind prepares once ([`Bv::relative`]).

use super::cost::QueryStats;
use super::scratch::{NodePair, PairQueue};
use super::{Bvh, QueryScratch};
use crate::bounding::Bv;
use crate::geometry::Isometry;
use std::ops::ControlFlow;

/// The order in which node pairs are visited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum TraversalOrder {
    /// A stack: descend to the leaves first; the queue stays short (`O(depth)`).
    #[default]
    DepthFirst,
    /// A FIFO: level by level; the queue grows with the overlap front.
    BreadthFirst,
    /// A max-heap by estimated BV overlap (ties in insertion order): the most promising pair
    /// first, at the price of `O(log n)` queue operations.
    Priority,
}

/// The two pairs a visit of `p` queues (the slides' rule: split the node with the larger BV; a
/// leaf is never split). `p` must not be a pair of leaves.
#[inline]
pub(crate) fn children_to_visit<B: Bv>(a: &Bvh<B>, b: &Bvh<B>, p: NodePair) -> [NodePair; 2] {
    let (na, nb) = (&a.nodes[p.a as usize], &b.nodes[p.b as usize]);
    match (na.children(), nb.children()) {
        (Some([l, r]), None) => [NodePair { a: l, b: p.b }, NodePair { a: r, b: p.b }],
        (Some([l, r]), Some(_)) if na.size >= nb.size => {
            [NodePair { a: l, b: p.b }, NodePair { a: r, b: p.b }]
        }
        (_, Some([l, r])) => [NodePair { a: p.a, b: l }, NodePair { a: p.a, b: r }],
        // Two leaves: nothing to split (callers never ask).
        (None, None) => [p, p],
    }
}

/// Tests the BVs of `pair` (B's grown by `margin` when positive) and queues it when they
/// overlap.
#[inline(always)]
fn test_and_queue<B: Bv, Q: PairQueue>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    rel: &B::Relative,
    margin: f32,
    pair: NodePair,
    queue: &mut Q,
    stats: &mut QueryStats,
) {
    stats.bv_tests += 1;
    let bva = &a.nodes[pair.a as usize].bv;
    let grown;
    let mut bvb = &b.nodes[pair.b as usize].bv;
    if margin > 0.0 {
        grown = bvb.grown(margin);
        bvb = &grown;
    }
    if Q::RANKED {
        if let Some(rank) = bva.overlap_estimate(bvb, rel) {
            queue.push(pair, rank);
        }
    } else if bva.overlaps(bvb, rel) {
        queue.push(pair, 0.0);
    }
}

/// The traversal, generic over the queue; `on_hit` sees each intersecting triangle pair and may
/// stop the search.
fn traverse<B: Bv, Q: PairQueue>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    (rel, margin): (&B::Relative, f32),
    queue: &mut Q,
    leaf_test: &mut impl FnMut(u32, u32) -> bool,
    on_hit: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
) -> QueryStats {
    let mut stats = QueryStats::default();
    queue.clear();
    test_and_queue(
        a,
        b,
        rel,
        margin,
        NodePair { a: 0, b: 0 },
        queue,
        &mut stats,
    );
    while let Some(pair) = queue.pop() {
        stats.nodes_visited += 1;
        let (na, nb) = (&a.nodes[pair.a as usize], &b.nodes[pair.b as usize]);
        if let (Some(ra), Some(rb)) = (na.triangle_range(), nb.triangle_range()) {
            for &ta in &a.order[ra] {
                for &tb in &b.order[rb.clone()] {
                    stats.leaf_tests += 1;
                    if leaf_test(ta, tb) && on_hit(ta, tb).is_break() {
                        return stats;
                    }
                }
            }
            continue;
        }
        for child in children_to_visit(a, b, pair) {
            test_and_queue(a, b, rel, margin, child, queue, &mut stats);
        }
    }
    stats
}

/// Runs [`traverse`] with the queue of `order`.
fn traverse_in_order<B: Bv>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    (pose_b_in_a, margin): (&Isometry, f32),
    order: TraversalOrder,
    scratch: &mut QueryScratch,
    leaf_test: &mut impl FnMut(u32, u32) -> bool,
    on_hit: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
) -> QueryStats {
    let rel = (&B::relative(pose_b_in_a), margin);
    match order {
        TraversalOrder::DepthFirst => traverse(a, b, rel, &mut scratch.stack, leaf_test, on_hit),
        TraversalOrder::BreadthFirst => traverse(a, b, rel, &mut scratch.fifo, leaf_test, on_hit),
        TraversalOrder::Priority => traverse(a, b, rel, &mut scratch.ranked, leaf_test, on_hit),
    }
}

impl<B: Bv> Bvh<B> {
    /// Early-out query: the first triangle pair `(triangle of self, triangle of other)` for which
    /// `leaf_test` returns true, or `None` when no pair does, with the work done.
    ///
    /// `other` is placed in `self`'s frame by `pose_b_in_a` (`pose_a.inv_mul(&pose_b)`).
    /// `leaf_test(ta, tb)` gets triangle indices of the two meshes; it is only called for
    /// triangles whose leaves' BVs overlap.
    pub fn first_intersecting_pair(
        &self,
        other: &Bvh<B>,
        pose_b_in_a: &Isometry,
        order: TraversalOrder,
        scratch: &mut QueryScratch,
        mut leaf_test: impl FnMut(u32, u32) -> bool,
    ) -> (Option<[u32; 2]>, QueryStats) {
        let mut found = None;
        let stats = traverse_in_order(
            self,
            other,
            (pose_b_in_a, 0.0),
            order,
            scratch,
            &mut leaf_test,
            &mut |ta, tb| {
                found = Some([ta, tb]);
                ControlFlow::Break(())
            },
        );
        (found, stats)
    }

    /// Enumerate-all query: every triangle pair for which `leaf_test` returns true, written to
    /// `out` (cleared first) in visiting order, with the work done. Arguments as for
    /// [`Bvh::first_intersecting_pair`].
    pub fn intersecting_pairs(
        &self,
        other: &Bvh<B>,
        pose_b_in_a: &Isometry,
        order: TraversalOrder,
        scratch: &mut QueryScratch,
        leaf_test: impl FnMut(u32, u32) -> bool,
        out: &mut Vec<[u32; 2]>,
    ) -> QueryStats {
        self.pairs_within(other, pose_b_in_a, 0.0, order, scratch, leaf_test, out)
    }

    /// [`Bvh::intersecting_pairs`] for triangles that may be up to `margin` apart: `other`'s BVs
    /// are grown by `margin` before each test, so `leaf_test` sees every pair of triangles whose
    /// leaves come within `margin` of each other (speculative contacts look this far ahead).
    #[allow(clippy::too_many_arguments)]
    pub fn pairs_within(
        &self,
        other: &Bvh<B>,
        pose_b_in_a: &Isometry,
        margin: f32,
        order: TraversalOrder,
        scratch: &mut QueryScratch,
        mut leaf_test: impl FnMut(u32, u32) -> bool,
        out: &mut Vec<[u32; 2]>,
    ) -> QueryStats {
        out.clear();
        traverse_in_order(
            self,
            other,
            (pose_b_in_a, margin),
            order,
            scratch,
            &mut leaf_test,
            &mut |ta, tb| {
                out.push([ta, tb]);
                ControlFlow::Continue(())
            },
        )
    }
}
