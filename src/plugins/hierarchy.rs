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
use crate::hierarchy::refit_order;
use crate::plugins::broad_phase::IndexBodies;
use crate::plugins::core::PrepareIndex;
use crate::plugins::validation::quarantine;
use crate::schedule::{BroadPhaseSystems, PhysicsSchedule, PhysicsSet, SubstepSchedule};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use std::time::Instant;

/// Propagates world poses down hierarchies and refits bounding volumes up them.
#[derive(Debug, Clone, Default)]
pub struct HierarchyPlugin;

impl Plugin for HierarchyPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<HierarchyScratch>()
            .add_systems(
                SubstepSchedule,
                (
                    propagate_poses.in_set(BroadPhaseSystems::Poses),
                    refit_bounding_volumes.in_set(BroadPhaseSystems::Refit),
                )
                    .run_if(any_with_component::<BoundingVolume>),
            )
            .add_systems(
                PhysicsSchedule,
                (propagate_poses, refit_bounding_volumes)
                    .chain()
                    .run_if(any_with_component::<BoundingVolume>)
                    .in_set(PhysicsSet::Finish),
            )
            .add_systems(
                PhysicsSchedule,
                (propagate_poses, refit_bounding_volumes)
                    .chain()
                    .run_if(any_with_component::<BoundingVolume>)
                    .in_set(PrepareIndex)
                    .before(IndexBodies),
            );
    }
}

#[derive(Resource, Default)]
struct HierarchyScratch {
    dirty: Vec<(u32, Entity)>,
    stack: Vec<(Entity, Isometry)>,
    order: Vec<(u32, Entity)>,
}

type LocalChanged = (
    Or<(Changed<Position>, Changed<Rotation>, Changed<ChildOf>)>,
    Without<Quarantined>,
);

/// World poses: roots copy their own pose; a subtree whose root moved, or whose local pose or
/// parent changed, is recomposed top-down (shallowest first, each node once).
fn propagate_poses(
    changed: Query<Entity, LocalChanged>,
    parents: Query<&ChildOf>,
    mut nodes: Query<(&Position, &Rotation, Option<&Children>, &mut GlobalPose)>,
    mut scratch: ResMut<HierarchyScratch>,
    mut stats: ResMut<PhysicsStats>,
) {
    let start = Instant::now();
    let s = &mut *scratch;
    s.dirty.clear();
    s.dirty
        .extend(changed.iter().map(|e| (depth(e, &parents), e)));
    s.dirty.sort_unstable();
    let mut updated = 0u32;
    for i in 0..s.dirty.len() {
        let (_, root) = s.dirty[i];
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

/// Number of ancestors of `e`.
fn depth(e: Entity, parents: &Query<&ChildOf>) -> u32 {
    let mut d = 0;
    let mut up = e;
    while let Ok(p) = parents.get(up) {
        d += 1;
        up = p.parent();
    }
    d
}

type RefitNode<'a> = (
    Option<&'a Collider>,
    &'a GlobalPose,
    Option<&'a Children>,
    &'a mut BoundingVolume,
    Has<Quarantined>,
);
type OwnChanged = (Or<(Changed<GlobalPose>, Changed<Collider>, Changed<Children>)>,);

/// Refits the volume of every node whose own collider moved or whose children changed, and of
/// their ancestors, deepest first. A bounded collider whose volume is not finite is quarantined.
#[allow(clippy::too_many_arguments)]
fn refit_bounding_volumes(
    changed: Query<Entity, OwnChanged>,
    mut removed: RemovedComponents<Collider>,
    parents: Query<&ChildOf>,
    mut nodes: Query<RefitNode>,
    mut scratch: ResMut<HierarchyScratch>,
    mut stats: ResMut<PhysicsStats>,
    mut commands: Commands,
) {
    let start = Instant::now();
    let s = &mut *scratch;
    let dirty = changed.iter().chain(removed.read());
    refit_order(
        dirty,
        |e| parents.get(e).ok().map(|p| p.parent()),
        &mut s.order,
    );
    for &(_, e) in &s.order {
        let Ok((collider, global, children, _, quarantined)) = nodes.get(e) else {
            continue;
        };
        let mut bv = match collider {
            Some(c) if !quarantined => c.shape.world_aabb(&global.0),
            _ => Aabb::EMPTY,
        };
        if collider.is_some_and(|c| !c.shape.is_unbounded()) && !quarantined && !bv.is_finite() {
            quarantine(
                &mut commands,
                e,
                format!("bounding volume is not finite: {bv:?}"),
            );
            bv = Aabb::EMPTY;
        }
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
    stats.set_counter("hierarchy/refits", s.order.len() as f64);
    stats.add_time(Stage::BroadPhase, start.elapsed());
}
