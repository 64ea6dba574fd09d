//! The NarrowPhase stage: exact shape tests on the broad phase's candidates.
//!
//! A candidate pair of compound bodies descends both hierarchies ([`descend_pairs`]: the
//! scene graph is the BV hierarchy, the larger volume is split first) down to pairs of
//! colliders, and each collider pair is tested at its world pose ([`GlobalPose`]); the
//! hierarchy's work is published as `hierarchy/bv_tests`, `hierarchy/nodes_visited` and
//! `hierarchy/collider_pairs`.
//!
//! With the rigid-body solver each pair is tested looking ahead by its speculative margin: the
//! fixed distances of its moving bodies and how far the two can close in a step
//! (`Lookahead::pair`, `soft_step/lookahead.rs`). The test grows spheres and boxes, raises
//! half-spaces and measures the gaps between two meshes' triangles
//! ([`speculative_contact_with_scratch`]), so manifolds may hold points still apart (negative
//! depth). A pair is always computed with its lower collider first, so which shape is
//! grown and which face is the reference never follow the broad phase's (archetype) order.
//!
//! A costly pair (a mesh against anything; two shapes that are neither spheres, half-spaces
//! nor two capsules: boxes, hulls, cylinders, cones; never an ellipsoid, whose contact moves
//! over its surface as it turns) that moved less than 1 mm
//! relative to each other since its last test, looking ahead no more than 1 mm farther,
//! reuses that test
//! ([`ManifoldCache`], Jolt's body pair cache); `narrow_phase/cached_pairs` counts the pairs
//! answered so in the last run.
//!
//! Pairs involving a mesh go through the mesh's bounding-volume hierarchy
//! ([`contact_with_scratch`]) with buffers kept in a resource from step to step, so a warm step
//! allocates nothing. The hierarchy work of the step — the slides' cost counters `Nv`, `Nn`, `Ns`
//! summed over every mesh query of every substep — is published as the counters
//! `narrow_phase/bvh_nodes_visited`, `narrow_phase/bv_tests` and `narrow_phase/triangle_tests`
//! (with `narrow_phase/mesh_pairs`, the mesh queries run) once a mesh pair has been tested.
//!
//! Collider pairs whose [`CollisionLayers`] do not interact are skipped before any shape test;
//! pairs with a [`Sensor`] are tested for overlap only (no lookahead) and listed in
//! [`SensorOverlaps`], apart from the contacts the solver sees.
//!
//! For debugging, [`OverlappingLeaves`] can list, per mesh pair in contact, the leaves of the
//! hierarchies whose triangles touched, and [`HierarchyVisits`] the scene-graph nodes the descent
//! of compound pairs tested, entered and pruned; each is filled only while enabled (the rerun
//! recording enables them on request), so the narrow phase pays nothing for them otherwise.

use crate::bvh::QueryStats;
use crate::components::*;
use crate::geometry::contacts::{
    ContactScratch, ManifoldCache, NO_TRIANGLE, RoundSide, contact_with_scratch,
    speculative_contact_with_scratch,
};
use crate::geometry::{ContactManifold, Shape};
use crate::hierarchy::{HierarchyStats, PairScratch, descend_pairs};
use crate::plugins::broad_phase::BroadPhasePairs;
use crate::plugins::joints::JointedPairs;
use crate::plugins::required_resources::RequireResource;
use crate::plugins::soft_step::{BodyMotion, LookaheadParams, Moves};
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::settings::SleepSettings;
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use glam::Vec3;
use std::time::Instant;

mod ecs_tree;
mod leaves;
mod outputs;
mod pair_rules;
mod visits;

use ecs_tree::{EcsTree, Node};
use leaves::{Leaf, NO_LEAF_OF_ITS_OWN, emptied};
pub use outputs::{
    ContactPair, Contacts, LeafOverlap, NO_LEAF, OverlappingLeaves, SensorOverlaps, SensorPair,
};
use pair_rules::{balls_meeting, is_mesh, worth_caching};
pub use visits::HierarchyVisits;
use visits::VisitRecorder;

/// Turns candidate pairs into contacts.
#[derive(Debug, Clone, Default)]
pub struct NarrowPhasePlugin;

/// The contact computation, as a label other stages can order against.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ComputeContacts;

/// Where a game edits the contacts before they are solved (Avian's `CollisionHooks`, rapier's
/// `PhysicsHooks`, in plain ECS): systems a game adds to [`SubstepSchedule`] in this set run
/// after the narrow phase and before the solver, with [`Contacts`] and any other data of the
/// world in reach. A pair removed from `Contacts.pairs` is neither solved nor reported as a
/// collision (a one-way platform, a ghost, a team filter); its manifold can be edited (points,
/// normal). Contacts found later in the step by continuous collision are not seen here.
///
/// ```
/// # use bevy_app::App;
/// # use bevy_ecs::prelude::*;
/// # use urto::prelude::*;
/// # use urto::plugins::narrow_phase::{ContactHooks, Contacts};
/// # use urto::schedule::SubstepSchedule;
/// #[derive(Component)]
/// struct Ghost;
///
/// fn ghosts_pass_through(mut contacts: ResMut<Contacts>, ghosts: Query<(), With<Ghost>>) {
///     contacts
///         .pairs
///         .retain(|p| !ghosts.contains(p.a) && !ghosts.contains(p.b));
/// }
///
/// let mut app = App::new();
/// app.add_plugins(UrtoPlugins::default())
///     .add_systems(SubstepSchedule, ghosts_pass_through.in_set(ContactHooks));
/// ```
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ContactHooks;

/// Buffers of the mesh and hierarchy queries, and the work of the current step.
#[derive(Resource, Default)]
struct NarrowPhaseScratch {
    contact: ContactScratch,
    /// Costly pairs' contacts, reused while the pair barely moves (`manifold_cache.rs`).
    cache: ManifoldCache,
    pairs: PairScratch<Entity, Entity>,
    leaf_pairs: Vec<(Entity, Entity)>,
    /// Nodes whose volume the descent read, while [`HierarchyVisits`] is enabled.
    tested_nodes: Vec<(Entity, crate::bounding::Aabb)>,
    hierarchy: HierarchyStats,
    /// The step the sums below belong to.
    step: u64,
    work: QueryStats,
    mesh_pairs: u64,
    /// What the pair loop asks of each body, read from the world once a step (a body in a
    /// pile is in about eight pairs; the lookups were a tenth of a 1,000-ball pile's step).
    bodies: EntityHashMap<BodyFacts>,
    /// The colliders of this step's bodies that are their own only collider, as
    /// [`BodyFacts::leaf`] indexes them: kept empty between steps for its capacity.
    leaves: Vec<Leaf<'static>>,
}

/// A body's part in this step's pairs.
#[derive(Clone, Copy, Debug)]
struct BodyFacts {
    /// Its part in its pairs' speculative margins.
    margin: BodyMotion,
    /// At rest and allowed to stay so (with sleeping on).
    dormant: bool,
    /// It has parts (the scene graph is descended).
    compound: bool,
    /// Its own collision layers (a compound's parts have theirs: they are read per part).
    layers: CollisionLayers,
    /// Its collider in this step's leaves, if it is a single collider.
    leaf: u32,
}

impl Plugin for NarrowPhasePlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<NarrowPhaseScratch>()
            .add_systems(
                SubstepSchedule,
                compute_contacts
                    .run_if(any_with_component::<Collider>)
                    .in_set(ComputeContacts)
                    .in_set(SubstepSet::NarrowPhase),
            )
            .configure_sets(
                SubstepSchedule,
                ContactHooks
                    .after(ComputeContacts)
                    .in_set(SubstepSet::NarrowPhase),
            );
    }
}

/// Whether a body is static or asleep (see [`crate::plugins::sleep`]).
pub(crate) type Dormancy = (Has<Static>, Has<Sleeping>);

/// What a root body's part in its pairs' speculative margins depends on, and whether it is
/// static or asleep (one lookup a body a step for both).
type Motion<'a> = (
    Has<Static>,
    Option<&'a Velocity>,
    Option<&'a AngularVelocity>,
    Option<&'a BoundingVolume>,
    Option<&'a GravityScale>,
    (
        Option<&'a ComputedMass>,
        Option<&'a LockedAxes>,
        Has<Sleeping>,
    ),
);

/// How the solver moves a body: a dynamic one along its free axes (gravity not pulling it while
/// it sleeps), a kinematic one by its velocity, one without a mass not at all.
fn moves(mass: Option<&ComputedMass>, locked: Option<&LockedAxes>, asleep: bool) -> Moves {
    match mass {
        Some(m) if m.inverse() > 0.0 => Moves::Dynamic {
            free: LockedAxes::of(locked).free_translation_axes(),
            asleep,
        },
        Some(_) => Moves::Kinematic,
        None => Moves::Not,
    }
}

#[allow(clippy::too_many_arguments)]
fn compute_contacts(
    pairs: Res<BroadPhasePairs>,
    nodes: Query<Node, Without<Quarantined>>,
    motion: Query<Motion>,
    layers: Query<&CollisionLayers>,
    sensors: Query<(), With<Sensor>>,
    jointed: Option<Res<JointedPairs>>,
    mut overlaps: ResMut<SensorOverlaps>,
    lookahead: LookaheadParams,
    sleep: Option<Res<SleepSettings>>,
    mut contacts: ResMut<Contacts>,
    mut scratch: ResMut<NarrowPhaseScratch>,
    mut debug: ResMut<OverlappingLeaves>,
    mut visits: ResMut<HierarchyVisits>,
    mut stats: ResMut<PhysicsStats>,
) {
    let scratch = &mut *scratch;
    if scratch.step != stats.step {
        scratch.step = stats.step;
        scratch.work = QueryStats::default();
        scratch.mesh_pairs = 0;
        scratch.hierarchy = HierarchyStats::default();
    }
    let record = debug.enabled;
    scratch.contact.set_record_hits(record);
    scratch.cache.begin_step();
    let hits_before = scratch.cache.hits();
    debug.pairs.clear();
    visits.clear();
    let lookahead = lookahead.get();
    // A body's margin, and whether it takes part in no simulation (static or asleep).
    let motion_of = |e: Entity| match motion.get(e) {
        Ok((false, v, w, Some(bv), g, (m, locked, asleep))) => (
            lookahead.motion(v, w, bv, g, moves(m, locked, asleep)),
            asleep,
        ),
        Ok((is_static, .., (_, _, asleep))) => (BodyMotion::default(), is_static || asleep),
        Err(_) => (BodyMotion::default(), false),
    };
    let start = Instant::now();
    contacts.pairs.clear();
    overlaps.pairs.clear();
    let sleeping = sleep.is_some_and(|s| s.enabled);
    // Layers and sensors are per collider (a compound's parts may differ), and a scene without
    // any pays no lookup for them.
    let (any_layers, any_sensors) = (!layers.is_empty(), !sensors.is_empty());
    let sensing =
        |x: Entity, y: Entity| any_sensors && (sensors.contains(x) || sensors.contains(y));
    let layers_of_entity = |x: Entity| layers_of(layers.get(x).ok());
    let interacts = |x: Entity, y: Entity| {
        !any_layers || layers_of_entity(x).interacts_with(&layers_of_entity(y))
    };
    let jointed = jointed.as_deref().filter(|j| !j.is_empty());
    let mut bodies = std::mem::take(&mut scratch.bodies);
    bodies.clear();
    // The last step's buffer, empty, lent for this step's borrows of the world.
    let mut leaves: Vec<Leaf<'_>> = std::mem::take(&mut scratch.leaves);
    // A body's facts are returned as computed, not read back from the map: a copy loaded
    // from an entry just written in pieces waited for those stores to land.
    let mut facts = |e: Entity| {
        if let Some(known) = bodies.get(&e) {
            return (*known, leaves.get(known.leaf as usize).copied());
        }
        let (margin, dormant) = motion_of(e);
        let (compound, leaf) = match nodes.get(e) {
            Ok((Some(collider), global, _, None)) => (false, Some(Leaf::new(collider, global))),
            node => (matches!(node, Ok((.., Some(_)))), None),
        };
        let facts = BodyFacts {
            margin,
            dormant: sleeping && dormant,
            compound,
            layers: if any_layers {
                layers_of_entity(e)
            } else {
                CollisionLayers::default()
            },
            leaf: leaf.map_or(NO_LEAF_OF_ITS_OWN, |leaf| {
                leaves.push(leaf);
                leaves.len() as u32 - 1
            }),
        };
        bodies.insert(e, facts);
        (facts, leaf)
    };
    for &(a, b) in &pairs.pairs {
        let ((fa, leaf_a), (fb, leaf_b)) = (facts(a), facts(b));
        let simple = !fa.compound && !fb.compound;
        // Two colliders whose layers keep them apart are dropped first: their layers came
        // with the facts, where the other tests read more (a net of 10,000 balls on layers of
        // their own has up to 18,000 candidate pairs a step).
        if simple && !fa.layers.interacts_with(&fb.layers) {
            continue;
        }
        if fa.dormant && fb.dormant {
            continue; // at rest against each other: nothing to compute until one wakes
        }
        if jointed.is_some_and(|j| j.contains(a, b)) {
            continue; // a joint keeps them from colliding
        }
        let margin = lookahead.pair(&fa.margin, &fb.margin);
        if simple {
            let (Some(la), Some(lb)) = (leaf_a, leaf_b) else {
                continue; // a body without a collider
            };
            let leaves = ((a, la), (b, lb));
            if sensing(a, b) {
                scratch.test_sensor((a, b), leaves, &mut overlaps);
            } else {
                let motion = lookahead.relative_motion(&fa.margin, &fb.margin);
                let ahead = (margin, motion);
                scratch.test_leaves((a, b), leaves, ahead, &mut contacts, &mut debug);
            }
            continue;
        }
        let tree = EcsTree {
            nodes: &nodes,
            grow: 0.5 * margin,
        };
        let NarrowPhaseScratch {
            pairs: stack,
            leaf_pairs,
            tested_nodes,
            hierarchy,
            ..
        } = &mut *scratch;
        leaf_pairs.clear();
        let found = |la, lb| leaf_pairs.push((la, lb));
        *hierarchy += if visits.enabled {
            let visits = &mut *visits;
            let recorder = VisitRecorder::new(&tree, tested_nodes, &mut visits.entered);
            descend_pairs(&recorder, a, &recorder, b, stack, found)
        } else {
            descend_pairs(&tree, a, &tree, b, stack, found)
        };
        if visits.enabled {
            visits.collider_pairs.extend_from_slice(&scratch.leaf_pairs);
        }
        for i in 0..scratch.leaf_pairs.len() {
            let (ea, eb) = scratch.leaf_pairs[i];
            if !interacts(ea, eb) {
                continue;
            }
            let (Some(la), Some(lb)) = (Leaf::of(&nodes, ea), Leaf::of(&nodes, eb)) else {
                continue;
            };
            let leaves = ((ea, la), (eb, lb));
            if sensing(ea, eb) {
                scratch.test_sensor((a, b), leaves, &mut overlaps);
                continue;
            }
            // A compound's parts also turn with it: no straight motion to meet along.
            let ahead = (margin, Vec3::ZERO);
            scratch.test_leaves((a, b), leaves, ahead, &mut contacts, &mut debug);
        }
    }
    scratch.bodies = bodies;
    scratch.leaves = emptied(leaves);
    if visits.enabled {
        visits.finish(&mut scratch.tested_nodes);
    }
    stats.add_time(Stage::NarrowPhase, start.elapsed());
    stats.count_run("narrow_phase");
    scratch.work += scratch.contact.take_stats();
    let n = contacts.pairs.len();
    stats.set_counter("narrow_phase/contacts", n as f64);
    let cached = scratch.cache.hits() - hits_before;
    stats.set_counter("narrow_phase/cached_pairs", cached as f64);
    if scratch.hierarchy.bv_tests > 0 || stats.counter("hierarchy/bv_tests").is_some() {
        let h = scratch.hierarchy;
        stats.set_counter("hierarchy/bv_tests", h.bv_tests as f64);
        stats.set_counter("hierarchy/nodes_visited", h.nodes_visited as f64);
        stats.set_counter("hierarchy/collider_pairs", h.leaf_pairs as f64);
    }
    if scratch.mesh_pairs > 0 || stats.counter("narrow_phase/mesh_pairs").is_some() {
        let w = scratch.work;
        stats.set_counter("narrow_phase/mesh_pairs", scratch.mesh_pairs as f64);
        stats.set_counter("narrow_phase/bvh_nodes_visited", w.nodes_visited as f64);
        stats.set_counter("narrow_phase/bv_tests", w.bv_tests as f64);
        stats.set_counter("narrow_phase/triangle_tests", w.leaf_tests as f64);
    }
}

impl NarrowPhaseScratch {
    /// Tests a pair with a sensor for overlap (no lookahead: a sensor reports what overlaps
    /// now) and lists it in `overlaps`.
    fn test_sensor(
        &mut self,
        (a, b): (Entity, Entity),
        ((ea, la), (eb, lb)): ((Entity, Leaf), (Entity, Leaf)),
        overlaps: &mut SensorOverlaps,
    ) {
        if contact_with_scratch(la.shape, la.pose, lb.shape, lb.pose, &mut self.contact).is_some() {
            overlaps.pairs.push(SensorPair {
                a,
                b,
                collider_a: ea,
                collider_b: eb,
            });
        }
    }

    /// Tests collider `leaves.0` (of body `roots.0`) against collider `leaves.1` (of `roots.1`)
    /// at their world poses, looking `margin` ahead, B moving by `motion` relative to A over
    /// the step; a mesh goes through its BVH.
    fn test_leaves(
        &mut self,
        (a, b): (Entity, Entity),
        ((ea, ca), (eb, cb)): ((Entity, Leaf), (Entity, Leaf)),
        (margin, motion): (f32, Vec3),
        contacts: &mut Contacts,
        debug: &mut OverlappingLeaves,
    ) {
        // The lower collider first, whatever order the broad phase found the pair in (its
        // order follows insertion, hence archetype order): which box gives the reference face,
        // which shape is grown by the margin, must not depend on an unrelated component.
        let swap = eb < ea;
        let ((sa, pa), (sb, pb)) = if swap {
            ((cb.shape, cb.pose), (ca.shape, ca.pose))
        } else {
            ((ca.shape, ca.pose), (cb.shape, cb.pose))
        };
        let involves_mesh = is_mesh(ca.shape) || is_mesh(cb.shape);
        // A costly pair that barely moved since its last test reuses it (not after a collider
        // changed), a mesh pair with the triangle pairs it found for the debug view.
        let cacheable = worth_caching(sa, sb) && !ca.changed && !cb.changed;
        let key = if swap { (eb, ea) } else { (ea, eb) };
        let key = (key.0.to_bits(), key.1.to_bits());
        let cached = if cacheable {
            self.cache.get(key, (pa, pb), sb.bounding_radius(), margin)
        } else {
            None
        };
        let scratch = &mut self.contact;
        let closing = if swap { -motion } else { motion };
        let meeting = balls_meeting((sa, pa), (sb, pb), margin, closing);
        let mut m = match (meeting, cached) {
            (Some(meeting), _) => {
                scratch.begin_query(); // no triangle pairs: a ball pair's hits are none
                Some(meeting)
            }
            (None, Some(m)) => {
                // The stored triangle pairs are kept only while recording: no second lookup
                // otherwise (most cached pairs are plain convex ones, with none).
                let hits = if debug.enabled {
                    self.cache.hits_of(key)
                } else {
                    &[]
                };
                scratch.set_hits(hits);
                m
            }
            (None, None) => {
                let m = if margin > 0.0 {
                    speculative_contact_with_scratch(sa, pa, sb, pb, margin, scratch)
                } else {
                    contact_with_scratch(sa, pa, sb, pb, scratch)
                };
                if cacheable {
                    let hits = if debug.enabled { scratch.hits() } else { &[] };
                    let tested = (m.as_ref(), RoundSide::of(sa, sb));
                    self.cache.insert(key, (pa, pb), margin, tested, hits);
                }
                m
            }
        };
        if swap {
            scratch.flip_hits();
            m = m.map(ContactManifold::flipped);
        }
        self.mesh_pairs += u64::from(involves_mesh);
        if let Some(manifold) = m {
            contacts.pairs.push(ContactPair {
                a,
                b,
                collider_a: ea,
                collider_b: eb,
                manifold,
                normal_impulse: 0.0,
                impact_speed: 0.0,
                rounding: [
                    ca.shape.rounding_along(ca.pose.rotation, manifold.normal),
                    cb.shape.rounding_along(cb.pose.rotation, manifold.normal),
                ],
            });
            if debug.enabled && involves_mesh {
                let overlap = leaf_overlap(ea, ca.shape, eb, cb.shape, &self.contact);
                debug.pairs.push(overlap);
            }
        }
    }
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
