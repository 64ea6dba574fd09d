//! The scene graph as a bounding-volume hierarchy (the slides' "Conclusioni": "if you have a
//! scene graph, use it directly as the hierarchy and keep the BV in the node").
//!
//! A node of a compound body may carry its own collider and may have children; its bounding
//! volume bounds both. This module holds the algorithms, over any tree that can answer a few
//! questions ([`BvTree`]), with no ECS inside:
//! - [`descend_pairs`]: the pair query between two hierarchies, the slides' traversal (a queue of
//!   node pairs starting at the two roots; when not both are leaves, split the one with the
//!   larger bounding volume), down to pairs of colliders;
//! - [`refit_order`]: which nodes to refit, deepest first, when some nodes changed — only the
//!   changed nodes and their ancestors, so a static town pays nothing and a moving wheel refits
//!   the wheel and the car, not the town;
//! - [`topmost_marked`]: which changed nodes to recompose poses from (those without a changed
//!   ancestor), so each node is recomposed once.
//!
//! Both memoise what they climbed: their cost is linear in the nodes on the changed paths,
//! however deep the chains.

mod pairs;
mod refit;

pub use pairs::{BvTree, HierarchyStats, PairScratch, descend_pairs};
pub use refit::{climb, refit_order, topmost_marked};
