//! The NarrowPhase stage: exact shape tests on the broad phase's candidates.
//!
//! Pairs involving a mesh go through the mesh's bounding-volume hierarchy
//! ([`contact_with_scratch`]) with buffers kept in a resource from step to step, so a warm step
//! allocates nothing. The hierarchy work of the step — the slides' cost counters `Nv`, `Nn`, `Ns`
//! summed over every mesh query of every substep — is published as the counters
//! `narrow_phase/bvh_nodes_visited`, `narrow_phase/bv_tests` and `narrow_phase/triangle_tests`
//! (with `narrow_phase/mesh_pairs`, the mesh queries run) once a mesh pair has been tested.
//!
//! For debugging, [`OverlappingLeaves`] can list, per mesh pair in contact, the leaves of the
//! hierarchies whose triangles touched; it is filled only while enabled (the rerun recording
//! enables it on request), so the narrow phase pays nothing for it otherwise.

use crate::bvh::QueryStats;
use crate::components::*;
use crate::geometry::contacts::{ContactScratch, NO_TRIANGLE, contact_with_scratch};
use crate::geometry::{ContactManifold, Shape};
use crate::plugins::broad_phase::BroadPhasePairs;
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;

/// Turns candidate pairs into contacts.
#[derive(Debug, Clone, Default)]
pub struct NarrowPhasePlugin;

/// A contact between two entities; the manifold's normal points from `a` to `b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPair {
    /// First body (a moving one).
    pub a: Entity,
    /// Second body.
    pub b: Entity,
    /// Where and how deep they touch.
    pub manifold: ContactManifold,
}

/// The contacts of this substep, in the broad phase's pair order.
#[derive(Resource, Debug, Default, Clone)]
pub struct Contacts {
    /// The touching pairs.
    pub pairs: Vec<ContactPair>,
}

/// Stands for "no leaf" in [`LeafOverlap::leaves`], on the side of a primitive shape.
pub const NO_LEAF: u32 = u32::MAX;

/// The hierarchy leaves through which two bodies touched in the last substep.
#[derive(Debug, Clone, PartialEq)]
pub struct LeafOverlap {
    /// First body.
    pub a: Entity,
    /// Second body.
    pub b: Entity,
    /// Pairs `[leaf of a, leaf of b]` (node indices in each body's
    /// [`MeshCollider::bvh`](crate::geometry::MeshCollider::bvh), [`NO_LEAF`] for a primitive),
    /// sorted, each once: the leaf pairs holding at least one pair of touching triangles.
    pub leaves: Vec<[u32; 2]>,
}

/// Debug output of the narrow phase: the leaves of each mesh contact. Empty unless `enabled`.
#[derive(Resource, Debug, Default, Clone)]
pub struct OverlappingLeaves {
    /// Fill [`pairs`](Self::pairs) (costs a little per mesh contact).
    pub enabled: bool,
    /// One entry per mesh pair in contact in the last substep, in the contacts' order.
    pub pairs: Vec<LeafOverlap>,
}

/// Buffers of the mesh queries, and the hierarchy work of the current step.
#[derive(Resource, Debug, Default)]
struct NarrowPhaseScratch {
    contact: ContactScratch,
    /// The step the sums below belong to.
    step: u64,
    work: QueryStats,
    mesh_pairs: u64,
}

impl Plugin for NarrowPhasePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Contacts>()
            .init_resource::<NarrowPhaseScratch>()
            .init_resource::<OverlappingLeaves>()
            .add_systems(
                SubstepSchedule,
                compute_contacts
                    .run_if(any_with_component::<Collider>)
                    .in_set(SubstepSet::NarrowPhase),
            );
    }
}

fn compute_contacts(
    pairs: Res<BroadPhasePairs>,
    colliders: Query<(&Collider, &Position, &Rotation)>,
    mut contacts: ResMut<Contacts>,
    mut scratch: ResMut<NarrowPhaseScratch>,
    mut debug: ResMut<OverlappingLeaves>,
    mut stats: ResMut<PhysicsStats>,
) {
    let scratch = &mut *scratch;
    if scratch.step != stats.step {
        scratch.step = stats.step;
        scratch.work = QueryStats::default();
        scratch.mesh_pairs = 0;
    }
    let record = debug.enabled;
    scratch.contact.set_record_hits(record);
    debug.pairs.clear();
    stats.time(Stage::NarrowPhase, "narrow_phase", || {
        contacts.pairs.clear();
        for &(a, b) in &pairs.pairs {
            let (Ok((ca, pa, ra)), Ok((cb, pb, rb))) = (colliders.get(a), colliders.get(b)) else {
                continue;
            };
            let m = contact_with_scratch(
                &ca.shape,
                &pose(pa, Some(ra)),
                &cb.shape,
                &pose(pb, Some(rb)),
                &mut scratch.contact,
            );
            let involves_mesh = is_mesh(&ca.shape) || is_mesh(&cb.shape);
            scratch.mesh_pairs += u64::from(involves_mesh);
            if let Some(manifold) = m {
                contacts.pairs.push(ContactPair { a, b, manifold });
                if record && involves_mesh {
                    debug
                        .pairs
                        .push(leaf_overlap(a, &ca.shape, b, &cb.shape, &scratch.contact));
                }
            }
        }
    });
    scratch.work += scratch.contact.take_stats();
    let n = contacts.pairs.len();
    stats.set_counter("narrow_phase/contacts", n as f64);
    if scratch.mesh_pairs > 0 || stats.counter("narrow_phase/mesh_pairs").is_some() {
        let w = scratch.work;
        stats.set_counter("narrow_phase/mesh_pairs", scratch.mesh_pairs as f64);
        stats.set_counter("narrow_phase/bvh_nodes_visited", w.nodes_visited as f64);
        stats.set_counter("narrow_phase/bv_tests", w.bv_tests as f64);
        stats.set_counter("narrow_phase/triangle_tests", w.leaf_tests as f64);
    }
}

fn is_mesh(shape: &Shape) -> bool {
    matches!(shape, Shape::TriMesh(_))
}

/// The leaf pairs of the last query's triangle hits.
fn leaf_overlap(
    a: Entity,
    shape_a: &Shape,
    b: Entity,
    shape_b: &Shape,
    scratch: &ContactScratch,
) -> LeafOverlap {
    let leaf = |shape: &Shape, t: u32| match shape {
        Shape::TriMesh(m) if t != NO_TRIANGLE => m.leaf_of_triangle(t).unwrap_or(NO_LEAF),
        _ => NO_LEAF,
    };
    let mut leaves: Vec<[u32; 2]> = scratch
        .hits()
        .iter()
        .map(|&[ta, tb]| [leaf(shape_a, ta), leaf(shape_b, tb)])
        .collect();
    leaves.sort_unstable();
    leaves.dedup();
    LeafOverlap { a, b, leaves }
}
