//! Waking what a joint holds when the joint goes, changes or loses its hold: a body asleep on a
//! rope to the world hung in the air after the rope was despawned, removed, disabled, made
//! breakable under its load or re-anchored, and after the static hook it hung from was moved
//! or despawned (a user-style probe): a sleeping body is simulated by nothing until something
//! wakes it, and `wake_on_writes` and `wake_on_scenery` wake on the body's own writes and on
//! its contacts, not on its joints. An awake body at the same moment has its stillness counted
//! from zero instead, so it cannot fall asleep on the step the change is made.
//!
//! The joints' ends are remembered as they were last written (one map entry per joint), so a
//! despawned joint's bodies are still known.

use crate::components::*;
use crate::plugins::joints::ActiveJoint;
use crate::plugins::sleep::Waker;
use crate::plugins::wake_on_scenery::SceneryWritten;
use bevy_ecs::entity::{EntityHashMap, EntityHashSet};
use bevy_ecs::prelude::*;

/// A joint added or written to, disabled, or quarantined (a body of it gone or bad).
type JointChanged = Or<(Changed<Joint>, Added<JointDisabled>, Added<Quarantined>)>;

/// What the check keeps from step to step.
#[derive(Default)]
pub(crate) struct JointWatch {
    /// Each joint's bodies as last written (`None`: the world).
    ends: EntityHashMap<[Option<Entity>; 2]>,
    /// Statics written to or stripped of their collider this step.
    scenery: EntityHashSet,
}

/// Wakes (or, awake, restarts the stillness of) the bodies of joints that changed, went or
/// were enabled again, and the bodies jointed to a static that moved or lost its collider.
#[allow(clippy::too_many_arguments)]
pub(crate) fn wake_on_joint_changes(
    changed: Query<(Entity, &Joint), JointChanged>,
    active: Query<&Joint, ActiveJoint>,
    (mut gone, mut enabled): (RemovedComponents<Joint>, RemovedComponents<JointDisabled>),
    written: Query<Entity, SceneryWritten>,
    mut uncollided: RemovedComponents<Collider>,
    mut states: Query<(&mut SleepState, Has<Sleeping>)>,
    mut waker: Waker,
    mut watch: Local<JointWatch>,
) {
    let mut stir = |e: Option<Entity>| {
        let Some((e, Ok((mut state, asleep)))) = e.map(|e| (e, states.get_mut(e))) else {
            return;
        };
        if asleep {
            waker.wake(e, Some(&mut state));
        } else {
            state.restart();
        }
    };
    for (joint, j) in &changed {
        let ends = [Some(j.body_a), j.body_b_entity()];
        watch.ends.insert(joint, ends);
        ends.into_iter().for_each(&mut stir);
    }
    for joint in gone.read() {
        if let Some(ends) = watch.ends.remove(&joint) {
            ends.into_iter().for_each(&mut stir);
        }
    }
    for joint in enabled.read() {
        if let Ok(j) = active.get(joint) {
            [Some(j.body_a), j.body_b_entity()]
                .into_iter()
                .for_each(&mut stir);
        }
    }
    watch.scenery.clear();
    watch
        .scenery
        .extend(written.iter().chain(uncollided.read()));
    if watch.scenery.is_empty() {
        return;
    }
    for j in &active {
        let b = j.body_b_entity();
        if watch.scenery.contains(&j.body_a) {
            stir(b);
        }
        if b.is_some_and(|b| watch.scenery.contains(&b)) {
            stir(Some(j.body_a));
        }
    }
}
