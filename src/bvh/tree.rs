//! The hierarchy's storage: nodes in one `Vec`, children by index, leaves as ranges of a
//! reordered triangle-index array.
//!
//! A flat array keeps the tree in a few cache-friendly allocations, copies and drops it in one
//! step, and lets the refit run as a single reverse sweep (children always sit after their
//! parent). The two children of a node are stored next to each other.

use crate::bounding::Bv;
use std::ops::Range;

/// One node: its BV and either two children or a run of triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode<B> {
    /// The node's bounding volume, in the mesh's frame.
    pub bv: B,
    /// `bv.size()`, cached for the traversal's "split the larger BV" rule.
    pub size: f32,
    /// Leaf: first index into [`Bvh::triangle_order`]; inner node: index of the left child (the
    /// right child follows it).
    pub(crate) start: u32,
    /// Leaf: number of triangles (`>= 1`); inner node: 0.
    pub(crate) count: u32,
}

impl<B> BvhNode<B> {
    /// True for a node holding triangles.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// Indices of the two children of an inner node.
    #[inline]
    pub fn children(&self) -> Option<[u32; 2]> {
        (!self.is_leaf()).then_some([self.start, self.start + 1])
    }

    /// The leaf's run in [`Bvh::triangle_order`].
    #[inline]
    pub fn triangle_range(&self) -> Option<Range<usize>> {
        self.is_leaf()
            .then(|| self.start as usize..(self.start + self.count) as usize)
    }
}

/// A binary BV hierarchy over a triangle mesh's triangles. The root is node 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh<B> {
    pub(crate) nodes: Vec<BvhNode<B>>,
    /// The mesh's triangle indices, reordered so that each leaf's triangles are contiguous.
    pub(crate) order: Vec<u32>,
}

impl<B: Bv> Bvh<B> {
    /// All nodes; the root is the first.
    pub fn nodes(&self) -> &[BvhNode<B>] {
        &self.nodes
    }

    /// The root (a hierarchy is never empty: building refuses empty meshes).
    pub fn root(&self) -> &BvhNode<B> {
        &self.nodes[0]
    }

    /// Every triangle index of the mesh, once, in leaf order.
    pub fn triangle_order(&self) -> &[u32] {
        &self.order
    }

    /// Number of triangles the hierarchy was built over.
    pub fn triangle_count(&self) -> usize {
        self.order.len()
    }

    /// The triangles of a leaf (empty for an inner node).
    #[inline]
    pub fn leaf_triangles(&self, node: &BvhNode<B>) -> &[u32] {
        match node.triangle_range() {
            Some(range) => &self.order[range],
            None => &[],
        }
    }

    /// Length of the longest root-to-leaf path, counted in nodes.
    pub fn depth(&self) -> usize {
        // Children follow their parent, so one forward sweep sets every depth.
        let mut depth = vec![1usize; self.nodes.len()];
        for (i, node) in self.nodes.iter().enumerate() {
            if let Some([l, r]) = node.children() {
                depth[l as usize] = depth[i] + 1;
                depth[r as usize] = depth[i] + 1;
            }
        }
        depth.into_iter().max().unwrap_or(0)
    }
}
