//! Waking what a joint holds when the joint goes or changes: a body asleep on a rope to the
//! world hung in the air after the rope was despawned, removed, disabled, made breakable under
//! its load or re-anchored (a user-style probe): a sleeping body is simulated by nothing until
//! something wakes it, and `wake_on_writes` wakes on the body's own writes, not on its joints
//! (`wake_on_scenery` wakes the sleepers jointed to a static the game moved or despawned). An
//! awake body at the same moment has its stillness counted from zero instead, so it cannot
//! fall asleep on the step the change is made.
//!
//! The joints' ends are remembered as they were last written (one map entry per joint), so a
//! despawned joint's bodies are still known.

use crate::components::*;
use crate::plugins::joints::ActiveJoint;
use crate::plugins::sleep::Waker;
use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;

/// A joint added or written to, disabled, or quarantined (a body of it gone or bad).
type JointChanged = Or<(Changed<Joint>, Added<JointDisabled>, Added<Quarantined>)>;

/// Each joint's bodies as last written (`None`: the world), kept from step to step.
#[derive(Default)]
pub(crate) struct JointEnds(EntityHashMap<[Option<Entity>; 2]>);

/// Wakes (or, awake, restarts the stillness of) the bodies of joints that changed, went or
/// were enabled again.
pub(crate) fn wake_on_joint_changes(
    changed: Query<(Entity, &Joint), JointChanged>,
    active: Query<&Joint, ActiveJoint>,
    (mut gone, mut enabled): (RemovedComponents<Joint>, RemovedComponents<JointDisabled>),
    mut states: Query<(&mut SleepState, Has<Sleeping>)>,
    mut waker: Waker,
    mut ends: Local<JointEnds>,
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
        let held = [Some(j.body_a), j.body_b_entity()];
        ends.0.insert(joint, held);
        held.into_iter().for_each(&mut stir);
    }
    for joint in gone.read() {
        if let Some(held) = ends.0.remove(&joint) {
            held.into_iter().for_each(&mut stir);
        }
    }
    for joint in enabled.read() {
        if let Ok(j) = active.get(joint) {
            [Some(j.body_a), j.body_b_entity()]
                .into_iter()
                .for_each(&mut stir);
        }
    }
}
