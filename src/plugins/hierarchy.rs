//! The scene graph as the bounding-volume hierarchy, in the ECS: bevy's own `ChildOf` /
//! `Children` relationship makes compound bodies (a car and its wheels, an arm and its links, a
//! block and its houses).
//!
//! Each substep (and in Prepare, for bodies spawned or moved by game code between steps, and in
//! Finish, after the response moved bodies), world poses propagate **down** from the subtrees whose root or local pose
//! changed, and bounding volumes are refit **up** only along the paths from changed nodes to
//! their roots ([`refit_order`]): a node's [`BoundingVolume`] bounds its own collider and its
//! children's volumes. A parked car or a static town costs nothing. The broad phase sees only
//! roots; the narrow phase descends both hierarchies of a pair ([`crate::hierarchy`]).
//!
//! Parts of a compound move with their root: only roots integrate (a child's [`Velocity`] is an
//! error, quarantined by validation), and contacts push the root.

use crate::bounding::Aabb;
use crate::components::*;
use crate::geometry::Isometry;
use crate::hierarchy::{refit_order, topmost_marked};
use crate::plugins::broad_phase::IndexBodies;
use crate::plugins::core::{PrepareIndex, PrepareStart};
use crate::plugins::plain_parents::place_plain_parents;
use crate::plugins::required_resources::RequireResource;
use crate::plugins::restored_state::restore_removed_state;
use crate::plugins::settle::Unsettled;
use crate::plugins::validation::{quarantine, quarantine_unplaced_bodies};
use crate::schedule::{BroadPhaseSystems, PhysicsSchedule, PhysicsSet, SubstepSchedule};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_ecs::query::QueryFilter;
use std::collections::HashMap;
use std::time::Instant;

/// Propagates world poses down hierarchies and refits bounding volumes up them.
#[derive(Debug, Clone, Default)]
pub struct HierarchyPlugin;

/// Marks a world whose bounding volumes a [`HierarchyPlugin`] keeps fresh (the broad phase
/// warns without it: nothing would ever collide).
#[derive(Resource)]
pub(crate) struct HierarchyInstalled;

impl Plugin for HierarchyPlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<HierarchyScratch>()
            .insert_resource(HierarchyInstalled)
            .add_systems(
                PhysicsSchedule,
                place_plain_parents
                    .run_if(any_with_component::<ChildOf>)
                    .in_set(PrepareStart)
                    .before(quarantine_unplaced_bodies),
            )
            .add_systems(
                SubstepSchedule,
                (
                    propagate_poses::<()>.in_set(BroadPhaseSystems::Poses),
                    refit_bounding_volumes::<()>.in_set(BroadPhaseSystems::Refit),
                )
                    .run_if(any_with_component::<BoundingVolume>),
            )
            .add_systems(
                PhysicsSchedule,
                (
                    propagate_poses::<()>,
                    refit_bounding_volumes::<()>,
                    remember_part_poses.run_if(any_with_component::<ChildOf>),
                )
                    .chain()
                    .run_if(any_with_component::<BoundingVolume>)
                    .in_set(PhysicsSet::Finish),
            )
            .add_systems(
                PhysicsSchedule,
                (
                    propagate_poses::<Without<Velocity>>,
                    refit_bounding_volumes::<Without<Velocity>>,
                )
                    .chain()
                    .run_if(any_with_component::<BoundingVolume>)
                    .in_set(PrepareIndex)
                    .before(IndexBodies),
            )
            .add_systems(
                PhysicsSchedule,
                restore_removed_state
                    .in_set(PrepareIndex)
                    .before(propagate_poses::<Without<Velocity>>)
                    .before(IndexBodies),
            );
    }
}

#[derive(Resource, Default)]
struct HierarchyScratch {
    dirty: Vec<Entity>,
    tops: Vec<Entity>,
    covered: HashMap<Entity, bool>,
    depths: HashMap<Entity, u32>,
    stack: Vec<(Entity, Isometry)>,
    order: Vec<(u32, Entity)>,
}

/// Bodies outside any hierarchy: their world pose is their own, their volume their collider's.
type Flat = (Without<ChildOf>, Without<Children>);
/// Parts and parents of compound bodies.
type InHierarchy = Or<(With<ChildOf>, With<Children>)>;

/// Sleeping bodies do not move (a write to one wakes it first), so they are left out.
type LocalChanged = (
    Or<(Changed<Position>, Changed<Rotation>, Changed<ChildOf>)>,
    Without<Quarantined>,
    Without<Sleeping>,
    Unsettled,
);

type FlatPose<'a> = (&'a Position, &'a Rotation, &'a mut GlobalPose);
type NodePose<'a> = (
    &'a Position,
    &'a Rotation,
    Option<&'a Children>,
    &'a mut GlobalPose,
);

/// World poses: a body outside any hierarchy copies its own pose (one linear pass); in a
/// hierarchy, a subtree whose root moved, or whose local pose or parent changed, is recomposed
/// top-down (shallowest first). `F` narrows which changed bodies are looked at (Prepare: only
/// bodies without a velocity — scenery placed between steps).
// A ParamSet of two queries (flat bodies, hierarchy nodes) aliases `GlobalPose`; a type alias
// for it would have to fix the queries' lifetimes, which stops the function being a system.
#[allow(clippy::type_complexity)]
fn propagate_poses<F: QueryFilter + 'static>(
    mut queries: ParamSet<(Query<FlatPose, (Flat, LocalChanged, F)>, Query<NodePose>)>,
    changed: Query<Entity, (InHierarchy, LocalChanged, F)>,
    parents: Query<&ChildOf>,
    mut scratch: ResMut<HierarchyScratch>,
    mut stats: ResMut<PhysicsStats>,
) {
    let start = Instant::now();
    let mut updated = 0u32;
    for (p, r, mut global) in &mut queries.p0() {
        global.set_if_neq(GlobalPose(Isometry::new(p.0, r.0)));
        updated += 1;
    }
    let s = &mut *scratch;
    s.dirty.clear();
    s.dirty.extend(changed.iter());
    // Only the changed nodes without a changed ancestor: their subtrees hold all the others,
    // each recomposed once (linear in the hierarchy, however deep).
    let parent = |e: Entity| parents.get(e).ok().map(|p| p.parent());
    topmost_marked(&s.dirty, parent, &mut s.covered, &mut s.tops);
    let mut nodes = queries.p1();
    for i in 0..s.tops.len() {
        let root = s.tops[i];
        let parent_pose = match parents.get(root) {
            Ok(p) => nodes.get(p.parent()).map_or(Isometry::IDENTITY, |n| n.3.0),
            Err(_) => Isometry::IDENTITY,
        };
        s.stack.clear();
        s.stack.push((root, parent_pose));
        while let Some((e, parent)) = s.stack.pop() {
            let Ok((p, r, children, mut global)) = nodes.get_mut(e) else {
                continue;
            };
            let world = parent * Isometry::new(p.0, r.0);
            global.set_if_neq(GlobalPose(world));
            updated += 1;
            if let Some(children) = children {
                s.stack.extend(children.iter().map(|c| (c, world)));
            }
        }
    }
    stats.set_counter("hierarchy/poses", updated as f64);
    stats.add_time(Stage::BroadPhase, start.elapsed());
}

/// Keeps each hierarchy node's world pose at the end of the step, which is where the next step
/// starts ([`StepStartPose`]), before the game moves the parts between steps. Only nodes whose
/// pose changed during the step are copied; a new part gets one at the end of its first step (during
/// that step its contacts treat it as still).
fn remember_part_poses(
    mut parts: Query<(Entity, &GlobalPose, Option<&mut StepStartPose>), PartMoved>,
    mut commands: Commands,
) {
    for (e, pose, start) in &mut parts {
        match start {
            Some(mut start) => start.0 = pose.0,
            None => {
                commands.entity(e).insert(StepStartPose(pose.0));
            }
        }
    }
}

type PartMoved = (InHierarchy, Changed<GlobalPose>, Unsettled);

type RefitNode<'a> = (
    Option<&'a Collider>,
    &'a GlobalPose,
    Option<&'a Children>,
    &'a mut BoundingVolume,
    Has<Quarantined>,
);
type FlatRefit<'a> = (Entity, &'a Collider, &'a GlobalPose, &'a mut BoundingVolume);
type OwnChanged = (
    Or<(Changed<GlobalPose>, Changed<Collider>, Changed<Children>)>,
    Without<Sleeping>,
    Unsettled,
);

/// Refits volumes: a collider outside any hierarchy from its own pose (one linear pass); in a
/// hierarchy, every node whose own collider moved or whose children changed, and its ancestors,
/// deepest first. A bounded collider whose volume is not finite is quarantined.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn refit_bounding_volumes<F: QueryFilter + 'static>(
    mut queries: ParamSet<(
        Query<FlatRefit, (Flat, OwnChanged, Without<Quarantined>, F)>,
        Query<RefitNode>,
    )>,
    changed: Query<Entity, (InHierarchy, OwnChanged, F)>,
    mut removed: RemovedComponents<Collider>,
    parents: Query<&ChildOf>,
    mut scratch: ResMut<HierarchyScratch>,
    mut stats: ResMut<PhysicsStats>,
    mut commands: Commands,
) {
    let start = Instant::now();
    let mut refits = 0usize;
    for (e, collider, global, mut out) in &mut queries.p0() {
        let bv = own_volume(e, Some(collider), global, false, &mut commands);
        out.set_if_neq(BoundingVolume(bv));
        refits += 1;
    }
    let s = &mut *scratch;
    let dirty = changed.iter().chain(removed.read());
    refit_order(
        dirty,
        |e| parents.get(e).ok().map(|p| p.parent()),
        &mut s.depths,
        &mut s.order,
    );
    let mut nodes = queries.p1();
    for &(_, e) in &s.order {
        let Ok((collider, global, children, _, quarantined)) = nodes.get(e) else {
            continue;
        };
        let mut bv = own_volume(e, collider, global, quarantined, &mut commands);
        for child in children.into_iter().flat_map(|c| c.iter()) {
            if let Ok((.., child_bv, _)) = nodes.get(child)
                && child_bv.0.is_valid()
            {
                bv = bv.union(&child_bv.0);
            }
        }
        if let Ok((.., mut out, _)) = nodes.get_mut(e) {
            out.set_if_neq(BoundingVolume(bv));
        }
    }
    refits += s.order.len();
    stats.set_counter("hierarchy/refits", refits as f64);
    stats.add_time(Stage::BroadPhase, start.elapsed());
}

/// The world volume of a node's own collider (empty without one or when quarantined); a bounded
/// collider whose volume is not finite is quarantined and counts as empty.
fn own_volume(
    e: Entity,
    collider: Option<&Collider>,
    global: &GlobalPose,
    quarantined: bool,
    commands: &mut Commands,
) -> Aabb {
    let Some(c) = collider.filter(|_| !quarantined) else {
        return Aabb::EMPTY;
    };
    let bv = c.shape.world_aabb(&global.0);
    if !c.shape.is_unbounded() && !bv.is_finite() {
        quarantine(
            commands,
            e,
            format!("bounding volume is not finite: {bv:?}"),
        );
        return Aabb::EMPTY;
    }
    bv
}
