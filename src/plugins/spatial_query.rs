//! Spatial queries for game code: the [`SpatialQuery`] system parameter casts rays and any
//! convex shape, lists overlaps and point containment, with a [`SpatialQueryFilter`] (layers,
//! excluded entities), answered by the core's [`SpatialIndex`] (a box tree over the colliders,
//! never a scan of every collider).
//!
//! ```
//! # use bevy_ecs::prelude::*;
//! # use urto::prelude::*;
//! fn aim(query: SpatialQuery) {
//!     let hit = query.cast_ray(glam::Vec3::new(0.0, 0.0, 5.0), -glam::Vec3::Z, 100.0,
//!         &SpatialQueryFilter::default());
//!     if let Ok(Some(hit)) = hit {
//!         println!("{:?} at {} m", hit.entity, hit.distance);
//!     }
//! }
//! ```
//!
//! The index is built lazily: the first query after a physics step refreshes it (refit in
//! `O(n)` while the colliders are the same ones; when a few came or went, the tree is kept and
//! only the new ones indexed apart; rebuilt when many did), so a game that
//! never queries pays nothing and one that queries pays once per step, whatever the number of
//! queries. It sees the world as the last step left it; bodies a game moves or spawns between
//! steps are seen after the next step, or at once after [`SpatialQuery::refresh`]. Roots are
//! read at their [`Position`] and [`Rotation`], parts of compound bodies at theirs composed
//! with their ancestors' (as the hierarchy stage composes their [`GlobalPose`], which is the
//! last step's until the next). A body the game moves through its `Transform` is seen after
//! the next step only, even after a refresh: the step reads `Transform` writes into
//! [`Position`] (`transform_sync`); write [`Position`] and [`Rotation`] to be seen at once.
//! Quarantined colliders are never hit.
//!
//! Static scenery is not read at each step. A [`Static`] root body nobody wrote to since the
//! last step is *settled* (the marker the step's change scans leave out, see `settle.rs`), and
//! settled colliders sit in the index's still group ([`SpatialIndex::update_still`]), read
//! again only when a body settles or stops being settled (or is despawned): the marker's hooks
//! give the set a new revision. A level of 100,000 static colliders then costs its queries
//! nothing per step, where it cost a box and a refit per collider (Avian keeps its static
//! colliders in a tree of their own for the same reason). A static the game moves leaves the
//! group at the next step (it is no longer settled) and comes back settled at that step's end.
//! Sleeping bodies sit in a group of their own ([`SpatialIndex::update_sleeping`]), read again
//! only when a body falls asleep or wakes (the [`Sleeping`] marker's hooks renew that set's
//! revision): a pile of sleeping debris costs its queries nothing per step, and a body falling
//! asleep or waking reads the sleepers again, never the level's statics. Index ids tell the
//! groups apart: a collider's is four times its stable key in its group, plus 0 (moving),
//! 1 (settled) or 2 (sleeping).

use crate::components::*;
use crate::geometry::{Isometry, Shape};
use crate::plugins::required_resources::RequireResource;
use crate::plugins::settle::{Settled, StillRevision};
use crate::spatial::{
    ColliderLookup, IndexUpdate, LayerMask, QueryError, Ray, SpatialIndex, StableIds,
};
use crate::stats::PhysicsStats;
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_ecs::query::QueryFilter;
use bevy_ecs::system::SystemParam;
use glam::Vec3;
use std::sync::{Mutex, MutexGuard};

/// Makes the query index a shared resource (without it each system keeps its own).
#[derive(Debug, Clone, Default)]
pub struct SpatialQueryPlugin;

impl Plugin for SpatialQueryPlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<SpatialQueryIndex>();
    }
}

/// The query index of the colliders and the step it was refreshed at.
#[derive(Resource, Default)]
pub struct SpatialQueryIndex {
    state: Mutex<IndexState>,
}

#[derive(Default)]
struct IndexState {
    index: SpatialIndex,
    /// The key of each collider entity in its group (moving, settled, sleeping), stable while
    /// others come and go (so that a change of a few colliders keeps the group's tree); its
    /// index id is `4 key + group`.
    ids: [StableIds<Entity>; 3],
    /// The physics step of the last refresh.
    step: Option<u64>,
    /// The revisions of the settled and sleeping sets when their groups were last read.
    seen: [Option<u64>; 2],
    refreshes: IndexRefreshes,
}

/// How the query index was refreshed so far (see [`SpatialQueryIndex::refreshes`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IndexRefreshes {
    /// Colliders came or went, many: the tree rebuilt.
    pub rebuilds: u64,
    /// Colliders came or went, a few: the tree kept (see [`crate::spatial::ColliderTree`]).
    pub updates: u64,
    /// The same colliders: the boxes refitted.
    pub refits: u64,
    /// The settled statics read again because their set changed: their tree is otherwise kept
    /// as it is, unread (see the [module](self)).
    pub still_reads: u64,
    /// The sleeping bodies read again because their set changed (a body fell asleep or woke).
    pub sleeping_reads: u64,
}

impl SpatialQueryIndex {
    /// How many times the tree was rebuilt, updated and refitted (for tests and the curious).
    pub fn refreshes(&self) -> IndexRefreshes {
        self.lock().refreshes
    }

    fn lock(&self) -> MutexGuard<'_, IndexState> {
        // A query that panicked mid-refresh leaves a state that the next refresh overwrites.
        self.state
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// Which colliders a query may hit.
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialQueryFilter {
    /// Hit colliders that are members of one of these layers ([`CollisionLayers`]).
    pub mask: LayerMask,
    /// Never hit these entities (the caster itself, say).
    pub excluded: Vec<Entity>,
}

impl Default for SpatialQueryFilter {
    fn default() -> Self {
        Self {
            mask: LayerMask::ALL,
            excluded: Vec::new(),
        }
    }
}

impl SpatialQueryFilter {
    /// Colliders in the layers of `mask`.
    pub fn from_mask(mask: LayerMask) -> Self {
        Self {
            mask,
            ..Default::default()
        }
    }

    /// The same filter, also excluding `entities`.
    #[must_use]
    pub fn with_excluded(mut self, entities: impl IntoIterator<Item = Entity>) -> Self {
        self.excluded.extend(entities);
        self
    }
}

/// A ray's or a cast's hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The collider hit (a part, for a compound body).
    pub entity: Entity,
    /// Distance along the unit direction (0: the cast started touching or inside).
    pub distance: f32,
    /// Where the surfaces meet.
    pub point: Vec3,
    /// Unit surface normal at the hit, pointing back toward the caster.
    pub normal: Vec3,
}

/// The collider nearest to a point, and where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointProjection {
    /// The collider (a part, for a compound body).
    pub entity: Entity,
    /// Its point nearest to the query point (the query point itself when inside a solid).
    pub point: Vec3,
    /// Distance to it (0 inside a solid).
    pub distance: f32,
    /// True when the query point is inside (or on) a solid collider; meshes are surfaces.
    pub inside: bool,
}

type QueryCollider = (
    Entity,
    &'static Collider,
    &'static GlobalPose,
    Option<&'static Position>,
    Option<&'static Rotation>,
    Has<ChildOf>,
    Option<&'static CollisionLayers>,
);

/// The colliders read at every refresh: all but the settled statics and the sleepers.
type Moving = (Without<Quarantined>, Without<Settled>, Without<Sleeping>);
/// The still ones: settled statics, read when their set changes.
type Still = (Without<Quarantined>, With<Settled>);
/// The sleeping bodies, read when their set changes (no static sleeps).
type Asleep = (Without<Quarantined>, Without<Settled>, With<Sleeping>);

/// Ray casts, sphere casts, overlap and point queries against the colliders (see the
/// [module](self)).
#[derive(SystemParam)]
pub struct SpatialQuery<'w, 's> {
    shared: Option<Res<'w, SpatialQueryIndex>>,
    own: Local<'s, SpatialQueryIndex>,
    colliders: Query<'w, 's, QueryCollider, Moving>,
    still: Query<'w, 's, QueryCollider, Still>,
    asleep: Query<'w, 's, QueryCollider, Asleep>,
    nodes: Query<'w, 's, Node>,
    revision: Option<Res<'w, StillRevision>>,
    stats: Option<Res<'w, PhysicsStats>>,
}

/// The ECS colliders by index id: its two low bits name the group (see [`IndexState`]).
struct Lookup<'a, 'w, 's> {
    ids: &'a [StableIds<Entity>; 3],
    colliders: &'a Query<'w, 's, QueryCollider, Moving>,
    still: &'a Query<'w, 's, QueryCollider, Still>,
    asleep: &'a Query<'w, 's, QueryCollider, Asleep>,
    nodes: &'a Query<'w, 's, Node>,
}

/// The groups' numbers in the index ids' two low bits.
const MOVING: u32 = 0;
const SETTLED: u32 = 1;
const SLEEPING: u32 = 2;

impl Lookup<'_, '_, '_> {
    /// The entity of `id`, if it has one.
    fn key(&self, id: u32) -> Option<Entity> {
        self.ids.get((id & 3) as usize)?.key(id >> 2)
    }

    /// The entity of `id`. The index reports only ids its filter accepted and the look-up
    /// found, which have entities; the placeholder stands in for what cannot happen.
    fn entity(&self, id: u32) -> Entity {
        self.key(id).unwrap_or(Entity::PLACEHOLDER)
    }

    /// The collider `id`'s row, if it is there (still in the group it was indexed in).
    fn row(&self, id: u32) -> Option<QueryItemOf<'_>> {
        let e = self.key(id)?;
        match id & 3 {
            MOVING => self.colliders.get(e).ok(),
            SETTLED => self.still.get(e).ok(),
            _ => self.asleep.get(e).ok(),
        }
    }

    /// Whether the collider `id` is there and passes `filter`.
    fn accepts(&self, id: u32, filter: &SpatialQueryFilter) -> bool {
        let Some(row) = self.row(id) else {
            return false;
        };
        let member = row.6.map_or(LayerMask::DEFAULT, |l| l.0.memberships);
        member.intersects(filter.mask) && !filter.excluded.contains(&row.0)
    }
}

impl ColliderLookup for Lookup<'_, '_, '_> {
    fn collider(&self, id: u32) -> Option<(&Shape, Isometry)> {
        let row = self.row(id)?;
        Some((&row.1.shape, pose_of(&row, self.nodes)))
    }
}

/// A node of the scene graph: what a part's pose is composed of.
type Node = (
    &'static Position,
    Option<&'static Rotation>,
    Option<&'static ChildOf>,
);

/// The deepest chain of parts composed for a query; a deeper part is read at its
/// [`GlobalPose`] (a `ChildOf` loop ends here too).
const MAX_CHAIN: usize = 16;

/// Where a collider is now: a root at its position; a part at its own and its ancestors'
/// positions, composed from the root down as the hierarchy stage composes its global pose, so
/// that it follows a root the game moved before a [`SpatialQuery::refresh`]. Read at its
/// global pose, the last step's, a part stayed where it was until the next step: a ray at the
/// part's new place missed it, one at its old place hit it (a user-style probe). A broken or
/// too deep chain falls back on the global pose.
fn pose_of(row: &QueryItemOf, nodes: &Query<Node>) -> Isometry {
    let (e, _, global, position, rotation, child, _) = *row;
    match (child, position, rotation) {
        (false, Some(p), Some(r)) => Isometry::new(p.0, r.0),
        (true, Some(_), _) => composed(e, nodes).unwrap_or(global.0),
        _ => global.0,
    }
}

/// Part `e`'s pose composed from its chain of [`ChildOf`] up to its root (`None` when a link
/// is missing or the chain is longer than [`MAX_CHAIN`]).
fn composed(e: Entity, nodes: &Query<Node>) -> Option<Isometry> {
    let mut chain = [Isometry::IDENTITY; MAX_CHAIN];
    let (mut len, mut at) = (0, e);
    loop {
        let (p, r, parent) = nodes.get(at).ok()?;
        *chain.get_mut(len)? = crate::components::pose(p, r);
        len += 1;
        match parent {
            Some(parent) => at = parent.parent(),
            None => break,
        }
    }
    let mut world = Isometry::IDENTITY;
    for local in chain[..len].iter().rev() {
        world = world * *local;
    }
    Some(world)
}

type QueryItemOf<'a> = (
    Entity,
    &'a Collider,
    &'a GlobalPose,
    Option<&'a Position>,
    Option<&'a Rotation>,
    bool,
    Option<&'a CollisionLayers>,
);

impl SpatialQuery<'_, '_> {
    fn index(&self) -> &SpatialQueryIndex {
        self.shared.as_deref().unwrap_or(&self.own)
    }

    /// The index, refreshed if a step ran since, if the settled or the sleeping set changed
    /// (a body woken or despawned between steps moves to the moving group or out), or if
    /// `force`d: the moving colliders read whole, the settled and the sleeping ones only if
    /// their set changed (or `force`).
    fn fresh(&self, force: bool) -> MutexGuard<'_, IndexState> {
        let mut state = self.index().lock();
        let step = self.stats.as_ref().map(|s| s.step);
        let new_step = step.is_none() || state.step != step;
        // `None` without the revisions (removed by game code until the next step puts them
        // back, or no core plugin): the kept groups are then read at each step.
        let seen = self.revision.as_ref().map(|r| [r.settled, r.sleeping]);
        let seen = seen.map_or([None; 2], |s| s.map(Some));
        let stale =
            [0, 1].map(|k| force || state.seen[k] != seen[k] || (seen[k].is_none() && new_step));
        if force || new_step || stale.contains(&true) {
            self.read_groups(&mut state, stale);
            state.seen = seen;
            state.step = step;
        }
        state
    }

    /// Reads the moving colliders into the index, and the settled and sleeping ones where
    /// `stale` says.
    fn read_groups(&self, state: &mut IndexState, stale: [bool; 2]) {
        let (index, ids) = (&mut state.index, &mut state.ids);
        let counts = &mut state.refreshes;
        match read_group(index, &mut ids[0], &self.colliders, &self.nodes, MOVING) {
            IndexUpdate::Refitted => counts.refits += 1,
            IndexUpdate::Updated => counts.updates += 1,
            IndexUpdate::Rebuilt => counts.rebuilds += 1,
        }
        if stale[0] {
            read_group(index, &mut ids[1], &self.still, &self.nodes, SETTLED);
            counts.still_reads += 1;
        }
        if stale[1] {
            read_group(index, &mut ids[2], &self.asleep, &self.nodes, SLEEPING);
            counts.sleeping_reads += 1;
        }
    }

    /// Re-reads every collider's pose now (after a game moved or spawned bodies between steps).
    pub fn refresh(&self) {
        drop(self.fresh(true));
    }

    /// Runs a query on the fresh index with the ECS lookup and `filter` as the acceptance test.
    fn with_index<R>(
        &self,
        filter: &SpatialQueryFilter,
        query: impl FnOnce(&mut SpatialIndex, &Lookup, &dyn Fn(u32) -> bool) -> R,
    ) -> R {
        let mut state = self.fresh(false);
        let IndexState { index, ids, .. } = &mut *state;
        let lookup = Lookup {
            ids,
            colliders: &self.colliders,
            still: &self.still,
            asleep: &self.asleep,
            nodes: &self.nodes,
        };
        query(index, &lookup, &|id| lookup.accepts(id, filter))
    }

    /// The nearest collider the ray from `origin` along `direction` hits within `max_distance`
    /// (`f32::INFINITY`: no limit). A ray starting inside a solid hits it at distance 0.
    pub fn cast_ray(
        &self,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        filter: &SpatialQueryFilter,
    ) -> Result<Option<RayHit>, QueryError> {
        self.cast_sphere(0.0, origin, direction, max_distance, filter)
    }

    /// The nearest collider a ball of `radius` moving from `origin` along `direction` meets
    /// within `max_distance`.
    pub fn cast_sphere(
        &self,
        radius: f32,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        filter: &SpatialQueryFilter,
    ) -> Result<Option<RayHit>, QueryError> {
        let ray = Ray::new(origin, direction)?;
        self.with_index(filter, |index, lookup, accept| {
            let hit = index.cast_sphere(lookup, &ray, radius, max_distance, accept)?;
            Ok(hit.map(|h| to_ray_hit(lookup, h)))
        })
    }

    /// The nearest collider a box of `half_extents` at `pose` meets when moved (without turning)
    /// along `direction` for at most `max_distance` (a character's or a crate's sweep). A box
    /// starting in contact hits at distance 0.
    pub fn cast_box(
        &self,
        half_extents: Vec3,
        pose: Isometry,
        direction: Vec3,
        max_distance: f32,
        filter: &SpatialQueryFilter,
    ) -> Result<Option<RayHit>, QueryError> {
        let shape = Shape::cuboid(half_extents);
        self.cast_shape(&shape, pose, direction, max_distance, filter)
    }

    /// The nearest collider a capsule (`half_length`, `radius`, along `pose`'s local z) meets
    /// when moved (without turning) along `direction` for at most `max_distance`: the sweep a
    /// character controller makes before it moves. A capsule starting in contact hits at 0.
    pub fn cast_capsule(
        &self,
        (half_length, radius): (f32, f32),
        pose: Isometry,
        direction: Vec3,
        max_distance: f32,
        filter: &SpatialQueryFilter,
    ) -> Result<Option<RayHit>, QueryError> {
        let shape = Shape::capsule(half_length, radius);
        self.cast_shape(&shape, pose, direction, max_distance, filter)
    }

    /// The nearest collider any convex `shape` (a ball, box, capsule, cylinder, cone,
    /// ellipsoid or convex hull) at `pose` meets when moved (without turning) along `direction`
    /// for at most `max_distance`; a half-space or a mesh is refused
    /// ([`QueryError::NotCastable`]). A shape starting in contact hits at distance 0.
    pub fn cast_shape(
        &self,
        shape: &Shape,
        pose: Isometry,
        direction: Vec3,
        max_distance: f32,
        filter: &SpatialQueryFilter,
    ) -> Result<Option<RayHit>, QueryError> {
        let cast = crate::spatial::ShapeCast {
            pose,
            shape,
            direction: Ray::new(pose.translation, direction)?.direction(),
            max_distance,
        };
        self.with_index(filter, |index, lookup, accept| {
            let hit = index.cast_shape(lookup, &cast, accept)?;
            Ok(hit.map(|h| to_ray_hit(lookup, h)))
        })
    }

    /// Every collider the ray hits within `max_distance`, nearest first.
    pub fn cast_ray_all(
        &self,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        filter: &SpatialQueryFilter,
    ) -> Result<Vec<RayHit>, QueryError> {
        let ray = Ray::new(origin, direction)?;
        self.with_index(filter, |index, lookup, accept| {
            let mut hits = Vec::new();
            index.cast_ray_all(lookup, &ray, max_distance, accept, &mut hits)?;
            Ok(hits.into_iter().map(|h| to_ray_hit(lookup, h)).collect())
        })
    }

    /// The colliders that `shape` placed at `pose` touches or overlaps (meshes are surfaces).
    pub fn overlapping(
        &self,
        shape: &Shape,
        pose: Isometry,
        filter: &SpatialQueryFilter,
    ) -> Result<Vec<Entity>, QueryError> {
        if !pose.is_finite() {
            return Err(QueryError::NonFiniteOrigin(pose.translation));
        }
        self.with_index(filter, |index, lookup, accept| {
            let mut ids = Vec::new();
            index.overlapping(lookup, (shape, &pose), accept, &mut ids);
            Ok(ids.into_iter().map(|id| lookup.entity(id)).collect())
        })
    }

    /// The collider nearest to `point` within `max_distance` (`f32::INFINITY`: no limit), and
    /// its nearest point; a point inside a solid is its own nearest point, at distance 0.
    /// Answered from the index, nearest boxes first (a mesh through its own hierarchy).
    pub fn nearest_point(
        &self,
        point: Vec3,
        max_distance: f32,
        filter: &SpatialQueryFilter,
    ) -> Result<Option<PointProjection>, QueryError> {
        self.with_index(filter, |index, lookup, accept| {
            let found = index.nearest(lookup, point, max_distance, accept)?;
            Ok(found.map(|(id, hit)| PointProjection {
                entity: lookup.entity(id),
                point: hit.point,
                distance: hit.distance,
                inside: hit.inside,
            }))
        })
    }

    /// The colliders holding `point` (inside or on a solid; on a mesh's surface).
    pub fn containing_point(
        &self,
        point: Vec3,
        filter: &SpatialQueryFilter,
    ) -> Result<Vec<Entity>, QueryError> {
        self.overlapping(
            &Shape::sphere(0.0),
            Isometry::from_translation(point),
            filter,
        )
    }
}

/// Reads `query`'s colliders into the index's `group`, each keyed in `ids` (index id
/// `4 key + group`).
fn read_group<F: QueryFilter>(
    index: &mut SpatialIndex,
    ids: &mut StableIds<Entity>,
    query: &Query<QueryCollider, F>,
    nodes: &Query<Node>,
    group: u32,
) -> IndexUpdate {
    ids.begin();
    let colliders = query.iter().map(|row| {
        (
            (ids.id(row.0) << 2) | group,
            &row.1.shape,
            pose_of(&row, nodes),
        )
    });
    let update = match group {
        MOVING => index.update(colliders),
        SETTLED => index.update_still(colliders),
        _ => index.update_sleeping(colliders),
    };
    ids.finish();
    update
}

fn to_ray_hit(lookup: &Lookup, h: crate::spatial::QueryHit) -> RayHit {
    RayHit {
        entity: lookup.entity(h.id),
        distance: h.hit.distance,
        point: h.hit.point,
        normal: h.hit.normal,
    }
}

#[cfg(test)]
#[path = "spatial_query_tests.rs"]
mod tests;
