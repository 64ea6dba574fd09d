//! Reusable buffers of the traversals, and the three queues of node pairs behind the slides'
//! visiting orders (depth-first: a stack; breadth-first: a FIFO; priority: a binary heap).
//!
//! Keeping them in a [`QueryScratch`] owned by the caller means a warm query allocates nothing:
//! the buffers are cleared, never dropped.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, VecDeque};

/// A pair of nodes, one of each hierarchy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct NodePair {
    pub a: u32,
    pub b: u32,
}

/// Buffers for [`Bvh`](super::Bvh) queries; create once, pass to every query.
#[derive(Debug, Default)]
pub struct QueryScratch {
    pub(crate) stack: Vec<NodePair>,
    pub(crate) fifo: VecDeque<NodePair>,
    pub(crate) ranked: RankedQueue,
    pub(crate) nodes: Vec<u32>,
    /// A walk along a path, nearest node first: each node and where the path enters it.
    pub(crate) along: Vec<(u32, f32)>,
}

impl QueryScratch {
    /// Empty buffers (they grow on first use and are kept).
    pub fn new() -> Self {
        Self::default()
    }
}

/// A queue of node pairs; `RANKED` queues want the overlap estimate of each pair.
pub(crate) trait PairQueue {
    const RANKED: bool;
    fn clear(&mut self);
    fn push(&mut self, pair: NodePair, rank: f32);
    fn pop(&mut self) -> Option<NodePair>;
}

impl PairQueue for Vec<NodePair> {
    const RANKED: bool = false;
    fn clear(&mut self) {
        Vec::clear(self);
    }
    #[inline]
    fn push(&mut self, pair: NodePair, _: f32) {
        Vec::push(self, pair);
    }
    #[inline]
    fn pop(&mut self) -> Option<NodePair> {
        Vec::pop(self)
    }
}

impl PairQueue for VecDeque<NodePair> {
    const RANKED: bool = false;
    fn clear(&mut self) {
        VecDeque::clear(self);
    }
    #[inline]
    fn push(&mut self, pair: NodePair, _: f32) {
        self.push_back(pair);
    }
    #[inline]
    fn pop(&mut self) -> Option<NodePair> {
        self.pop_front()
    }
}

/// A pair with its rank. Ordered by rank, then by *earlier* insertion, so equal ranks pop in
/// insertion order and the visit is deterministic.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct RankedPair {
    /// `rank.to_bits()`: ranks are in `[0, 1]`, where the bits order like the numbers.
    key: u32,
    seq: u32,
    pair: NodePair,
}

impl Ord for RankedPair {
    fn cmp(&self, other: &Self) -> Ordering {
        self.key
            .cmp(&other.key)
            .then_with(|| other.seq.cmp(&self.seq))
    }
}

impl PartialOrd for RankedPair {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Max-heap of pairs by overlap estimate.
#[derive(Debug, Default)]
pub(crate) struct RankedQueue {
    heap: BinaryHeap<RankedPair>,
    seq: u32,
}

impl PairQueue for RankedQueue {
    const RANKED: bool = true;
    fn clear(&mut self) {
        self.heap.clear();
        self.seq = 0;
    }
    #[inline]
    fn push(&mut self, pair: NodePair, rank: f32) {
        // NaN or negative ranks (never produced by the BV kinds) sort first-out-last.
        let rank = if rank >= 0.0 { rank.min(1.0) } else { 0.0 };
        self.heap.push(RankedPair {
            key: rank.to_bits(),
            seq: self.seq,
            pair,
        });
        self.seq = self.seq.wrapping_add(1);
    }
    #[inline]
    fn pop(&mut self) -> Option<NodePair> {
        self.heap.pop().map(|r| r.pair)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranked_queue_pops_by_rank_then_insertion_order() {
        let mut q = RankedQueue::default();
        let p = |a| NodePair { a, b: 0 };
        q.push(p(0), 0.5);
        q.push(p(1), 0.9);
        q.push(p(2), 0.5);
        q.push(p(3), f32::NAN);
        q.push(p(4), 0.9);
        let order: Vec<u32> = std::iter::from_fn(|| q.pop()).map(|n| n.a).collect();
        assert_eq!(order, [1, 4, 0, 2, 3]);
    }
}
