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
//! children), which is what makes an OBB tree tight. The recursion runs on an explicit stack, so
//! a lopsided SAH tree cannot overflow the call stack.

use super::binned_sah::{Primitive, binned_sah_split};
use super::{Bvh, BvhError, BvhNode};
use crate::bounding::{Aabb, Bv};
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
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            rule: BuildRule::BinnedSah,
            leaf_size: DEFAULT_LEAF_SIZE,
            sah_bins: DEFAULT_SAH_BINS,
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
    if u32::try_from(triangles.len()).is_err() {
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

/// A node waiting to be fitted and split: its index and its run of `order`.
struct Pending {
    node: usize,
    start: usize,
    end: usize,
}

impl<B: Bv> Bvh<B> {
    /// Builds the hierarchy of the mesh `(vertices, triangles)` (triangles index `vertices`).
    ///
    /// Errors on an empty mesh, non-finite vertices, out-of-range indices or bad options.
    /// Degenerate triangles (repeated or collinear corners) are fine. Deterministic: the same
    /// input gives the same tree.
    pub fn build(
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        options: &BuildOptions,
    ) -> Result<Self, BvhError> {
        options.validate()?;
        validate_mesh(vertices, triangles)?;
        let primitives: Vec<Primitive> = triangles
            .iter()
            .map(|t| Primitive::of_triangle(t.map(|i| vertices[i as usize])))
            .collect();
        // `validate_mesh` checked that the count fits in u32.
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let n = triangles.len();
        let mut nodes: Vec<BvhNode<B>> = Vec::with_capacity(2 * n.div_ceil(options.leaf_size));
        // A placeholder root, fitted when popped like every other node.
        nodes.push(leaf_node(B::fit_points(std::iter::empty()), 0, n));
        let mut pending = vec![Pending {
            node: 0,
            start: 0,
            end: n,
        }];
        while let Some(Pending { node, start, end }) = pending.pop() {
            let bv = B::fit_triangles(vertices, triangles, &order[start..end]);
            nodes[node] = leaf_node(bv, start, end);
            if end - start <= options.leaf_size {
                continue;
            }
            let run = &mut order[start..end];
            let mid = start + split(run, &primitives, options);
            let left = nodes.len();
            // Placeholders, fitted when popped; `left` and `left + 1` stay adjacent.
            nodes.push(leaf_node(bv, start, mid));
            nodes.push(leaf_node(bv, mid, end));
            nodes[node].start = left as u32;
            nodes[node].count = 0;
            pending.push(Pending {
                node: left + 1,
                start: mid,
                end,
            });
            pending.push(Pending {
                node: left,
                start,
                end: mid,
            });
        }
        Ok(Self { nodes, order })
    }
}

/// A leaf over `order[start..end]` (indices fit in u32: checked by `validate_mesh`).
fn leaf_node<B: Bv>(bv: B, start: usize, end: usize) -> BvhNode<B> {
    BvhNode {
        bv,
        size: bv.size(),
        start: start as u32,
        count: (end - start) as u32,
    }
}

/// Reorders `run` (at least two triangles) and returns the size of its left part, in
/// `1..run.len()`.
fn split(run: &mut [u32], primitives: &[Primitive], options: &BuildOptions) -> usize {
    let sah = match options.rule {
        BuildRule::BinnedSah => binned_sah_split(run, primitives, options.sah_bins),
        BuildRule::Median => None,
    };
    sah.unwrap_or_else(|| median_split(run, primitives))
}

/// Splits at the median centroid along the longest axis of the centroids' bounds; ties (and
/// coincident centroids) are broken by triangle index, so the split always halves the run and is
/// deterministic.
pub(crate) fn median_split(run: &mut [u32], primitives: &[Primitive]) -> usize {
    let bounds = Aabb::from_points(run.iter().map(|&t| primitives[t as usize].centroid));
    let axis = bounds.longest_axis();
    let mid = run.len() / 2;
    run.select_nth_unstable_by(mid, |&a, &b| {
        let ka = primitives[a as usize].centroid[axis];
        let kb = primitives[b as usize].centroid[axis];
        ka.total_cmp(&kb).then(a.cmp(&b))
    });
    mid
}
