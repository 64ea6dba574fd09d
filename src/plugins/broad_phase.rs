//! The BroadPhase stage (after [`HierarchyPlugin`](crate::plugins::HierarchyPlugin) refit the
//! bounding volumes): keeps the broad-phase structures in step with the world and lists the
//! candidate pairs of root bodies.
//!
//! - Moving bodies are in an incremental sweep and prune (the slides' §8; from 20,000 bodies
//!   its segmented form, a sweep per cell of a grid), fed only the bodies whose volume
//!   changed, so bodies at rest cost nothing.
//! - Bounded static scenery is in a hashed uniform grid (the slides' "object vs static scene"):
//!   indexed once, queried with each moving body's volume; statics never enter the sort. A
//!   query keeps the statics met by a fattened volume ([`GridQueryCache`], Box2D's fat AABBs),
//!   so a body still inside it next step filters that short list and hashes no cell: same
//!   answer, a resting pile's grid queries for a fraction of the cost.
//! - Unbounded scenery (grounds, walls) is paired with every moving body whose volume reaches
//!   it: a half-space only with the bodies whose grown volume has a corner below its plane (a
//!   ball in the middle of a box of six planes is paired with none), anything else unbounded
//!   (a half-space with colliders below it in the scene graph, a compound) with every moving
//!   body.
//! - A root without parts whose [`CollisionLayers`] interact with none (no membership or no
//!   filter) is left out: every pair it could make would fail the narrow phase's layer test.
//!   New layers, removed layers or a first part put it back in within the step (a sleeping
//!   body woken by the write). Spatial queries keep their own index (their masks decide).
//! - Sleeping bodies stay indexed where they are but are paired with nothing (neither scenery
//!   nor other sleepers) until they wake: the plugin hears of each body falling asleep or
//!   waking from the [`Sleeping`] marker's hooks, so a sleeping pile costs no pass here.
//! - With the rigid-body solver, a moving body's volume in the sweep is grown by its speculative
//!   margin ([`SpeculativeMargin`](crate::plugins::SpeculativeMargin)), and a new velocity or
//!   [`GravityScale`] (written or removed) re-indexes it, so pairs are found while the bodies
//!   can still close in one step.
//!
//! The moving-body algorithm is replaceable: any [`BroadPhase`] works, e.g.
//! `BroadPhasePlugin { moving: || Box::new(RegionSweep::new()), ..default() }` (the segmented
//! sweep and prune, for scenes of many thousands of moving bodies; the step's result is the
//! same bit for bit, `tests/determinism.rs`).
//!
//! [`RegionSweep`]: crate::broad_phase::RegionSweep

use crate::bounding::Aabb;
use crate::broad_phase::{
    AdaptiveSweep, BodyKind, BroadPhase, GridQueryCache, GridQueryStats, ProxyId, StaticGrid,
    StaticGridConfig,
};
use crate::components::*;
use crate::plugins::core::PrepareIndex;
use crate::plugins::hierarchy::HierarchyInstalled;
use crate::plugins::proxy_table::{Proxy, ProxyTable};
use crate::plugins::required_resources::RequireResource;
use crate::plugins::settle::Unsettled;
use crate::plugins::soft_step::{Lookahead, LookaheadParams};
use crate::plugins::validation::quarantine;
use crate::schedule::{BroadPhaseSystems, PhysicsSchedule, SubstepSchedule};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::change_detection::{CheckChangeTicks, Tick};
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemChangeTick;
use std::time::Instant;
use world_plane::WorldPlane;

mod world_plane;

/// Makes a fresh moving-body broad phase.
pub type BroadPhaseFactory = fn() -> Box<dyn BroadPhase + Send + Sync>;

/// Keeps bounding volumes and the broad-phase structures fresh and finds candidate pairs.
#[derive(Debug, Clone)]
pub struct BroadPhasePlugin {
    /// The moving-body algorithm (default: incremental sweep and prune that falls back to
    /// sorting from scratch while insertion sort loses, and moves into the segmented sweep and
    /// prune from 20,000 bodies, [`AdaptiveSweep`]).
    pub moving: BroadPhaseFactory,
    /// The static grid's settings (default: cell size chosen from the statics' sizes).
    pub grid: StaticGridConfig,
}

impl Default for BroadPhasePlugin {
    fn default() -> Self {
        Self {
            moving: || Box::new(AdaptiveSweep::new()),
            grid: StaticGridConfig::default(),
        }
    }
}

/// Indexing bodies spawned, moved or removed between steps, in Prepare: scenery is in the grid
/// before any substep sweeps against it.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct IndexBodies;

/// Candidate pairs of this substep; the first entity of a pair is always a moving body.
#[derive(Resource, Debug, Default, Clone)]
pub struct BroadPhasePairs {
    /// The pairs, in a deterministic order: moving–moving, then moving–static, then
    /// moving–unbounded.
    pub pairs: Vec<(Entity, Entity)>,
}

/// Whether a node among `children` or below them has a collider (`stack`: scratch; a deep
/// `ChildOf` chain is walked without recursion).
fn has_collider_below(
    children: &Children,
    nodes: &Query<(Has<Collider>, Option<&Children>)>,
    stack: &mut Vec<Entity>,
) -> bool {
    stack.clear();
    stack.extend(children.iter());
    while let Some(node) = stack.pop() {
        match nodes.get(node) {
            Ok((true, _)) => return true,
            Ok((false, Some(below))) => stack.extend(below.iter()),
            _ => {}
        }
    }
    false
}

/// The broad-phase structures and the entity ↔ id table.
#[derive(Resource)]
pub struct BroadPhaseIndex {
    moving: Box<dyn BroadPhase + Send + Sync>,
    grid: StaticGrid,
    grid_config: StaticGridConfig,
    proxies: ProxyTable,
    static_batch: Vec<(ProxyId, Aabb)>,
    moving_batch: Vec<(ProxyId, Aabb, BodyKind)>,
    hits: Vec<u32>,
    /// The statics each moving body's last grid query met, reused while it stays inside the
    /// box they were found for (resting bodies query no cell).
    grid_queries: GridQueryCache,
    /// The world planes of the unbounded statics that are half-spaces (in their order),
    /// taken each substep.
    planes: Vec<Option<WorldPlane>>,
    /// Made since the last sync (first step, or made again after game code removed it): every
    /// root is indexed, not only the changed ones.
    fresh: bool,
    /// The lookahead the indexed volumes were grown with: when the margin settings, the step,
    /// gravity or the solver's substeps change, every root is indexed again (a resting body's
    /// velocity does not change, so nothing else would re-grow it).
    grown_with: Option<Lookahead>,
    /// When the index was last synced, by either of its two systems (the step's start and the
    /// substep): each `Changed` filter sees the writes since its own system last ran, so the
    /// substep's sync re-sent every body the step's start had just indexed (with the solver
    /// nothing moves between the two: a tenth of the broad phase of 10,000 resting balls).
    synced_at: Option<Tick>,
}

impl BroadPhaseIndex {
    fn new(plugin: &BroadPhasePlugin) -> Self {
        Self {
            moving: (plugin.moving)(),
            grid: StaticGrid::new(plugin.grid).unwrap_or_else(|e| {
                log::error!("urto: bad static grid settings ({e}); using the defaults");
                StaticGrid::default()
            }),
            grid_config: plugin.grid,
            proxies: ProxyTable::default(),
            static_batch: Vec::new(),
            moving_batch: Vec::new(),
            hits: Vec::new(),
            grid_queries: GridQueryCache::default(),
            planes: Vec::new(),
            fresh: true,
            grown_with: None,
            synced_at: None,
        }
    }

    /// The static grid (read-only: for debug drawing and queries by game code).
    pub fn grid(&self) -> &StaticGrid {
        &self.grid
    }

    /// The moving-body broad phase.
    pub fn moving(&self) -> &(dyn BroadPhase + Send + Sync) {
        self.moving.as_ref()
    }

    /// Appends to `out` the static roots whose volume meets `aabb` (from the grid, ascending
    /// proxy id) and then every unbounded static (entity order): the scenery a volume may touch.
    pub fn statics_touching(&mut self, aabb: &Aabb, out: &mut Vec<Entity>) {
        if !self.grid.is_empty() && self.grid.query(aabb, &mut self.hits).is_ok() {
            out.extend(self.hits.iter().map(|&id| self.proxies.entity(id)));
        }
        out.extend_from_slice(self.proxies.unbounded());
    }
}

impl Plugin for BroadPhasePlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<SleepTransitions>()
            .insert_required({
                let plugin = self.clone();
                move || BroadPhaseIndex::new(&plugin)
            })
            .add_systems(
                SubstepSchedule,
                (
                    sync_broad_phase.in_set(BroadPhaseSystems::Index),
                    find_candidate_pairs.in_set(BroadPhaseSystems::Pairs),
                )
                    .run_if(any_with_component::<Collider>),
            )
            .add_systems(
                PhysicsSchedule,
                sync_broad_phase
                    .run_if(any_with_component::<Collider>)
                    .in_set(IndexBodies)
                    .in_set(PrepareIndex),
            )
            .add_observer(clamp_synced_tick);
    }
}

/// What the broad phase needs to know of a root body (then: whether it sleeps, and whether it
/// pairs with nothing).
type Indexed<'a> = (
    Entity,
    &'a BoundingVolume,
    Has<Static>,
    Option<&'a Velocity>,
    Option<&'a AngularVelocity>,
    Option<&'a GravityScale>,
    Has<Sleeping>,
    (Option<&'a CollisionLayers>, Has<Children>),
);
/// [`Indexed`] with the change ticks, to tell what changed since the last sync of either
/// schedule.
type Watched<'a> = (
    Entity,
    Ref<'a, BoundingVolume>,
    Has<Static>,
    Option<Ref<'a, Velocity>>,
    Option<Ref<'a, AngularVelocity>>,
    Option<Ref<'a, GravityScale>>,
    (Option<Ref<'a, CollisionLayers>>, Option<Ref<'a, Children>>),
);
/// A root's layers and whether it has parts: see [`pairs_with_nothing`].
type Inertness<'a> = (Option<&'a CollisionLayers>, bool);
type IndexedRow<'a> = (
    Entity,
    &'a BoundingVolume,
    bool,
    Option<&'a Velocity>,
    Option<&'a AngularVelocity>,
    Option<&'a GravityScale>,
    bool,
    Inertness<'a>,
);

/// Whether a root can pair with no collider, so the broad phase leaves it out: a body without
/// parts whose layers interact with none (no membership or no filter, as the balls of a joint
/// net with collisions off). Its pairs would all be dropped by the narrow phase's layer test;
/// leaving it out also saves its place in the sweeps (a sixth of the instructions of a
/// 10,000-ball joint net's step). A root with children is kept: its parts have layers of
/// their own.
fn pairs_with_nothing((layers, has_parts): Inertness) -> bool {
    !has_parts && layers.is_some_and(|l| l.0.interact_with_none())
}
type Root = (Without<ChildOf>, Without<Quarantined>);
/// A moving body's margin follows its velocity, so a new velocity re-indexes it.
/// Sleeping bodies are left out: they do not move, and a write to one wakes it first.
type Moved = (
    Or<(
        Changed<BoundingVolume>,
        Changed<Velocity>,
        Changed<AngularVelocity>,
        Changed<GravityScale>,
        Changed<CollisionLayers>,
        Changed<Children>,
    )>,
    Without<Sleeping>,
    Unsettled,
);
type NoLongerRoot = (Or<(Added<Quarantined>, Changed<ChildOf>)>, Unsettled);

/// Brings the structures in step with the world: registers new roots (in bulk), moves changed
/// ones, drops removed, despawned, quarantined and re-parented ones, then commits. Only roots of
/// hierarchies are indexed; their volume bounds their whole compound body, grown by its
/// speculative margin when the solver asks for one ([`Lookahead`]).
#[allow(clippy::too_many_arguments)]
fn sync_broad_phase(
    mut index: ResMut<BroadPhaseIndex>,
    changed: Query<Watched, (Root, Moved)>,
    roots: Query<Indexed, Root>,
    gone: Query<Entity, NoLongerRoot>,
    mut despawned: RemovedComponents<BoundingVolume>,
    mut released: RemovedComponents<Quarantined>,
    mut orphaned: RemovedComponents<ChildOf>,
    (mut unscaled, mut unlayered): (
        RemovedComponents<GravityScale>,
        RemovedComponents<CollisionLayers>,
    ),
    mut transitions: ResMut<SleepTransitions>,
    lookahead: LookaheadParams,
    mut stats: ResMut<PhysicsStats>,
    mut commands: Commands,
    (hierarchy, mut warned): (Option<Res<HierarchyInstalled>>, Local<bool>),
    ticks: SystemChangeTick,
) {
    if hierarchy.is_none() && !*warned {
        *warned = true;
        log::warn!(
            "urto: no HierarchyPlugin: poses and bounding volumes are never updated, so the \
             broad phase sees bodies where they were spawned and nothing collides; replace it \
             with a stage that writes GlobalPose (GlobalPose::propagated) and BoundingVolume"
        );
    }
    let start = Instant::now();
    let lookahead = lookahead.get();
    let index = &mut *index;
    if index.grown_with.replace(lookahead) != Some(lookahead) {
        index.fresh = true;
    }
    // Back in the index, or with a margin that changed without a new velocity. A body that
    // woke is indexed again: a write to it while it slept (skipped then) is older than the
    // last sync. A body whose volume was removed is forgotten, and indexed again if it has one
    // now: both syncs read the removal, and the second must not leave out a volume put back.
    let mut back: Vec<Entity> = Vec::new();
    for (e, asleep) in transitions.0.drain(..) {
        index.proxies.set_asleep(e, asleep);
        if !asleep {
            back.push(e);
        }
    }
    for e in despawned.read() {
        index.forget(e);
        back.push(e);
    }
    for e in gone.iter() {
        index.forget(e);
    }
    back.extend(
        released
            .read()
            .chain(orphaned.read())
            .chain(unscaled.read())
            .chain(unlayered.read()),
    );
    if std::mem::take(&mut index.fresh) {
        for row in roots.iter() {
            index.upsert(row, &lookahead);
        }
    }
    for row in back.iter().filter_map(|e| roots.get(*e).ok()) {
        index.upsert(row, &lookahead);
    }
    // Changed since this system last ran, and since the other one did too (the later of the
    // two runs; `clamp_synced_tick` keeps the stored one comparable, as Bevy keeps a system's).
    let (own, now) = (ticks.last_run(), ticks.this_run());
    let since = index
        .synced_at
        .filter(|t| t.is_newer_than(own, now))
        .unwrap_or(own);
    let newer = |t: Tick| t.is_newer_than(since, now);
    for (e, bv, is_static, v, w, g, (layers, parts)) in changed.iter() {
        let stamps = [
            Some(bv.last_changed()),
            v.as_ref().map(|r| r.last_changed()),
            w.as_ref().map(|r| r.last_changed()),
            g.as_ref().map(|r| r.last_changed()),
            // New layers or a first part may put a root left out back in.
            layers.as_ref().map(|r| r.last_changed()),
            parts.as_ref().map(|r| r.last_changed()),
        ];
        let moved = stamps.into_iter().flatten().any(newer);
        if moved {
            // `changed` holds no sleeper.
            let row = (
                e,
                &*bv,
                is_static,
                v.as_deref(),
                w.as_deref(),
                g.as_deref(),
                false,
                (layers.as_deref(), parts.is_some()),
            );
            index.upsert(row, &lookahead);
        }
    }
    index.synced_at = Some(ticks.this_run());
    index.flush_batches(&mut commands);
    index.moving.commit();
    index.proxies.end_step();
    let steps = index.moving.stats();
    // Summed: the index is committed at the step's start and again in its substeps, and a
    // commit with nothing moved would otherwise hide the one that did the work.
    stats.add_counter("broad_phase/sap_swaps", steps.endpoint_swaps as f64);
    stats.add_counter(
        "broad_phase/rebuilt_from_scratch",
        f64::from(u8::from(steps.rebuilt)),
    );
    stats.set_counter("broad_phase/moving_bodies", index.moving.len() as f64);
    stats.set_counter("broad_phase/static_bodies", index.grid.len() as f64);
    stats.add_time(Stage::BroadPhase, start.elapsed());
}

/// Keeps the stored tick of the last sync comparable with the present one, as Bevy does with
/// every system's last run (a tick more than `u32::MAX` old would wrap and look new).
fn clamp_synced_tick(check: On<CheckChangeTicks>, index: Option<ResMut<BroadPhaseIndex>>) {
    if let Some(mut index) = index
        && let Some(tick) = index.synced_at.as_mut()
    {
        tick.check_tick(*check);
    }
}

impl BroadPhaseIndex {
    /// Removes `e` from whichever structure holds it.
    fn forget(&mut self, e: Entity) {
        match self.proxies.unregister(e) {
            Some(Proxy::Moving(id)) => {
                let _ = self.moving.remove(id);
            }
            Some(Proxy::Static(id)) => {
                let _ = self.grid.remove(id);
            }
            Some(Proxy::Unbounded) | None => {}
        }
    }

    /// Registers a new root or moves a known one (re-registering it if its kind changed); a
    /// root with nothing to collide (an empty volume, or layers that interact with none) is
    /// dropped.
    fn upsert(
        &mut self,
        (e, bv, is_static, v, w, g, asleep, inertness): IndexedRow,
        lookahead: &Lookahead,
    ) {
        if !bv.0.is_valid() || pairs_with_nothing(inertness) {
            self.forget(e);
            return;
        }
        let bounded = bv.0.is_finite();
        let moving = v.is_some() && !is_static;
        let aabb = if moving {
            bv.0.expanded(lookahead.of(v, w, bv, g))
        } else {
            bv.0
        };
        let wanted = |p: Proxy| match p {
            Proxy::Moving(_) => bounded && moving,
            Proxy::Static(_) => bounded && !moving,
            Proxy::Unbounded => !bounded,
        };
        match self.proxies.get(e) {
            Some(Proxy::Moving(id)) if wanted(Proxy::Moving(id)) => {
                let _ = self.moving.update(id, aabb);
            }
            Some(Proxy::Static(id)) if wanted(Proxy::Static(id)) => {
                let _ = self.grid.update(id, aabb);
            }
            Some(Proxy::Unbounded) if !bounded => {}
            known => {
                if known.is_some() {
                    self.forget(e);
                }
                match self.proxies.register(e, bounded, moving) {
                    Proxy::Moving(id) => self.moving_batch.push((id, aabb, BodyKind::Dynamic)),
                    Proxy::Static(id) => self.static_batch.push((id, aabb)),
                    Proxy::Unbounded => {}
                }
                // A new id starts awake; a sleeper (its volume put back, or the index made
                // again) stays out of the pairs.
                if asleep {
                    self.proxies.set_asleep(e, true);
                }
            }
        }
    }

    /// Inserts the step's new bodies in bulk; the first statics also choose the grid's cell size.
    fn flush_batches(&mut self, commands: &mut Commands) {
        if !self.moving_batch.is_empty() {
            if let Err(err) = self.moving.insert_bulk(&self.moving_batch) {
                // One bad body must not keep the others out: fall back to one by one.
                log::warn!("urto: broad phase bulk insert failed ({err}); inserting one by one");
                for &(id, aabb, kind) in &self.moving_batch {
                    if let Err(err) = self.moving.insert(id, aabb, kind) {
                        let e = self.proxies.entity(id);
                        self.proxies.unregister(e);
                        quarantine(commands, e, format!("broad phase refused it: {err}"));
                    }
                }
            }
            self.moving_batch.clear();
        }
        if !self.static_batch.is_empty() {
            let result = if self.grid.is_empty() && self.grid_config.cell_size.is_none() {
                StaticGrid::build_with(&self.static_batch, self.grid_config).map(|g| self.grid = g)
            } else {
                self.grid.insert_bulk(&self.static_batch)
            };
            if let Err(err) = result {
                log::warn!("urto: static grid bulk insert failed ({err}); inserting one by one");
                for &(id, aabb) in &self.static_batch {
                    if let Err(err) = self.grid.insert(id, aabb) {
                        let e = self.proxies.entity(id);
                        self.proxies.unregister(e);
                        quarantine(commands, e, format!("static grid refused it: {err}"));
                    }
                }
            }
            self.static_batch.clear();
        }
    }
}

/// Moving–moving pairs from the sweep and prune, then each moving body against the statics its
/// volume's grid cells list, then against the unbounded colliders its volume reaches.
fn find_candidate_pairs(
    mut index: ResMut<BroadPhaseIndex>,
    mut out: ResMut<BroadPhasePairs>,
    mut stats: ResMut<PhysicsStats>,
    planes: Query<(&Collider, &GlobalPose, Option<&Children>)>,
    nodes: Query<(Has<Collider>, Option<&Children>)>,
    mut stack: Local<Vec<Entity>>,
) {
    let start = Instant::now();
    let index = &mut *index;
    out.pairs.clear();
    index.planes.clear();
    // A plane with colliders below it (a compound) is paired with everything; children without
    // one (a ground's render meshes) do not count.
    let world_plane = |&e: &Entity| {
        let (c, pose, children) = planes.get(e).ok()?;
        let parts = children.is_some_and(|c| has_collider_below(c, &nodes, &mut stack));
        (!parts).then(|| WorldPlane::of(&c.shape, &pose.0))?
    };
    index
        .planes
        .extend(index.proxies.unbounded().iter().map(world_plane));
    let proxies = &index.proxies;
    // Two sleeping bodies at rest against each other need no test until one wakes.
    out.pairs.extend(
        index
            .moving
            .pairs()
            .iter()
            .filter(|p| !(proxies.is_asleep(p.a) && proxies.is_asleep(p.b)))
            .map(|p| (proxies.entity(p.a), proxies.entity(p.b))),
    );
    let moving_pairs = out.pairs.len();
    let mut grid_work = GridQueryStats::default();
    index.grid_queries.begin_round();
    if !index.grid.is_empty() || !proxies.unbounded().is_empty() {
        // Sleeping bodies are not paired with scenery: nothing moved.
        for id in proxies.awake_moving_ids() {
            let (Some(aabb), e) = (index.moving.aabb(id), proxies.entity(id)) else {
                continue;
            };
            if !index.grid.is_empty()
                && let Ok(q) = index
                    .grid_queries
                    .query(&mut index.grid, id, &aabb, &mut index.hits)
            {
                grid_work += q;
                out.pairs
                    .extend(index.hits.iter().map(|&s| (e, proxies.entity(s))));
            }
            // A half-space pairs only with the bodies whose volume (grown by their margin)
            // reaches below its plane: the walls of a box of planes, not every wall.
            let unbounded = proxies.unbounded().iter().zip(&index.planes);
            out.pairs.extend(
                unbounded
                    .filter(|(_, plane)| plane.is_none_or(|p| p.reaches(&aabb)))
                    .map(|(&u, _)| (e, u)),
            );
        }
    }
    stats.set_counter("broad_phase/pairs", moving_pairs as f64);
    stats.set_counter(
        "broad_phase/static_pairs",
        (out.pairs.len() - moving_pairs) as f64,
    );
    stats.set_counter(
        "broad_phase/grid_cells_visited",
        grid_work.cells_visited as f64,
    );
    stats.set_counter(
        "broad_phase/grid_queries_reused",
        grid_work.reused_queries as f64,
    );
    stats.add_time(Stage::BroadPhase, start.elapsed());
    stats.count_run("broad_phase");
}
