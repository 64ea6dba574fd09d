//! One hierarchy against a single volume: mesh–sphere, mesh–plane, mesh–box queries.
//!
//! The caller knows the other volume, so it gives the test: a predicate on node BVs ("does this
//! node's BV meet my sphere?", usually through [`Bv::local_aabb`] or the BV's own fields, with the
//! volume already carried into the mesh's frame) and a callback per triangle of every leaf whose
//! BV passed. The descent is depth-first on the scratch's node stack.

use super::cost::QueryStats;
use super::{Bvh, QueryScratch};
use crate::bounding::Bv;
use std::ops::ControlFlow;

impl<B: Bv> Bvh<B> {
    /// Visits the triangles of every leaf whose BV, and every ancestor's, passes `node_test`;
    /// `on_triangle` may stop the descent. Counts: `Nv` nodes visited, `Nn` node tests, `Ns`
    /// triangles handed to `on_triangle`.
    pub fn descend(
        &self,
        scratch: &mut QueryScratch,
        mut node_test: impl FnMut(&B) -> bool,
        mut on_triangle: impl FnMut(u32) -> ControlFlow<()>,
    ) -> QueryStats {
        let mut stats = QueryStats::default();
        let stack = &mut scratch.nodes;
        stack.clear();
        stats.bv_tests += 1;
        if node_test(&self.nodes[0].bv) {
            stack.push(0);
        }
        while let Some(index) = stack.pop() {
            stats.nodes_visited += 1;
            let node = &self.nodes[index as usize];
            match node.children() {
                Some(children) => {
                    // Right first onto the stack, so the left child is visited first.
                    for child in children.into_iter().rev() {
                        stats.bv_tests += 1;
                        if node_test(&self.nodes[child as usize].bv) {
                            stack.push(child);
                        }
                    }
                }
                None => {
                    for &t in self.leaf_triangles(node) {
                        stats.leaf_tests += 1;
                        if on_triangle(t).is_break() {
                            return stats;
                        }
                    }
                }
            }
        }
        stats
    }
}
