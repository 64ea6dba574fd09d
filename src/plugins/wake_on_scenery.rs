//! Waking sleepers whose support changed. A sleeping body's own writes wake it
//! (`wake_on_writes`); this wakes the sleepers touching a static body game code moved, turned,
//! reshaped, stripped of its collider or of its `Static` marker (made a body that falls), made
//! a sensor (or solid again), or gave new layers, friction or restitution, the sleepers
//! jointed to such a static, the sleepers overlapping such a static sensor (the overlap of a
//! sleeper and a static is not tested either: a zone moved off a sleeping box ended nothing,
//! and a zone made solid around one left it asleep inside), and a sleeper that lost its
//! collider or became a sensor (its island wakes with it). Without it, a box asleep on a floor
//! the game moved down by a metre hung in the air, as it did on a floor whose collider was
//! removed or that became a sensor (and, two steps long, on a floor made dynamic): the pair of
//! a sleeper and a static body is dormant (`collision_messages`), never tested again until one
//! of them wakes.
//!
//! A static spawned or moved *onto* a sleeper has no pair with it to follow, so the sleepers
//! its new volume overlaps wake too (a root static's collider; a compound's parts are placed
//! after this runs): a trigger zone placed over resting loot reports it, a wall spawned
//! through a sleeping box pushes it out. rapier reports a sensor's new overlap without waking
//! the body; here the body is awake for the half second it takes to fall asleep again.
//!
//! The statics written to are found among the *unsettled* ones only (`settle`: a write takes a
//! static's marker off before this runs), so a level of a million untouched statics costs no
//! scan; the dormant pairs are read only in a step in which something changed, and the
//! sleepers' volumes only in a step in which a static was spawned or moved (one test against
//! the new volumes' union each, then against those volumes if inside it).

use crate::bounding::Aabb;
use crate::components::*;
use crate::plugins::collision_messages::TouchingPairs;
use crate::plugins::joints::ActiveJoint;
use crate::plugins::settle::Unsettled;
use crate::plugins::sleep::Waker;
use bevy_ecs::entity::EntityHashSet;
use bevy_ecs::prelude::*;

/// Statics game code wrote something to that a body resting on them feels.
pub(crate) type SceneryWritten = (
    With<Static>,
    Unsettled,
    Or<(
        Changed<Position>,
        Changed<Rotation>,
        Changed<Collider>,
        Changed<CollisionLayers>,
        Changed<Friction>,
        Changed<Restitution>,
    )>,
);

/// A static collider outside any hierarchy, with its pose (a compound's parts are placed only
/// after this runs).
type FlatStatic<'a> = (&'a Collider, &'a Position, &'a Rotation);
type FlatStaticFilter = (With<Static>, Without<ChildOf>, Without<Children>);

/// Wakes the sleepers touching a changed static or a changed sleeper, and the changed
/// sleepers themselves (module docs).
#[allow(clippy::too_many_arguments)]
pub(crate) fn wake_on_scenery_changes(
    written: Query<Entity, SceneryWritten>,
    made_sensors: Query<Entity, Added<Sensor>>,
    (mut uncollided, mut unsensed, mut unfixed): (
        RemovedComponents<Collider>,
        RemovedComponents<Sensor>,
        RemovedComponents<Static>,
    ),
    touching: Option<Res<TouchingPairs>>,
    joints: Query<&Joint, ActiveJoint>,
    mut sleepers: Query<&mut SleepState, With<Sleeping>>,
    placed: Query<FlatStatic, FlatStaticFilter>,
    sleeping_volumes: Query<(Entity, &BoundingVolume), With<Sleeping>>,
    mut waker: Waker,
    (mut changed, mut new_volumes): (Local<EntityHashSet>, Local<Vec<Aabb>>),
) {
    changed.clear();
    changed.extend(written.iter().chain(made_sensors.iter()));
    changed.extend(
        uncollided
            .read()
            .chain(unsensed.read())
            .chain(unfixed.read()),
    );
    if changed.is_empty() {
        return;
    }
    let mut wake = |e: Entity, waker: &mut Waker| {
        if let Ok(mut state) = sleepers.get_mut(e) {
            waker.wake(e, Some(&mut state));
        }
    };
    for &e in changed.iter() {
        wake(e, &mut waker);
    }
    // A static spawned or moved onto a sleeper (a trigger zone placed over resting loot, a wall
    // spawned through a sleeping box) has no pair with it yet: the sleepers its new volume
    // overlaps wake.
    if !sleeping_volumes.is_empty() {
        new_volumes.clear();
        new_volumes.extend(
            changed
                .iter()
                .filter_map(|&e| placed.get(e).ok())
                .map(|(c, p, r)| c.shape.world_aabb(&pose(p, Some(r)))),
        );
        if let Some(reach) = new_volumes.iter().copied().reduce(|a, b| a.union(&b)) {
            for (e, bv) in &sleeping_volumes {
                let under = |v: &Aabb| v.intersects(&bv.0);
                if under(&reach) && new_volumes.iter().any(under) {
                    wake(e, &mut waker);
                }
            }
        }
    }
    // A ball asleep on a rope from a static hook hung on where the hook had been moved or
    // despawned (a user-style probe).
    for j in &joints {
        let b = j.body_b_entity();
        if let Some(b) = b.filter(|_| changed.contains(&j.body_a)) {
            wake(b, &mut waker);
        }
        if b.is_some_and(|b| changed.contains(&b)) {
            wake(j.body_a, &mut waker);
        }
    }
    let Some(touching) = touching else {
        return;
    };
    // A sleeper in a static sensor that moved, took new layers or became solid: woken, so
    // that the overlap is tested again (it ends, or the solid pushes the sleeper out).
    for &(a, b) in touching.dormant().iter().chain(touching.sensing()) {
        if changed.contains(&a) {
            wake(b, &mut waker);
        }
        if changed.contains(&b) {
            wake(a, &mut waker);
        }
    }
}
