//! Top-down construction of a [`Bvh`]: split the triangles in two, recurse, stop at `leaf_size`.
//!
//! Two split rules (the slides' question "how is it built?"):
//! - [`BuildRule::Median`]: half the triangles on each side of the median centroid along the
//!   longest axis of the centroids' bounds. Balanced (depth ⌈log₂(n/leaf)⌉), cheap, blind to
//!   the shape.
//! - [`BuildRule::BinnedSah`]: the surface-area heuristic evaluated on a few bins per axis (Wald
//!   2007, "On fast construction of SAH-based bounding volume hierarchies"); see `binned_sah.rs`.
//!   Falls back to the median when the centroids cannot be told apart.
//!
//! Whatever the rule, each node's BV is fitted to the node's own triangles (not merged from its
//! children), which is what makes an OBB tree tight; what a fit needs of the surface (the OBB's
//! covariance, the AABB's box) comes from moments summed bottom-up, so only the exact extents
//! cost a pass over a node's corners.

use super::binned_sah::{Primitive, centroid_bounds};
use super::topology::{PARALLEL_MIN_RUN, Span, split_top_down};
use super::{Bvh, BvhError, BvhNode};
use crate::bounding::{Aabb, Bv, SurfaceMoments, TriangleSet};
use glam::Vec3;

/// Triangles per leaf unless told otherwise: small leaves keep `Ns` low, which pays when the
/// leaf test (triangle–triangle) costs more than a BV test.
pub const DEFAULT_LEAF_SIZE: usize = 4;
/// SAH bins per axis unless told otherwise (Wald 2007 finds 8–16 as good as a full sweep).
pub const DEFAULT_SAH_BINS: usize = 12;
/// Most SAH bins per axis (they live in a fixed array on the stack).
pub const MAX_SAH_BINS: usize = 64;

/// How a node's triangles are split between its two children.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BuildRule {
    /// Median centroid along the longest axis.
    Median,
    /// Binned surface-area heuristic, on AABBs whatever the stored BV kind.
    BinnedSah,
}

/// Parameters of [`Bvh::build`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BuildOptions {
    /// The split rule.
    pub rule: BuildRule,
    /// Most triangles in a leaf, `>= 1`.
    pub leaf_size: usize,
    /// Bins per axis for [`BuildRule::BinnedSah`], in `2..=MAX_SAH_BINS`.
    pub sah_bins: usize,
    /// Most threads the build may use: `0` for as many as the machine has
    /// ([`std::thread::available_parallelism`]), `1` to build on the caller's thread only. The
    /// tree is the same whatever the count; meshes under a few thousand triangles are built on
    /// the caller's thread anyway.
    pub threads: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            rule: BuildRule::BinnedSah,
            leaf_size: DEFAULT_LEAF_SIZE,
            sah_bins: DEFAULT_SAH_BINS,
            threads: 0,
        }
    }
}

impl BuildOptions {
    /// Default options with the given rule.
    pub fn with_rule(rule: BuildRule) -> Self {
        Self {
            rule,
            ..Self::default()
        }
    }

    /// The threads a build of `triangles` triangles uses: never more than the machine has.
    fn thread_count(&self, triangles: usize) -> usize {
        if triangles < PARALLEL_MIN_RUN {
            return 1;
        }
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        match self.threads {
            0 => cores,
            n => n.min(cores),
        }
    }

    fn validate(&self) -> Result<(), BvhError> {
        if self.leaf_size == 0 {
            return Err(BvhError::BadLeafSize(self.leaf_size));
        }
        if !(2..=MAX_SAH_BINS).contains(&self.sah_bins) {
            return Err(BvhError::BadBinCount(self.sah_bins));
        }
        Ok(())
    }
}

/// Checks the mesh once, so that nothing later needs to: finite vertices, indices in range, a
/// triangle count that fits in `u32`.
pub(crate) fn validate_mesh(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Result<(), BvhError> {
    if triangles.is_empty() {
        return Err(BvhError::EmptyMesh);
    }
    // A tree has fewer than 2 × triangles nodes, and nodes are indexed by u32.
    if triangles.len() > u32::MAX as usize / 2 {
        return Err(BvhError::TooManyTriangles(triangles.len()));
    }
    if let Some(vertex) = vertices.iter().position(|v| !v.is_finite()) {
        return Err(BvhError::NonFiniteVertex { vertex });
    }
    for (triangle, corners) in triangles.iter().enumerate() {
        if let Some(&index) = corners.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(BvhError::IndexOutOfRange {
                triangle,
                index,
                vertex_count: vertices.len(),
            });
        }
    }
    Ok(())
}

impl<B: Bv> Bvh<B> {
    /// Builds the hierarchy of the mesh `(vertices, triangles)` (triangles index `vertices`).
    ///
    /// Errors on an empty mesh, non-finite vertices, out-of-range indices or bad options.
    /// Degenerate triangles (repeated or collinear corners) are fine. Deterministic: the same
    /// input gives the same tree.
    ///
    /// Three passes (the first and the last on several threads for large meshes, see
    /// [`BuildOptions::threads`]): the topology top-down (splitting the primitives in place, so that every
    /// node's triangles are contiguous), the surface moments bottom-up (each triangle integrated
    /// once, each inner node the sum of its children's), then every node's BV fitted to its
    /// contiguous corners and its summed moments.
    pub fn build(
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        options: &BuildOptions,
    ) -> Result<Self, BvhError> {
        options.validate()?;
        validate_mesh(vertices, triangles)?;
        let corners_of = |t: u32| triangles[t as usize].map(|i| vertices[i as usize]);
        // `validate_mesh` checked that the count fits in u32.
        let mut primitives: Vec<Primitive> = (0..triangles.len() as u32)
            .map(|t| Primitive::of_triangle(t, corners_of(t)))
            .collect();
        let threads = options.thread_count(triangles.len());
        let spans = split_top_down(&mut primitives, options, threads);
        let order: Vec<u32> = primitives.iter().map(|p| p.triangle).collect();
        let corners: Vec<[Vec3; 3]> = order.iter().map(|&t| corners_of(t)).collect();
        let origin = Aabb::from(centroid_bounds(&primitives)).center();
        let surfaces = summed_surfaces(&spans, &corners, origin);
        let nodes = fit_nodes(&spans, &surfaces, &corners, threads);
        Ok(Self { nodes, order })
    }
}

/// Every node's BV, fitted to its corners and summed moments, on up to `threads` threads (the
/// nodes are independent; each thread takes a run of them holding about the same number of
/// triangles).
fn fit_nodes<B: Bv>(
    spans: &[Span],
    surfaces: &[SurfaceMoments],
    corners: &[[Vec3; 3]],
    threads: usize,
) -> Vec<BvhNode<B>> {
    let fit = |(span, surface): (&Span, &SurfaceMoments)| {
        let set = TriangleSet::with_surface(&corners[span.start..span.end], *surface);
        let bv = B::fit_triangles(&set);
        let (start, count) = match span.left {
            Some(left) => (left, 0),
            None => (span.start, span.end - span.start),
        };
        // Indices and counts fit in u32: there are fewer nodes than 2 × triangles.
        BvhNode {
            bv,
            size: bv.size(),
            start: start as u32,
            count: count as u32,
        }
    };
    let fit_run = |range: std::ops::Range<usize>| -> Vec<BvhNode<B>> {
        spans[range.clone()]
            .iter()
            .zip(&surfaces[range])
            .map(fit)
            .collect()
    };
    let cuts = balanced_cuts(spans, threads);
    let runs: Vec<_> = cuts.windows(2).map(|w| w[0]..w[1]).collect();
    let Some((last, others)) = runs.split_last() else {
        return Vec::new();
    };
    std::thread::scope(|scope| {
        let spawned: Vec<_> = others
            .iter()
            .map(|run| {
                let (fit_run, mine) = (&fit_run, run.clone());
                let handle = std::thread::Builder::new().spawn_scoped(scope, move || fit_run(mine));
                (run.clone(), handle)
            })
            .collect();
        // This thread fits the last run while the others work.
        let last = fit_run(last.clone());
        let mut nodes = Vec::with_capacity(spans.len());
        for (run, handle) in spawned {
            nodes.extend(match handle {
                // A panic on a fitting thread is a bug; pass it on rather than hide it.
                Ok(handle) => handle
                    .join()
                    .unwrap_or_else(|e| std::panic::resume_unwind(e)),
                // No thread to be had (the system's limit): fit the run here.
                Err(_) => fit_run(run),
            });
        }
        nodes.extend(last);
        nodes
    })
}

/// Node indices cutting `spans` into `threads` runs of about equal work (the triangles the
/// nodes cover), from 0 to `spans.len()`.
fn balanced_cuts(spans: &[Span], threads: usize) -> Vec<usize> {
    let total: usize = spans.iter().map(|s| s.end - s.start).sum();
    // A run too small to pay for its thread is not cut off.
    let share = total.div_ceil(threads.max(1)).max(PARALLEL_MIN_RUN);
    let mut cuts = vec![0];
    let mut work = 0;
    for (i, span) in spans.iter().enumerate() {
        work += span.end - span.start;
        if work >= share * cuts.len() && i + 1 < spans.len() {
            cuts.push(i + 1);
        }
    }
    cuts.push(spans.len());
    cuts
}

/// Every node's surface moments about `origin`: a leaf integrates its triangles, an inner node
/// adds its children's (children sit after their parent, so one reverse sweep sees them first).
fn summed_surfaces(spans: &[Span], corners: &[[Vec3; 3]], origin: Vec3) -> Vec<SurfaceMoments> {
    let mut surfaces = vec![SurfaceMoments::empty(origin); spans.len()];
    for (node, span) in spans.iter().enumerate().rev() {
        surfaces[node] = match span.left {
            Some(left) => surfaces[left].plus(&surfaces[left + 1]),
            None => corners[span.start..span.end]
                .iter()
                .fold(SurfaceMoments::empty(origin), |sum, &t| {
                    sum.plus(&SurfaceMoments::of_triangle(t, origin))
                }),
        };
    }
    surfaces
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cuts cover every node once, in order, and no run holds much more than its share of
    /// the work.
    #[test]
    fn balanced_cuts_cover_the_nodes_in_runs_of_about_equal_work() {
        // A complete tree over 65,536 triangles, leaves of 4, in preorder.
        fn preorder(start: usize, end: usize, out: &mut Vec<Span>) {
            out.push(Span {
                start,
                end,
                left: None,
            });
            if end - start > 4 {
                let mid = (start + end) / 2;
                preorder(start, mid, out);
                preorder(mid, end, out);
            }
        }
        let mut spans = Vec::new();
        preorder(0, 1 << 16, &mut spans);
        for threads in [1, 2, 3, 8] {
            let cuts = balanced_cuts(&spans, threads);
            assert_eq!((cuts[0], *cuts.last().unwrap()), (0, spans.len()));
            assert!(cuts.windows(2).all(|w| w[0] < w[1]));
            assert!(cuts.len() - 1 <= threads);
            assert_eq!(
                cuts.len() - 1,
                threads,
                "a 65,536-triangle tree keeps every thread busy"
            );
            let total: usize = spans.iter().map(|s| s.end - s.start).sum();
            for w in cuts.windows(2) {
                let work: usize = spans[w[0]..w[1]].iter().map(|s| s.end - s.start).sum();
                // A run overshoots its share by at most one node (the root covers all 65,536).
                let share = total.div_ceil(threads).max(PARALLEL_MIN_RUN);
                assert!(work <= share + (1 << 16), "{threads}: {work}");
            }
        }
    }
}
