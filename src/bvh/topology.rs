//! The shape of a hierarchy: the triangles split top-down, in place, until every run is a leaf.
//!
//! The split rule is the caller's ([`BuildRule`]); this file decides the order of the nodes and
//! who computes them. The nodes come out in depth-first preorder with the two children of a node
//! side by side, after their parent (what `tree.rs` stores and the refit's reverse sweep needs).
//!
//! The two halves below a split share nothing (each owns its run of primitives), so on large
//! meshes the first levels hand one half to another thread ([`std::thread::scope`]), as
//! parallel BVH builders do (Wald 2007, §4; Embree's builders). The halves' node lists are then
//! laid out exactly as the sequential build would lay them out, so the tree is the same bit for
//! bit whatever the thread count.

use super::binned_sah::{Primitive, SahBins, binned_sah_split, centroid_bounds};
use super::build::{BuildOptions, BuildRule};
use crate::bounding::Aabb;

/// Runs shorter than this are never handed to another thread (the thread would cost more than
/// the split work it takes over).
pub(crate) const PARALLEL_MIN_RUN: usize = 4096;

/// A node of the tree being built: its run of primitives and, once split, its left child (the
/// right one follows it).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Span {
    pub start: usize,
    pub end: usize,
    pub left: Option<usize>,
}

/// Splits the primitives top-down until runs of at most `leaf_size`, on up to `threads` threads;
/// returns the nodes (the root first).
pub(crate) fn split_top_down(
    primitives: &mut [Primitive],
    options: &BuildOptions,
    threads: usize,
) -> Vec<Span> {
    // Each level of handing off doubles the threads at work: at most `threads` of them.
    let levels = threads.max(1).ilog2();
    split_in_parallel(primitives, options, levels)
}

/// The root split here; below it, the left half on a new thread and the right half on this one
/// while `levels` remain and the run is long enough.
fn split_in_parallel(
    primitives: &mut [Primitive],
    options: &BuildOptions,
    levels: u32,
) -> Vec<Span> {
    let n = primitives.len();
    if levels == 0 || n < PARALLEL_MIN_RUN {
        return split_sequentially(primitives, options);
    }
    let mid = split(primitives, options, &mut SahBins::new(options.sah_bins));
    let (left, right) = primitives.split_at_mut(mid);
    let (left, right) = std::thread::scope(|scope| {
        let left = scope.spawn(|| split_in_parallel(left, options, levels - 1));
        let right = split_in_parallel(right, options, levels - 1);
        // A panic on the other thread is a bug in this file; pass it on rather than hide it.
        (
            left.join().unwrap_or_else(|e| std::panic::resume_unwind(e)),
            right,
        )
    });
    joined(n, mid, &left, &right)
}

/// The tree of a run split at `mid` into the subtrees `left` (over `0..mid`) and `right` (over
/// `mid..n`, with spans relative to `mid`), in the sequential build's layout: root, both
/// children, the left child's descendants, then the right child's.
fn joined(n: usize, mid: usize, left: &[Span], right: &[Span]) -> Vec<Span> {
    let mut spans = Vec::with_capacity(1 + left.len() + right.len());
    spans.push(Span {
        start: 0,
        end: n,
        left: Some(1),
    });
    // Local index k of the left subtree: its root goes to 1, its descendants after both roots.
    let left_index = |k: usize| if k == 0 { 1 } else { k + 2 };
    let right_index = |k: usize| if k == 0 { 2 } else { k + 1 + left.len() };
    spans.push(moved(left[0], 0, left_index));
    spans.push(moved(right[0], mid, right_index));
    spans.extend(left[1..].iter().map(|&s| moved(s, 0, left_index)));
    spans.extend(right[1..].iter().map(|&s| moved(s, mid, right_index)));
    spans
}

/// A subtree's span placed in the joined tree: its run shifted by `offset`, its child renumbered.
fn moved(span: Span, offset: usize, index: impl Fn(usize) -> usize) -> Span {
    Span {
        start: span.start + offset,
        end: span.end + offset,
        left: span.left.map(index),
    }
}

/// The sequential build, on an explicit stack so that a lopsided SAH tree cannot overflow the
/// call stack.
fn split_sequentially(primitives: &mut [Primitive], options: &BuildOptions) -> Vec<Span> {
    let n = primitives.len();
    let mut spans = Vec::with_capacity(2 * n.div_ceil(options.leaf_size));
    spans.push(Span {
        start: 0,
        end: n,
        left: None,
    });
    let mut pending = vec![0];
    let mut bins = SahBins::new(options.sah_bins);
    while let Some(node) = pending.pop() {
        let Span { start, end, .. } = spans[node];
        if end - start <= options.leaf_size {
            continue;
        }
        let mid = start + split(&mut primitives[start..end], options, &mut bins);
        let left = spans.len();
        for (start, end) in [(start, mid), (mid, end)] {
            spans.push(Span {
                start,
                end,
                left: None,
            });
        }
        spans[node].left = Some(left);
        pending.push(left + 1);
        pending.push(left);
    }
    spans
}

/// Reorders `run` (at least two triangles) and returns the size of its left part, in
/// `1..run.len()`.
fn split(run: &mut [Primitive], options: &BuildOptions, bins: &mut SahBins) -> usize {
    let sah = match options.rule {
        BuildRule::BinnedSah => binned_sah_split(run, bins),
        BuildRule::Median => None,
    };
    sah.unwrap_or_else(|| median_split(run))
}

/// Splits at the median centroid along the longest axis of the centroids' bounds; ties (and
/// coincident centroids) are broken by triangle index, so the split always halves the run and is
/// deterministic.
fn median_split(run: &mut [Primitive]) -> usize {
    let axis = Aabb::from(centroid_bounds(run)).longest_axis();
    let mid = run.len() / 2;
    run.select_nth_unstable_by(mid, |a, b| {
        a.centroid()[axis]
            .total_cmp(&b.centroid()[axis])
            .then(a.triangle.cmp(&b.triangle))
    });
    mid
}
