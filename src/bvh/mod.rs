//! Bounding-volume hierarchies over triangle meshes, and the pair traversal that uses them (the
//! slides' "Gerarchie di bounding volumes" and "Uso della gerarchia").
//!
//! - [`Bvh`] (`tree.rs`): a binary tree in a flat array, generic over the BV kind ([`Bv`]).
//! - `build.rs`: construction: the split top-down by median or binned SAH (Wald 2007;
//!   `topology.rs`, `binned_sah.rs`), then every node's BV fitted to its triangles and their
//!   summed surface moments.
//! - `query.rs`: the slides' traversal of node pairs — depth-first, breadth-first or by priority —
//!   with early-out or enumeration of every intersecting triangle pair.
//! - `descend.rs`: one hierarchy against a single volume (mesh–sphere, –plane, –box queries).
//! - `refit.rs`: bottom-up update of the BVs after the vertices move.
//! - `cost.rs`: the counters of the cost model `Tc = Nv*Cv + Nn*Cn + Ns*Cs` and a measurement of
//!   the unit costs.
//!
//! The hierarchy stores no geometry: it holds triangle indices, and every query calls back the
//! caller with them, so the same tree serves any leaf test (triangle–triangle, triangle–sphere…).
//!
//! [`Bv`]: crate::bounding::Bv

mod binned_sah;
mod build;
mod cost;
mod descend;
mod error;
mod query;
mod refit;
mod scratch;
mod topology;
mod tree;

pub use build::{BuildOptions, BuildRule, DEFAULT_LEAF_SIZE, DEFAULT_SAH_BINS, MAX_SAH_BINS};
pub use cost::{QueryStats, UnitCosts, measure_unit_costs};
pub use error::BvhError;
pub use query::TraversalOrder;
pub use scratch::QueryScratch;
pub use tree::{Bvh, BvhNode};
